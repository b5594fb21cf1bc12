"""Sweep definitions: `Parameter` (a path and its distribution or grid) and `Sweep`
(a mechanism, its parameters, metrics, workspace sample and trajectory, and the kind of sweep),
which generates every parameter set up front from its seed and runs them on a backend.

Layer: methods (docs/architecture.md)."""
from __future__ import annotations

import itertools
import math
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np
import numpy.typing as npt

from mechbal.errors import ConfigError
from mechbal.sweep.metrics import STATIC, MetricSpec, resolve
from mechbal.sweep.parameters import Target, nominal_value, parse_path

if TYPE_CHECKING:
    from mechbal.sweep.results import SweepResult

KINDS = ("monte_carlo", "sensitivity", "grid")
#: largest number of evaluations of one sweep (rows of the table)
MAX_EVALUATIONS = 10_000_000
#: default evaluations per task: batched sets are cheap (a matrix product each), rebuilt ones not
CHUNK_BATCHED = 4096
CHUNK_REBUILT = 64


@dataclass(frozen=True)
class Parameter:
    """A swept number: ``path`` (see `mechbal.sweep.parameters`) and exactly one range:

    - ``tolerance``: relative, nominal x (1 -+ tolerance); ``delta``: absolute, nominal -+ delta;
      ``lower``/``upper``: absolute bounds; the range is sampled uniformly, or with
      ``distribution = "normal"`` as a normal law whose 3-sigma half-width is the tolerance
      (mean the nominal);
    - ``std`` (with ``distribution = "normal"``, optional ``mean``, default the nominal);
    - ``values``: a list (Monte Carlo draws from it uniformly, a grid takes each value).

    A sensitivity sweep takes the two ends of the range (mean -+ 3 sigma for a normal law, min and
    max of a list); a grid takes ``steps`` evenly spaced values across it (default 3) or the list.
    ``nominal`` overrides the mechanism's value (required for a design variable)."""

    path: str
    distribution: str = "uniform"
    tolerance: float | None = None
    delta: float | None = None
    lower: float | None = None
    upper: float | None = None
    mean: float | None = None
    std: float | None = None
    values: Sequence[float] | None = None
    nominal: float | None = None
    steps: int | None = None


@dataclass(frozen=True)
class Resolved:
    """A parameter against a mechanism: its target, nominal value and law."""
    path: str
    target: Target
    nominal: float
    law: str              # uniform | normal | list
    lower: float = math.nan
    upper: float = math.nan
    mean: float = math.nan
    std: float = math.nan
    values: tuple = ()
    steps: int = 3

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        if self.law == "uniform":
            return rng.uniform(self.lower, self.upper, n)
        if self.law == "normal":
            return rng.normal(self.mean, self.std, n)
        return np.asarray(self.values, float)[rng.integers(0, len(self.values), n)]

    def ends(self) -> tuple[float, float]:
        """(low, high) of a sensitivity sweep."""
        if self.law == "uniform":
            return self.lower, self.upper
        if self.law == "normal":
            return self.mean - 3.0 * self.std, self.mean + 3.0 * self.std
        return float(min(self.values)), float(max(self.values))

    def grid(self) -> np.ndarray:
        if self.law == "list":
            return np.asarray(self.values, float)
        lo, hi = self.ends()
        return np.linspace(lo, hi, self.steps)


