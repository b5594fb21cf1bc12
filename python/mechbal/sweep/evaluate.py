"""Evaluation of parameter sets: the plan shipped to workers, the per-process context built from it
once, and `evaluate_chunk`, the pure function every backend runs.

A chunk's result depends only on the plan and the chunk's rows (never on the backend, the worker
or the order of execution), which is what makes a seeded sweep give the same table serially, on
local processes and on a cluster.

Two paths:

- **batched** (a set that changes only body parameters): the regressors Y(q) of the nominal model
  are evaluated once per process (gravity regressor at the poses, torque regressor along the
  trajectory, and the momentum-rate regressor, read as the torques of six virtual base joints of a
  weightless copy of the model); each set's inertial parameters pi are computed in numpy, and each
  quantity is ``Y pi`` for a whole block of sets in one matrix product;
- **rebuilt** (a set that changes a joint or gravity, and every set for a callable metric): the
  spec is changed, the model rebuilt and evaluated directly.

For a closed mechanism the loops are solved on the nominal model (batched) or the rebuilt one, and
the actuated forces are C^T tau, C the coupling matrix of v = C v# (read column by column from the
loop solve of unit actuated velocities).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import dataclasses
import inspect
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechbal.sweep.metrics import STATIC, MetricSpec
from mechbal.sweep.parameters import Target, apply_values, inertial_parameters, physical_status

#: names of the six virtual base joints of the momentum-rate model
_VIRTUAL = ("__sweep_px", "__sweep_py", "__sweep_pz", "__sweep_rx", "__sweep_ry", "__sweep_rz")
#: largest rows x sets block of one regressor product: ~2 MB of float64, so that the product and
#: the statistics over it stay in cache (the work is memory-bound, not flop-bound)
_BLOCK_ELEMENTS = 262_144


@dataclass
class Plan:
    """Everything a worker needs, picklable: the nominal spec, the parameters (targets and nominal
    values), the metrics, the workspace sample (actuated coordinates at ``poses``), the trajectory
    (actuated ``q, v, a``), initial guesses for closed loops, and which callable metrics return
    which keys. ``token`` identifies the plan in a worker's context cache."""

    token: str
    spec: Any
    paths: list[str]
    targets: list[Target]
    nominal: np.ndarray
    metrics: list[MetricSpec]
    poses: np.ndarray | None
    trajectory: tuple[np.ndarray, np.ndarray, np.ndarray] | None
    q_guess: np.ndarray | None = None
    callable_keys: dict[str, list[str] | None] = field(default_factory=dict)
    design_names: list[str] = field(default_factory=list)

    @property
    def columns(self) -> list[str]:
        """Metric columns, in order (a callable returning a dict gives ``name.key`` columns)."""
        out = []
        for m in self.metrics:
            keys = self.callable_keys.get(m.name) if not m.builtin else None
            out += [f"{m.name}.{k}" for k in keys] if keys else [m.name]
        return out

    @property
    def geometric_columns(self) -> np.ndarray:
        return np.array([not t.batched for t in self.targets], dtype=bool)


# ---- motion of any mechanism (open or closed) ----------------------------------------------------

class LoopFailure(ValueError):
    pass


def motion(mech, qa, va=None, aa=None, q_guess=None, coupling: bool = True):
    """(q, v, a, C) in full coordinates for actuated motion (qa, va, aa) (N, na); C (N, n, na) with
    v = C v# (None for an open mechanism: C = identity). Raises LoopFailure where the loops cannot
    be assembled."""
    from mechbal import _core

    va = np.zeros_like(qa) if va is None else va
    aa = np.zeros_like(qa) if aa is None else aa
    if not mech.is_closed:
        return qa, va, aa, None
    guess = np.zeros(mech.dof) if q_guess is None else q_guess
    ok_mask = ~np.uint32(int(_core.Status.singular))
    m = mech.closed_motion(qa, va, aa, q_guess=guess)
    if np.any(m.status & ok_mask):
        k = int(np.argmax((m.status & ok_mask) != 0))
        raise LoopFailure(f"the loops cannot be assembled at sample {k} (closure residual {m.residual[k]:.3g})")
    C = None
    if coupling:
        na = qa.shape[1]
        C = np.empty((qa.shape[0], mech.dof, na))
        for k in range(na):
            unit = np.zeros_like(qa)
            unit[:, k] = 1.0
            C[:, :, k] = mech.closed_motion(qa, unit, np.zeros_like(qa), q_guess=guess).v
    return m.q, m.v, m.a, C


