"""RMS or peak actuator torque minimisation by counterweights along a trajectory.

Arakelian, Le Baron & Mottu 2011 (Mechatronics 21:310-314), eqs 32-59, generalised to any
mechanism. The actuator torques are linear in every body's 10 inertial parameters
(``tau = Y(q, v, a) pi``, the torque regressor), and a counterweight of mass m at p (link frame,
inertia I_c about its centre) adds ``theta(m, p) = [m, m p, I_c + m (|p|^2 E - p p^T)]`` to its
link: along a sampled motion

    tau(t_i) = tau_0(t_i) + sum_k Y_L_k(t_i)[:, 0:10] theta(m_k, p_k)

exactly (closed mechanisms: the actuated forces C^T tau). For a fixed mass on a line
p = center + r direction this is the paper's quadratic ``alpha r^2 + beta r + d`` (eqs 32, 36),
for free masses and positions a polynomial; the objective is the mean square (RMS) or the peak of
the torques.

``coupling``:

* ``"per_joint"`` (open mechanisms; the paper's): each slot serves the joint that moves its link
  (or the nearest moving, non-geared ancestor), and joints are sized from the distal end towards
  the base, each minimising its own RMS (or peak) torque with the slots of its descendants
  already fixed: a counterweight does not change the torque of a joint that is not its ancestor,
  so this is the corrected ordering of eqs 43-45 for any tree. A joint served by one slot of fixed
  mass on a line, minimising RMS, is the paper's quartic: its stationarity cubic (eqs 41-49) is
  solved in closed form (Viete / Cardano, eqs 50-59: `cubic_real_roots`; the paper's own
  coefficients, eqs 33-38, are `mechbal.papers.arm2dof.rms_optimal_radii`)
  and every real root inside the bounds and both bounds are compared (the fast path, checked
  against the numerical path in the tests).
* ``"total"``: every slot together minimises ``sum_j w_j mean(tau_j^2)`` (or the largest
  ``max |tau_j| / w_j``) with scipy (several starts: the objective is not convex).

Bounds that the optimum sits on are reported in ``limited_by`` (a fixed mass is a choice, not a
limit); the result is ``exact`` only when no bound stops the optimum.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from mechbal import _core
from mechbal.balance import common
from mechbal.balance.result import BalanceResult, CounterweightSlot

_IDX = [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)]  # Ixx, Ixy, Iyy, Ixz, Iyz, Izz


# ---- the quartic in a radius and its stationarity cubic (Arakelian et al. 2011, eqs 39-59, general form)

def quadratic_in_radius(torque_of_r: Callable[[float], np.ndarray]):
    """(alpha, beta, gamma) with torque(r) = alpha r^2 + beta r + gamma, exactly, from three
    evaluations at r = -1, 0, 1 (valid for any mechanism where a point mass slides on a body-fixed
    line: the torque is quadratic in its position)."""
    tm, t0, tp = torque_of_r(-1.0), torque_of_r(0.0), torque_of_r(1.0)
    return 0.5 * (tp + tm) - t0, 0.5 * (tp - tm), t0


def stationarity_cubic(alpha, beta, d) -> tuple[float, float, float]:
    """Monic z^3 + a z^2 + b z + c = 0 of d/dr sum_i (alpha_i r^2 + beta_i r + d_i)^2 = 0
    (eqs 41-49 in general form): a = 3 S(ab)/(2 S(aa)), b = (S(bb) + 2 S(ad))/(2 S(aa)),
    c = S(bd)/(2 S(aa)). Raises ValueError if S(aa) = 0 (no acceleration: the optimum is then the
    static one, -S(bd)/S(bb))."""
    den = 2.0 * float(np.sum(alpha * alpha))
    if not den > 0.0:
        raise ValueError("the cubic of eqs 41-49 degenerates: the counterweight has no "
                         "acceleration along this trajectory (sum alpha^2 = 0)")
    return (3.0 * float(np.sum(alpha * beta)) / den,
            (float(np.sum(beta * beta)) + 2.0 * float(np.sum(alpha * d))) / den,
            float(np.sum(beta * d)) / den)


def cubic_real_roots(a: float, b: float, c: float) -> list[float]:
    """Real roots of z^3 + a z^2 + b z + c = 0 by Viete / Cardano (eqs 50-59, eq 55 corrected).

    Q = (a^2 - 3b)/9, R = (2a^3 - 9ab + 27c)/54.
    R^2 < Q^3 (three real roots): t = acos(R / sqrt(Q^3)) / 3,
        z = -2 sqrt(Q) cos(t) - a/3, -2 sqrt(Q) cos(t + 2pi/3) - a/3, -2 sqrt(Q) cos(t - 2pi/3) - a/3.
    Otherwise: A = -sign(R) cbrt(|R| + sqrt(R^2 - Q^3)), B = Q/A (0 if A = 0), z1 = A + B - a/3;
        when A = B (confluent case) the double root z2 = -A - a/3 is real as well.
    """
    Q = (a * a - 3.0 * b) / 9.0
    R = (2.0 * a ** 3 - 9.0 * a * b + 27.0 * c) / 54.0
    if R * R < Q ** 3:
        t = math.acos(max(-1.0, min(1.0, R / math.sqrt(Q ** 3)))) / 3.0
        s = -2.0 * math.sqrt(Q)
        return [s * math.cos(t) - a / 3.0, s * math.cos(t + 2.0 * math.pi / 3.0) - a / 3.0,
                s * math.cos(t - 2.0 * math.pi / 3.0) - a / 3.0]
    A = -math.copysign(1.0, R) * (abs(R) + math.sqrt(R * R - Q ** 3)) ** (1.0 / 3.0)
    B = Q / A if A != 0.0 else 0.0
    roots = [A + B - a / 3.0]
    if abs(A - B) <= 1e-12 * max(1.0, abs(A)):
        roots.append(-A - a / 3.0)
    return roots


def squared_sum(alpha, beta, d, r: float) -> float:
    """Delta tau of eq 39: sum_i (alpha_i r^2 + beta_i r + d_i)^2."""
    return float(np.sum((alpha * r * r + beta * r + d) ** 2))


def trajectory_sample(mech, samples, *, q_guess=None):
    """(q, v, a, C): ``samples`` a tuple (q, v, a) of (N, dof) arrays, or (q#, v#, a#) of the
    actuated joints of a closed mechanism, in time order; C the coupling matrices (N, dof, na)
    of a closed mechanism (None otherwise). Raises ValueError where the loops cannot be solved."""
    try:
        q, v, a = (np.atleast_2d(np.asarray(x, float)) for x in samples)
    except (TypeError, ValueError):
        raise ValueError("samples: must be a tuple (q, v, a) of arrays along a trajectory") from None
    width = len(mech.actuated_names) if mech.is_closed else mech.dof
    if not (q.shape == v.shape == a.shape) or q.ndim != 2 or q.shape[1] != width:
        raise ValueError(f"samples: q, v, a must be (N, {width}) arrays (got {q.shape}, {v.shape}, {a.shape})")
    if not mech.is_closed:
        return q, v, a, None
    m = mech.closed_motion(q, v, a, q_guess=q_guess)
    cols = [mech.closed_motion(q, np.eye(width)[i][None, :].repeat(len(q), 0), q_guess=q_guess).v
            for i in range(width)]
    bad = (np.asarray(m.status) & ~np.uint32(int(_core.Status.singular))) != 0
    if np.any(bad):
        raise ValueError(f"samples: the loops cannot be solved at instant {int(np.argmax(bad))} of the trajectory")
    return m.q, m.v, m.a, np.stack(cols, axis=-1)


def _theta(m: float, p: np.ndarray, Ic: np.ndarray):
    """theta (10,), d theta/dm (10,), d theta/dp (10, 3) of a body of mass m at p (link frame)."""
    E = np.eye(3)
    I = Ic + m * (p @ p * E - np.outer(p, p))
    dI_dm = p @ p * E - np.outer(p, p)
    th = np.concatenate([[m], m * p, [I[i, j] for i, j in _IDX]])
    dm = np.concatenate([[1.0], p, [dI_dm[i, j] for i, j in _IDX]])
    dp = np.zeros((10, 3))
    dp[1:4] = m * E
    for c in range(3):
        e = E[c]
        dIc = m * (2 * p[c] * E - np.outer(e, p) - np.outer(p, e))
        dp[4:, c] = [dIc[i, j] for i, j in _IDX]
    return th, dm, dp


class _Variables:
    """The free variables of a group of slots: per slot its mass (unless fixed) and its position
    (a signed distance r along ``direction``, 3 coordinates, or none when it is given), in the
    user frame. A tied slot shares the variables of the slot it is tied to (in the group)."""

    def __init__(self, slots: Sequence[common.Slot]):
        self.slots = list(slots)
        index: list = [None] * len(self.slots)
        #: False for a tied slot whose variables are another's (its bounds are the same)
        self.owner = [False] * len(self.slots)
        n = 0
        first = {}
        # the first slot of each group (its root if present) owns the variables, in slot order
        for k, s in sorted(enumerate(self.slots), key=lambda e: (e[1].tie is not None, e[0])):
            key = s.tie or s.name
            if key in first:
                index[k] = index[first[key]]
                continue
            first[key] = k
            im = None if s.mass_fixed else n
            n += 0 if s.mass_fixed else 1
            width = 0 if s.fixed_position else (1 if s.direction is not None else 3)
            ip = list(range(n, n + width))
            n += len(ip)
            index[k] = (im, ip)
            self.owner[k] = True
        self.index = index
        self.n = n

    def unpack(self, y):
        """[(m, p_user)] per slot."""
        out = []
        for s, (im, ip) in zip(self.slots, self.index):
            m = s.mass_min if im is None else y[im]
            if s.fixed_position:
                p = s.center.copy()
            else:
                p = s.center + s.direction * y[ip[0]] if s.direction is not None else y[ip]
            out.append((m, p))
        return out

    def bounds(self):
        b = [None] * self.n
        for s, (im, ip) in zip(self.slots, self.index):
            if im is not None:
                b[im] = (s.mass_min, s.mass_max if math.isfinite(s.mass_max) else None)
            R = s.max_radius if math.isfinite(s.max_radius) else None
            if not ip:
                continue
            if s.direction is not None:
                b[ip[0]] = (-R if R is not None else None, R)
            else:
                for k, i in enumerate(ip):
                    b[i] = ((s.center[k] - R) if R is not None else None, (s.center[k] + R) if R is not None else None)
        return b

    def start(self, rng, first: bool):
        y = np.zeros(self.n)
        for s, (im, ip) in zip(self.slots, self.index):
            if im is not None:
                hi = s.mass_max if math.isfinite(s.mass_max) else max(2 * s.mass_min, 1.0)
                y[im] = 0.5 * (s.mass_min + hi) if first else rng.uniform(s.mass_min, hi)
            R = s.max_radius if math.isfinite(s.max_radius) else 1.0
            if not ip:
                continue
            if s.direction is not None:
                y[ip[0]] = 0.0 if first else rng.uniform(-R, R)
            else:
                y[ip] = s.center + (0.0 if first else rng.uniform(-R, R, 3) / math.sqrt(3))
        return y

    def active(self, y, tol=1e-7) -> list[str]:
        out = []
        for s, (m, p), (im, ip), own in zip(self.slots, self.unpack(y), self.index, self.owner):
            if not own:
                continue
            if im is not None:
                if m <= s.mass_min + tol * max(1.0, s.mass_min):
                    out.append(f"{s.name}.mass_min")
                if math.isfinite(s.mass_max) and m >= s.mass_max - tol * max(1.0, s.mass_max):
                    out.append(f"{s.name}.mass_max")
            if ip and math.isfinite(s.max_radius) and np.linalg.norm(p - s.center) >= s.max_radius * (1 - tol) - tol:
                out.append(f"{s.name}.max_radius")
        return out


class _TorqueModel:
    """tau(y) = tau_fixed + sum over the group's slots of Y_k theta_k(y), with its Jacobian."""

    def __init__(self, tau_fixed: np.ndarray, Y: Sequence[np.ndarray], var: _Variables):
        self.tau_fixed, self.Y, self.var = tau_fixed, list(Y), var

    def __call__(self, y, grad: bool = True):
        tau = self.tau_fixed.copy()
        J = np.zeros(tau.shape + (self.var.n,)) if grad else None
        for s, Yk, (m, p), (im, ip) in zip(self.var.slots, self.Y, self.var.unpack(y), self.var.index):
            pL = s.link_point(p)
            th, dm, dp = _theta(m, pL, s.link_inertia())
            tau += Yk @ th
            if grad:
                if im is not None:
                    J[..., im] += Yk @ dm
                dpu = dp @ s.T[:3, :3]                       # d theta / d p_user
                if not ip:
                    pass
                elif s.direction is not None:
                    J[..., ip[0]] += Yk @ (dpu @ s.direction)
                else:
                    J[..., ip] += np.einsum("...i,ij->...j", Yk, dpu)
        return tau, J


def _served_joint(mech, link: str) -> int:
    """The coordinate index whose torque a counterweight on ``link`` serves: the link's joint,
    or its nearest ancestor with a coordinate of its own (not fixed, not geared)."""
    joints = {j.name: j for j in mech.model.description.joints}
    names = mech.joint_names
    name = link
    while name in joints:
        j = joints[name]
        if name in names and j.type != _core.JointType.fixed and not j.mimic_joint:
            return names.index(name)
        name = j.parent
    raise ValueError(f"design: link '{link}' has no moving joint to serve (per_joint coupling)")


def _depth(mech, k: int) -> int:
    joints = {j.name: j for j in mech.model.description.joints}
    name, d = mech.joint_names[k], 0
    while name in joints:
        name, d = joints[name].parent, d + 1
    return d


def _minimise(model: _TorqueModel, var: _Variables, columns, w, objective, starts, rng, mass_budget):
    """scipy over the group's variables: L-BFGS-B for RMS with box bounds only, SLSQP otherwise
    (cones of 3-D positions, the mass budget, the peak's epigraph)."""
    from scipy.optimize import minimize

    cols = np.asarray(columns)
    N = model.tau_fixed.shape[0]
    bounds = var.bounds()
    cones = [(s, ip) for s, (im, ip), own in zip(var.slots, var.index, var.owner)
             if own and ip and s.direction is None and math.isfinite(s.max_radius)]
    budget_rows = []
    if mass_budget is not None and math.isfinite(mass_budget):
        row = np.zeros(var.n)
        fixed = 0.0
        for s, (im, ip) in zip(var.slots, var.index):
            if im is None:
                fixed += s.mass_min
            else:
                row[im] += 1.0
        budget_rows.append((row, mass_budget - fixed))

    def rms(y):
        tau, J = model(y)
        t, Jt = tau[:, cols], J[:, cols]
        return float(np.sum(w * np.mean(t ** 2, axis=0))), 2.0 * np.einsum("j,nj,njk->k", w, t, Jt) / N

    cons = []
    for s, ip in cones:  # R^2 - |p - c|^2 >= 0 (box bounds above keep the start sane)
        cons.append({"type": "ineq", "fun": lambda y, s=s, ip=ip: s.max_radius ** 2 - np.sum((y[ip] - s.center) ** 2),
                     "jac": lambda y, s=s, ip=ip: _cone_jac(y, s, ip, var.n)})
    for row, lim in budget_rows:
        cons.append({"type": "ineq", "fun": lambda y, row=row, lim=lim: lim - row @ y,
                     "jac": lambda y, row=row: -row})
    best = None
    for s_i in range(max(1, starts)):
        y0 = var.start(rng, s_i == 0)
        if objective == "rms":
            if cons:
                r = minimize(rms, y0, jac=True, method="SLSQP", bounds=bounds, constraints=cons,
                             options=dict(ftol=1e-15, maxiter=1000))
            else:
                r = minimize(rms, y0, jac=True, method="L-BFGS-B", bounds=bounds,
                             options=dict(ftol=1e-15, gtol=1e-12, maxiter=2000))
            y, f = r.x, rms(r.x)[0]
        else:  # peak: minimise s with s >= +-tau_j(t)/w_j (epigraph), variables (y, s)
            def obj(z):
                g = np.zeros_like(z)
                g[-1] = 1.0
                return z[-1], g

            def ep(z):
                tau, _ = model(z[:-1], grad=False)
                t = tau[:, cols] / w
                return np.concatenate([z[-1] - t.ravel(), z[-1] + t.ravel()])

            def ep_jac(z):
                _, J = model(z[:-1])
                Jt = (J[:, cols] / w[None, :, None]).reshape(-1, var.n)
                one = np.ones((Jt.shape[0], 1))
                return np.vstack([np.hstack([-Jt, one]), np.hstack([Jt, one])])

            lift = lambda c: {**c, "fun": (lambda z, f=c["fun"]: f(z[:-1])),  # noqa: E731
                              "jac": (lambda z, j=c["jac"]: np.append(j(z[:-1]), 0.0))}
            tau0, _ = model(y0, grad=False)
            z0 = np.append(y0, float(np.max(np.abs(tau0[:, cols]) / w)))
            r = minimize(obj, z0, jac=True, method="SLSQP", bounds=bounds + [(0.0, None)],
                         constraints=[{"type": "ineq", "fun": ep, "jac": ep_jac}] + [lift(c) for c in cons],
                         options=dict(ftol=1e-12, maxiter=500))
            y = r.x[:-1]
            tau, _ = model(y, grad=False)
            f = float(np.max(np.abs(tau[:, cols]) / w))
        if best is None or f < best[1]:
            best = (y, f)
    return best[0]


def _cone_jac(y, s, ip, n):
    g = np.zeros(n)
    g[ip] = -2.0 * (y[ip] - s.center)
    return g


def _cardano(model: _TorqueModel, var: _Variables, j: int):
    """The paper's closed form for one slot of fixed mass on a line, RMS of joint j: tau_j is
    alpha r^2 + beta r + d exactly (three evaluations), the stationarity cubic is solved by
    Viete / Cardano and the best real root within the bounds (or a bound) is kept."""
    s = var.slots[0]
    tau_of = lambda r: model(np.array([r]), grad=False)[0][:, j]  # noqa: E731
    alpha, beta, d = quadratic_in_radius(tau_of)
    R = s.max_radius
    candidates = [r for r in ([] if not np.any(alpha) else cubic_real_roots(*stationarity_cubic(alpha, beta, d)))
                  if abs(r) <= R]
    if not np.any(alpha):  # no acceleration of the counterweight: quadratic in r
        bb = float(beta @ beta)
        if bb > 0:
            r = -float(beta @ d) / bb
            candidates += [r] if abs(r) <= R else []
    if math.isfinite(R):
        candidates += [-R, R]
    if not candidates:
        candidates = [0.0]
    values = [squared_sum(alpha, beta, d, r) for r in candidates]
    return np.array([candidates[int(np.argmin(values))]])


def balance(mechanism, design: Sequence[CounterweightSlot], samples, *, objective: str = "rms",
            coupling: str | None = None, weights=None, mass_budget: float | None = None,
            starts: int = 5, seed: int = 0, q_guess=None, fast_path: bool = True) -> BalanceResult:
    """Counterweights minimising the RMS (``objective="rms"``) or peak (``"peak"``) actuator
    torques along a sampled trajectory ``samples = (q, v, a)`` (closed: of the actuated joints).

    ``coupling``: ``"per_joint"`` (default for open mechanisms: the paper's joint-by-joint
    sizing, distal first) or ``"total"`` (default for closed ones: all slots together,
    ``weights`` per actuated joint). ``mass_budget`` bounds the total counterweight mass (total
    coupling, or within each joint's group). ``fast_path``: use the closed form (Cardano) where
    it applies. ``residual``: RMS of all actuator torques after [N m], ``residual_before``
    before; per-joint RMS and peak before/after in ``metrics``."""
    mech = mechanism
    if objective not in ("rms", "peak"):
        raise ValueError(f"objective: must be 'rms' or 'peak' (got {objective!r})")
    coupling = coupling or ("total" if mech.is_closed else "per_joint")
    if coupling not in ("per_joint", "total"):
        raise ValueError(f"coupling: must be 'per_joint' or 'total' (got {coupling!r})")
    if coupling == "per_joint" and mech.is_closed:
        raise ValueError("coupling: 'per_joint' needs an open mechanism (a closed one's actuators share "
                         "every link): use 'total'")
    slots = common.normalise_slots(mech, design, need_radius=False)
    q, v, a, C = trajectory_sample(mech, samples, q_guess=q_guess)
    probe, col = common.probe_mechanism(mech, slots)
    Yfull = probe.torque_regressor(q, v, a)                            # (N, dof, 10 L)
    tau0 = mech.inverse_dynamics(q, v, a)
    if C is not None:
        Yfull = np.einsum("nij,nik->njk", C, Yfull)
        tau0 = np.einsum("nij,ni->nj", C, tau0)
    Y = [Yfull[..., c:c + 10] for c in col]
    n_act = tau0.shape[1]
    w = np.ones(n_act) if weights is None else np.asarray(weights, float)
    if w.shape != (n_act,) or np.any(w < 0) or not np.any(w > 0) or not np.all(np.isfinite(w)):
        raise ValueError(f"weights: must be {n_act} finite values >= 0, not all zero (got {weights})")
    rng = np.random.default_rng(seed)
    values = {}
    methods = {}
    active = []
    if coupling == "total":
        var = _Variables(slots)
        model = _TorqueModel(tau0, Y, var)
        cols = [j for j in range(n_act) if w[j] > 0]
        y = _minimise(model, var, cols, w[cols], objective, starts, rng, mass_budget) if var.n else np.zeros(0)
        values = dict(zip([s.name for s in slots], var.unpack(y)))
        active = var.active(y)
        methods = {s.name: "numerical (scipy, all slots together)" for s in slots}
    else:
        served = [_served_joint(mech, s.link) for s in slots]
        joint_of = dict(zip([s.name for s in slots], served))
        for s in slots:
            if s.tie is not None and joint_of[s.tie] != joint_of[s.name]:
                raise ValueError(f"{s.field}.tie: '{s.name}' serves joint '{mech.joint_names[joint_of[s.name]]}' "
                                 f"and '{s.tie}' joint '{mech.joint_names[joint_of[s.tie]]}': per_joint coupling "
                                 "sizes joints one at a time, so tied slots must serve the same joint (use "
                                 "coupling 'total')")
        tau_fixed = tau0.copy()
        for j in sorted(set(served), key=lambda k: -_depth(mech, k)):
            group = [i for i, sj in enumerate(served) if sj == j]
            gs = [slots[i] for i in group]
            var = _Variables(gs)
            model = _TorqueModel(tau_fixed, [Y[i] for i in group], var)
            closed_form = (fast_path and objective == "rms" and len(gs) == 1 and gs[0].mass_fixed
                           and gs[0].direction is not None)
            if closed_form:
                y = _cardano(model, var, j)
            elif var.n == 0:
                y = np.zeros(0)
            else:
                y = _minimise(model, var, [j], np.ones(1), objective, starts, rng, mass_budget)
            for s, mp in zip(gs, var.unpack(y)):
                values[s.name] = mp
                methods[s.name] = ("closed form (stationarity cubic, Viete/Cardano: Arakelian et al. "
                                   "2011 eqs 41-59)" if closed_form else "numerical (scipy)")
            active += var.active(y)
            tau_fixed = model(y, grad=False)[0]
    placed = [(s, float(values[s.name][0]), np.asarray(values[s.name][1], float)) for s in slots]
    design_out = {}
    for s, m, p in placed:
        design_out[s.name] = common._slot_design(s, m, p, active)
        design_out[s.name]["method"] = methods[s.name]
    balanced = common.balanced_mechanism(mech, placed)
    tau_after = balanced.inverse_dynamics(q, v, a)
    if C is not None:
        tau_after = np.einsum("nij,ni->nj", C, tau_after)
    rms_b, rms_a = np.sqrt(np.mean(tau0 ** 2, axis=0)), np.sqrt(np.mean(tau_after ** 2, axis=0))
    pk_b, pk_a = np.max(np.abs(tau0), axis=0), np.max(np.abs(tau_after), axis=0)
    budget_active = (mass_budget is not None and math.isfinite(mass_budget)
                     and sum(m for _, m, _ in placed) >= mass_budget * (1 - 1e-7))
    if budget_active:
        active.append("mass_budget")
    limited = [f"bound: {b}" for b in active]
    metrics = {
        "objective": objective, "coupling": coupling, "samples": int(len(q)),
        "rms_torque_before": rms_b, "rms_torque_after": rms_a,
        "peak_torque_before": pk_b, "peak_torque_after": pk_a,
        "rms_reduction_pct": common.reduction_pct(rms_b, rms_a),
        "peak_reduction_pct": common.reduction_pct(pk_b, pk_a),
        "added_mass": float(sum(m for _, m, _ in placed)),
    }
    return BalanceResult(method="rms", design=design_out, residual=float(np.sqrt(np.mean(tau_after ** 2))),
                         residual_before=float(np.sqrt(np.mean(tau0 ** 2))),
                         residual_units="N m (RMS of the actuator torques over the trajectory)",
                         rank=None, unknowns=_Variables(slots).n, limited_by=limited,
                         metrics=metrics, balanced=balanced, active_bounds=list(active),
                         tied=common.tied_groups(slots))
