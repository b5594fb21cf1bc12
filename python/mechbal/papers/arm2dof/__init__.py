"""The 2-DOF arm of Arakelian, Le Baron & Mottu 2011 ("Torque minimisation of the 2-DOF serial
manipulators based on minimum energy consideration and optimum mass redistribution",
Mechatronics 21:310-314, Fig. 1) on the general mechanism model.

Geometry (as ``mechbal/arm2dof.hpp``): the arm moves in the vertical x-z plane of the base frame
(z up, gravity (0, 0, -g)). Joint ``shoulder`` at A (the origin), joint ``elbow`` at B = (l1, 0, 0)
of the shoulder link's frame; both axes along -y, so that a positive angle lifts +x towards +z:
theta1 is link 1's angle from +x, theta2 link 2's angle relative to link 1 (the paper's
convention). Each link's frame has x along the link (A -> B for link 1).

Bodies (one per physical part, not lumped):

* ``link1`` on ``shoulder``: mass m1, centre of mass S1 at (l_S1, 0, 0), inertia I_S1 about S1
  (eq 16: I_A = I_S1 + m1 l_S1^2 about A);
* ``link2`` on ``elbow``: mass m2, S2 at (l_S2, 0, 0), inertia I_S2 about S2 (eqs 18-19);
* ``counterweight1`` on ``shoulder``: point mass m_CW1 on the extension of link 1 beyond A, at
  (-r_CW1, 0, 0) (eqs 23-31);
* ``counterweight2`` on ``elbow``: point mass m_CW2 beyond B, at (-r_CW2, 0, 0).

Link inertias are slender-rod tensors diag(0, I, I) about the centre of mass (link frame); the
planar motion about y only sees I. Frames: ``B`` (the elbow axis point on link 1).

The general model's inverse dynamics, mass matrix and gravity torque equal the corrected closed
form of eqs 14-31 (``mechbal.Arm2DofDynamics``, the fast path) to 1e-12 relative along the
paper's trajectories (tests/python/test_papers.py).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
import numpy.typing as npt

from mechbal.balance.rms import cubic_real_roots, squared_sum, stationarity_cubic

from mechbal import _core
from mechbal._deprecation import renamed_kwargs
from mechbal.mechanism import Mechanism
from mechbal.papers._closed_form import AccelerationBatch, TorqueBatch, closed_form_batch

# the closed forms of the C++ core (cpp/src/papers/arm2dof/): fast paths of the general model
Arm2DofParameters = _core.Arm2DofParameters
Arm2DofCounterweights = _core.Arm2DofCounterweights
pd_error_analytic = _core.pd_error_analytic


class Arm2DofDynamics(_core.Arm2DofDynamics):
    """Closed-form dynamics of the 2-DOF arm (Arakelian, Le Baron & Mottu 2011, eqs 14-31,
    corrected): the fast path of the general model, a dynamics back end of
    `mechbal.control.ComputedTorque` and a plant of `mechbal.simulate.closed_loop`.

    Args:
        arm: ``Arm2DofParameters``.
        counterweights: ``Arm2DofCounterweights`` (default: none).

    ``inverse_dynamics(q, v, a)`` and ``forward_dynamics(q, v, tau)`` take one sample ((2,) each:
    a (2,) result, ValueError on rejected input) or N samples ((N, 2) each: an (N, 2) array whose
    ``status`` (N,) flags the rejected instants), as `mechbal.Mechanism` does.
    """

    @renamed_kwargs(qd="v", qdd="a")
    def inverse_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
                         a: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Joint torques tau [N m], (2,) or (N, 2)."""
        return closed_form_batch("Arm2DofDynamics.inverse_dynamics", super().inverse_dynamics,
                                 TorqueBatch, "tau", q=q, v=v, a=a)

    @renamed_kwargs(qd="v")
    def forward_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
                         tau: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Joint accelerations a [rad/s^2], (2,) or (N, 2)."""
        return closed_form_batch("Arm2DofDynamics.forward_dynamics", super().forward_dynamics,
                                 AccelerationBatch, "a", q=q, v=v, tau=tau)

__all__ = ["Arm2DofParameters", "Arm2DofCounterweights", "Arm2DofDynamics", "pd_error_analytic",
           "arm2dof_mechanism", "arm_torques", "static_balancing_radii", "cw_coefficients",
           "RadiiResult", "rms_optimal_radii", "rms_optimal_radii_numerical"]

_ARM_KEYS = ("m1", "m2", "l1", "l_s1", "l_s2", "i_s1", "i_s2", "g")
_CW_KEYS = ("m_cw1", "m_cw2", "r_cw1", "r_cw2")


def _values(source: Any, keys: tuple[str, ...], what: str, defaults: Mapping[str, float] = {}) -> dict:
    out = {}
    for k in keys:
        if isinstance(source, Mapping):
            value = source.get(k, defaults.get(k))
        else:
            value = getattr(source, k, defaults.get(k))
        if value is None:
            raise ValueError(f"{what}.{k}: is required")
        value = float(value)
        if not np.isfinite(value):
            raise ValueError(f"{what}.{k}: must be finite (got {value})")
        out[k] = value
    return out


def _point(x: float) -> np.ndarray:
    return np.array([x, 0.0, 0.0])


def arm2dof_mechanism(arm, counterweights=None, *, name: str = "arm2dof") -> Mechanism:
    """The arm of Fig. 1 as a `mechbal.Mechanism` (module docstring for the frames).

    ``arm``: a ``mechbal.Arm2DofParameters`` or a mapping with its fields (the case file's
    ``[arm]`` table: m1, m2, l1, l_s1, l_s2, i_s1, i_s2, g; g defaults to 9.81).
    ``counterweights``: ``None`` for the bare arm (eqs 14-22), or a
    ``mechbal._core.Arm2DofCounterweights`` or a mapping with m_cw1, m_cw2, r_cw1, r_cw2 (eqs
    23-31; a radius is the signed distance beyond the joint, negative puts the mass on the link
    side). Counterweights are separate point-mass bodies of kind ``"counterweight"`` on their links.

    Raises ValueError naming the field on a missing or non-finite value; the model itself refuses
    negative masses or inertias.
    """
    a = _values(arm, _ARM_KEYS, "arm", {"g": 9.81})
    if a["l1"] <= 0.0:
        raise ValueError(f"arm.l1: must be > 0 (got {a['l1']})")
    elbow = np.eye(4)
    elbow[:3, 3] = _point(a["l1"])
    axis = np.array([0.0, -1.0, 0.0])  # a positive angle lifts +x towards +z
    joints = [_core.Joint("shoulder", _core.JointType.revolute, "base", np.eye(4), axis),
              _core.Joint("elbow", _core.JointType.revolute, "shoulder", elbow, axis)]
    rod = lambda inertia: np.diag([0.0, inertia, inertia])  # noqa: E731
    bodies = [_core.Body("link1", "shoulder", a["m1"], _point(a["l_s1"]), rod(a["i_s1"]), "link"),
              _core.Body("link2", "elbow", a["m2"], _point(a["l_s2"]), rod(a["i_s2"]), "link")]
    if counterweights is not None:
        c = _values(counterweights, _CW_KEYS, "counterweights")
        bodies += [_core.Body("counterweight1", "shoulder", c["m_cw1"], _point(-c["r_cw1"]),
                              np.zeros((3, 3)), "counterweight"),
                   _core.Body("counterweight2", "elbow", c["m_cw2"], _point(-c["r_cw2"]),
                              np.zeros((3, 3)), "counterweight")]
    frames = [_core.Frame("B", "shoulder", elbow)]
    return Mechanism.from_description(joints, bodies, frames, gravity=(0.0, 0.0, -a["g"]), name=name)


# ---- RMS-optimal counterweights ------------------------------------------------------------------
# RMS-optimal counterweight radii (eqs 32-59): the paper's fast path, and the regression test of
# the general method `mechbal.balance.rms`, which the ``arm2dof`` runner sizes with.
#
# Why it works for any mechanism: a point mass on a body-fixed line through a joint at signed
# distance r has a position linear in r, so its kinetic energy is quadratic in r and its potential
# energy linear: along a given motion every joint torque is exactly
#
#     tau_j(t_i) = alpha_ji r^2 + beta_ji r + d_ji            (eqs 32 and 36)
#
# and the squared-torque sum Delta tau_j(r) = sum_i tau_j(t_i)^2 (eq 39) is a quartic in r with
# leading coefficient sum alpha^2 > 0 whenever the motion has acceleration. Its stationarity
# condition is the cubic (2 S aa) r^3 + (3 S ab) r^2 + (S bb + 2 S ad) r + S bd = 0 (eqs 41-49;
# S = sum over samples), solved in closed form by Viete/Cardano (eqs 50-59); every real root is
# evaluated and the one with the least Delta tau kept.
#
# Corrections to the printed paper (see also mechbal/arm2dof.hpp):
#  - eq 35 (c13): the theta1'' coefficient is l1^2 + r2^2 - 2 l1 r2 cos(theta2) (the factor 2 is
#    missing in print);
#  - eq 38 (c22): c22 = -m_CW2 [l1 theta1'' cos theta2 + l1 theta1'^2 sin theta2 + g cos(theta1+theta2)]
#    (sign missing; with the printed sign the cubic returns r_CW2 = -0.191 m, the mirror image);
#  - eq 55: t = (1/3) acos(R / sqrt(Q^3)) (printed acos(R sqrt(Q^3) / 3));
#  - eqs 43-45: c13 depends on r_CW2, so joint 2 must be solved first and joint 1 with c13(r_CW2);
#  - after eq 59: the confluent case R^2 = Q^3 has one simple and one double real root.
#  - eqs 14 and 23 (in the torques themselves): -k32 theta2'^2 sin(theta2).
#
# The paper's optimum r_CW2 = 0.147 m is NOT reproduced: its own (corrected) equations give
# 0.1913 m, confirmed by a direct numerical minimisation of the full inverse dynamics (see
# `rms_optimal_radii_numerical`, `mechbal.balance.rms` and ``mechbal run arm2dof``).

@renamed_kwargs(qd="v", qdd="a")
def arm_torques(arm, counterweights, q, v, a) -> np.ndarray:
    """Joint torques (N, 2) of the 2-DOF arm (closed form, eqs 14-31 corrected) along samples."""
    cw = counterweights if counterweights is not None else _core.Arm2DofCounterweights()
    out = _core.Arm2DofDynamics(arm, cw).inverse_dynamics(q, v, a)
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


@renamed_kwargs(qd="v", qdd="a")
def cw_coefficients(arm, m_cw1: float, m_cw2: float, r_cw2: float, q, v, a):
    """Per-sample coefficients of tau1_CW = c11 r1^2 + c12 r1 + c13(r2) (eq 32) and
    tau2_CW = c21 r2^2 + c22 r2 (eq 36):

    c11 = m_CW1 q1''                                                          (eq 33)
    c12 = -m_CW1 g cos q1                                                     (eq 34)
    c13 = m_CW2 [(l1^2 + r2^2 - 2 l1 r2 cos q2) q1'' + (r2^2 - l1 r2 cos q2) q2''
                 + l1 r2 sin q2 (2 q1' q2' + q2'^2) + g l1 cos q1 - g r2 cos(q1+q2)]  (eq 35, factor 2)
    c21 = m_CW2 (q1'' + q2'')                                                 (eq 37)
    c22 = -m_CW2 [l1 q1'' cos q2 + l1 q1'^2 sin q2 + g cos(q1+q2)]             (eq 38, sign fixed)
    """
    q, v, a = (np.asarray(x, float) for x in (q, v, a))
    q1, q2, d1, d2, a1, a2 = q[:, 0], q[:, 1], v[:, 0], v[:, 1], a[:, 0], a[:, 1]
    l1, g, r2 = arm.l1, arm.g, r_cw2
    c2, s2, c12 = np.cos(q2), np.sin(q2), np.cos(q1 + q2)
    c11 = m_cw1 * a1
    c12_ = -m_cw1 * g * np.cos(q1)
    c13 = m_cw2 * ((l1 ** 2 + r2 ** 2 - 2 * l1 * r2 * c2) * a1 + (r2 ** 2 - l1 * r2 * c2) * a2
                   + l1 * r2 * s2 * (2 * d1 * d2 + d2 ** 2) + g * l1 * np.cos(q1) - g * r2 * c12)
    c21 = m_cw2 * (a1 + a2)
    c22 = -m_cw2 * (l1 * a1 * c2 + l1 * d1 ** 2 * s2 + g * c12)
    return c11, c12_, c13, c21, c22


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


@renamed_kwargs(qd="v", qdd="a")
def rms_optimal_radii(arm, m_cw1: float, m_cw2: float, q, v, a) -> RadiiResult:
    """Counterweight radii that minimise the RMS torque of each joint along the sampled motion
    (q, v, a each (N, 2)), for any 2R arm, trajectory and counterweight masses (eqs 39-59).

    tau2 depends on r2 only (CW1 rides on link 1), tau1 on r1 and r2: r2 is found first from the
    joint-2 cubic, then r1 from the joint-1 cubic with c13(r2) (corrected ordering of eqs 43-45).
    Every real root of each cubic is tried and the one with the least Delta tau kept.
    """
    q, v, a = (np.asarray(x, float) for x in (q, v, a))
    tau0 = arm_torques(arm, None, q, v, a)
    _, _, _, c21, c22 = cw_coefficients(arm, m_cw1, m_cw2, 0.0, q, v, a)
    cubic2 = stationarity_cubic(c21, c22, tau0[:, 1])
    roots2 = cubic_real_roots(*cubic2)
    dt2 = [squared_sum(c21, c22, tau0[:, 1], r) for r in roots2]
    r2 = roots2[int(np.argmin(dt2))]
    c11, c12, c13, _, _ = cw_coefficients(arm, m_cw1, m_cw2, r2, q, v, a)
    d1 = tau0[:, 0] + c13
    cubic1 = stationarity_cubic(c11, c12, d1)
    roots1 = cubic_real_roots(*cubic1)
    dt1 = [squared_sum(c11, c12, d1, r) for r in roots1]
    r1 = roots1[int(np.argmin(dt1))]
    return RadiiResult(r1, r2, cubic1, cubic2, roots1, roots2, dt1, dt2)


@renamed_kwargs(qd="v", qdd="a")
def rms_optimal_radii_numerical(arm, m_cw1: float, m_cw2: float, q, v, a,
                                bracket: tuple[float, float] = (-2.0, 2.0)) -> tuple[float, float]:
    """Independent check of `rms_optimal_radii`: scipy minimises the mean squared torque of
    the full closed-form inverse dynamics (no coefficient formulas), joint 2 over r2 first, then
    joint 1 over r1 at that r2. Global over ``bracket``: a dense grid, then bounded Brent."""
    from scipy.optimize import minimize_scalar

    def ms(joint, r1, r2):
        cw = _core.Arm2DofCounterweights(m_cw1, m_cw2, r1, r2)
        return float(np.mean(arm_torques(arm, cw, q, v, a)[:, joint] ** 2))

    def argmin(f):
        grid = np.linspace(bracket[0], bracket[1], 201)
        k = int(np.argmin([f(x) for x in grid]))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
        return float(minimize_scalar(f, bounds=(lo, hi), method="bounded",
                                     options=dict(xatol=1e-12, maxiter=500)).x)

    r2 = argmin(lambda r: ms(1, 0.0, r))
    r1 = argmin(lambda r: ms(0, r, r2))
    return r1, r2

# importing the schema registers this paper's case kind (mechbal.registry imports this package)
from mechbal.papers.arm2dof import schema as _schema  # noqa: E402,F401
