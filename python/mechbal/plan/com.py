"""The centre-of-mass law: the total centre of mass on a straight line, with a bang-bang,
minimum-jerk or cubic profile, for mechanisms whose centre of mass is an invertible function of
the actuated joints that move it.

The shaking force is the total mass times the acceleration of the centre of mass, ``F = m c''``
(Briot & Arakelian 2009, eq 1), so a motion that drives the centre of mass along the straight
line from its start to its end position controls the shaking force directly (the published
method: a bang-bang acceleration profile of the centre of mass, |F| = 4 m L / T^2 throughout, the
least peak force of a rest-to-rest straight line). ``profile``:

* ``"bang_bang"``: ``s'' = +-4 / T^2`` (least peak force on the line; the acceleration jumps at
  the start, the middle and the end);
* ``"cubic"``: ``s = 3 u^2 - 2 u^3`` (least RMS force of any rest-to-rest motion of the centre
  of mass between the two points: ``F_rms = m L sqrt(12) / T^2``);
* ``"minimum_jerk"``: ``s = 10 u^3 - 15 u^4 + 6 u^5``.

The actuated joints that move the centre of mass (a non-zero column of its Jacobian) must be as
many as the rank of that Jacobian all along (the centre of mass an invertible function of them);
the others follow the quintic. Their positions solve ``c(q#) = c*(t)`` by Newton's method at
every instant, their rates ``J v# = c*'`` and accelerations ``J a# = c*'' - Jdot v#`` exactly,
so the shaking force of the motion is ``m c*''``.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechbal.mechanism import Mechanism
from mechbal.plan.model import ActuatedModel, LoopFailure

PROFILES = ("bang_bang", "cubic", "minimum_jerk")


class ComLawNotApplicable(ValueError):
    """The centre of mass is not an invertible function of the actuated joints here (the message
    says why)."""


def _profile(name: str, u: np.ndarray, T: float):
    if name == "bang_bang":
        first = u <= 0.5
        s = np.where(first, 2 * u ** 2, 1 - 2 * (1 - u) ** 2)
        ds = np.where(first, 4 * u, 4 * (1 - u)) / T
        dds = np.where(first, 4.0, -4.0) / T ** 2
    elif name == "cubic":
        s, ds, dds = 3 * u ** 2 - 2 * u ** 3, (6 * u - 6 * u ** 2) / T, (6 - 12 * u) / T ** 2
    elif name == "minimum_jerk":
        s = 10 * u ** 3 - 15 * u ** 4 + 6 * u ** 5
        ds = (30 * u ** 2 - 60 * u ** 3 + 30 * u ** 4) / T
        dds = (60 * u - 180 * u ** 2 + 120 * u ** 3) / T ** 2
    else:
        raise ValueError(f"profile must be one of {', '.join(PROFILES)}, got {name!r}")
    return s, ds, dds


class SampledMotion:
    """A motion of the actuated joints given at sample times (q, v, a exact there): the times it
    was made at are the times it can be evaluated at."""

    def __init__(self, law: str, t: np.ndarray, q: np.ndarray, v: np.ndarray, a: np.ndarray):
        self.law, self.t, self.q, self.v, self.a = law, t, q, v, a

    @property
    def dof(self) -> int:
        return int(self.q.shape[1])

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    def evaluate(self, t):
        from mechbal.trajectory import Motion

        t = np.atleast_1d(np.asarray(t, float))
        idx = np.searchsorted(self.t, t)
        idx = np.clip(idx, 0, len(self.t) - 1)
        if not np.allclose(self.t[idx], t, rtol=0, atol=1e-12):
            raise ValueError("a SampledMotion is evaluated at the times it was made at only")
        return Motion(self.q[idx], self.v[idx], self.a[idx])

    evaluate_batch = evaluate


@dataclass
class ComLawResult:
    """The motion (``trajectory``: a `SampledMotion` at ``t``), the joints that move the centre
    of mass, the profile, the mass and the straight line (``start``, ``end`` of the centre of mass
    [m]), the largest distance of the centre of mass from its target along the motion [m]."""

    trajectory: SampledMotion
    profile: str
    joints: list[int]
    mass: float
    com_start: np.ndarray
    com_end: np.ndarray
    max_com_error: float


def com_law(mech: Mechanism, start, end, duration: float, *, profile: str = "bang_bang",
            samples: int = 501, q_guess=None, max_iterations: int = 30,
            tolerance: float = 1e-12) -> ComLawResult:
    """The centre-of-mass law (module docstring) from ``start`` to ``end`` (actuated joints, rad
    or m) in ``duration`` [s], rest to rest, at ``samples`` instants. Raises
    `ComLawNotApplicable` where the centre of mass is not an invertible function of the joints
    that move it, or where the straight line leaves what they can reach."""
    from mechbal.plan.min_shaking import quintic_with_velocities

    na = len(mech.actuated_names)
    q0, q1 = np.asarray(start, float).reshape(na), np.asarray(end, float).reshape(na)
    T = float(duration)
    if mech.is_closed and q_guess is None:
        from mechbal.assembly import assemble

        q_guess = assemble(mech, q0).q
    am = ActuatedModel(mech, q_guess=q_guess)
    m = float(mech.total_mass)
    t = np.linspace(0.0, T, int(samples))
    ref = quintic_with_velocities(q0, q1, T, np.zeros(na), np.zeros(na)).evaluate(t)

    def com_and_jacobian(q):
        # every instant with its na variants (q, 0, e_j) consecutive: F(q, 0, e_j) = m J_c e_j
        N = len(q)
        A = np.zeros((N, na + 1, na))
        A[:, 1:] = np.eye(na)
        Q = np.repeat(q[:, None, :], na + 1, axis=1).reshape(-1, na)
        full_q, full_v, full_a, _ = am.full(Q, np.zeros_like(Q), A.reshape(-1, na))
        F = am.wrench_of(full_q, full_v, full_a)[:, :3].reshape(N, na + 1, 3)
        c = mech.center_of_mass(full_q.reshape(N, na + 1, -1)[:, 0])
        return np.asarray(c), np.moveaxis(F[:, 1:], 1, 2) / m

    c_ref, J_ref = com_and_jacobian(ref.q)
    moves = np.max(np.abs(J_ref), axis=(0, 1)) > 1e-12 * max(1.0, float(np.max(np.abs(J_ref))))
    S = [j for j in range(na) if moves[j]]
    if not S:
        raise ComLawNotApplicable("no actuated joint moves the centre of mass")
    ranks = np.linalg.matrix_rank(J_ref[:, :, S], tol=1e-9 * max(1e-300, float(np.max(np.abs(J_ref)))))
    if np.any(ranks < len(S)):
        raise ComLawNotApplicable(
            f"the centre of mass is not an invertible function of the {len(S)} actuated joints that move "
            f"it ({', '.join(mech.actuated_names[j] for j in S)}): its Jacobian has rank "
            f"{int(np.min(ranks))} (redundant joints)")
    c0, c1 = c_ref[0], c_ref[-1]
    s, ds, dds = _profile(profile, t / T, T)
    target = c0 + np.outer(s, c1 - c0)
    # Newton on c(q#) = c* over the joints S (least squares where they span less than 3 directions)
    q = ref.q.copy()
    err = np.inf
    for _ in range(max_iterations):
        try:
            c, J = com_and_jacobian(q)
        except LoopFailure:
            err = np.inf
            break
        r = target - c
        err = float(np.max(np.linalg.norm(r, axis=1)))
        if err <= tolerance * max(1.0, float(np.linalg.norm(c1 - c0))):
            break
        dq = np.einsum("ijk,ik->ij", np.linalg.pinv(J[:, :, S]), r)
        q[:, S] += dq
    if not err <= 1e-9:
        where = "the loops cannot be assembled on the way" if not np.isfinite(err) else f"it stays {err:.3g} m away"
        raise ComLawNotApplicable(
            f"the centre of mass cannot follow the straight line from {np.round(c0, 6).tolist()} to "
            f"{np.round(c1, 6).tolist()} m ({where}): the {len(S)} joint(s) that move it do not "
            "reach every point of it")
    # rates and accelerations: J v = c*', J a = c*'' - Jdot v (J restricted to S; the others: quintic)
    c, J = com_and_jacobian(q)
    v, a = ref.v.copy(), ref.a.copy()
    JS = J[:, :, S]
    other = [j for j in range(na) if j not in S]
    cd = np.outer(ds, c1 - c0) - np.einsum("ikj,ij->ik", J[:, :, other], v[:, other])
    pinv = np.linalg.pinv(JS)
    v[:, S] = np.einsum("ijk,ik->ij", pinv, cd)
    a_zero = a.copy()
    a_zero[:, S] = 0.0
    bias = am.evaluate(q, v, a_zero).wrench[:, :3] / m      # c'' with a# = 0 on S
    cdd = np.outer(dds, c1 - c0) - bias
    a[:, S] = np.einsum("ijk,ik->ij", pinv, cdd)
    final = np.asarray(mech.center_of_mass(am.full(q, v, a)[0]))
    return ComLawResult(SampledMotion(f"com_{profile}", t, q, v, a), profile, S, m, c0, c1,
                        float(np.max(np.linalg.norm(final - target, axis=1))))