def resolve_parameter(p: Parameter, spec, field: str) -> Resolved:
    target = parse_path(p.path, f"{field}.path")
    if p.nominal is not None:
        nominal = float(p.nominal)
        if target.kind != "design":
            nominal_value(spec, target, f"{field}.path")  # the path must exist
    else:
        nominal = nominal_value(spec, target, f"{field}.path")
    if p.distribution not in ("uniform", "normal"):
        raise ConfigError(f"{field}.distribution", "must be one of uniform, normal", p.distribution)
    given = [k for k in ("tolerance", "delta", "lower", "std", "values") if getattr(p, k) is not None]
    if p.upper is not None and p.lower is None:
        given.append("upper")
    if len(given) != 1:
        raise ConfigError(field, "give exactly one range: tolerance, delta, lower and upper, std (normal) "
                                 f"or values (got {', '.join(given) or 'none'})", has_value=False)
    how = given[0]
    steps = 3 if p.steps is None else int(p.steps)
    if steps < 2:
        raise ConfigError(f"{field}.steps", "must be >= 2", p.steps)
    if how == "values":
        values = tuple(float(v) for v in p.values)
        if not values or not all(math.isfinite(v) for v in values):
            raise ConfigError(f"{field}.values", "must be a non-empty list of finite numbers", p.values)
        return Resolved(p.path, target, nominal, "list", values=values, steps=steps)
    if how == "std":
        if p.distribution != "normal":
            raise ConfigError(f"{field}.std", "is for distribution = \"normal\"", p.std)
        mean = nominal if p.mean is None else float(p.mean)
        return Resolved(p.path, target, nominal, "normal", mean=mean, std=float(p.std), steps=steps)
    if p.mean is not None:
        raise ConfigError(f"{field}.mean", "goes with std (a normal law)", p.mean)
    if how == "lower":
        if p.upper is None:
            raise ConfigError(f"{field}.upper", "is required with lower", has_value=False)
        lo, hi = float(p.lower), float(p.upper)
        if not lo <= hi:
            raise ConfigError(f"{field}.upper", f"must be >= lower = {lo!r}", p.upper)
    else:
        half = abs(nominal) * float(p.tolerance) if how == "tolerance" else float(p.delta)
        if half < 0 or not math.isfinite(half):
            raise ConfigError(f"{field}.{how}", "must be a finite number >= 0", getattr(p, how))
        lo, hi = nominal - half, nominal + half
    if p.distribution == "normal":
        return Resolved(p.path, target, nominal, "normal", lower=lo, upper=hi, mean=0.5 * (lo + hi),
                        std=(hi - lo) / 6.0, steps=steps)
    return Resolved(p.path, target, nominal, "uniform", lower=lo, upper=hi, steps=steps)


# ---- the base mechanism ----------------------------------------------------------------------------

def spec_of_mechanism(mech) -> Any:
    """A `mechbal.spec.MechanismSpec` of a built `mechbal.Mechanism` (from its
    model's description: the way to sweep a URDF robot)."""
    from mechbal import _core
    from mechbal.spec import BodySpec, FrameSpec, JointSpec, LoopSpec, MechanismSpec, SpringSpec

    d = mech.model.description
    names = {_core.JointType.revolute: "revolute", _core.JointType.prismatic: "prismatic",
             _core.JointType.fixed: "fixed"}
    loop_names = {_core.LoopType.point: "point", _core.LoopType.planar_point: "planar_point",
                  _core.LoopType.axis: "axis", _core.LoopType.weld: "weld"}
    root = d.root_name  # a URDF's root link: "base" in a spec
    link = lambda name: "base" if name == root else name  # noqa: E731
    joints = []
    for j in d.joints:
        mimic = (j.mimic_joint, float(j.mimic_ratio), float(j.mimic_offset)) if j.mimic_joint else None
        joints.append(JointSpec(j.name, names[j.type], link(j.parent), np.array(j.placement), np.array(j.axis),
                                float(j.lower), float(j.upper), float(j.velocity_limit),
                                float(j.effort_limit), mimic))
    bodies = [BodySpec(b.name, b.kind, link(b.link), float(b.mass), np.array(b.com), np.array(b.inertia))
              for b in d.bodies]
    frames = [FrameSpec(f.name, link(f.link), np.array(f.placement)) for f in d.frames]
    loops = [LoopSpec(lp.name, loop_names[lp.type], lp.frame_a, lp.frame_b) for lp in d.loops]
    springs = [SpringSpec(sp.name, link(sp.link_a), np.array(sp.anchor_a), link(sp.link_b), np.array(sp.anchor_b),
                          float(sp.rate), float(sp.free_length), float(sp.preload), int(sp.count),
                          float(sp.pulley_ratio)) for sp in d.springs]
    return MechanismSpec(np.array(d.gravity), joints, bodies, frames, loops, list(d.actuated), springs=springs)


@dataclass
class Base:
    """The mechanism a sweep varies, with its default motion."""
    name: str
    spec: Any
    trajectory: tuple | None = None   # (t, qa, va, aa) of the actuated joints
    q_guess: np.ndarray | None = None