def _actuated(C, x):
    """C^T x per sample (x (N, n)); x itself for an open mechanism."""
    return x if C is None else np.einsum("tnk,tn->tk", C, x)


# ---- statistics ------------------------------------------------------------------------------------

def _statistic(norm2: np.ndarray, statistic: str) -> np.ndarray:
    """Peak or RMS over axis 0 of squared norms (samples, ...)."""
    if statistic == "peak":
        return np.sqrt(np.max(norm2, axis=0))
    return np.sqrt(np.mean(norm2, axis=0))


def builtin_values(quantities: dict[str, np.ndarray], metrics: list[MetricSpec], joint_index,
                   buffer=None) -> dict:
    """Built-in metrics from quantity arrays (samples, components, ...sets); ``buffer(key, shape)``
    gives scratch arrays for the squared norms."""
    out, norms = {}, {}
    for m in metrics:
        if not m.builtin:
            continue
        key = (m.quantity, m.joint)
        if key not in norms:
            X = quantities[m.quantity]
            shape = (X.shape[0],) + X.shape[2:]
            scratch = buffer(("norm",) + key, shape) if buffer is not None else np.empty(shape)
            if m.joint is not None:
                norms[key] = np.square(X[:, joint_index[m.joint]], out=scratch)
            else:
                norms[key] = np.einsum("ij...,ij...->i...", X, X, out=scratch)
        out[m.name] = _statistic(norms[key], m.statistic)
    return out


def needed(metrics: list[MetricSpec]) -> set[str]:
    return {m.quantity for m in metrics if m.builtin}


# ---- direct evaluation of one mechanism -------------------------------------------------------------

def direct_quantities(mech, plan: Plan, wanted: set[str]) -> dict[str, np.ndarray]:
    """Each wanted quantity of ``mech`` as (samples, components), evaluated directly (no regressor)."""
    out = {}
    if wanted & set(STATIC):
        q, _, _, C = motion(mech, plan.poses, q_guess=plan.q_guess)
        out["gravity_torque"] = _actuated(C, mech.gravity_torque(q))
    if wanted - set(STATIC):
        qa, va, aa = plan.trajectory
        need_c = "joint_torque" in wanted
        q, v, a, C = motion(mech, qa, va, aa, q_guess=plan.q_guess, coupling=need_c)
        if need_c:
            out["joint_torque"] = _actuated(C, mech.inverse_dynamics(q, v, a))
        if wanted & {"shaking_force", "shaking_moment"}:
            w = mech.shaking_wrench(q, v, a)
            out["shaking_force"] = w.shaking_force
            out["shaking_moment"] = w.shaking_moment
    return out


def call_metric(m: MetricSpec, mech, design: dict[str, float] | None):
    return m.function(mech) if design is None else m.function(mech, design)


# ---- the per-process context --------------------------------------------------------------------------

