"""Motions that minimise shaking: ``min_shaking(mech, start, end, duration, ...)``.

A rest-to-rest (or given boundary velocities) motion of the actuated joints of any mechanism
(serial, tree, closed loop) from ``start`` to ``end`` in ``duration`` that minimises the RMS or
the peak of the shaking force or of the shaking moment (about ``moment_point``, default O), or a
weighted sum of the mean squares of shaking force, shaking moment and actuator torque, subject to
the joints' position, velocity, acceleration and torque limits.

* Parameterisation: a clamped quintic B-spline per actuated joint (`mechbal.plan.spline`), the
  boundary positions and velocities held exactly (and zero accelerations with ``smooth_ends``);
  the quintic law is one point of it, the warm start.
* Gradients: the partial derivatives of the shaking wrench and the torques in the actuated
  positions, rates and accelerations are exact, forward mode on the model's expression graph
  (`mechbal.plan.exact`; central differences in the positions where the code generator does not
  take the mechanism), chained through the spline basis.
* Solvers (scipy): RMS objectives, integrated by Gauss-Legendre quadrature on each knot span,
  by BFGS without the limits first; where that motion exceeds a limit, SLSQP from there with the
  limits imposed where the motion comes near them (an active set: local maxima within 5 % of a
  limit), each tightened by `LIMIT_MARGIN`; peaks by SLSQP with an epigraph variable. The
  torques are checked on a grid ten times finer than the output samples, positions, velocities
  and accelerations on one a hundred times finer; every violation found there is watched too and
  the problem solved again.
* Infeasible requests (a duration too short for the torque, velocity or acceleration limits) are
  refused before the long run with `PlanInfeasible`, whose message gives the shortest duration
  the planner found feasible.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
from numpy.typing import ArrayLike

from mechbal.mechanism import Mechanism
from mechbal.plan.model import ActuatedModel, Evaluation, LoopFailure
from mechbal.plan.spline import SplineBasis, SplineTrajectory

OBJECTIVES = ("force_rms", "force_peak", "moment_rms", "moment_peak")
#: the solver holds each limit tightened by this much (relative), so that it holds between the
#: instants it was imposed at too; the plan is then checked against the limit itself
LIMIT_MARGIN = 1e-5
#: relative excess over a limit on the check grid that counts as exceeding it (none)
LIMIT_TOLERANCE = 0.0
#: BFGS stops where |gradient| of the objective (scaled to 1 at the quintic) is below this
GRADIENT_TOLERANCE = 1e-9
#: and accepts a stop on "precision loss" (a flat optimum, rounding of the partials) below this
ACCEPTED_GRADIENT = 1e-6
#: what the objective and the constraints say of a trial step where the loops cannot be assembled
#: (the line searches step back)
OUT_OF_WORKSPACE = 1e12
#: nodes of the Gauss-Legendre quadrature per knot span
NODES_PER_SPAN = 6


class PlanInfeasible(ValueError):
    """No motion within the limits exists for this request (the message says what would make it
    feasible: ``shortest_duration`` [s], or None where none was found)."""

    def __init__(self, message: str, shortest_duration: float | None = None, field: str = "duration"):
        super().__init__(message)
        self.shortest_duration = shortest_duration
        self.field = field


@dataclass(frozen=True)
class Limits:
    """Limits of the actuated joints (inf where none): positions [rad or m], velocity [rad/s or
    m/s], acceleration [rad/s^2 or m/s^2], torque [N m or N]."""

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray

    def shrunk(self, margin: float) -> "Limits":
        """The limits tightened by ``margin`` (relative; positions: of the range where bounded on
        both sides, else of the bound's size)."""
        both = np.isfinite(self.lower) & np.isfinite(self.upper)
        span = np.where(both, self.upper - self.lower, 0.0)
        lower, upper = self.lower.copy(), self.upper.copy()
        fin = np.isfinite(lower)
        lower[fin] += margin * np.where(both, span, np.abs(lower))[fin]
        fin = np.isfinite(upper)
        upper[fin] -= margin * np.where(both, span, np.abs(upper))[fin]
        k = 1.0 - margin
        return Limits(lower, upper, k * self.velocity, k * self.acceleration, k * self.torque)

    def active_kinds(self) -> list[str]:
        out = []
        if np.any(np.isfinite(self.lower)) or np.any(np.isfinite(self.upper)):
            out.append("position")
        for k in ("velocity", "acceleration", "torque"):
            if np.any(np.isfinite(getattr(self, k))):
                out.append(k)
        return out


@dataclass
class PlanResult:
    """A planned motion and what it achieved.

    ``trajectory``: the motion of the actuated joints (`SplineTrajectory`); ``quintic``: the
    quintic with the same boundary conditions (the warm start and the reference); ``objective``:
    the name (``force_rms``, ..., or ``weighted``); ``value`` and ``quintic_value``: the objective
    of each ([N] or [N m]; a weighted objective: the weighted sum of mean squares), on the same
    time grid; ``reduction``: ``1 - value / quintic_value``; ``active_limits``: the limits the
    plan touches (kind, joint, time, value, limit); ``ok`` and ``message`` from the solver;
    ``limits``: the limits held; ``checked_samples``: the size of the grid the limits were checked
    on."""

    trajectory: SplineTrajectory
    quintic: Any
    objective: str
    weights: dict[str, float]
    moment_point: np.ndarray
    value: float
    quintic_value: float
    reduction: float
    active_limits: list[dict[str, Any]]
    limits: Limits
    ok: bool
    message: str
    iterations: int
    checked_samples: int
    metrics: dict[str, dict[str, float]] = field(default_factory=dict)
    #: how the position partials were had: "exact" (forward mode) or "differences"
    derivatives: str = "exact"

    def summary(self, names: list[str]) -> dict[str, Any]:
        """What summary.json says about the plan (``plan``)."""
        return {"objective": self.objective, "weights": self.weights,
                "moment_point": self.moment_point.tolist(), "value": self.value,
                "quintic_value": self.quintic_value, "reduction": self.reduction,
                "ok": self.ok, "message": self.message, "iterations": self.iterations,
                "control_points": int(self.trajectory.basis.count),
                "active_limits": [{**a, "joint": names[a["joint"]]} for a in self.active_limits],
                "limits_checked_on": self.checked_samples, "metrics": self.metrics,
                "derivatives": self.derivatives}


def quintic_with_velocities(start, end, duration, v0, v1):
    """The quintic polynomial with the given boundary positions and velocities and zero boundary
    accelerations (`mechbal.trajectory.ViaPoints` with two points)."""
    from mechbal.trajectory import ViaPoints

    return ViaPoints([0.0, duration], np.vstack([start, end]), velocities=np.vstack([v0, v1]))


def model_limits(mech: Mechanism, acceleration_limit=None, torque_limit=None,
                 velocity_limit=None) -> Limits:
    """The actuated joints' limits: the model's (URDF ``<limit>``, the case's ``limits``), with
    the given acceleration, velocity and torque limits (one per actuated joint) where tighter."""
    na = len(mech.actuated_names)
    idx = list(mech.model.actuated_coordinates) if mech.is_closed else list(range(mech.dof))
    pick = lambda xs: np.asarray(xs, float)[idx]  # noqa: E731
    lower, upper = pick(mech.model.lower_limits), pick(mech.model.upper_limits)
    vel, tau = pick(mech.model.velocity_limits), pick(mech.model.effort_limits)
    acc = np.full(na, np.inf)
    for name, given, base in (("acceleration_limit", acceleration_limit, acc),
                              ("torque_limit", torque_limit, tau),
                              ("velocity_limit", velocity_limit, vel)):
        if given is None:
            continue
        g = np.broadcast_to(np.asarray(given, float), (na,)).copy()
        if np.any(~(g > 0)):
            raise ValueError(f"{name} must be > 0 (one per actuated joint), got {g.tolist()}")
        base[:] = np.minimum(base, g)
    return Limits(lower, upper, vel, acc, tau)


class _Problem:
    """The optimisation problem over the free control points (and the epigraph variable)."""

    def __init__(self, am: ActuatedModel, basis: SplineBasis, boundary: np.ndarray, objective: str,
                 weights: Mapping[str, float], limits: Limits, nodes: np.ndarray, node_weights: np.ndarray):
        self.am, self.basis, self.boundary = am, basis, boundary
        self.objective, self.weights, self.limits = objective, dict(weights), limits
        self.na = am.na
        self.nf = basis.free_count
        self.peak = objective.endswith("_peak")
        self.need_torque = bool(np.any(np.isfinite(limits.torque)) or self.weights.get("torque", 0.0))
        self.set_nodes(nodes, node_weights)
        self.watched: dict[tuple[str, int, float], np.ndarray] = {}
        self._cache: tuple[bytes, Evaluation] | None = None
        self.scale = 1.0

    def set_nodes(self, nodes, node_weights):
        self.nodes, self.node_weights = np.asarray(nodes), np.asarray(node_weights)
        B = self.basis.matrices(self.nodes)
        self.Z = [b @ self.basis.free_map for b in B]        # (N, nf) each
        self.R = [b @ self.basis.boundary_map @ self.boundary for b in B]  # (N, na)

    # ---- motion of the free points -------------------------------------------------------------
    def motion(self, z: np.ndarray):
        Zm = z[: self.na * self.nf].reshape(self.nf, self.na)
        return [Zk @ Zm + Rk for Zk, Rk in zip(self.Z, self.R)]

    def evaluate(self, z: np.ndarray) -> Evaluation:
        key = z.tobytes()
        if self._cache is None or self._cache[0] != key:
            q, v, a = self.motion(z)
            self._cache = (key, self.am.evaluate(q, v, a, torque=self.need_torque, partials=True))
        return self._cache[1]

    def _chain(self, dq, dv, da):
        """d(quantity)/dz (N, k, na * nf) from the partials (N, k, na)."""
        out = (np.einsum("ikj,il->iklj", dq, self.Z[0]) + np.einsum("ikj,il->iklj", dv, self.Z[1])
               + np.einsum("ikj,il->iklj", da, self.Z[2]))
        return out.reshape(dq.shape[0], dq.shape[1], -1)

    def _squares(self, ev: Evaluation):
        """Per node: the weighted sum of squares that the objective integrates, and its partials
        with respect to the actuated q, v, a (N, na)."""
        W = ev.wrench
        w = np.zeros(6)
        if self.objective in ("force_rms", "force_peak"):
            w[:3] = 1.0
        elif self.objective in ("moment_rms", "moment_peak"):
            w[3:] = 1.0
        else:
            w[:3], w[3:] = self.weights.get("force", 0.0), self.weights.get("moment", 0.0)
        s = np.sum(w * W ** 2, axis=1)
        gq = 2.0 * np.einsum("ik,k,ikj->ij", W, w, ev.dq)
        gv = 2.0 * np.einsum("ik,k,ikj->ij", W, w, ev.dv)
        ga = 2.0 * np.einsum("ik,k,ikj->ij", W, w, ev.da)
        wt = self.weights.get("torque", 0.0) if self.objective == "weighted" else 0.0
        if wt:
            T = ev.torque
            s = s + wt * np.sum(T ** 2, axis=1)
            gq = gq + 2.0 * wt * np.einsum("ik,ikj->ij", T, ev.torque_dq)
            gv = gv + 2.0 * wt * np.einsum("ik,ikj->ij", T, ev.torque_dv)
            ga = ga + 2.0 * wt * np.einsum("ik,ikj->ij", T, ev.torque_da)
        return s, gq, gv, ga

    def _dz(self, gq, gv, ga):
        """sum over nodes of g (N, na) chained: (N, nf * na) rows."""
        return (np.einsum("ij,il->ilj", gq, self.Z[0]) + np.einsum("ij,il->ilj", gv, self.Z[1])
                + np.einsum("ij,il->ilj", ga, self.Z[2])).reshape(gq.shape[0], -1)

    def value(self, z: np.ndarray) -> float:
        """The objective (mean square or peak square) of the motion, unscaled."""
        s, *_ = self._squares(self.evaluate(z))
        if self.peak:
            return float(np.max(s))
        return float(np.sum(self.node_weights * s) / self.basis.duration)

    # ---- scipy callbacks -----------------------------------------------------------------------
    def fun(self, x: np.ndarray):
        if self.peak:
            g = np.zeros_like(x)
            g[-1] = 1.0
            return float(x[-1]), g
        try:
            ev = self.evaluate(x)
        except LoopFailure:   # a trial step out of the workspace: the line search steps back
            return OUT_OF_WORKSPACE, np.zeros_like(x)
        s, gq, gv, ga = self._squares(ev)
        J = np.sum(self.node_weights * s) / self.basis.duration
        G = self.node_weights @ self._dz(gq, gv, ga) / self.basis.duration
        return float(J / self.scale), G / self.scale

    def _weights6(self) -> np.ndarray:
        w = np.zeros(6)
        if self.objective in ("force_rms", "force_peak"):
            w[:3] = 1.0
        elif self.objective in ("moment_rms", "moment_peak"):
            w[3:] = 1.0
        else:
            w[:3], w[3:] = self.weights.get("force", 0.0), self.weights.get("moment", 0.0)
        return w

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """r with sum r^2 = the mean-square objective / scale (least squares form)."""
        ev = self.evaluate(x)
        c = np.sqrt(self.node_weights / self.basis.duration / self.scale)[:, None]
        r = [c * np.sqrt(self._weights6()) * ev.wrench]
        wt = self.weights.get("torque", 0.0) if self.objective == "weighted" else 0.0
        if wt:
            r.append(c * np.sqrt(wt) * ev.torque)
        return np.concatenate(r, axis=1).reshape(-1)

    def residual_jacobian(self, x: np.ndarray) -> np.ndarray:
        ev = self.evaluate(x)
        c = np.sqrt(self.node_weights / self.basis.duration / self.scale)[:, None, None]
        J = [c * np.sqrt(self._weights6())[None, :, None] * self._chain(ev.dq, ev.dv, ev.da)]
        wt = self.weights.get("torque", 0.0) if self.objective == "weighted" else 0.0
        if wt:
            J.append(c * np.sqrt(wt) * self._chain(ev.torque_dq, ev.torque_dv, ev.torque_da))
        return np.concatenate(J, axis=1).reshape(-1, x.size)

    def peak_constraint(self, x: np.ndarray):
        try:
            ev = self.evaluate(x)
        except LoopFailure:
            return np.full(len(self.nodes), -OUT_OF_WORKSPACE), np.zeros((len(self.nodes), x.size))
        s, gq, gv, ga = self._squares(ev)
        c = x[-1] - s / self.scale
        J = np.zeros((s.size, x.size))
        J[:, :-1] = -self._dz(gq, gv, ga) / self.scale
        J[:, -1] = 1.0
        return c, J

    # ---- the limits, imposed where the motion comes near them (an active set, refined) --------
    def watch(self, kind: str, joint: int, side: float, times: np.ndarray) -> None:
        """Impose the ``side`` (+1 upper, -1 lower) limit of ``kind`` on ``joint`` at ``times`` too."""
        key = (kind, int(joint), float(side))
        old = self.watched.get(key, np.zeros(0))
        self.watched[key] = np.unique(np.concatenate([old, np.asarray(times, float)]))

    def linear_constraints(self, size: int) -> list[dict]:
        """SLSQP constraints ``b - A x >= 0`` of the watched position, velocity and acceleration
        limits (linear in the free points; scaled by the limit)."""
        out = []
        L = self.limits
        bounds = {"position": (L.lower, L.upper), "velocity": (-L.velocity, L.velocity),
                  "acceleration": (-L.acceleration, L.acceleration)}
        order = {"position": 0, "velocity": 1, "acceleration": 2}
        for (kind, j, side), times in self.watched.items():
            if kind == "torque":
                continue
            Bk = self.basis.matrices(times)[order[kind]]
            Z = Bk @ self.basis.free_map
            R = (Bk @ self.basis.boundary_map @ self.boundary)[:, j]
            bound = bounds[kind][1 if side > 0 else 0][j]
            scale = max(abs(bound), 1e-12)
            A = np.zeros((len(times), size))
            A[:, j: self.na * self.nf: self.na] = side * Z / scale
            b = side * (bound - R) / scale
            out.append({"type": "ineq", "fun": (lambda x, A=A, b=b: b - A @ x), "jac": (lambda x, A=A: -A)})
        return out

    def torque_constraint(self, x: np.ndarray):
        """1 -+ tau / tau_max >= 0 at the watched instants of each joint's torque limits."""
        keys = [k for k in self.watched if k[0] == "torque"]
        times = np.unique(np.concatenate([self.watched[k] for k in keys]))
        B = self.basis.matrices(times)
        Z = [b @ self.basis.free_map for b in B]
        Zm = x[: self.na * self.nf].reshape(self.nf, self.na)
        q, v, a = [Zk @ Zm + b @ self.basis.boundary_map @ self.boundary for Zk, b in zip(Z, B)]
        lim = self.limits.torque
        m = sum(len(self.watched[k]) for k in keys)
        try:
            ev = self.am.evaluate(q, v, a, torque=True, partials=True)
        except LoopFailure:
            return np.full(m, -OUT_OF_WORKSPACE), np.zeros((m, x.size))
        dT = (np.einsum("ikj,il->iklj", ev.torque_dq, Z[0]) + np.einsum("ikj,il->iklj", ev.torque_dv, Z[1])
              + np.einsum("ikj,il->iklj", ev.torque_da, Z[2])).reshape(len(q), self.na, -1)
        c, J = [], []
        for (_, j, side) in keys:
            rows = np.searchsorted(times, self.watched[("torque", j, side)])
            c.append(1.0 - side * ev.torque[rows, j] / lim[j])
            Jj = np.zeros((len(rows), x.size))
            Jj[:, : self.na * self.nf] = -side * dT[rows, j, :] / lim[j]
            J.append(Jj)
        return np.concatenate(c), np.vstack(J)


def _gauss_nodes(knots: np.ndarray, per_span: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(per_span)
    spans = np.unique(knots)
    nodes, weights = [], []
    for a, b in zip(spans[:-1], spans[1:]):
        nodes.append(0.5 * (b - a) * x + 0.5 * (a + b))
        weights.append(0.5 * (b - a) * w)
    return np.concatenate(nodes), np.concatenate(weights)


def _vector(name: str, value, n: int) -> np.ndarray:
    a = np.asarray(value, float).reshape(-1)
    if a.size == 1 and n > 1:
        a = np.full(n, float(a[0]))
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must have {n} finite values (one per actuated joint), got {np.asarray(value).tolist()}")
    return a


def _violations(am: ActuatedModel, traj, limits: Limits, t: np.ndarray, torque: bool):
    """Relative excess over each limit: list of (kind, joint, time, value, limit, largest excess,
    excess along the grid, the grid) and the torque (or None). The torques are checked on the
    grid ``t``; positions, velocities and accelerations (the spline alone, cheap) on a grid ten
    times finer."""
    fine = np.linspace(t[0], t[-1], 10 * (len(t) - 1) + 1)
    q, v, a = traj.evaluate(fine)
    tau = None
    if torque:
        qt, vt, at = traj.evaluate(t)
        tau = am.full(qt, vt, at, torque=True)[3]
    out = []
    for kind, x, lo, hi, grid in (("position", q, limits.lower, limits.upper, fine),
                                  ("velocity", v, -limits.velocity, limits.velocity, fine),
                                  ("acceleration", a, -limits.acceleration, limits.acceleration, fine),
                                  ("torque", tau, -limits.torque, limits.torque, t)):
        if x is None:
            continue
        for j in range(x.shape[1]):
            for bound, sign in ((hi[j], 1.0), (lo[j], -1.0)):
                if not np.isfinite(bound):
                    continue
                excess = sign * (x[:, j] - bound)
                k = int(np.argmax(excess))
                scale = max(abs(bound), 1e-12)
                out.append((kind, j, float(grid[k]), float(x[k, j]), float(bound), float(excess[k] / scale),
                            excess / scale, grid, sign))
    return out, tau


def min_shaking(mech: Mechanism, start: ArrayLike, end: ArrayLike, duration: float, *,
                objective: str = "force_rms", weights: Mapping[str, float] | None = None,
                moment_point: ArrayLike = (0.0, 0.0, 0.0), start_velocity: ArrayLike | None = None,
                end_velocity: ArrayLike | None = None, acceleration_limit: ArrayLike | None = None,
                torque_limit: ArrayLike | None = None, velocity_limit: ArrayLike | None = None,
                smooth_ends: bool = False, control_points: int = 14, samples: int = 501,
                q_guess: ArrayLike | None = None, max_iterations: int = 2000,
                feasibility_search: bool = True, derivatives: str = "exact") -> PlanResult:
    """Plan the motion of ``mech``'s actuated joints from ``start`` to ``end`` (rad or m, one per
    actuated joint) in ``duration`` [s] that minimises shaking (module docstring).

    Args:
        objective: ``"force_rms" | "force_peak" | "moment_rms" | "moment_peak"``; ignored when
            ``weights`` is given.
        weights: ``{"force": w1, "moment": w2, "torque": w3}``: minimise
            ``w1 mean|F|^2 + w2 mean|M_p|^2 + w3 mean|tau|^2`` (SI units; objective ``weighted``).
        moment_point: the point p of the shaking moment ``M_p = M_O - p x F`` [m], in O.
        start_velocity: velocities at the start (default zero: from rest).
        end_velocity: velocities at the end (default zero: to rest).
        acceleration_limit: |acceleration| limit per actuated joint (or one number for all).
        torque_limit: |torque| limit per actuated joint (or one number for all), besides the
            model's effort limits (the tighter wins).
        velocity_limit: |velocity| limit per actuated joint, besides the model's (the tighter
            wins).
        smooth_ends: also hold zero accelerations at both ends (no step in the actuator
            torques at the start and the end; by default the accelerations there are free).
        control_points: control points per joint of the quintic B-spline (>= 7).
        samples: the output grid (``samples`` instants over ``[0, duration]``); the limits are
            checked on a grid ten times finer.
        q_guess: a closed mechanism's assembly at the start (default: `mechbal.assembly.assemble`).
        derivatives: ``"exact"`` (forward mode on the model's expression graph where the code
            generator takes the mechanism, `mechbal.plan.exact`; else differences) or
            ``"differences"`` (central differences of the model in the positions).

    Raises `PlanInfeasible` when no motion within the limits is found, with the shortest duration
    the planner found feasible in its message; ValueError on bad arguments."""
    na = len(mech.actuated_names)
    if weights is not None:
        bad = set(weights) - {"force", "moment", "torque"}
        if bad:
            raise ValueError(f"weights: unknown key {sorted(bad)} (known: force, moment, torque)")
        weights = {k: float(v) for k, v in weights.items()}
        if any(not (v >= 0 and np.isfinite(v)) for v in weights.values()) or not any(weights.values()):
            raise ValueError(f"weights must be finite, >= 0 and not all zero, got {weights}")
        objective = "weighted"
    elif objective not in OBJECTIVES:
        raise ValueError(f"objective must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be a finite number of seconds > 0, got {duration!r}")
    q0, q1 = _vector("start", start, na), _vector("end", end, na)
    v0 = np.zeros(na) if start_velocity is None else _vector("start_velocity", start_velocity, na)
    v1 = np.zeros(na) if end_velocity is None else _vector("end_velocity", end_velocity, na)
    limits = model_limits(mech, acceleration_limit, torque_limit, velocity_limit)
    for name, x in (("start", q0), ("end", q1)):
        out = (x < limits.lower) | (x > limits.upper)
        if np.any(out):
            j = int(np.argmax(out))
            raise PlanInfeasible(f"{name} of {mech.actuated_names[j]} = {x[j]:g} is outside its position "
                                 f"limits [{limits.lower[j]:g}, {limits.upper[j]:g}]", None, name)
    for name, x in (("start_velocity", v0), ("end_velocity", v1)):
        out = np.abs(x) > limits.velocity
        if np.any(out):
            j = int(np.argmax(out))
            raise PlanInfeasible(f"{name} of {mech.actuated_names[j]} = {x[j]:g} exceeds its velocity "
                                 f"limit {limits.velocity[j]:g}", None, name)
    if mech.is_closed and q_guess is None:
        from mechbal.assembly import assemble

        q_guess = assemble(mech, q0).q
    am = ActuatedModel(mech, q_guess=q_guess, moment_point=moment_point, derivatives=derivatives)
    with _single_threaded_blas():
        return _plan(am, q0, q1, v0, v1, float(duration), limits, objective=objective, weights=weights,
                     control_points=control_points, samples=samples, max_iterations=max_iterations,
                     smooth_ends=smooth_ends, feasibility_search=feasibility_search)


def _single_threaded_blas():
    """BLAS on one thread while planning: the solver's matrices are small, and a threaded BLAS
    spinning on a loaded machine makes each iteration ten times slower (threadpoolctl where it is
    installed; nothing otherwise)."""
    import contextlib

    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return contextlib.nullcontext()
    return threadpool_limits(1, user_api="blas")


def _plan(am, q0, q1, v0, v1, duration, limits, *, objective, weights, control_points, samples,
          max_iterations, smooth_ends, feasibility_search) -> PlanResult:
    common = dict(objective=objective, weights=weights or {}, control_points=control_points,
                  samples=samples, max_iterations=max_iterations, smooth_ends=smooth_ends)
    if feasibility_search and limits.active_kinds():
        # feasible at all? (before the long run: a motion within the limits, no objective)
        first = _solve(am, q0, q1, v0, v1, float(duration), limits, feasibility_only=True, **common)
        if not first.ok and _is_limited(first):
            shortest = _shortest_duration(am, q0, q1, v0, v1, duration, limits, common)
            raise PlanInfeasible(_shortest_duration_message(duration, first, shortest), shortest)
    return _solve(am, q0, q1, v0, v1, float(duration), limits, **common)


def _shortest_duration(am, q0, q1, v0, v1, duration, limits, common) -> float | None:
    """The shortest duration (to 0.5 %) at which the planner finds a motion within the limits
    (bisection over durations, doubling first), or None up to 4096 times ``duration``."""
    def feasible(T: float) -> bool:
        try:
            return _solve(am, q0, q1, v0, v1, T, limits, feasibility_only=True, **common).ok
        except LoopFailure:   # the search wandered out of the workspace: no motion found at T
            return False
    lo, hi = float(duration), 2.0 * float(duration)
    for _ in range(12):
        if feasible(hi):
            break
        lo, hi = hi, 2.0 * hi
    else:
        return None
    while hi - lo > 0.005 * hi:
        mid = 0.5 * (lo + hi)
        if feasible(mid):
            hi = mid
        else:
            lo = mid
    return hi


def _shortest_duration_message(duration: float, first: PlanResult, shortest: float | None) -> str:
    why = first.message.removeprefix("limits exceeded: ").split(" (solver:")[0]
    if shortest is None:
        return (f"duration {duration:g} s is too short for the limits ({why}), and no duration up to "
                f"{4096 * duration:g} s holds them")
    return (f"duration {duration:g} s is too short for the limits ({why}); the shortest feasible "
            f"duration found is {shortest:.4g} s")


def _is_limited(result: PlanResult) -> bool:
    return result.message.startswith("limits exceeded")


def _solve(am: ActuatedModel, q0, q1, v0, v1, T: float, limits: Limits, *, objective: str,
           weights: dict, control_points: int, samples: int, max_iterations: int, smooth_ends: bool,
           feasibility_only: bool = False) -> PlanResult:
    from scipy.optimize import minimize

    na = am.na
    basis = SplineBasis.make(T, int(control_points), 3 if smooth_ends else 2)
    boundary = (np.vstack([q0, v0, np.zeros(na), q1, v1, np.zeros(na)]) if smooth_ends
                else np.vstack([q0, v0, q1, v1]))
    quintic = quintic_with_velocities(q0, q1, T, v0, v1)
    nodes, node_weights = _gauss_nodes(basis.knots, NODES_PER_SPAN)
    # warm start: the quintic, exactly a spline of this basis
    fit_t = np.linspace(0.0, T, 4 * control_points)
    z0 = basis.fit(fit_t, quintic.evaluate(fit_t).q, boundary)
    prob = _Problem(am, basis, boundary, objective, weights, limits.shrunk(LIMIT_MARGIN), nodes, node_weights)
    x0 = z0.reshape(-1)
    quintic_value = prob.value(x0)
    prob.scale = quintic_value if quintic_value > 0 else 1.0
    if prob.peak:
        x0 = np.concatenate([x0, [1.0 + 1e-6]])
    check_t = np.linspace(0.0, T, 10 * (int(samples) - 1) + 1)
    torque = bool(np.any(np.isfinite(limits.torque)))
    x = x0
    res = None
    message, iterations = "", 0
    traj_of = lambda x: SplineTrajectory(  # noqa: E731
        basis, basis.control_points(x[: na * basis.free_count].reshape(basis.free_count, na), boundary))
    traj = traj_of(x)
    rounds = 8
    if not prob.peak and not feasibility_only:
        # without its limits first (BFGS: the exact gradient, cheap iterations); the limits
        # after, by SLSQP from there, where the motion touches them
        first = minimize(prob.fun, x0, jac=True, method="BFGS",
                         options={"maxiter": max_iterations, "gtol": GRADIENT_TOLERANCE})
        x, iterations, message = first.x, int(first.nit), str(first.message)
        traj = traj_of(x)
        found, _ = _violations(am, traj, limits, check_t, torque)
        if not any(v[5] > LIMIT_TOLERANCE for v in found):
            rounds = 0
            res = first
            # BFGS stops on "precision loss" at a flat optimum: converged if the gradient is nil
            res.success = bool(first.success or np.linalg.norm(first.jac, np.inf) <= ACCEPTED_GRADIENT)
        else:
            # the quintic's near-limit instants too: SLSQP's path from here stays within them
            _watch(prob, _violations(am, traj_of(x0), limits, check_t, torque)[0])
    elif rounds:
        found, _ = _violations(am, traj, limits, check_t, torque)
    for _round in range(rounds):
        _watch(prob, found)
        cons = prob.linear_constraints(x.size)
        if any(k[0] == "torque" for k in prob.watched):
            cons.append({"type": "ineq", "fun": lambda x: prob.torque_constraint(x)[0],
                         "jac": lambda x: prob.torque_constraint(x)[1]})
        if prob.peak:
            cons.append({"type": "ineq", "fun": lambda x: prob.peak_constraint(x)[0],
                         "jac": lambda x: prob.peak_constraint(x)[1]})
        if feasibility_only:
            fun = lambda x: (0.0, np.zeros_like(x))  # noqa: E731
        else:
            fun = prob.fun
        res = minimize(fun, x, jac=True, method="SLSQP", constraints=cons,
                       options={"maxiter": max_iterations, "ftol": 1e-12})
        x = res.x
        iterations += int(res.nit)
        message = str(res.message)
        traj = traj_of(x)
        found, _ = _violations(am, traj, limits, check_t, torque)
        if not any(v[5] > LIMIT_TOLERANCE for v in found):
            break
    found, _ = _violations(am, traj, limits, check_t, torque)
    over = [v for v in found if v[5] > LIMIT_TOLERANCE]
    ok = bool(res is not None and res.success and not over)
    if over:
        worst = max(over, key=lambda v: v[5])
        message = (f"limits exceeded: {worst[0]} of joint {worst[1]} reaches {worst[3]:.6g} against "
                   f"{worst[4]:.6g} at t = {worst[2]:.4g} s (solver: {message})")
    active = [dict(kind=v[0], joint=v[1], time=v[2], value=v[3], limit=v[4])
              for v in found if v[5] > -1e-4]
    metrics: dict[str, dict[str, float]] = {}
    if feasibility_only:
        value = float("nan")
    else:
        planned = _metrics(am, traj, check_t, prob)
        reference = _metrics(am, quintic, check_t, prob)
        value, quintic_value = planned.pop("objective"), reference.pop("objective")
        metrics = {"planned": planned, "quintic": reference}
    return PlanResult(trajectory=traj, quintic=quintic, objective=objective, weights=weights,
                      moment_point=am.moment_point, value=value, quintic_value=quintic_value,
                      reduction=1.0 - value / quintic_value if quintic_value > 0 else 0.0,
                      active_limits=active, limits=limits, ok=ok, message=message,
                      iterations=iterations, checked_samples=len(check_t), metrics=metrics,
                      derivatives="exact" if am.exact_of(prob.need_torque) is not None else "differences")


#: a limit is watched (imposed) at the instants where the motion comes within this fraction of it
NEAR_LIMIT = 0.05
#: at most this many instants per limit and round (the local maxima first)
WATCH_PER_ROUND = 24


def _watch(prob: "_Problem", found) -> None:
    """Watch each limit at the instants where the motion comes near it: its local maxima within
    `NEAR_LIMIT` of the limit, and a few instants spread over the stretches near it."""
    for kind, j, _, _, _, _, excess, grid, side in found:
        near = excess > -NEAR_LIMIT
        if not np.any(near):
            continue
        inner = np.r_[False, (excess[1:-1] >= excess[:-2]) & (excess[1:-1] >= excess[2:]), False]
        peaks = np.flatnonzero(near & (inner | (np.arange(len(excess)) == 0) | (np.arange(len(excess)) == len(excess) - 1)))
        peaks = peaks[np.argsort(excess[peaks])[::-1][:WATCH_PER_ROUND]]
        spread = np.flatnonzero(near)
        spread = spread[np.linspace(0, len(spread) - 1, min(len(spread), WATCH_PER_ROUND)).astype(int)]
        prob.watch(kind, j, side, grid[np.union1d(peaks, spread)])


def _metrics(am: ActuatedModel, traj, t: np.ndarray, prob: "_Problem") -> dict[str, float]:
    """RMS and peak |F|, |M_p| and the objective of a motion on the grid ``t`` (RMS by the
    trapezoid rule over [0, T])."""
    q, v, a = traj.evaluate(t)
    ev = am.evaluate(q, v, a, torque=prob.need_torque)
    w = _trapezoid(t) / (t[-1] - t[0])
    F2 = np.sum(ev.wrench[:, :3] ** 2, axis=1)
    M2 = np.sum(ev.wrench[:, 3:] ** 2, axis=1)
    out = {"rms_shaking_force": float(np.sqrt(w @ F2)), "peak_shaking_force": float(np.sqrt(F2.max())),
           "rms_shaking_moment": float(np.sqrt(w @ M2)), "peak_shaking_moment": float(np.sqrt(M2.max()))}
    if ev.torque is not None:
        T2 = np.sum(ev.torque ** 2, axis=1)
        out["rms_joint_torque"] = float(np.sqrt(w @ T2))
    if prob.objective == "weighted":
        wt = prob.weights
        out["objective"] = (wt.get("force", 0.0) * float(w @ F2) + wt.get("moment", 0.0) * float(w @ M2)
                            + wt.get("torque", 0.0) * (out.get("rms_joint_torque", 0.0) ** 2))
    else:
        quantity, stat = prob.objective.split("_")
        out["objective"] = out[f"{stat}_shaking_{quantity}"]
    return out


def _trapezoid(t: np.ndarray) -> np.ndarray:
    w = np.zeros_like(t)
    d = np.diff(t)
    w[:-1] += 0.5 * d
    w[1:] += 0.5 * d
    return w
