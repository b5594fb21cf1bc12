"""``mechbal balance CASE --method METHOD --out DIR``: balance a case's mechanism and write the run.

CASE is a TOML case of kind ``mechanism`` / ``serial_chain`` (its ``[mechanism]``, ``[trajectory]``
and ``[balance]`` tables), a case of a kind that a paper registers an adapter for
(`register_case`, in ``mechbal/papers/<paper>/balance.py``: ``paminsa``, ``discs``, ``rpsp``,
``orthoglide``, ``arm2dof``; found through `mechbal.registry`, never imported here), or a URDF
file (with ``--design FILE.toml`` holding a ``[balance]`` table and optionally a ``[trajectory]``).

DIR receives (all or nothing, `mechbal.output`): ``summary.json`` (the design, the
residuals, the bounds and undetermined combinations, and before/after peak and RMS of the gravity
torque, the actuator torques, the shaking force and the shaking moment along the trajectory),
``gravity_torque.png``, ``joint_torques.png``, ``shaking_wrench.png``, ``bodies_unbalanced.npz``
and ``bodies_balanced.npz`` (the schema of `mechbal.export`), ``balanced.toml`` (a case that
``mechbal run`` runs; springs as ``[[mechanism.springs]]``), ``balanced.xml`` (MJCF, for MuJoCo:
`mechbal.export.mjcf`, the pose of the trajectory's start as keyframe) and, for trees without
springs, ``balanced.urdf`` (URDF cannot carry loops or springs: summary.json's ``urdf`` says why
instead).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from mechbal import _core, progress, report
from mechbal.balance import METHODS, common, method as method_module
from mechbal.balance.result import (
    BalanceResult, CounterweightDesign, CounterweightSlot, DiscDesign, SpringDesign)
from mechbal.errors import ConfigError
from mechbal.export import write_bodies, write_summary

#: methods written here; the others are dispatched to their modules when they exist
COUNTERWEIGHT_METHODS = ("static", "force", "rms")
DEFAULT_SAMPLES = {"static": 1000, "force": 200}


@dataclass
class BalanceCase:
    """What a balance run needs: the mechanism, the validated ``[balance]`` table (or None),
    the trajectory (actuated joints: q, v, a (N, na) and t), its description for the TOML
    written back, the assembly guess of a closed mechanism, and the source; ``default_design``:
    per method of `mechbal.balance.METHODS` outside the counterweight methods, the
    (design, samples, options) it runs without a ``[balance]`` table (the case's own design
    variables); ``notes``: what summary.json says about the case (``case_notes``)."""

    name: str
    title: str
    mechanism: Any
    table: Any
    t: np.ndarray
    motion: tuple
    trajectory_table: dict
    q_guess: np.ndarray | None
    raw: dict | None
    kind: str
    default_slots: list
    default_design: dict | None = None
    notes: dict | None = None
    #: closed mechanisms: the assembly at the start (`mechbal.assembly.Assembly.summary`)
    assembly: dict | None = None


#: what builds the BalanceCase of a validated case, and (optionally) the case written back with the
#: sized design instead of a ``kind = "mechanism"`` case: ``(cfg, raw, table, design_cfg) ->
#: BalanceCase`` and ``(bc, result) -> dict | None``
CaseBuilder = Callable[[Any, Optional[dict], Any, Any], BalanceCase]
WrittenBack = Callable[[BalanceCase, BalanceResult], Optional[dict]]


@dataclass(frozen=True)
class CaseAdapter:
    """The ``mechbal balance`` adapter of a case kind that is not general (a paper's)."""

    build: CaseBuilder
    written_back: WrittenBack | None = None


_ADAPTERS: dict[str, CaseAdapter] = {}


def register_case(kind: str, *, written_back: WrittenBack | None = None) -> Callable[[CaseBuilder], CaseBuilder]:
    """Register ``build`` as the ``mechbal balance`` adapter of case kind ``kind`` (a paper's
    ``balance.py`` does, on import; `mechbal.registry` imports it when a case is balanced)."""
    def deco(build: CaseBuilder) -> CaseBuilder:
        _ADAPTERS[kind] = CaseAdapter(build, written_back)
        return build

    return deco


def case_adapter(kind: str) -> CaseAdapter | None:
    """The registered adapter of ``kind``, or None."""
    if kind not in _ADAPTERS:
        from mechbal.registry import paper_modules

        paper_modules("balance")
    return _ADAPTERS.get(kind)


def design_trajectory(mech, design_cfg, default: dict, guess):
    """``(t, motion, trajectory_table, guess)`` of an adapter's case: the ``--design`` file's
    ``[trajectory]`` when it has one (its ``initial_guess`` replacing ``guess``), else ``default``
    (a ``[trajectory]``-like dict in the actuated joints)."""
    if design_cfg is not None and design_cfg.trajectory is not None:
        tr = design_cfg.trajectory
        if getattr(tr, "branch", None) is not None:
            raise ConfigError("trajectory.branch", "is read for kind = 'mechanism' cases; this case kind "
                              "picks its assembly with a full initial_guess", tr.branch)
        g = getattr(tr, "initial_guess", None)
        guess = guess if g is None else np.array(g, float)
        t, motion, tt = _trajectory_motion(mech, tr)
    else:
        t, motion, tt = _trajectory_motion(mech, default)
    if guess is not None:
        tt["initial_guess"] = [float(x) for x in guess]
    return t, motion, tt, guess


def slots_from_table(table, field: str = "balance.counterweights") -> list[CounterweightSlot]:
    """CounterweightSlots of ``[[balance.counterweights]]`` (validated entries)."""
    from mechbal.schema import inertia_matrix

    out = []
    for c in table.counterweights if table is not None else []:
        lo = c.mass if c.mass is not None else (c.mass_min or 0.0)
        hi = c.mass if c.mass is not None else (c.mass_max if c.mass_max is not None else math.inf)
        out.append(CounterweightSlot(
            name=c.name, link=c.link, mass_min=lo, mass_max=hi,
            max_radius=c.max_radius if c.max_radius is not None else math.inf,
            center=tuple(c.center), direction=None if c.direction is None else tuple(c.direction),
            inertia=None if c.inertia is None else inertia_matrix(c.inertia),
            position=None if c.position is None else tuple(c.position), tie=c.tie))
    return out


def _trajectory_motion(mech, tt, law=None, field="trajectory"):
    from mechbal.config import trajectory_from_config

    n = len(mech.actuated_names) if mech.is_closed else mech.dof
    table = tt if isinstance(tt, dict) else tt.model_dump(exclude_none=True)
    if law is not None:
        table = {**table, "law": law}
    table = {k: v for k, v in table.items() if k != "initial_guess"}
    if table.get("law") == "min_shaking":
        # a planned motion (mechbal.plan: `mechbal run` plans it): balance over the quintic
        # between the same ends, and say so
        import warnings

        from mechbal.errors import ConfigWarning
        from mechbal.tables import PLAN_KEYS

        warnings.warn(f"{field}.law: 'min_shaking' is planned by `mechbal run`; balancing samples the "
                      "quintic between the same start and end", ConfigWarning, stacklevel=2)
        table = {**{k: v for k, v in table.items() if k not in PLAN_KEYS}, "law": "quintic"}
    traj, t = trajectory_from_config(table, n, field)
    return t, traj.evaluate_batch(t), table


def balance_case(case: str, design: str | None = None) -> BalanceCase:
    """Read CASE (`mechbal.case.load_case`; and ``--design``) into a `BalanceCase`; ConfigError
    naming the field."""
    from mechbal.case.load import load_case
    from mechbal.config import check_case_file
    from mechbal.mechanism import Mechanism
    from mechbal.schema import Balance, ChainTrajectory, Table, validate_table

    design_cfg = None
    if design is not None:
        from mechbal.config import read_toml
        from typing import Optional

        class DesignFile(Table):
            balance: Balance
            trajectory: Optional[ChainTrajectory] = None

        path = check_case_file(design)
        design_cfg = validate_table(DesignFile, read_toml(path), "")
    if str(case).lower().endswith(".urdf"):
        try:
            mech = Mechanism.from_urdf(case)
        except AttributeError:
            raise ConfigError("case", "URDF input needs the URDF reader (mechbal._core.mechanism_from_urdf), "
                                      "which this build does not have yet", str(case)) from None
        if design_cfg is None:
            raise ConfigError("--design", "a URDF has no [balance] table: give --design FILE.toml with "
                                          "[[balance.counterweights]] (and optionally a [trajectory])", has_value=False)
        rng = np.random.default_rng(design_cfg.balance.seed)
        for key in ("initial_guess", "branch"):
            value = getattr(design_cfg.trajectory, key, None)
            if value is not None and not mech.is_closed:
                raise ConfigError(f"trajectory.{key}", "is for closed mechanisms (with loops); this URDF has none",
                                  value)
        if design_cfg.trajectory is not None:
            t, motion, tt = _trajectory_motion(mech, design_cfg.trajectory)
        else:
            # the default motion: a quintic move between two random poses of the sample box
            # (joint limits), over 1 s or longer where the URDF's velocity or effort limits need it
            from mechbal.trajectory import quintic_within_limits

            lo, hi = common.sample_box(mech, design_cfg.balance.lower, design_cfg.balance.upper)
            start, end = lo + (hi - lo) * rng.random(len(lo)), lo + (hi - lo) * rng.random(len(lo))
            duration, limits = quintic_within_limits(mech, start, end, 1.0)
            t, motion, tt = _trajectory_motion(mech, {"law": "quintic", "start": limits["start"],
                                                      "end": limits["end"], "duration": duration,
                                                      "samples": 501})
        bc = BalanceCase(mech.name, f"{mech.name} (URDF)", mech, design_cfg.balance, t, motion, tt,
                         None, None, "urdf", [])
        if design_cfg.trajectory is None:
            bc.notes = {"default_motion": limits}
        return bc
    loaded = load_case(case)
    return case_from_config(loaded.config, loaded.raw, design_cfg, source=str(loaded.source))


def case_from_config(cfg, raw: dict | None = None, design_cfg=None, *, source: str | None = None) -> BalanceCase:
    """The `BalanceCase` of a validated case (``mechbal.schema.validate_case``; ``raw`` its
    TOML table, for the case written back): what ``mechbal balance`` and the papers' runners
    balance. ``design_cfg`` (a validated ``--design`` file) replaces the case's ``[balance]`` (and
    its ``[trajectory]`` the case's trajectory). ConfigError for a kind without a general model."""
    from mechbal.mechanism import Mechanism
    from mechbal.schema import SerialChainCase

    table = design_cfg.balance if design_cfg is not None else getattr(cfg, "balance", None)
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    if isinstance(cfg, SerialChainCase):
        mech = Mechanism.from_spec(cfg.spec, name=name, source=source)
        tr = design_cfg.trajectory if design_cfg is not None and design_cfg.trajectory is not None else cfg.trajectory
        guess = getattr(tr, "initial_guess", None)
        t, motion, tt = _trajectory_motion(mech, tr)
        if guess is not None:
            tt["initial_guess"] = list(guess)
        q_guess, assembly = None if guess is None else np.array(guess, float), None
        if mech.is_closed:   # the assembly at the start, on [trajectory] branch
            from mechbal.assembly import assemble

            asm = assemble(mech, motion[0][0], branch=getattr(tr, "branch", None), initial_guess=guess)
            q_guess, assembly = asm.q, asm.summary()
        return BalanceCase(name, title, mech, table, t, motion, tt, q_guess, raw, cfg.case.kind, [],
                           assembly=assembly)
    adapter = case_adapter(cfg.case.kind)
    if adapter is not None:
        return adapter.build(cfg, raw, table, design_cfg)
    known = ", ".join(["mechanism", "serial_chain", *sorted(_ADAPTERS)])
    raise ConfigError("case.kind", f"mechbal balance reads cases of kind {known}, and URDF files "
                                   f"({cfg.case.kind!r}: its mechanism is not on the general model yet)", cfg.case.kind)


# ---- evaluation --------------------------------------------------------------------------------

def evaluate(bc: BalanceCase, mech) -> dict:
    """Along the case's trajectory: q, v, a, actuator torque, gravity torque (actuated; with
    springs the static torque, gravity plus springs: what the actuators hold still), shaking
    wrench and the bodies' poses."""
    qa, va, aa = bc.motion
    if mech.is_closed:
        m = mech.closed_motion(qa, va, aa, q_guess=bc.q_guess, with_forces=True)
        bad = (np.asarray(m.status) & ~np.uint32(int(_core.Status.singular))) != 0
        if np.any(bad):
            raise ConfigError("trajectory", f"the loops cannot be assembled at t = {bc.t[int(np.argmax(bad))]:.4g} s",
                              has_value=False)
        q, v, a, tau = m.q, m.v, m.a, m.actuated_force
        _, G = mech.reduced_mass_matrix(qa, q_guess=bc.q_guess)
        if mech.springs:  # the static torque: gravity and springs, C^T (G + K)
            G = G + np.einsum("ndk,nd->nk", m.projection, mech.spring_torque(q))
    else:
        q, v, a = qa, va, aa
        tau = mech.inverse_dynamics(q, v, a)   # springs included
        G = mech.static_torque(q)              # gravity plus springs (gravity alone without springs)
    sw = mech.shaking_wrench(q, v, a)
    bm = mech.body_motion(q, v, a)
    return dict(q=q, v=v, a=a, torque=tau, gravity_torque=G, static_torque=G, shaking_force=sw.shaking_force,
                shaking_moment=sw.shaking_moment, com=bm.com, rotation=bm.rotation)


def _stats(x: np.ndarray) -> dict:
    return {"peak": report.peak_abs(x), "rms": np.sqrt(np.mean(np.asarray(x) ** 2, axis=0))}


def _comparison(before: dict, after: dict) -> dict:
    out = {}
    for key, unit in (("static_torque", "N m or N"), ("torque", "N m or N"), ("shaking_force", "N"),
                      ("shaking_moment", "N m")):
        b, a = _stats(before[key]), _stats(after[key])
        name = "joint_torque" if key == "torque" else key
        out[name] = {"unit": unit, "unbalanced": b, "balanced": a,
                     "peak_reduction_pct": common.reduction_pct(b["peak"], a["peak"]),
                     "rms_reduction_pct": common.reduction_pct(b["rms"], a["rms"])}
    # the static torque (gravity + springs: what holds each pose) was labelled gravity_torque;
    # the old key stays one release as a deprecated copy
    out["gravity_torque"] = dict(out["static_torque"], deprecated=(
        "renamed static_torque (gravity + springs); this copy goes in the next release"))
    return out


# ---- the run -------------------------------------------------------------------------------------

#: the methods of --objective, --residual-target and --front (linear in the counterweights)
OPTIMAL_METHODS = ("static", "force")
#: why the other methods have no certified design or front (docs/guide.md, "What the convex path
#: does not cover")
NOT_CONVEX = {
    "moment": "a disc's inertia carries no mass in the model (nothing to make lightest), and a "
              "counterweight's shaking moment is linear in its second moment m |p|^2, not in (m, m p): "
              "a force-vs-moment front over point-mass counterweights is not a convex program",
    "springs": "a spring's rate carries no mass in the model (nothing to make lightest), and anchors the "
               "method may move enter the torque bilinearly; its rates are a bounded least squares",
    "rms": "the RMS torque over a motion is quadratic in the counterweights' second moments, not linear "
           "in their (m, m p)",
}


def _not_optimal(flag: str, name: str, value) -> ConfigError:
    why = NOT_CONVEX.get(name)
    return ConfigError(flag, f"is for the methods linear in the counterweights ({', '.join(OPTIMAL_METHODS)}), "
                             f"not {name!r}" + (f": {why}" if why else ""), value)


def run_method(bc: BalanceCase, name: str, *, objective: str | None = None,
               residual_target: float | None = None) -> BalanceResult:
    """Run balancing method ``name`` on the case (slots from ``[balance]``, else the case's own);
    ``objective`` and ``residual_target``: the convex stage 2 of the static and force methods
    (`mechbal.balance.optimal`)."""
    optimal_opts = {}
    for flag, v in (("--objective", objective), ("--residual-target", residual_target)):
        if v is not None and name not in OPTIMAL_METHODS:
            raise _not_optimal(flag, name, v)
    if residual_target is not None and not (math.isfinite(residual_target) and residual_target >= 0):
        raise ConfigError("--residual-target", "must be a finite number >= 0", residual_target)
    if objective is not None:
        optimal_opts["objective"] = objective
    if residual_target is not None:
        optimal_opts["residual_target"] = residual_target
    if name not in METHODS:
        raise ConfigError("--method", f"unknown balancing method (known: {', '.join(METHODS)})", name)
    try:
        module = method_module(name)
    except ModuleNotFoundError:
        raise ConfigError("--method", f"'{name}' is not available yet (mechbal.balance.{name} is being "
                                      f"written); available: {', '.join(COUNTERWEIGHT_METHODS)}",
                          has_value=False) from None
    table = bc.table
    mech = bc.mechanism
    if name not in COUNTERWEIGHT_METHODS:
        make = getattr(module, "design_from_table", None)
        if make is None:
            raise ConfigError("--method", f"mechbal.balance.{name} has no design_from_table(table, mechanism): "
                                          "mechbal balance cannot read its design", has_value=False)
        if table is None and bc.default_design is not None and name in bc.default_design:
            design, samples, options = bc.default_design[name]
            design, options = list(design), dict(options)
        else:
            design, samples, options = make(table, mech)
        import inspect

        if bc.q_guess is not None and "q_guess" in inspect.signature(module.balance).parameters:
            options.setdefault("q_guess", bc.q_guess)   # the assembly mode of a closed mechanism
        return module.balance(mech, design, samples, **options)
    slots = slots_from_table(table) or list(bc.default_slots)
    if not slots:
        raise ConfigError("balance.counterweights", "no counterweight slots: add [[balance.counterweights]] "
                                                    "entries (name, link, mass bounds, max_radius, direction)",
                          has_value=False)
    try:
        common.normalise_slots(mech, slots, field_name="balance.counterweights", need_radius=name != "rms")
    except ValueError as exc:
        raise ConfigError("", str(exc), has_value=False) from None
    budget = table.mass_budget if table is not None else None
    if name == "rms":
        opts = {}
        if table is not None:
            opts = dict(objective=table.objective, coupling=table.coupling, weights=table.weights, seed=table.seed)
        return module.balance(mech, slots, bc.motion, mass_budget=budget, q_guess=bc.q_guess, **opts)
    n = table.samples if table is not None and table.samples is not None else DEFAULT_SAMPLES[name]
    lower = table.lower if table is not None else None
    upper = table.upper if table is not None else None
    if mech.is_closed and lower is None and upper is None:  # the trajectory's range assembles
        lower, upper = np.min(bc.motion[0], axis=0), np.max(bc.motion[0], axis=0)
    width = len(mech.actuated_names) if mech.is_closed else mech.dof
    for key, v in (("lower", lower), ("upper", upper)):
        if v is not None and len(v) != width:
            raise ConfigError(f"balance.{key}", f"must have {width} values", list(v))
    kwargs = dict(mass_budget=budget, seed=table.seed if table is not None else 0, lower=lower, upper=upper,
                  q_guess=bc.q_guess)
    if optimal_opts:
        from mechbal.balance.optimal import MissingExtra

        try:
            return module.balance(mech, slots, int(n), **kwargs, **optimal_opts)
        except MissingExtra as exc:
            raise ConfigError("--objective" if objective is not None else "--residual-target", str(exc),
                              has_value=False) from None
        except ValueError as exc:
            raise ConfigError("", str(exc), has_value=False) from None
    return module.balance(mech, slots, int(n), **kwargs)


def run_front(bc: BalanceCase, name: str, points: int, out: Path) -> dict:
    """The trade-off front (`mechbal.balance.fronts`) of the case's counterweight design into
    ``out``: front.csv, front.json, front.png, front/<k>/balanced.toml. Returns what summary.json
    says of it."""
    from mechbal.balance import fronts as fr
    from mechbal.balance.optimal import MissingExtra

    if name not in OPTIMAL_METHODS:
        raise _not_optimal("--front", name, points)
    if points < 2:
        raise ConfigError("--front", "must be an integer >= 2 (the number of designs)", points)
    table = bc.table
    slots = slots_from_table(table) or list(bc.default_slots)
    n = table.samples if table is not None and table.samples is not None else DEFAULT_SAMPLES[name]
    lower = table.lower if table is not None else None
    upper = table.upper if table is not None else None
    if bc.mechanism.is_closed and lower is None and upper is None:
        lower, upper = np.min(bc.motion[0], axis=0), np.max(bc.motion[0], axis=0)
    ev = lambda m: (lambda e: {"torque": e["torque"], "shaking_force": e["shaking_force"],  # noqa: E731
                               "shaking_moment": e["shaking_moment"]})(evaluate(bc, m))
    try:
        front = fr.front(bc.mechanism, slots, points, method=name, samples=int(n),
                         mass_budget=table.mass_budget if table is not None else None,
                         seed=table.seed if table is not None else 0, lower=lower, upper=upper,
                         q_guess=bc.q_guess, evaluate=ev)
    except MissingExtra as exc:
        raise ConfigError("--front", str(exc), has_value=False) from None
    front.motion = "the case's [trajectory]"
    files = fr.write(front, out, lambda r: _balanced_toml(bc, r, name), case=bc.name,
                     title=f"{bc.title}: {name} balance, least residual per added-mass budget")
    return {"points": len(front.points), "knee": front.knee, "files": files,
            "added_mass_kg": [p.added_mass for p in front.points],
            "residual": [p.residual for p in front.points]}


def _balanced_toml(bc: BalanceCase, result: BalanceResult, method: str) -> str:
    from mechbal.export.toml import inertia_table, mechanism_table, toml_text

    cws = {k: v for k, v in result.design.items() if isinstance(v, CounterweightDesign)}
    springs = {k: v for k, v in result.design.items() if isinstance(v, SpringDesign)}
    discs = {k: v for k, v in result.design.items() if isinstance(v, DiscDesign)}
    added = ([f"counterweights " + ", ".join(
        f"{k} {v.mass:.6g} kg at {np.round(np.asarray(v.position, float), 6).tolist()} m on {v.link}"
        for k, v in cws.items())] if cws else [])
    added += ([f"springs " + ", ".join(f"{k} {v.rate:.6g} N/m x {v.count} ({v.link_a} - {v.link_b})"
                                       for k, v in springs.items())] if springs else [])
    added += ([f"discs " + ", ".join(f"{k} ({v.inertia:.6g} kg m^2, ratio {v.ratio:.6g} to {v.joint}) on {v.carrier}"
                                     for k, v in discs.items())] if discs else [])
    header = (f"{bc.name} balanced by `mechbal balance --method {method}`: " + "; ".join(added or ["nothing added"])
              + f".\nResidual {result.residual:.6g} {result.residual_units} (unbalanced {result.residual_before:.6g}).")
    case = {"name": f"{bc.name}-balanced", "kind": "mechanism", "title": f"{bc.title}, balanced ({method})"}
    tt = dict(bc.trajectory_table)
    adapter = _ADAPTERS.get(bc.kind)
    if adapter is not None and adapter.written_back is not None and bc.raw is not None:
        data = adapter.written_back(bc, result)
        if data is not None:   # the case itself with the sized design (e.g. the Orthoglide's rates)
            data["case"] = {**data["case"], **case, "kind": bc.kind}
            return toml_text(data, header)
    if bc.kind in ("mechanism", "serial_chain", "rpsp") and bc.raw is not None:
        # the case itself with the balancing elements added (rpsp: its counterweight bodies, which
        # the case lists with the paper's masses, replaced by the sized ones)
        data = copy.deepcopy(bc.raw)
        data.pop("balance", None)
        data["case"] = {**data["case"], **case, "kind": bc.kind}
        mech = data["mechanism"]
        own = set(bc.mechanism.body_names)
        bodies = [b for b in mech.get("bodies", []) if b.get("name") in own or b.get("name") not in
                  {x.name for x in result.balanced.bodies}]
        for b in result.balanced.bodies:   # the counterweights, back in the user's link frames
            if b.name in own:
                continue
            T = bc.mechanism.user_frame(b.link)
            R, t = T[:3, :3], T[:3, 3]
            com = R.T @ (np.asarray(b.com, float) - t)
            I = R.T @ np.asarray(b.inertia, float) @ R
            bodies.append({"name": b.name, "kind": "counterweight", "link": b.link, "mass": float(b.mass),
                           "com": com.tolist(), "inertia": inertia_table(I)})
        mech["bodies"] = bodies
        springs = list(mech.get("springs", []))
        own_springs = set(bc.mechanism.spring_names)
        root = result.balanced.model.root_name
        for sp in result.balanced.springs:   # the springs, back in the user's link frames
            if sp.name in own_springs:
                continue
            entry = {"name": sp.name}
            for side in ("a", "b"):
                link = getattr(sp, f"link_{side}")
                T = bc.mechanism.user_frame(link)
                anchor = T[:3, :3].T @ (np.asarray(getattr(sp, f"anchor_{side}"), float) - T[:3, 3])
                entry[f"link_{side}"] = "base" if link == root else link
                entry[f"anchor_{side}"] = anchor.tolist()
            entry.update(rate=float(sp.rate), free_length=float(sp.free_length), preload=float(sp.preload),
                         count=int(sp.count), pulley_ratio=float(sp.pulley_ratio))
            springs.append(entry)
        if springs:
            mech["springs"] = springs
        return toml_text(data, header)
    data = {"case": case, "mechanism": mechanism_table(result.balanced), "trajectory": tt}
    return toml_text(data, header)


def run_balance(case: str, method: str | None, out: Path, design: str | None = None, *,
                objective: str | None = None, residual_target: float | None = None,
                front: int | None = None, partial: bool = False,
                shaking_target: float | None = None) -> dict:
    """The whole run into ``out`` (a fresh folder: the caller stages it). Returns the summary.
    ``objective``, ``residual_target``: `run_method`'s; ``front``: also the trade-off front of
    that many designs (`run_front`); ``partial``: the combined design of the force method under
    the case's mass budget plus a minimum-shaking motion (`run_partial`), ``shaking_target`` [N]
    its goal on the RMS shaking force."""
    progress.stage("reading the case")
    bc = balance_case(case, design)
    name = method or (bc.table.method if bc.table is not None else None)
    if name is None:
        raise ConfigError("--method", "give --method static|force|moment|springs|rms (or balance.method "
                                      "in the case)", has_value=False)
    if shaking_target is not None and not partial:
        raise ConfigError("--shaking-target", "is the goal of --partial (the combined design)", shaking_target)
    if partial:
        _check_partial(bc, name, shaking_target)
    progress.stage(f"balancing ({name})")
    result = run_method(bc, name, objective=objective, residual_target=residual_target)
    progress.stage("evaluating the trajectory")
    before = evaluate(bc, bc.mechanism)
    after = evaluate(bc, result.balanced)
    progress.stage("files")
    for label, mech, ev in (("unbalanced", bc.mechanism, before), ("balanced", result.balanced, after)):
        bodies = mech.bodies
        write_bodies(out / f"bodies_{label}.npz", t=bc.t, names=mech.body_names,
                     mass=np.array([b.mass for b in bodies]),
                     inertia_body=np.array([b.inertia for b in bodies]).reshape(-1, 3, 3),
                     com=ev["com"], rotation=ev["rotation"], shaking_force=ev["shaking_force"],
                     shaking_moment=ev["shaking_moment"], q=ev["q"], qd=ev["v"], qdd=ev["a"],
                     torque=ev["torque"], gravity_torque=ev["gravity_torque"])
    joints = bc.mechanism.actuated_names
    types = {j.name: j.type for j in bc.mechanism.model.description.joints}
    units = ["N" if types.get(n) == _core.JointType.prismatic else "N m" for n in joints]
    variants = {"unbalanced": before, "balanced": after}
    title = f"{bc.title}: {name} balancing"
    sprung = bool(result.balanced.springs or bc.mechanism.springs)
    report.plot_series(out / "gravity_torque.png", bc.t, {k: v["gravity_torque"] for k, v in variants.items()},
                       joints, [f"{'static' if sprung else 'gravity'} torque [{u}]" for u in units], title=title,
                       caption=("Static torque (gravity + springs: the actuator torque that holds each pose)"
                                if sprung else "Gravity torque (the actuator torque that holds each pose)")
                               + " along the trajectory, before and after balancing.")
    report.plot_series(out / "joint_torques.png", bc.t, {k: v["torque"] for k, v in variants.items()},
                       joints, [f"torque [{u}]" for u in units], title=title,
                       caption="Actuator torque (revolute) or force (prismatic) along the trajectory, "
                               "gravity included, before and after balancing.")
    report.plot_wrench(out / "shaking_wrench.png", bc.t,
                       {k: (v["shaking_force"], v["shaking_moment"]) for k, v in variants.items()},
                       title=title, caption="Shaking force dP/dt and shaking moment dH_O/dt about the base "
                                            "origin (inertial only), before and after balancing.")
    files = ["bodies_unbalanced.npz", "bodies_balanced.npz", "gravity_torque.png", "joint_torques.png",
             "shaking_wrench.png", "balanced.toml"]
    (out / "balanced.toml").write_text(_balanced_toml(bc, result, name))
    from mechbal.export.common import ExportError
    from mechbal.export.urdf import urdf_refusal, urdf_text

    from mechbal.export.mujoco_engine import validate_mjcf

    export_notes, mjcf_validation = {}, None
    try:   # MJCF: any mechanism, assembled at the trajectory's start
        mjcf = result.balanced.to_mjcf(q=after["q"][0], q_guess=bc.q_guess, name=f"{bc.name}-balanced")
    except ExportError as exc:
        export_notes["mjcf"] = f"no balanced.xml: {exc}"
    else:
        try:   # loaded in MuJoCo (when installed): a file MuJoCo refuses is an error, not a note
            mjcf_validation = validate_mjcf(mjcf)
        except ExportError as exc:
            raise ExportError(f"balanced.xml: {exc}") from None
        (out / "balanced.xml").write_text(mjcf)
        files.append("balanced.xml")
    why = urdf_refusal(result.balanced)   # no URDF that silently drops loops or springs
    if why:
        export_notes["urdf"] = f"no balanced.urdf: {why}; balanced.toml and balanced.xml carry them"
    else:
        (out / "balanced.urdf").write_text(urdf_text(result.balanced, f"{bc.name}-balanced"))
        files.append("balanced.urdf")
    progress.stage("summary")
    summary = {"case": bc.name, "kind": bc.kind, "method": name, "mechanism": repr(bc.mechanism),
               "actuated": joints, "closed": bc.mechanism.is_closed,
               "balance": result.summary(),
               "trajectory": {k: v for k, v in bc.trajectory_table.items()},
               "before_after": _comparison(before, after),
               "total_mass": {"unbalanced": bc.mechanism.total_mass, "balanced": result.balanced.total_mass},
               "files": files}
    summary.update(export_notes)
    if "optimality" in result.metrics:
        summary["optimality"] = result.metrics["optimality"]
    if front is not None:
        progress.stage("front")
        summary["front"] = run_front(bc, name, int(front), out)
        files += ["front.csv", "front.json", "front.png"]
    if partial:
        progress.stage("planning the motion (--partial)")
        combined = run_partial(bc, result, out, shaking_target)
        summary["partial"] = combined.summary()
        files += ["partial_shaking_wrench.png"]
    if mjcf_validation is not None:
        summary["mjcf_validation"] = mjcf_validation
    if bc.assembly is not None:
        summary["assembly"] = bc.assembly
    if bc.notes:
        summary["case_notes"] = bc.notes
    write_summary(out / "summary.json", summary, command="balance")
    rows = [[k, v.mass, np.asarray(v.position, float), ", ".join(v.active_bounds) or "-"]
            for k, v in result.design.items() if isinstance(v, CounterweightDesign)]
    if rows:
        print(report.table(rows, ["counterweight", "mass [kg]", "position [m] (link frame)", "active bounds"]))
    rows = [[k, v.rate, v.count, v.pulley_ratio, v.peak_tension]
            for k, v in result.design.items() if isinstance(v, SpringDesign)]
    if rows:
        print(report.table(rows, ["spring", "rate [N/m]", "count", "pulley ratio", "peak tension [N]"]))
    discs = [[k, v.carrier, v.joint, v.ratio, v.inertia] for k, v in result.design.items()
             if isinstance(v, DiscDesign)]
    if discs:
        print(report.table(discs, ["disc", "carrier", "geared to", "ratio", "inertia [kg m^2]"]))
    cmp = summary["before_after"]
    print(report.table([[k, cmp[k]["unbalanced"]["peak"], cmp[k]["balanced"]["peak"]] for k in cmp],
                       ["peak along the trajectory", "unbalanced", "balanced"]))
    print(f"residual {result.residual:.4g} {result.residual_units} (unbalanced {result.residual_before:.4g})"
          + ("" if result.exact else "; limited by: " + "; ".join(result.limited_by)))
    if partial:
        print(report.table(combined.table_rows(), combined.TABLE_HEADER))
        print(f"combined design (counterweights {combined.added_mass:.4g} kg of {combined.mass_budget:g} kg, "
              f"min-shaking motion): " + ("ok" if combined.ok else "NOT ok: " + "; ".join(combined.limited_by)))
    return summary


def _check_partial(bc: BalanceCase, name: str, shaking_target: float | None) -> None:
    """--partial's requirements, before the long run: the force method, a mass budget, a
    rest-to-rest trajectory."""
    if name != "force":
        raise ConfigError("--partial", f"is the combined design of the force method (counterweights under a "
                                       f"mass budget plus a min-shaking motion), not of {name!r}", has_value=False)
    if bc.table is None or bc.table.mass_budget is None:
        raise ConfigError("balance.mass_budget", "--partial needs a mass budget (kg, the total counterweight "
                                                 "mass): add mass_budget to [balance]", has_value=False)
    tt = bc.trajectory_table
    if tt.get("law", "quintic") not in ("quintic", "cubic") or "end" not in tt:
        raise ConfigError("trajectory.law", "--partial plans a rest-to-rest motion between start and end in "
                                            "duration (law quintic, cubic or min_shaking)", tt.get("law"))
    if shaking_target is not None and not (np.isfinite(shaking_target) and shaking_target > 0):
        raise ConfigError("--shaking-target", "must be a finite force > 0 (N)", shaking_target)


def run_partial(bc: BalanceCase, result: BalanceResult, out: Path, shaking_target: float | None = None):
    """The combined design (`mechbal.plan.partial`) of a force balance under the case's mass budget:
    the four-way comparison, its plot (partial_shaking_wrench.png) and verdict."""
    from mechbal.plan.partial import LABELS, VARIANTS, combined_design, plan_options_of

    tt = bc.trajectory_table
    added = float(sum(v.mass for v in result.design.values() if isinstance(v, CounterweightDesign)))
    raw_tr = (bc.raw or {}).get("trajectory") if isinstance(bc.raw, dict) else None
    combined = combined_design(bc.mechanism, result.balanced, tt["start"], tt["end"], float(tt["duration"]),
                               added_mass=added, mass_budget=float(bc.table.mass_budget),
                               shaking_target=shaking_target, budget_active="mass_budget" in result.active_bounds,
                               samples=len(bc.t), q_guess=bc.q_guess, plan_options=plan_options_of(raw_tr))
    report.plot_wrench(out / "partial_shaking_wrench.png", np.linspace(0.0, float(tt["duration"]), len(bc.t)),
                       {LABELS[k]: combined.series[k] for k in VARIANTS},
                       title=f"{bc.title}: counterweights within {bc.table.mass_budget:g} kg and the planned motion",
                       caption="Shaking force and shaking moment about O of the quintic and of the motion that "
                               "minimises shaking, on the unbalanced mechanism and with the counterweights.")
    return combined