class Context:
    """What a process builds once per plan: the nominal mechanism and, when a set is batched, the
    regressors split into a constant part (bodies no parameter touches, at their nominal values)
    and the columns of the bodies the parameters change."""

    def __init__(self, plan: Plan):
        from mechbal.mechanism import Mechanism

        self.plan = plan
        self.mechanism = Mechanism.from_spec(plan.spec, name="nominal")
        names = self.mechanism.actuated_names
        self.joint_index = {n: i for i, n in enumerate(names)}
        self._regressors = None

    # ---- body parameters -> inertial parameters --------------------------------------------------
    def _body_frames(self, bodies: list[str]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """(R, t) per body: link-frame values of the spec -> the model's (the model folds fixed
        joints into their moving ancestor). Read from the model itself: coms placed at 0 and at
        the unit vectors."""
        from mechbal.mechanism import Mechanism

        spec = self.plan.spec
        probes = []
        for c in (np.zeros(3), np.eye(3)[0], np.eye(3)[1], np.eye(3)[2]):
            s = dataclasses.replace(spec, bodies=[dataclasses.replace(b, com=c.copy()) if b.name in bodies
                                                  else b for b in spec.bodies], loops=[], actuated=[])
            mech = Mechanism.from_spec(s)
            index = {n: i for i, n in enumerate(mech.body_names)}
            probes.append({n: np.asarray(mech.bodies[index[n]].com, float) for n in bodies})
        out = {}
        for n in bodies:
            t = probes[0][n]
            R = np.column_stack([probes[k][n] - t for k in (1, 2, 3)])
            out[n] = (R, t)
        return out

    def _setup_regressors(self):
        plan, mech = self.plan, self.mechanism
        model_bodies = mech.body_names
        var = sorted({t.name for t in plan.targets if t.kind == "body"}, key=model_bodies.index)
        frames = self._body_frames(var) if var else {}
        spec_bodies = {b.name: b for b in plan.spec.bodies}
        pi = mech.inertial_parameters()
        regressors = {}
        wanted = needed(plan.metrics)
        if wanted & set(STATIC):
            q, _, _, C = motion(mech, plan.poses, q_guess=plan.q_guess)
            Y = mech.gravity_regressor(q)
            if C is not None:
                Y = np.einsum("tnk,tnp->tkp", C, Y)
            regressors["gravity_torque"] = Y
        if wanted - set(STATIC):
            qa, va, aa = plan.trajectory
            need_c = "joint_torque" in wanted
            q, v, a, C = motion(mech, qa, va, aa, q_guess=plan.q_guess, coupling=need_c)
            if need_c:
                Y = mech.torque_regressor(q, v, a)
                if C is not None:
                    Y = np.einsum("tnk,tnp->tkp", C, Y)
                regressors["joint_torque"] = Y
            if wanted & {"shaking_force", "shaking_moment"}:
                Yw = self._wrench_regressor(q, v, a)
                regressors["shaking_force"] = Yw[:, :3]
                regressors["shaking_moment"] = Yw[:, 3:]
        # the variable bodies in the model's frames, at their nominal values; a body whose mass
        # alone varies changes pi along one direction, pi = pi0 + (m - m0) [1, c, c.c 1 - c c^T]:
        # one regressor column instead of ten
        self._var = var
        self._bodies = {}
        blocks = []
        for n in var:
            R, t = frames[n]
            b = spec_bodies[n]
            com0, inertia0 = R @ np.asarray(b.com, float) + t, R @ np.asarray(b.inertia, float) @ R.T
            mass_only = all(x.attr == "mass" for x in plan.targets if x.kind == "body" and x.name == n)
            pi0 = inertial_parameters(np.array([b.mass]), com0[None], inertia0[None])[0]
            direction = inertial_parameters(np.ones(1), com0[None], np.zeros((1, 3, 3)))[0]
            k = model_bodies.index(n)
            blocks.append((slice(10 * k, 10 * k + 10), direction[:, None] if mass_only else np.eye(10)))
            self._bodies[n] = dict(mass=float(b.mass), com=np.asarray(b.com, float),
                                   inertia=np.asarray(b.inertia, float), R=R, t=t, pi0=pi0,
                                   inertia_model=inertia0, mass_only=mass_only)
        self._regressors = {}
        for name, Y in regressors.items():
            samples, comps, _ = Y.shape
            flat = Y.reshape(samples * comps, -1)
            base = flat @ pi
            reduced = np.concatenate([flat[:, cols] @ W for cols, W in blocks], axis=1) if blocks \
                else np.zeros((flat.shape[0], 0))
            self._regressors[name] = (np.ascontiguousarray(reduced), base, (samples, comps))

    def _buffer(self, key, shape) -> np.ndarray:
        """A scratch array kept between chunks: large temporaries allocated anew each time are
        fresh pages for the kernel to fault in (Dask workers set MALLOC_TRIM_THRESHOLD_, which
        turns glibc's reuse of large blocks off), which made a worker 2-3x slower than this
        process."""
        buffers = self.__dict__.setdefault("_buffers", {})
        b = buffers.get((key, shape))
        if b is None:
            if len(buffers) > 32:
                buffers.clear()
            b = buffers[(key, shape)] = np.empty(shape)
        return b

    def _wrench_regressor(self, q, v, a) -> np.ndarray:
        """(T, 6, 10 B): [dP/dt; dH_O/dt] = Y pi, the torques of six virtual joints (x, y, z slides
        and rotations at O) carrying the mechanism in a weightless copy of the model: with no
        gravity the base reaction they transmit is the shaking wrench."""
        from mechbal.mechanism import Mechanism
        from mechbal.spec import JointSpec

        spec = self.plan.spec
        chain, parent = [], "base"
        for name, kind, axis in zip(_VIRTUAL, ["prismatic"] * 3 + ["revolute"] * 3,
                                    [np.eye(3)[i] for i in (0, 1, 2, 0, 1, 2)]):
            chain.append(JointSpec(name, kind, parent, np.eye(4), axis.copy()))
            parent = name
        joints = chain + [dataclasses.replace(j, parent=parent) if j.parent == "base" else j for j in spec.joints]
        augmented = Mechanism.from_spec(dataclasses.replace(spec, joints=joints, gravity=np.zeros(3),
                                                            loops=[], actuated=[]))
        index = [augmented.joint_names.index(n) for n in _VIRTUAL]
        rest = [augmented.joint_names.index(n) for n in self.mechanism.joint_names]
        N = q.shape[0]
        Q, V, A = (np.zeros((N, augmented.dof)) for _ in range(3))
        Q[:, rest], V[:, rest], A[:, rest] = q, v, a
        assert augmented.body_names == self.mechanism.body_names
        Y = augmented.torque_regressor(Q, V, A)[:, index]  # (N, 6, 10 B): forces x y z, moments x y z
        return Y

    def batched(self, values: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray, list[str]]:
        """Built-in metrics of sets that change only body parameters: ({metric: (S,)}, ok (S,),
        reasons (S,) for the sets that are not physical)."""
        if self._regressors is None:
            self._setup_regressors()
        plan = self.plan
        S = values.shape[0]
        ok = np.ones(S, dtype=bool)
        reasons = [""] * S
        columns = []
        for n in self._var:
            b = self._bodies[n]
            mass = np.full(S, b["mass"])
            com = None
            inertia = None
            for k, t in enumerate(plan.targets):
                if t.kind != "body" or t.name != n:
                    continue
                if t.attr == "mass":
                    mass = values[:, k].copy()
                elif t.attr == "com":
                    if com is None:
                        com = np.tile(b["com"], (S, 1))
                    com[:, t.index] = values[:, k]
                else:
                    if inertia is None:
                        inertia = np.tile(b["inertia"], (S, 1, 1))
                    i, j = t.index
                    inertia[:, i, j] = values[:, k]
                    inertia[:, j, i] = values[:, k]
            good = physical_status(mass, inertia)
            for s_i in np.flatnonzero(~good & ok):
                reasons[s_i] = f"bodies.{n}: not a physical body (mass >= 0, inertia positive semi-definite " \
                               "with the triangle inequality)"
            ok &= good
            if b["mass_only"]:
                columns.append((mass - b["mass"])[:, None])
                continue
            R, t = b["R"], b["t"]
            com_model = np.broadcast_to(R @ b["com"] + t, (S, 3)) if com is None else com @ R.T + t
            inertia_model = (np.broadcast_to(b["inertia_model"], (S, 3, 3)) if inertia is None
                             else np.einsum("ij,sjk,lk->sil", R, inertia, R))
            columns.append(inertial_parameters(mass, com_model, inertia_model) - b["pi0"])
        D = np.concatenate(columns, axis=1) if columns else np.zeros((S, 0))
        results = {m.name: np.empty(S) for m in plan.metrics if m.builtin}
        rows = max(Yv.shape[0] for Yv, _, _ in self._regressors.values()) if self._regressors else 1
        block = max(1, _BLOCK_ELEMENTS // max(1, rows))
        for start in range(0, S, block):
            stop = min(S, start + block)
            n = stop - start
            DbT = np.ascontiguousarray(D[start:stop].T)
            quantities = {}
            for name, (Yv, base, (samples, comps)) in self._regressors.items():
                X = self._buffer(name, (Yv.shape[0], n))
                if DbT.shape[0]:
                    np.matmul(Yv, DbT, out=X)
                    X += base[:, None]
                else:
                    X[...] = base[:, None]
                quantities[name] = X.reshape(samples, comps, n)
            for k, v in builtin_values(quantities, plan.metrics, self.joint_index, self._buffer).items():
                results[k][start:stop] = v
        for v in results.values():
            v[~ok] = np.nan
        return results, ok, reasons


_CONTEXTS: dict[str, Context] = {}


def context(plan: Plan) -> Context:
    """The context of ``plan`` in this process (built on first use, then cached)."""
    ctx = _CONTEXTS.get(plan.token)
    if ctx is None:
        if len(_CONTEXTS) > 4:
            _CONTEXTS.clear()
        ctx = _CONTEXTS[plan.token] = Context(plan)
    return ctx


def evaluate_set(plan: Plan, ctx: Context, row: np.ndarray, builtins: bool = True) -> tuple[dict, str]:
    """Metrics of one parameter set on the rebuilt mechanism: ({column: value}, status)."""
    from mechbal.mechanism import Mechanism

    out: dict[str, float] = {}
    try:
        changed = any(t.kind != "design" and v != n for t, v, n in zip(plan.targets, row, plan.nominal))
        mech = (Mechanism.from_spec(apply_values(plan.spec, plan.targets, row, plan.nominal), name="set")
                if changed else ctx.mechanism)
        if builtins:
            q = direct_quantities(mech, plan, needed(plan.metrics))
            for k, v in builtin_values({n: x[..., None] for n, x in q.items()}, plan.metrics,
                                       ctx.joint_index).items():
                out[k] = float(v[0])
        design = ({n: float(row[i]) for i, n in enumerate(plan.paths) if plan.targets[i].kind == "design"}
                  if plan.design_names else None)
        for m in plan.metrics:
            if m.builtin:
                continue
            value = call_metric(m, mech, design)
            keys = plan.callable_keys.get(m.name)
            if keys:
                value = dict(value) if isinstance(value, dict) else {}
                for key in keys:
                    out[f"{m.name}.{key}"] = _as_float(value.get(key, math.nan))
            else:
                out[m.name] = _as_float(value)
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        message = " ".join(str(exc).split()) or type(exc).__name__
        return {}, message
    return out, "ok"


def _as_float(x) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


_BLAS = []


def _one_blas_thread():
    """BLAS on one thread while a chunk runs (threadpoolctl, part of the 'sweep' extra): the
    products are small (a few hundred rows by tens of columns), a second BLAS thread only spins
    against the other workers, and the result cannot depend on a thread count."""
    import contextlib

    if not _BLAS:
        try:
            from threadpoolctl import ThreadpoolController

            _BLAS.append(ThreadpoolController())
        except ImportError:
            _BLAS.append(None)
    if _BLAS[0] is None:
        return contextlib.nullcontext()
    return _BLAS[0].limit(limits=1, user_api="blas")


def evaluate_chunk(plan: Plan, start: int, values: np.ndarray) -> dict[str, Any]:
    """The metrics of the sets ``values`` (s, parameters), evaluations ``start .. start + s - 1``:
    ``{"start": start, "columns": {column: (s,) float}, "status": [str] * s}``. Pure: the result
    depends only on the plan and the rows."""
    with _one_blas_thread():
        return _evaluate_chunk(plan, start, values)


def _evaluate_chunk(plan: Plan, start: int, values: np.ndarray) -> dict[str, Any]:
    ctx = context(plan)
    values = np.asarray(values, dtype=float)
    s = values.shape[0]
    columns = {c: np.full(s, np.nan) for c in plan.columns}
    status = ["ok"] * s
    geometric = np.any(values[:, plan.geometric_columns] != plan.nominal[plan.geometric_columns], axis=1) \
        if plan.geometric_columns.any() else np.zeros(s, dtype=bool)
    has_builtin = any(m.builtin for m in plan.metrics)
    has_callable = any(not m.builtin for m in plan.metrics)
    batch = np.flatnonzero(~geometric)
    if has_builtin and batch.size:
        results, ok, reasons = ctx.batched(values[batch])
        for name, v in results.items():
            columns[name][batch] = v
        for i, s_i in enumerate(batch):
            if not ok[i]:
                status[s_i] = reasons[i]
    for i in range(s):
        if geometric[i] or (has_callable and status[i] == "ok"):
            out, st = evaluate_set(plan, ctx, values[i], builtins=bool(geometric[i]))
            if st != "ok":
                status[i] = st
                for c in columns:
                    columns[c][i] = np.nan
                continue
            for k, v in out.items():
                columns[k][i] = v
    return {"start": int(start), "columns": columns, "status": status}


def discover_callable_keys(plan: Plan, mech) -> dict[str, list[str] | None]:
    """Which callable metrics return dicts (their keys, sorted), from one nominal evaluation."""
    design = ({n: float(plan.nominal[i]) for i, n in enumerate(plan.paths) if plan.targets[i].kind == "design"}
              if plan.design_names else None)
    keys = {}
    for m in plan.metrics:
        if m.builtin:
            continue
        try:
            params = inspect.signature(m.function).parameters
            takes = len([p for p in params.values() if p.default is inspect.Parameter.empty
                         and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)])
        except (TypeError, ValueError):
            takes = None
        if design is not None and takes == 1:
            raise ValueError(f"metrics: {m.name!r} takes one argument, but the sweep has design "
                             "variables: write it as f(mechanism, design)")
        value = call_metric(m, mech, design)
        keys[m.name] = sorted(map(str, value)) if isinstance(value, dict) else None
    return keys


__all__ = ["Context", "LoopFailure", "Plan", "context", "direct_quantities", "discover_callable_keys",
           "evaluate_chunk", "evaluate_set", "motion"]