def load_base(case, trajectory_samples: int | None = None) -> Base:
    """The base of a sweep from a built-in case name, a TOML case file (``[mechanism]`` and
    ``[trajectory]``), a URDF file (its default trajectory), a `mechbal.Mechanism` or a
    `mechbal.spec.MechanismSpec`."""
    from mechbal.case.load import load_case
    from mechbal.config import trajectory_from_config
    from mechbal.mechanism import Mechanism
    from mechbal.schema import SerialChainCase
    from mechbal.spec import MechanismSpec

    if isinstance(case, MechanismSpec):
        return Base("mechanism", case)
    if isinstance(case, Mechanism):
        return Base(case.name, spec_of_mechanism(case))
    if str(case).lower().endswith(".urdf"):
        from mechbal._core import RestToRestTrajectory, TimeLaw
        from mechbal.case.load import DEFAULT_DURATION, DEFAULT_SAMPLES
        from mechbal.trajectory import default_motion

        mech = Mechanism.from_urdf(case)
        start, end = default_motion(mech)
        traj = RestToRestTrajectory(start, end, DEFAULT_DURATION, TimeLaw.quintic)
        t = np.linspace(0.0, DEFAULT_DURATION, trajectory_samples or DEFAULT_SAMPLES)
        return Base(mech.name, spec_of_mechanism(mech), (t, *traj.evaluate_batch(t)))
    validated = load_case(case, warn=False).config
    if not isinstance(validated, SerialChainCase):
        raise ConfigError("case.kind", "a sweep needs a case of kind mechanism or serial_chain "
                                       "(a [mechanism] table)", validated.case.kind)
    spec = validated.spec
    na = len(spec.actuated) if spec.loops else spec.dof
    tr = validated.trajectory
    if trajectory_samples is not None:
        tr = tr.model_copy(update={"samples": int(trajectory_samples)})
    traj, t = trajectory_from_config(tr, na)
    guess = tr.initial_guess
    return Base(validated.case.name, spec, (t, *traj.evaluate_batch(t)),
                None if guess is None else np.array(guess, float))


# ---- the sweep --------------------------------------------------------------------------------------

