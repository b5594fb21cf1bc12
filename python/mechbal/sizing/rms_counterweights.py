"""RMS-optimal counterweight radii.

Arakelian V., Le Baron J.-P., Mottu P., "Torque minimisation of the 2-DOF serial manipulators
based on minimum energy consideration and optimum mass redistribution", Mechatronics 21 (2011)
310-314, eqs 32-59, and a generalisation to any serial chain.

Why it works for any mechanism: a point mass on a body-fixed line through a joint at signed
distance r has a position linear in r, so its kinetic energy is quadratic in r and its potential
energy linear: along a given motion every joint torque is exactly

    tau_j(t_i) = alpha_ji r^2 + beta_ji r + d_ji            (eqs 32 and 36)

and the squared-torque sum Delta tau_j(r) = sum_i tau_j(t_i)^2 (eq 39) is a quartic in r with
leading coefficient sum alpha^2 > 0 whenever the motion has acceleration. Its stationarity
condition is the cubic (2 S aa) r^3 + (3 S ab) r^2 + (S bb + 2 S ad) r + S bd = 0 (eqs 41-49;
S = sum over samples), solved in closed form by Viete/Cardano (eqs 50-59); every real root is
evaluated and the one with the least Delta tau kept.

Corrections to the printed paper (see also mechbal/arm2dof.hpp):
 - eq 35 (c13): the theta1'' coefficient is l1^2 + r2^2 - 2 l1 r2 cos(theta2) (the factor 2 is
   missing in print);
 - eq 38 (c22): c22 = -m_CW2 [l1 theta1'' cos theta2 + l1 theta1'^2 sin theta2 + g cos(theta1+theta2)]
   (sign missing; with the printed sign the cubic returns r_CW2 = -0.191 m, the mirror image);
 - eq 55: t = (1/3) acos(R / sqrt(Q^3)) (printed acos(R sqrt(Q^3) / 3));
 - eqs 43-45: c13 depends on r_CW2, so joint 2 must be solved first and joint 1 with c13(r_CW2);
 - after eq 59: the confluent case R^2 = Q^3 has one simple and one double real root.
 - eqs 14 and 23 (in the torques themselves): -k32 theta2'^2 sin(theta2).

The paper's optimum r_CW2 = 0.147 m is NOT reproduced: its own (corrected) equations give
0.1913 m, confirmed by a direct numerical minimisation of the full inverse dynamics (see
:func:`rms_optimal_radii_numerical` and ``mechbal run arm2dof``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from mechbal import _core


# ---- dynamics evaluation (C++ core) ------------------------------------------------------------

def arm_torques(arm, counterweights, q, qd, qdd) -> np.ndarray:
    """Joint torques (N, 2) of the 2-DOF arm (closed form, eqs 14-31 corrected) along samples."""
    cw = counterweights if counterweights is not None else _core.Arm2DofCounterweights()
    out = _core.Arm2DofDynamics(arm, cw).inverse_dynamics(q, qd, qdd)
    if out["status"] != _core.Status.ok:
        raise ValueError(f"inverse dynamics failed along the trajectory: {out['status']}")
    return out["tau"]


def static_balancing_radii(arm, m_cw1: float, m_cw2: float) -> tuple[float, float]:
    """Radii that cancel the gravity torques for every pose: m_CW2 r2 = m2 l_S2 and
    m_CW1 r1 = m1 l_S1 + (m2 + m_CW2) l1 (s1 + M2 l1 = 0 and s2 = 0 in eqs 21-22, 30-31)."""
    if m_cw1 <= 0 or m_cw2 <= 0:
        raise ValueError(f"static balancing needs m_cw1, m_cw2 > 0 (got {m_cw1}, {m_cw2})")
    r2 = arm.m2 * arm.l_s2 / m_cw2
    r1 = (arm.m1 * arm.l_s1 + (arm.m2 + m_cw2) * arm.l1) / m_cw1
    return r1, r2


# ---- eqs 33-38 (corrected) ---------------------------------------------------------------------

def cw_coefficients(arm, m_cw1: float, m_cw2: float, r_cw2: float, q, qd, qdd):
    """Per-sample coefficients of tau1_CW = c11 r1^2 + c12 r1 + c13(r2) (eq 32) and
    tau2_CW = c21 r2^2 + c22 r2 (eq 36):

    c11 = m_CW1 q1''                                                          (eq 33)
    c12 = -m_CW1 g cos q1                                                     (eq 34)
    c13 = m_CW2 [(l1^2 + r2^2 - 2 l1 r2 cos q2) q1'' + (r2^2 - l1 r2 cos q2) q2''
                 + l1 r2 sin q2 (2 q1' q2' + q2'^2) + g l1 cos q1 - g r2 cos(q1+q2)]  (eq 35, factor 2)
    c21 = m_CW2 (q1'' + q2'')                                                 (eq 37)
    c22 = -m_CW2 [l1 q1'' cos q2 + l1 q1'^2 sin q2 + g cos(q1+q2)]             (eq 38, sign fixed)
    """
    q, qd, qdd = (np.asarray(x, float) for x in (q, qd, qdd))
    q1, q2, d1, d2, a1, a2 = q[:, 0], q[:, 1], qd[:, 0], qd[:, 1], qdd[:, 0], qdd[:, 1]
    l1, g, r2 = arm.l1, arm.g, r_cw2
    c2, s2, c12 = np.cos(q2), np.sin(q2), np.cos(q1 + q2)
    c11 = m_cw1 * a1
    c12_ = -m_cw1 * g * np.cos(q1)
    c13 = m_cw2 * ((l1 ** 2 + r2 ** 2 - 2 * l1 * r2 * c2) * a1 + (r2 ** 2 - l1 * r2 * c2) * a2
                   + l1 * r2 * s2 * (2 * d1 * d2 + d2 ** 2) + g * l1 * np.cos(q1) - g * r2 * c12)
    c21 = m_cw2 * (a1 + a2)
    c22 = -m_cw2 * (l1 * a1 * c2 + l1 * d1 ** 2 * s2 + g * c12)
    return c11, c12_, c13, c21, c22


def quadratic_in_radius(torque_of_r: Callable[[float], np.ndarray]):
    """(alpha, beta, gamma) with torque(r) = alpha r^2 + beta r + gamma, exactly, from three
    evaluations at r = -1, 0, 1 (valid for any mechanism where a point mass slides on a body-fixed
    line: the torque is quadratic in its position)."""
    tm, t0, tp = torque_of_r(-1.0), torque_of_r(0.0), torque_of_r(1.0)
    return 0.5 * (tp + tm) - t0, 0.5 * (tp - tm), t0


# ---- eqs 39-59 ---------------------------------------------------------------------------------

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


@dataclass
class RadiiResult:
    """RMS-optimal radii and how they were chosen (per joint: the monic cubic, its real roots and
    the Delta tau of eq 39 at each root)."""

    r_cw1: float
    r_cw2: float
    cubic1: tuple[float, float, float]
    cubic2: tuple[float, float, float]
    roots1: list[float]
    roots2: list[float]
    delta_tau1: list[float] = field(default_factory=list)
    delta_tau2: list[float] = field(default_factory=list)


def rms_optimal_radii(arm, m_cw1: float, m_cw2: float, q, qd, qdd) -> RadiiResult:
    """Counterweight radii that minimise the RMS torque of each joint along the sampled motion
    (q, qd, qdd each (N, 2)), for any 2R arm, trajectory and counterweight masses (eqs 39-59).

    tau2 depends on r2 only (CW1 rides on link 1), tau1 on r1 and r2: r2 is found first from the
    joint-2 cubic, then r1 from the joint-1 cubic with c13(r2) (corrected ordering of eqs 43-45).
    Every real root of each cubic is tried and the one with the least Delta tau kept.
    """
    q, qd, qdd = (np.asarray(x, float) for x in (q, qd, qdd))
    tau0 = arm_torques(arm, None, q, qd, qdd)
    _, _, _, c21, c22 = cw_coefficients(arm, m_cw1, m_cw2, 0.0, q, qd, qdd)
    cubic2 = stationarity_cubic(c21, c22, tau0[:, 1])
    roots2 = cubic_real_roots(*cubic2)
    dt2 = [squared_sum(c21, c22, tau0[:, 1], r) for r in roots2]
    r2 = roots2[int(np.argmin(dt2))]
    c11, c12, c13, _, _ = cw_coefficients(arm, m_cw1, m_cw2, r2, q, qd, qdd)
    d1 = tau0[:, 0] + c13
    cubic1 = stationarity_cubic(c11, c12, d1)
    roots1 = cubic_real_roots(*cubic1)
    dt1 = [squared_sum(c11, c12, d1, r) for r in roots1]
    r1 = roots1[int(np.argmin(dt1))]
    return RadiiResult(r1, r2, cubic1, cubic2, roots1, roots2, dt1, dt2)


def rms_optimal_radii_numerical(arm, m_cw1: float, m_cw2: float, q, qd, qdd,
                                bracket: tuple[float, float] = (-2.0, 2.0)) -> tuple[float, float]:
    """Independent check of :func:`rms_optimal_radii`: scipy minimises the mean squared torque of
    the full closed-form inverse dynamics (no coefficient formulas), joint 2 over r2 first, then
    joint 1 over r1 at that r2. Global over ``bracket``: a dense grid, then bounded Brent."""
    from scipy.optimize import minimize_scalar

    def ms(joint, r1, r2):
        cw = _core.Arm2DofCounterweights(m_cw1, m_cw2, r1, r2)
        return float(np.mean(arm_torques(arm, cw, q, qd, qdd)[:, joint] ** 2))

    def argmin(f):
        grid = np.linspace(bracket[0], bracket[1], 201)
        k = int(np.argmin([f(x) for x in grid]))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
        return float(minimize_scalar(f, bounds=(lo, hi), method="bounded",
                                     options=dict(xatol=1e-12, maxiter=500)).x)

    r2 = argmin(lambda r: ms(1, 0.0, r))
    r1 = argmin(lambda r: ms(0, r, r2))
    return r1, r2


# ---- generalisation: any serial chain (kept for its callers; mechbal.balance.rms is the general
# ---- method on any mechanism, of which the functions above are the 2-DOF fast path) ------------

@dataclass(frozen=True)
class CounterweightMount:
    """A point-mass counterweight on link ``link`` (0-based) at anchor + r * direction, both in
    the link frame; mass in kg (fixed, or the start value when masses are optimised)."""

    link: int
    anchor: Sequence[float]
    direction: Sequence[float]
    mass: float
    r_bounds: tuple[float, float] = (-1.0, 1.0)


def _merge_point_mass(joint, m_p: float, p: np.ndarray):
    """JointSpec with a point mass m_p at p (link frame) merged into the link body."""
    m, c, I = joint.mass, np.asarray(joint.com), np.asarray(joint.inertia)
    M = m + m_p
    if M <= 0.0:
        return joint
    x = (m * c + m_p * p) / M

    def shift(mass, d):
        return mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))

    I_new = I + shift(m, c - x) + shift(m_p, p - x)
    return _core.JointSpec(joint.name, joint.type, joint.origin, joint.axis, M, x,
                           0.5 * (I_new + I_new.T))


def chain_with_point_masses(model, masses: dict[int, list[tuple[float, np.ndarray]]]):
    """A copy of ``model`` (base at the identity) with point masses merged into its links."""
    joints = list(model.joints)
    for link, items in masses.items():
        for m_p, p in items:
            joints[link] = _merge_point_mass(joints[link], m_p, np.asarray(p, float))
    return _core.ChainModel(joints, np.asarray(model.gravity))


@dataclass
class ChainTorqueModel:
    """tau(r, m) = tau0 + sum_k m_k (a_k r_k^2 + b_k r_k + c_k), exact, (N, dof) arrays per mount.

    Built from 3K + 1 KDL inverse-dynamics sweeps: the dynamics are linear in each link's inertial
    parameters and a point mass adds (m, m p, m p p^T) to them, with p linear in r."""

    tau0: np.ndarray
    a: np.ndarray  # (K, N, dof), per unit mass
    b: np.ndarray
    c: np.ndarray

    def torque(self, r, m) -> np.ndarray:
        r, m = np.asarray(r, float), np.asarray(m, float)
        return self.tau0 + np.einsum("k,knj->nj", m, self.a * r[:, None, None] ** 2
                                     + self.b * r[:, None, None] + self.c)


def chain_torque_model(model, mounts: Sequence[CounterweightMount], q, qd, qdd) -> ChainTorqueModel:
    """The exact torque model of :class:`ChainTorqueModel`, evaluated on the general model of the
    chain (``chain_description``: its base placement included) with the mounts' point masses as
    extra bodies. For new code, :mod:`mechbal.balance.rms` does this for any mechanism on the
    torque regressor (one sweep instead of 3K + 1)."""
    from mechbal.mechanism import Mechanism

    for i, mt in enumerate(mounts):
        if not 0 <= mt.link < model.dof:
            raise ValueError(f"mounts[{i}].link must be in [0, {model.dof - 1}] (got {mt.link})")
        if np.linalg.norm(mt.direction) == 0.0:
            raise ValueError(f"mounts[{i}].direction must be non-zero (got {list(mt.direction)})")
    mech = Mechanism(_core.MechanismModel(_core.chain_description(model)), name="chain")
    links = [j.name for j in mech.model.description.joints]

    def tau(masses):
        bodies = [_core.Body(f"mount{link}_{k}", links[link], float(m_p), np.asarray(p, float),
                             np.zeros((3, 3)), "counterweight")
                  for link, items in masses.items() for k, (m_p, p) in enumerate(items)]
        return (mech.with_bodies(bodies) if bodies else mech).inverse_dynamics(q, qd, qdd)

    q, qd, qdd = (np.ascontiguousarray(x, dtype=float) for x in (q, qd, qdd))
    tau0 = tau({})
    a, b, c = [], [], []
    for mt in mounts:
        u = np.asarray(mt.direction, float) / np.linalg.norm(mt.direction)
        anchor = np.asarray(mt.anchor, float)
        al, be, ga = quadratic_in_radius(lambda r: tau({mt.link: [(1.0, anchor + r * u)]}) - tau0)
        a.append(al), b.append(be), c.append(ga)
    return ChainTorqueModel(tau0, np.array(a), np.array(b), np.array(c))


@dataclass
class ChainSizingResult:
    radii: np.ndarray
    masses: np.ndarray
    rms_torque: np.ndarray
    rms_torque_bare: np.ndarray
    objective: float
    success: bool
    message: str


def size_chain_counterweights(model, mounts: Sequence[CounterweightMount], q, qd, qdd, *,
                              weights: Sequence[float] | None = None, optimise_masses: bool = False,
                              mass_budget: float | None = None, starts: int = 5,
                              seed: int = 0) -> ChainSizingResult:
    """Counterweight radii (and optionally masses, with sum m <= mass_budget) that minimise
    J = sum_j w_j mean_i tau_j(t_i)^2 (weighted sum of squared RMS joint torques) for an n-joint
    serial chain (KDL), numerically. The exact quadratic-in-radius torque model makes J a
    polynomial (quartic in each radius), evaluated with its analytic gradient; several starts
    guard against the local minima a quartic can have."""
    from scipy.optimize import minimize

    q, qd, qdd = (np.asarray(x, float) for x in (q, qd, qdd))
    tm = chain_torque_model(model, mounts, q, qd, qdd)
    K, (N, n) = len(mounts), tm.tau0.shape
    w = np.ones(n) if weights is None else np.asarray(weights, float)
    if w.shape != (n,) or np.any(w < 0) or not np.any(w > 0):
        raise ValueError(f"weights must be {n} values >= 0, not all zero (got {weights})")
    m0 = np.array([mt.mass for mt in mounts], float)
    if np.any(m0 < 0):
        raise ValueError(f"mounts[*].mass must be >= 0 (got {m0.tolist()})")
    if optimise_masses and (mass_budget is None or mass_budget <= 0):
        raise ValueError(f"optimise_masses needs mass_budget > 0 (got {mass_budget})")
    rb = [mt.r_bounds for mt in mounts]

    def unpack(x):
        return (x[:K], x[K:]) if optimise_masses else (x, m0)

    def J(x):
        r, m = unpack(x)
        P = tm.a * r[:, None, None] ** 2 + tm.b * r[:, None, None] + tm.c  # (K, N, n)
        dP = 2.0 * tm.a * r[:, None, None] + tm.b
        tau = tm.tau0 + np.einsum("k,knj->nj", m, P)
        f = float(np.sum(w * np.mean(tau ** 2, axis=0)))
        g_r = 2.0 * np.einsum("j,nj,knj->k", w, tau, m[:, None, None] * dP) / N
        if not optimise_masses:
            return f, g_r
        g_m = 2.0 * np.einsum("j,nj,knj->k", w, tau, P) / N
        return f, np.concatenate([g_r, g_m])

    rng = np.random.default_rng(seed)
    bounds = rb + ([(0.0, mass_budget)] * K if optimise_masses else [])
    cons = ([{"type": "ineq", "fun": lambda x: mass_budget - np.sum(x[K:]),
              "jac": lambda x: np.concatenate([np.zeros(K), -np.ones(K)])}]
            if optimise_masses else [])
    best = None
    for s in range(max(1, starts)):
        r_start = np.array([0.5 * (lo + hi) if s == 0 else rng.uniform(lo, hi) for lo, hi in rb])
        m_start = np.minimum(m0, mass_budget / max(K, 1)) if optimise_masses else m0
        x0 = np.concatenate([r_start, m_start]) if optimise_masses else r_start
        res = (minimize(J, x0, jac=True, method="SLSQP", bounds=bounds, constraints=cons,
                        options=dict(ftol=1e-15, maxiter=500)) if optimise_masses else
               minimize(J, x0, jac=True, method="L-BFGS-B", bounds=bounds,
                        options=dict(ftol=1e-15, gtol=1e-12, maxiter=1000)))
        if best is None or res.fun < best.fun:
            best = res
    r, m = unpack(best.x)
    tau = tm.torque(r, m)
    return ChainSizingResult(np.array(r), np.array(m), np.sqrt(np.mean(tau ** 2, axis=0)),
                             np.sqrt(np.mean(tm.tau0 ** 2, axis=0)), float(best.fun),
                             bool(best.success), str(best.message))
