"""Modular dynamic modelling with redundant coordinates: the coupling-matrix method of Coutinho &
Hess Coelho, "A new approach for designing dynamic balanced serial mechanisms" (eqs 1-3, 11-12,
22-23, 32-33), for any number of subsystems, numerically (numpy) and symbolically (sympy).

Each subsystem k has its own model ``M_k p_k' + v_k + g_k = u_k`` in its own quasi-velocities
``p_k``. Stacked: ``p = (p#, p°)``, ``M# = blockdiag(M_k)``, ``v#``, ``g#``. Linear quasi-velocity
constraints ``A p = A# p# + A° p° = 0`` give ``p = C p#`` with the coupling matrix

    C = [1; -(A°)^-1 A#]                                     (eqs 12, 23, 33)

and, differentiating, ``p' = C p#' + cbar`` with ``cbar = [0; -(A°)^-1 (A' p)]``. Projecting with
C^T (the constraint forces do no work on admissible motions):

    M' = C^T M# C,   v' = C^T (M# cbar + v#),   g' = C^T g#.

The ``M# cbar`` term vanishes only when C is constant (planar discs); it is essential for the
spatial arm and the 5R. Disc subsystems carry the Euler term ``v_d = omega x J omega``; the
paper's eq 20 writes ``v = 0`` (correction C5 in docs/discs_derivation.md), which is harmless for
planar discs and after balancing but gives wrong Coriolis terms otherwise (eq 24's printed 1/4).

The serial arms with discs are data on the general model (``mechbal.papers.discs``: each disc a
gear-coupled joint, evaluated by MechanismDynamics, whose projection tau = G^T tau_joint is this
one with A° = 1). The per-tick C++ evaluator of the paper's form is
``mechbal._core.FiveBarDynamics`` (the 5R five-bar, A° a 4x4 matrix, over the paper's fixed-size
``mechbal::CoupledProjection``, papers/five_bar/coupled_projection.hpp); this module is its independent Python reference
(mechbal.papers.discs.fivebar_model) and builds the two-stage model of the paper (arm model
first, then discs coupled to it) that cross-checks the general model's single-stage form.

Layer: papers (the discs paper's own method; docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, ClassVar, Sequence

import numpy as np

from mechbal._deprecation import DeprecatedAttributes

GRAVITY = np.array([0.0, 0.0, -9.81])


@dataclass
class Subsystem:
    """One subsystem's own model in its quasi-velocities: ``M p' + v + g = u``."""
    mass: np.ndarray
    velocity: np.ndarray
    gravity: np.ndarray


@dataclass
class CoupledModel:
    mass: np.ndarray       # M'
    velocity: np.ndarray   # v'
    gravity: np.ndarray    # g'
    coupling: np.ndarray   # C
    p: np.ndarray          # full redundant quasi-velocities C p#


def block_diag(mats: Sequence[np.ndarray]) -> np.ndarray:
    n = sum(m.shape[0] for m in mats)
    out = np.zeros((n, n))
    k = 0
    for m in mats:
        s = m.shape[0]
        out[k:k + s, k:k + s] = m
        k += s
    return out


def coupling_matrix(A: np.ndarray, independent: Sequence[int]) -> np.ndarray:
    """C = [1; -(A°)^-1 A#] with rows in the order of p (eqs 12, 23, 33)."""
    n = A.shape[1]
    ind = np.asarray(independent, int)
    dep = np.setdiff1d(np.arange(n), ind)
    if A.shape[0] != len(dep):
        raise ValueError(f"A has {A.shape[0]} constraint rows but {len(dep)} dependent "
                         f"quasi-velocities")
    C = np.zeros((n, len(ind)))
    C[ind, np.arange(len(ind))] = 1.0
    C[dep, :] = -np.linalg.solve(A[:, dep], A[:, ind])
    return C


def couple(subsystems: Sequence[Subsystem], A: np.ndarray, independent: Sequence[int],
           pdot_bias: np.ndarray | Callable[[np.ndarray], np.ndarray],
           p_independent: np.ndarray) -> CoupledModel:
    """Couple any number of subsystems through ``A p = 0`` at one state.

    pdot_bias: ``A' p`` as a vector, or a callable receiving the full consistent ``p = C p#``
    (needed when dependent rates enter the bias, e.g. the 5R's passive joints).
    """
    M = block_diag([np.atleast_2d(s.mass) for s in subsystems])
    v = np.concatenate([np.atleast_1d(s.velocity) for s in subsystems])
    g = np.concatenate([np.atleast_1d(s.gravity) for s in subsystems])
    C = coupling_matrix(A, independent)
    p = C @ np.asarray(p_independent, float)
    adp = pdot_bias(p) if callable(pdot_bias) else np.asarray(pdot_bias, float)
    dep = np.setdiff1d(np.arange(M.shape[0]), np.asarray(independent, int))
    cbar = np.zeros(M.shape[0])
    cbar[dep] = -np.linalg.solve(A[:, dep], adp)
    return CoupledModel(C.T @ M @ C, C.T @ (M @ cbar + v), C.T @ g, C, p)


def couple_symbolic(masses, velocities, gravities, A, independent, pdot_bias=None):
    """The same projection in sympy (offline derivations): returns (M', v', g', C).
    ``pdot_bias`` may be None when C is constant (then cbar = 0)."""
    import sympy as sp

    M = sp.diag(*[sp.Matrix(m) for m in masses])
    v = sp.Matrix.vstack(*[sp.Matrix(x) for x in velocities])
    g = sp.Matrix.vstack(*[sp.Matrix(x) for x in gravities])
    A = sp.Matrix(A)
    n = A.shape[1]
    ind = list(independent)
    dep = [i for i in range(n) if i not in ind]
    Ao, As = A.extract(list(range(A.shape[0])), dep), A.extract(list(range(A.shape[0])), ind)
    C = sp.zeros(n, len(ind))
    for c, i in enumerate(ind):
        C[i, c] = 1
    lower = -Ao.LUsolve(As)
    for r, i in enumerate(dep):
        C[i, :] = lower[r, :]
    cbar = sp.zeros(n, 1)
    if pdot_bias is not None:
        low = -Ao.LUsolve(sp.Matrix(pdot_bias))
        for r, i in enumerate(dep):
            cbar[i] = low[r]
    return C.T * M * C, C.T * (M * cbar + v), C.T * g, C


# ---------------------------------------------------------------------------------------------
# Serial-chain building blocks (numpy): joints, links as Newton-Euler subsystems, discs
# ---------------------------------------------------------------------------------------------
def _cross(a, b):
    """3-vector cross product (np.cross is slow on single vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = skew(a)
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


@dataclass
class Joint:
    """'R' or 'P'; axis and offset (joint position at q = 0) in the previous link frame."""
    type: str
    axis: np.ndarray
    offset: np.ndarray


@dataclass
class Link:
    """Mass, centre of mass and central inertia tensor in the link frame."""
    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclass
class Disc:
    """Disc carried by link ``carrier``, spinning about ``axis`` (carrier frame) at
    ratio * qd[joint] relative to it; ``inertia`` principal central moments, disc frame."""
    carrier: int
    joint: int
    axis: np.ndarray
    ratio: float
    inertia: np.ndarray


@dataclass(frozen=True)
class LinkKinematics(DeprecatedAttributes):
    """One link frame of `chain_kinematics` (O axes): rotation ``R`` (3, 3) link to O, origin
    ``p`` [m] (on its joint), joint axis ``z`` and joint origin ``o`` [m], angular velocity ``w``
    [rad/s] and bias angular acceleration ``al`` [rad/s^2], origin velocity ``v`` [m/s] and bias
    acceleration ``a`` [m/s^2], joint ``type`` ("R" or "P"). ``kin["R"]``, the dict of earlier
    releases, works for one release with a DeprecationWarning."""

    R: np.ndarray
    p: np.ndarray
    z: np.ndarray
    o: np.ndarray
    w: np.ndarray
    al: np.ndarray
    v: np.ndarray
    a: np.ndarray
    type: str

    _dict_keys: ClassVar[dict[str, str]] = {k: k for k in ("R", "p", "z", "o", "w", "al", "v", "a", "type")}


def chain_kinematics(joints, q, v, base=np.zeros(3)) -> list[LinkKinematics]:
    """Poses, rates and bias (a = 0) accelerations of every link frame (origin on its joint), for
    positions ``q`` and velocities ``v`` of the joints."""
    qd = v
    R, p = np.eye(3), np.asarray(base, float).copy()
    w, al, v, a = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    out = []
    for i, jt in enumerate(joints):
        o = p + R @ jt.offset
        z = R @ jt.axis
        dp = o - p
        v_n = v + _cross(w, dp)
        a_n = a + _cross(al, dp) + _cross(w, _cross(w, dp))
        if jt.type == "R":
            R_n = R @ rotation(jt.axis, q[i])
            al_n = al + _cross(w, z * qd[i])
            w_n = w + z * qd[i]
            p_n = o
        else:
            R_n = R.copy()
            p_n = o + z * q[i]
            v_n = v_n + _cross(w, z * q[i]) + z * qd[i]
            a_n = a_n + _cross(al, z * q[i]) + _cross(w, _cross(w, z * q[i])) \
                + 2.0 * _cross(w, z * qd[i])
            w_n, al_n = w.copy(), al.copy()
        out.append(LinkKinematics(R=R_n, p=p_n, z=z, o=o, w=w_n, al=al_n, v=v_n, a=a_n, type=jt.type))
        R, p, w, al, v, a = R_n, p_n, w_n, al_n, v_n, a_n
    return out


def point_jacobian(kin, i, r):
    n = len(kin)
    Jv, Jw = np.zeros((3, n)), np.zeros((3, n))
    for j in range(i + 1):
        if kin[j].type == "R":
            Jw[:, j] = kin[j].z
            Jv[:, j] = _cross(kin[j].z, r - kin[j].o)
        else:
            Jv[:, j] = kin[j].z
    return Jv, Jw


def point_bias(kin, i, r):
    k = kin[i]
    rho = r - k.p
    return k.a + _cross(k.al, rho) + _cross(k.w, _cross(k.w, rho))


def link_subsystem(link: Link, kin_i, gravity=GRAVITY) -> Subsystem:
    """Newton-Euler model of a rigid link in (v_G, omega), base frame."""
    R = kin_i.R
    Iw = R @ link.inertia @ R.T
    w = kin_i.w
    return Subsystem(block_diag([link.mass * np.eye(3), Iw]),
                     np.concatenate([np.zeros(3), _cross(w, Iw @ w)]),
                     np.concatenate([-link.mass * np.asarray(gravity), np.zeros(3)]))


def arm_model(joints, links, q, qd, base=np.zeros(3), gravity=GRAVITY):
    """An arm's own model (M#, v#, g#): links coupled to the joint coordinates (a massless
    subsystem) by p_link - J qd = 0 (paper eqs 7, 9, 17, 19, 28, 30 are instances)."""
    n = len(joints)
    kin = chain_kinematics(joints, q, qd, base)
    subs = [Subsystem(np.zeros((n, n)), np.zeros(n), np.zeros(n))]
    rows, bias = [], []
    for i, b in enumerate(links):
        rG = kin[i].p + kin[i].R @ b.com
        Jv, Jw = point_jacobian(kin, i, rG)
        subs.append(link_subsystem(b, kin[i], gravity))
        rows.append(np.vstack([Jv, Jw]))
        bias.append(np.concatenate([point_bias(kin, i, rG), kin[i].al]))
    N = len(links)
    A = np.zeros((6 * N, n + 6 * N))
    for k in range(N):
        A[6 * k:6 * k + 6, :n] = -rows[k]
        A[6 * k:6 * k + 6, n + 6 * k:n + 6 * k + 6] = np.eye(6)
    return couple(subs, A, np.arange(n), -np.concatenate(bias), qd), kin


def disc_subsystem(disc: Disc, kin, q, qd):
    """Disc model in its body-frame angular velocity and its constraint rows
    omega_d - J_d qd = 0 (A° = 1, A# = -J_d), bias J_d' qd (eqs 10-11, 20-21, 31-32)."""
    c = kin[disc.carrier]
    axis = np.asarray(disc.axis, float) / np.linalg.norm(disc.axis)
    Rd = c.R @ rotation(axis, disc.ratio * q[disc.joint])
    a_w = c.R @ axis
    n = len(kin)
    _, Jw_c = point_jacobian(kin, disc.carrier, c.p)
    E = np.zeros((3, n))
    E[:, disc.joint] = disc.ratio * a_w
    Jd = Rd.T @ (Jw_c + E)
    bias = Rd.T @ (c.al + _cross(c.w, disc.ratio * a_w * qd[disc.joint]))
    wB = Jd @ qd
    Jm = np.diag(disc.inertia)
    return Subsystem(Jm, _cross(wB, Jm @ wB), np.zeros(3)), Jd, bias


def arm_with_discs(joints, links, discs, q, qd, gravity=GRAVITY) -> CoupledModel:
    """The paper's two-stage procedure: the arm's model (M#, v#, g#) first, then each disc
    coupled to it (eqs 11-13, 21-24, 32-34)."""
    q, qd = np.asarray(q, float), np.asarray(qd, float)
    arm, kin = arm_model(joints, links, q, qd, gravity=gravity)
    n = len(joints)
    if not discs:
        return arm
    subs = [Subsystem(arm.mass, arm.velocity, arm.gravity)]
    rows, bias = [], []
    for d in discs:
        sub, Jd, b = disc_subsystem(d, kin, q, qd)
        subs.append(sub)
        rows.append(Jd)
        bias.append(b)
    m = 3 * len(discs)
    A = np.zeros((m, n + m))
    for k in range(len(discs)):
        A[3 * k:3 * k + 3, :n] = -rows[k]
        A[3 * k:3 * k + 3, n + 3 * k:n + 3 * k + 3] = np.eye(3)
    return couple(subs, A, np.arange(n), -np.concatenate(bias), qd)