class Sweep:
    """A sweep over a mechanism (see the package docstring of `mechbal.sweep`).

    ``case``: a built-in case name, a TOML or URDF path, a `mechbal.Mechanism` or a
    `mechbal.spec.MechanismSpec`; ``parameters``: `Parameter` objects (or dicts of
    their fields); ``metrics``: built-in names and/or ``{name: callable}`` (see
    `mechbal.sweep.metrics`); ``kind``: monte_carlo (``evaluations`` draws from ``seed``),
    sensitivity (nominal, then each parameter at the low and high end of its range, the others
    nominal) or grid (every combination). ``poses``: the workspace sample of the gravity metrics,
    an (P, na) array of actuated coordinates, or generated: ``pose_source`` "trajectory"
    (``pose_count`` instants evenly spread along the trajectory; the default when there is one) or
    "uniform" (uniform in ``pose_lower``/``pose_upper``, default the joint limits or -+pi, from the
    seed). ``trajectory``: (qa, va, aa) arrays (N, na) of the actuated joints, default the case's
    (``trajectory_samples`` instants). ``chunk_size``: evaluations per task (default 4096 when
    every set is batched, 64 otherwise)."""

    def __init__(self, case: Any, parameters: Sequence[Parameter | Mapping[str, Any]],
                 metrics: str | Sequence[str] | Mapping[str, Callable[..., Any]] | Sequence[Any], *,
                 kind: str = "monte_carlo", evaluations: int | None = None, seed: int = 0,
                 poses: npt.ArrayLike | None = None, pose_count: int = 100,
                 pose_source: str | None = None, pose_lower: npt.ArrayLike | None = None,
                 pose_upper: npt.ArrayLike | None = None,
                 trajectory: tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike] | None = None,
                 trajectory_samples: int | None = None, q_guess: npt.ArrayLike | None = None,
                 chunk_size: int | None = None, name: str = "sweep", title: str = "") -> None:
        self.base = case if isinstance(case, Base) else load_base(case, trajectory_samples)
        self.name, self.title = name, title
        if kind not in KINDS:
            from mechbal.schema import did_you_mean
            raise ConfigError("kind", f"must be one of {', '.join(KINDS)}{did_you_mean(kind, list(KINDS))}", kind)
        self.kind = kind
        if kind == "monte_carlo":
            if evaluations is None or not 1 <= int(evaluations) <= MAX_EVALUATIONS:
                raise ConfigError("evaluations", f"a Monte Carlo sweep needs 1 .. {MAX_EVALUATIONS} evaluations",
                                  evaluations)
        self.evaluations = None if evaluations is None else int(evaluations)
        self.seed = int(seed)
        spec = self.base.spec
        params = [p if isinstance(p, Parameter) else Parameter(**p) for p in parameters]
        if not params:
            raise ConfigError("parameters", "must declare at least one parameter", has_value=False)
        self.parameters = [resolve_parameter(p, spec, f"parameters[{i}]") for i, p in enumerate(params)]
        paths = [p.path for p in self.parameters]
        for i, p in enumerate(paths):
            if p in paths[:i]:
                raise ConfigError(f"parameters[{i}].path", "declared twice", p)
        from mechbal.mechanism import Mechanism

        self._nominal_mech = Mechanism.from_spec(spec, name=self.base.name)
        self.actuated = self._nominal_mech.actuated_names
        self.metrics: list[MetricSpec] = resolve(metrics, self.actuated)
        self.chunk_size = None if chunk_size is None else int(chunk_size)
        if self.chunk_size is not None and self.chunk_size < 1:
            raise ConfigError("chunk_size", "must be >= 1", chunk_size)
        self.q_guess = (np.asarray(q_guess, float) if q_guess is not None else self.base.q_guess)
        wanted = {m.quantity for m in self.metrics if m.builtin}
        # trajectory
        if trajectory is not None:
            qa, va, aa = (np.ascontiguousarray(x, dtype=float) for x in trajectory)
            self.trajectory = (qa, va, aa)
        elif self.base.trajectory is not None:
            self.trajectory = tuple(np.ascontiguousarray(x) for x in self.base.trajectory[1:])
        else:
            self.trajectory = None
        if wanted - set(STATIC) and self.trajectory is None:
            raise ConfigError("metrics", "trajectory metrics need a trajectory (a case with [trajectory], "
                                         "or trajectory=(q, v, a))", has_value=False)
        # workspace sample
        self.poses = None
        if wanted & set(STATIC) or poses is not None:
            self.poses = self._poses(poses, pose_count, pose_source, pose_lower, pose_upper)

    def _poses(self, poses, count, source, lower, upper) -> np.ndarray:
        na = len(self.actuated)
        if poses is not None:
            poses = np.ascontiguousarray(poses, dtype=float)
            if poses.ndim != 2 or poses.shape[1] != na:
                raise ConfigError("poses", f"must have shape (P, {na})", poses.shape)
            return poses
        source = source or ("trajectory" if self.trajectory is not None else "uniform")
        if not 1 <= int(count) <= 100_000:
            raise ConfigError("poses.count", "must be between 1 and 100000", count)
        if source == "trajectory":
            if self.trajectory is None:
                raise ConfigError("poses.source", "there is no trajectory to take poses from", source)
            qa = self.trajectory[0]
            return np.ascontiguousarray(qa[np.linspace(0, len(qa) - 1, int(count)).round().astype(int)])
        if source != "uniform":
            raise ConfigError("poses.source", "must be one of trajectory, uniform", source)
        mech = self._nominal_mech
        index = [mech.joint_names.index(n) for n in self.actuated]
        lim_lo = np.asarray(mech.model.lower_limits, float)[index]
        lim_hi = np.asarray(mech.model.upper_limits, float)[index]
        lo = np.where(np.isfinite(lim_lo), lim_lo, -math.pi) if lower is None else np.asarray(lower, float)
        hi = np.where(np.isfinite(lim_hi), lim_hi, math.pi) if upper is None else np.asarray(upper, float)
        for key, v in (("lower", lo), ("upper", hi)):
            if v.shape != (na,):
                raise ConfigError(f"poses.{key}", f"must have {na} values (one per actuated joint: "
                                                  f"{', '.join(self.actuated)})", v.tolist())
        if np.any(lo > hi):
            raise ConfigError("poses.upper", "must be >= poses.lower", hi.tolist())
        rng = np.random.default_rng([self.seed, 1])  # a stream of its own: poses do not shift the sets
        return rng.uniform(lo, hi, (int(count), na))

    # ---- parameter sets -------------------------------------------------------------------------
    @property
    def paths(self) -> list[str]:
        return [p.path for p in self.parameters]

    @property
    def nominal(self) -> np.ndarray:
        return np.array([p.nominal for p in self.parameters])

    def sets(self) -> tuple[np.ndarray, dict[str, list]]:
        """Every parameter set (S, parameters), generated up front, and label columns (a
        sensitivity sweep's ``parameter`` and ``level``)."""
        nominal = self.nominal
        if self.kind == "monte_carlo":
            rng = np.random.default_rng([self.seed, 0])
            values = np.column_stack([p.sample(rng, self.evaluations) for p in self.parameters])
            return values, {}
        if self.kind == "sensitivity":
            rows, which, level = [nominal.copy()], ["nominal"], ["nominal"]
            for i, p in enumerate(self.parameters):
                for lv, x in zip(("low", "high"), p.ends()):
                    r = nominal.copy()
                    r[i] = x
                    rows.append(r)
                    which.append(p.path)
                    level.append(lv)
            return np.array(rows), {"parameter": which, "level": level}
        grids = [p.grid() for p in self.parameters]
        size = math.prod(len(g) for g in grids)
        if size > MAX_EVALUATIONS:
            raise ConfigError("parameters", f"the grid has {size} points, more than {MAX_EVALUATIONS}",
                              has_value=False)
        return np.array(list(itertools.product(*grids)), dtype=float).reshape(size, len(grids)), {}

    def plan(self):
        from mechbal.sweep.evaluate import Plan, discover_callable_keys

        plan = Plan(token=uuid.uuid4().hex, spec=self.base.spec, paths=self.paths,
                    targets=[p.target for p in self.parameters], nominal=self.nominal,
                    metrics=self.metrics, poses=self.poses, trajectory=self.trajectory,
                    q_guess=self.q_guess,
                    design_names=[p.path for p in self.parameters if p.target.kind == "design"])
        plan.callable_keys = discover_callable_keys(plan, self._nominal_mech)
        return plan

    def default_chunk_size(self) -> int:
        if self.chunk_size is not None:
            return self.chunk_size
        rebuilt = any(not p.target.batched for p in self.parameters) or any(not m.builtin for m in self.metrics)
        return CHUNK_REBUILT if rebuilt else CHUNK_BATCHED

    def run(self, backend: str = "auto", *, workers: int | None = None, scheduler: Any = None,
            progress: bool = True,
            callback: Callable[[int, int], object] | None = None) -> SweepResult:
        """Evaluate every set: ``backend`` auto (serial unless the sweep would take longer than
        `mechbal.sweep.backends.AUTO_SERIAL_SECONDS` in one process, judged from its first
        chunk; then processes), serial, processes (``workers`` local processes, default
        every core, through Dask's process scheduler) or dask (a distributed cluster: ``scheduler``
        an address ``tcp://host:port`` or a ``distributed.Client``); ``callback(done, total)``
        is called with the chunks done after each one (progress in a notebook). Returns a
        `mechbal.sweep.results.SweepResult`; the table is the same on every backend."""
        from mechbal.sweep.backends import run_chunks
        from mechbal.sweep.evaluate import evaluate_chunk
        from mechbal.sweep.results import SweepResult

        values, labels = self.sets()
        plan = self.plan()
        size = self.default_chunk_size()
        chunks = [(start, values[start:start + size]) for start in range(0, len(values), size)]
        results = run_chunks(plan, chunks, backend=backend, workers=workers, scheduler=scheduler,
                             progress=progress, callback=callback)
        nominal = evaluate_chunk(plan, 0, self.nominal[None, :])
        return SweepResult.assemble(self, plan, values, labels, results, nominal)


__all__ = ["Base", "KINDS", "MAX_EVALUATIONS", "Parameter", "Resolved", "Sweep", "load_base",
           "resolve_parameter", "spec_of_mechanism"]
