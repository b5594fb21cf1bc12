"""The lightest (or least-inertia, or least peak-torque) counterweight design as a convex program,
solved with a certificate of optimality.

**Why convex.** The balancing conditions of the counterweight methods (static: gravity torque;
force: linear momentum) are linear in each slot's mass m and mass moment h = m p
(`mechbal.balance.common`): residual rows ``A x + b``. The slot bounds are convex in (m, h):
``mass_min <= m <= mass_max`` and a total ``mass_budget`` are linear, a radius ``|p - c| <= R``
is the second-order cone ``|h - m c| <= R m``. So the added mass ``sum m`` is a linear objective
over a second-order-cone set (the "sum of norms": each mass is |mass moment| / radius at its
best), and the RMS residual ``|A x + b| / sqrt(N)`` is a second-order cone too. The added
inertia is convex as well: a point mass m at p adds ``m f(p)`` to the trace of the joint-space mass
matrix (f a convex quadratic: the squared norm of the point's Jacobian), ``= w^T W w / m`` for
w = (m, h), a quadratic over linear (a rotated cone). The peak static torque ``max |A x + b|``
over the samples is linear with an epigraph.

**Lexicographic.** (1) The least residual: the balance is as good as the slots allow. (2) Among
the designs of that residual, the least objective. When a least-squares solution meets the
bounds, the designs of the least residual are the least-squares set ``y_0 + Z z`` (the SVD's
minimum-norm solution and null space, exact) and the objective is minimised over z. When the
bounds exclude every least-squares solution, (1) is the conic program ``min t``,
``|R y + c| <= t`` over the bounds (R the triangular factor of the rows), and (2) minimises the
objective over the designs whose RMS residual is within ``RESIDUAL_RTOL`` (1e-6, relative) of
that least residual: the exact set of least-residual designs has no interior where a bound is
active, and its lightest design moves like the square root of any error in (1)'s solution, so no
finite-precision solver pins it; within 1e-6 the program is well posed and certified. With a ``residual_target`` above the least
residual, (2) is ``min objective`` subject to ``RMS residual <= target`` instead (the
epsilon-constraint, `mechbal.balance.fronts`); with a ``mass_budget``, (1) is the least residual
within that budget.

**Certificate.** Each stage is solved by Clarabel (an interior-point conic solver, the
``optimal`` extra: ``pip install mechbal[optimal]``, imported on first use); the result carries
the primal and dual objectives and their difference (the duality gap: the optimum lies between
them), the solver's status and iterations, in ``BalanceResult.metrics["optimality"]`` and
summary.json.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

#: the objectives of stage 2
OBJECTIVES = ("mass", "inertia", "torque")
#: when the bounds exclude the least squares, stage 2 takes the designs whose RMS residual is within
#: this fraction of the least one (the "same residual" of the lexicographic order)
RESIDUAL_RTOL = 1e-6
#: a free mass below this fraction of the mass scale is taken for zero in the polish of `solve`
APEX_RTOL = 1e-8
#: the solver's tolerances (relative duality gap, feasibility)
TOL_GAP = 1e-11
TOL_FEAS = 1e-11


class MissingExtra(ImportError):
    """The ``optimal`` extra (Clarabel) is not installed."""


def clarabel_module():
    """The Clarabel module, or a MissingExtra naming the extra."""
    try:
        import clarabel
    except ImportError:
        raise MissingExtra("the certified convex solve (objective, residual target, fronts) needs the "
                           "'optimal' extra: pip install 'mechbal[optimal]' (the Clarabel conic solver)") from None
    return clarabel


def available() -> bool:
    try:
        clarabel_module()
    except MissingExtra:
        return False
    return True


@dataclass
class Stage:
    """One conic solve: ``primal`` and ``dual`` objectives (in the stage's unit), their
    difference ``gap``, the solver status and iterations."""

    name: str
    status: str
    primal: float
    dual: float
    iterations: int
    unit: str

    @property
    def gap(self) -> float:
        return abs(self.primal - self.dual)

    def to_dict(self) -> dict[str, Any]:
        return {"stage": self.name, "status": self.status, "primal_objective": self.primal,
                "dual_objective": self.dual, "duality_gap": self.gap,
                "relative_gap": self.gap / max(abs(self.primal), abs(self.dual), 1e-300),
                "iterations": self.iterations, "unit": self.unit}


class _Conic:
    """Rows of ``A v + s = b, s in K`` over the variables v, cone by cone (Clarabel's form)."""

    def __init__(self, n: int):
        self.n = n
        self.blocks: list[tuple[str, np.ndarray, np.ndarray]] = []

    def nonneg(self, a: np.ndarray, b: np.ndarray) -> None:
        """a v + b >= 0, row-wise."""
        a = np.atleast_2d(a)
        if a.shape[0]:
            self.blocks.append(("+", -a, np.asarray(b, float).reshape(-1)))

    def soc(self, a: np.ndarray, b: np.ndarray) -> None:
        """(a v + b)[0] >= |(a v + b)[1:]|."""
        self.blocks.append(("q", -np.atleast_2d(a), np.asarray(b, float).reshape(-1)))

    def solve(self, c: np.ndarray, name: str, unit: str, scale: float = 1.0):
        clarabel = clarabel_module()
        import scipy.sparse as sp

        A = sp.csc_matrix(np.vstack([blk[1] for blk in self.blocks]).reshape(-1, self.n))
        b = np.concatenate([blk[2] for blk in self.blocks]) if self.blocks else np.zeros(0)
        cones = []
        for kind, a, _ in self.blocks:
            if kind == "+":
                if cones and isinstance(cones[-1], clarabel.NonnegativeConeT):
                    cones[-1] = clarabel.NonnegativeConeT(cones[-1].dim + a.shape[0])  # type: ignore[attr-defined]
                else:
                    cones.append(clarabel.NonnegativeConeT(a.shape[0]))
            else:
                cones.append(clarabel.SecondOrderConeT(a.shape[0]))
        st = clarabel.DefaultSettings()
        st.verbose = False
        st.tol_gap_rel = st.tol_gap_abs = TOL_GAP
        st.tol_feas = TOL_FEAS
        st.tol_ktratio = 1e-10
        st.max_iter = 400
        P = sp.csc_matrix((self.n, self.n))
        sol = clarabel.DefaultSolver(P, np.asarray(c, float), A, b, cones, st).solve()
        status = str(sol.status)
        # a solve that stalled (InsufficientProgress, MaxIterations) still returns its last iterate:
        # the caller checks it against the bounds and the certificate reports the gap it reached
        bad = "Infeasible" in status or not np.all(np.isfinite(np.asarray(sol.x, float)))
        x = None if bad else np.asarray(sol.x, float)
        stage = Stage(name, status, float(sol.obj_val) * float(scale), float(sol.obj_val_dual) * float(scale),
                      int(sol.iterations), unit)
        return x, stage


def _cone_cons(prob: _Conic, dsg, to_y: np.ndarray, y_off: np.ndarray, mscale: float) -> None:
    """The slots' bounds over variables v with y = to_y v + y_off (kg units: moments / L)."""
    if len(dsg.g):
        sc = (dsg.lin_scale * mscale)[:, None]
        prob.nonneg((dsg.G @ to_y) / sc, (dsg.G @ y_off + dsg.g) / sc[:, 0])
    for k in dsg.cones:
        s = dsg.slots[k]
        j = dsg.mass_var[k]
        rows_a = np.zeros((1 + len(dsg.d_vars[k]), to_y.shape[1]))
        rows_b = np.zeros(1 + len(dsg.d_vars[k]))
        if j is not None:
            rows_a[0] = s.max_radius / dsg.L * to_y[j]
            rows_b[0] = s.max_radius / dsg.L * y_off[j]
        else:
            rows_b[0] = s.max_radius * s.mass_min
        rows_a[1:] = to_y[dsg.d_vars[k]]
        rows_b[1:] = y_off[dsg.d_vars[k]]
        sc = dsg.L * mscale
        prob.soc(rows_a / sc, rows_b / sc)


@dataclass
class Objective:
    """What stage 2 minimises. ``kind``: "mass" (the added mass, kg), "inertia" (the mean over the
    samples of the trace of the joint-space inertia the counterweights add, kg m^2: ``W`` per slot,
    (4, 4) in (m, h_user)), "torque" (the peak |static torque| over the samples, N m: ``rows``
    (At, bt) with torque = At x + bt)."""

    kind: str = "mass"
    W: list[np.ndarray] | None = None
    rows: tuple[np.ndarray, np.ndarray] | None = None
    #: the objective's constant part (the slots' own central inertias, for "inertia")
    constant: float = 0.0

    def unit(self) -> str:
        return {"mass": "kg", "inertia": "kg m^2", "torque": "N m"}[self.kind]


@dataclass
class ConvexSolution:
    """(y, residual RMS, objective value, stages) of `solve`."""

    y: np.ndarray
    residual: float
    least_residual: float
    objective: float
    stages: list[Stage] = field(default_factory=list)
    #: the least-residual design of stage 1 where the bounds exclude the least squares: the bounds
    #: active there are what limits the balance (the design within the band may leave them by ~1e-6)
    y_least: np.ndarray | None = None

    def certificate(self, objective: str) -> dict[str, Any]:
        return {"solver": "clarabel", "objective": objective, "lexicographic": "least residual first, "
                "then the objective among the designs of that residual (or within residual_target)",
                "stages": [s.to_dict() for s in self.stages],
                "duality_gap": self.stages[-1].gap if self.stages else None}


def solve(dsg, Ay: np.ndarray, by: np.ndarray, Z: np.ndarray, mscale: float, *,
          objective: Objective | None = None, residual_target: float | None = None,
          P: np.ndarray | None = None, xc: np.ndarray | None = None,
          y0: np.ndarray | None = None, rows: int | None = None, rest: float = 0.0) -> ConvexSolution:
    """The lexicographic program of the module docstring over the free variables y of ``dsg``
    (`mechbal.balance.common._Design`): residual rows ``Ay y + by`` (RMS over the rows), null space
    ``Z`` of Ay, ``y0`` its least-squares solution (tried first); ``rows``, ``rest``: the rows are
    a compressed form, RMS ``sqrt((|Ay y + by|^2 + rest) / rows)``. ``P``, ``xc``: x = P y + xc, (m, h_user) per group root (for the inertia and
    torque objectives; default dsg's). ValueError when ``residual_target`` is below the least
    residual the bounds allow (naming both)."""
    obj = objective or Objective()
    if obj.kind not in OBJECTIVES:
        raise ValueError(f"objective: must be one of {', '.join(OBJECTIVES)} (got {obj.kind!r})")
    P = dsg.P if P is None else P
    xc = dsg.xc if xc is None else xc
    N = Ay.shape[0] if rows is None else int(rows)
    ny = Ay.shape[1]
    ys = mscale * dsg.L                      # y = ys u: u is O(1)
    Qf, Rf = np.linalg.qr(Ay)
    cf = Qf.T @ by
    e0 = by - Qf @ cf
    const0 = float(e0 @ e0) + rest
    rscale = max(float(np.linalg.norm(by)), 1e-300)
    rms = lambda y: float(np.sqrt((np.sum((Ay @ y + by) ** 2) + rest) / N)) if N else 0.0  # noqa: E731

    def stage2(base, off, tau=None):
        """The objective over y = off + base z (within |R y + c| <= tau when given)."""
        extra = _extra_vars(obj, dsg)
        nz = base.shape[1]
        n = nz + extra
        if nz == 0:
            v0 = _value(obj, dsg, P, xc, off)
            return off.copy(), Stage(f"least {obj.kind}", "Solved", v0, v0, 0, obj.unit())
        pr = _Conic(n)
        to_y = np.hstack([base, np.zeros((ny, extra))])
        _cone_cons(pr, dsg, to_y, off, mscale)
        if tau is not None:
            r1 = Rf @ y1 + cf if y1 is not None else None
            T = float(np.linalg.norm(r1)) if r1 is not None else 0.0
            if T > 0 and tau > T:
                # |r| <= tau written about the stage-1 residual r1 (unit u, length T): with
                # u.r = T (1 + e a), the rest of r = T sqrt(2 e) v, e = tau / T - 1, it is
                # |v|^2 + (e / 2) a^2 <= 1 + e / 2 - a: the same set, but a cone of order one where
                # |r| <= tau is a band of relative width e (which an interior-point solve resolves
                # badly)
                e = tau / T - 1.0
                u = r1 / T
                Up = np.linalg.svd(np.eye(len(u)) - np.outer(u, u))[0][:, :len(u) - 1]
                Ar, br = Rf @ to_y, Rf @ off + cf
                a_a, a_b = (u @ Ar) / (T * e), (u @ br - T) / (T * e)            # a = a_a v + a_b
                v_a, v_b = (Up.T @ Ar) / (T * math.sqrt(2 * e)), (Up.T @ br) / (T * math.sqrt(2 * e))
                k = math.sqrt(e / 2)
                s_a, s_b = -a_a, 1.0 + e / 2 - a_b                                # s = 1 + e/2 - a
                rows_a = np.vstack([s_a, 2 * v_a, 2 * k * a_a, s_a])
                rows_b = np.r_[s_b + 1.0, 2 * v_b, 2 * k * a_b, s_b - 1.0]
                pr.soc(rows_a, rows_b)
            else:
                a = np.vstack([np.zeros(n), (Rf @ to_y) / rscale])
                pr.soc(a, np.r_[tau / rscale, (Rf @ off + cf) / rscale])
        cost, unit_scale = _stage2(pr, obj, dsg, P, xc, to_y, off, nz, mscale)
        v, st = pr.solve(cost, f"least {obj.kind}", obj.unit(), unit_scale)
        if obj.kind == "mass":   # the cost counts the free masses' change from ``off``: add the rest
            rest = float(dsg.mass_row @ off) + sum(dsg.count[k] * s.mass_min for k, s in enumerate(dsg.slots)
                                                   if dsg.mass_var[k] is None)
            st.primal += rest
            st.dual += rest
        return (None if v is None else off + to_y @ v), st

    def polished(base, off, tau=None):
        """stage2, then again with the slots it left at their cone's apex (a vanishing free mass,
        where an interior-point solve stalls) fixed at zero: the design on the same set, exact."""
        y, st = stage2(base, off, tau)
        if y is None:
            return y, st
        apex = [k for k in dsg.cones if dsg.mass_var[k] is not None and dsg.slots[k].mass_min == 0.0
                and y[dsg.mass_var[k]] / dsg.L < APEX_RTOL * mscale]
        if not apex:
            return y, st
        from scipy.linalg import null_space

        idx = [i for k in apex for i in [dsg.mass_var[k], *dsg.d_vars[k]]]
        B = base[idx]
        zp = np.linalg.lstsq(B, -off[idx], rcond=None)[0]
        if np.linalg.norm(B @ zp + off[idx]) > 1e-12 * ys:
            return y, st
        N2 = null_space(B)
        off2 = off + base @ zp
        off2[idx] = 0.0
        y2, st2 = stage2(base @ N2, off2, tau)
        if y2 is None or dsg.violation(y2, mscale) > max(dsg.violation(y, mscale), 1e-9):
            return y, st
        if _value(obj, dsg, P, xc, y2) > _value(obj, dsg, P, xc, y) + 1e-8 * max(abs(st.primal), 1e-300):
            return y, st
        st2.name += " (vanishing slots fixed at zero)"
        return y2, st2

    y1 = None
    stages: list[Stage] = []
    if (dsg.budget is not None and dsg.budget <= 0.0
            and all(s.mass_min == 0.0 and (math.isfinite(s.max_radius) or s.fixed_position) for s in dsg.slots)):
        # no mass to add: the only design is no counterweight at all (a point, no interior)
        y = np.zeros(ny)
        return ConvexSolution(y, rms(y), rms(y), _value(obj, dsg, P, xc, y),
                              [Stage("no added mass", "Solved", 0.0, 0.0, 0, obj.unit())])
    if residual_target is None and y0 is not None:
        # the least-squares set y0 + Z z (exact, from the SVD): when a design on it meets the
        # bounds, the least residual is the least squares' and stage 1 is not needed
        if Z.shape[1] == 0:
            if dsg.violation(y0, mscale) <= 1e-9:
                return ConvexSolution(y0, rms(y0), rms(y0), _value(obj, dsg, P, xc, y0), stages)
        else:
            y, st = polished(Z * ys, y0)
            if y is not None and dsg.violation(y, mscale) <= 1e-7:
                return ConvexSolution(y, rms(y), rms(y0), _value(obj, dsg, P, xc, y), [st])

    # stage 1: least residual, min t s.t. |R y + c| <= t, the bounds
    pr = _Conic(ny + 1)
    eye = np.hstack([np.eye(ny) * ys, np.zeros((ny, 1))])
    _cone_cons(pr, dsg, eye, np.zeros(ny), mscale)
    a = np.vstack([np.r_[np.zeros(ny), 1.0], np.hstack([Rf * ys, np.zeros((ny, 1))]) / rscale])
    pr.soc(a, np.r_[0.0, cf / rscale])
    c1 = np.r_[np.zeros(ny), 1.0]
    v, st1 = pr.solve(c1, "least residual", "norm of the residual rows / norm of the unbalanced rows")
    if v is None:
        raise RuntimeError(f"the convex solve failed at the least residual (Clarabel status {st1.status})")
    y1 = ys * v[:ny]
    t1 = float(np.linalg.norm(Rf @ y1 + cf))
    least = math.sqrt((t1 ** 2 + const0) / N) if N else 0.0
    stages.append(st1)

    # stage 2: the objective among the least-residual designs (y1 + Z z), or within the target
    if residual_target is not None:
        if residual_target < least * (1 - 1e-9) - 1e-15:
            raise ValueError(f"residual_target: {residual_target:.6g} is below the least residual the slots "
                             f"and bounds allow ({least:.6g})")
        tau = math.sqrt(max(N * residual_target ** 2 - const0, 0.0))
        y, st2 = polished(np.eye(ny) * ys, np.zeros(ny), tau)
    else:
        # the bounds exclude the least squares: the designs whose residual is within RESIDUAL_RTOL
        # of the least (the exact set, R y = R y1, has no interior where a bound is active, and its
        # lightest design moves like the square root of any error in y1: no solver pins it)
        tau = math.sqrt(max(N * (least * (1 + RESIDUAL_RTOL)) ** 2 - const0, 0.0))
        y, st2 = polished(np.eye(ny) * ys, np.zeros(ny), tau)
        st2.name += f" within {RESIDUAL_RTOL:g} (relative) of the least residual"
        if y is not None and obj.kind == "mass" and st2.status != "Solved":
            # the band is thin (1e-6): where an interior-point solve stops short of its tolerance there,
            # a local polish from its point (SLSQP on the same convex program) is kept when it is
            # feasible and lighter
            yp = _polish_band(dsg, Rf, cf, tau, y, mscale)
            if yp is not None and float(dsg.mass_row @ yp) < float(dsg.mass_row @ y):
                y = yp
                st2.name += ", polished by SLSQP"
    if y is None:
        raise RuntimeError(f"the convex solve failed at the objective (Clarabel status {st2.status})")
    stages.append(st2)
    return ConvexSolution(y, rms(y), least, _value(obj, dsg, P, xc, y), stages,
                          y_least=y1 if residual_target is None else None)


def _polish_band(dsg, Rf, cf, tau, y, mscale):
    """SLSQP from ``y``: min added mass over the bounds and ``|Rf y + cf| <= tau``; None unless it
    is feasible (bounds to 1e-10 of the mass scale, the band to 1e-12)."""
    from scipy.optimize import minimize

    c = dsg.mass_row / mscale
    t2 = max(tau * tau, 1e-300)
    cons = dsg.scipy(lambda yy: yy, np.eye(len(y)))
    cons.append({"type": "ineq", "fun": lambda yy: np.array([1.0 - float(np.sum((Rf @ yy + cf) ** 2)) / t2]),
                 "jac": lambda yy: (-2.0 * (Rf.T @ (Rf @ yy + cf)) / t2)[None, :]})
    try:
        r = minimize(lambda yy: (float(c @ yy), c), y, jac=True, method="SLSQP", constraints=cons,
                     options=dict(ftol=1e-15, maxiter=500))
    except (ValueError, np.linalg.LinAlgError):
        return None
    yp = r.x
    if not np.all(np.isfinite(yp)) or dsg.violation(yp, mscale) > 1e-10:
        return None
    if float(np.sum((Rf @ yp + cf) ** 2)) > t2 * (1 + 1e-12):
        return None
    return yp


def _extra_vars(obj: Objective, dsg) -> int:
    if obj.kind == "inertia":
        return len(dsg.slots)
    if obj.kind == "torque":
        return 1
    return 0


def _stage2(pr: _Conic, obj: Objective, dsg, P, xc, to_y, off, nz, mscale):
    """Add the objective's epigraph rows; (cost, scale back to the unit)."""
    n = pr.n
    if obj.kind == "mass":
        return np.r_[dsg.mass_row @ to_y[:, :nz], np.zeros(n - nz)] / mscale, mscale
    if obj.kind == "torque":
        At, bt = obj.rows
        T = At @ P                  # torque rows over y
        tb = At @ xc + bt
        tsc = max(float(np.max(np.abs(tb))), 1e-300)
        ty = T @ to_y / tsc
        t0 = (T @ off + tb) / tsc
        ty[:, -1] = 0.0
        e = np.zeros(n)
        e[-1] = 1.0
        pr.nonneg(e[None, :] - ty, -t0)          # t - torque >= 0
        pr.nonneg(e[None, :] + ty, t0)           # t + torque >= 0
        return e, tsc
    # inertia: s_k >= w^T W w / m (rotated cone), w = (m, h_user) of slot k
    Wsc = max(max(float(np.trace(W)) for W in obj.W), 1e-300) * mscale
    cost = np.zeros(n)
    for k, W in enumerate(obj.W):
        wa = P[4 * k:4 * k + 4] @ to_y / mscale          # w / mscale (kg units: h / L ... in kg m)
        wb = (P[4 * k:4 * k + 4] @ off + xc[4 * k:4 * k + 4]) / mscale
        ev, evec = np.linalg.eigh(0.5 * (W + W.T))
        Wh = (evec * np.sqrt(np.clip(ev, 0.0, None))) @ evec.T / math.sqrt(Wsc / mscale)
        j = nz + k
        es = np.zeros(n)
        es[j] = 1.0
        # || (2 Wh w, s - m) || <= s + m
        rows_a = np.vstack([es + wa[0], 2.0 * Wh @ wa, es - wa[0]])
        rows_b = np.r_[wb[0], 2.0 * Wh @ wb, -wb[0]]
        pr.soc(rows_a, rows_b)
        cost[j] = 1.0
    return cost, Wsc


def _value(obj: Objective, dsg, P, xc, y) -> float:
    if obj.kind == "mass":
        return float(dsg.mass_row @ y)
    x = P @ y + xc
    if obj.kind == "torque":
        At, bt = obj.rows
        return float(np.max(np.abs(At @ x + bt))) if len(bt) else 0.0
    total = obj.constant
    for k, W in enumerate(obj.W):
        w = x[4 * k:4 * k + 4]
        if w[0] > 1e-300:
            total += float(w @ W @ w) / w[0]
    return total


def inertia_weights(mech, slots: Sequence[Any], q: np.ndarray, C: np.ndarray | None = None) -> list[np.ndarray]:
    """Per slot, W (4, 4) in (m, h_user) such that a point mass m at p (user frame) adds
    ``w^T W w / m`` (w = (m, m p)) to the mean over the samples ``q`` of the trace of the
    joint-space mass matrix (closed: of C^T M C, the actuated coordinates'). Read from the public
    mass matrix with a unit point mass at 10 points per link (the trace is quadratic in p)."""
    from mechbal import _core

    q = np.atleast_2d(q)

    def tr(M):
        if C is not None:
            M = np.einsum("nia,nij,njb->nab", C, M, C)
        return float(np.mean(np.trace(M, axis1=1, axis2=2)))

    base = tr(mech.mass_matrix(q))
    cache: dict[str, np.ndarray] = {}
    out = []
    for s in slots:
        if s.link not in cache:
            def f(p):
                body = _core.Body("__inertia_probe", s.link, 1.0, np.asarray(p, float), np.zeros((3, 3)), "other")
                return tr(mech.with_bodies([body]).mass_matrix(q)) - base
            c0 = f(np.zeros(3))
            E = np.eye(3)
            fp = [f(E[i]) for i in range(3)]
            fm = [f(-E[i]) for i in range(3)]
            Q = np.zeros((3, 3))
            lvec = np.zeros(3)
            for i in range(3):
                Q[i, i] = 0.5 * (fp[i] + fm[i]) - c0
                lvec[i] = 0.25 * (fp[i] - fm[i])
            for i in range(3):
                for j in range(i + 1, 3):
                    Q[i, j] = Q[j, i] = 0.5 * (f(E[i] + E[j]) - c0 - 2 * lvec[i] - 2 * lvec[j] - Q[i, i] - Q[j, j])
            Wl = np.zeros((4, 4))
            Wl[0, 0], Wl[0, 1:], Wl[1:, 0], Wl[1:, 1:] = c0, lvec, lvec, Q
            cache[s.link] = Wl
        Wl = cache[s.link]
        R, t = s.T[:3, :3], s.T[:3, 3]
        T4 = np.eye(4)
        T4[1:, 0] = t
        T4[1:, 1:] = R
        out.append(T4.T @ Wl @ T4)
    return out
