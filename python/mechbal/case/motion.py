"""The motion of a case: what its ``[trajectory]`` asks the mechanism to do.

* `mechanism_motion`: (q, v, a, torque) along a trajectory of the actuated joints (the loops solved
  instant by instant for a closed mechanism); `start_assembly`: the assembly at its start;
  `motion_summary`: what summary.json says about a constant-speed motion.
* The operational-space mode's path (``[control] task_frame``): `task_end_pose` (where it ends)
  and `frame_path` (the frame's pose, twist and twist rate along it).

Layer: the case (docs/architecture.md)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from mechbal import control
from mechbal.errors import ConfigError

if TYPE_CHECKING:
    from mechbal.mechanism import Mechanism


def _rotation_matrix(rotation_vector: Any) -> np.ndarray:
    """exp([r]x) of a rotation vector r = theta k (Rodrigues)."""
    r = np.asarray(rotation_vector, float)
    theta = float(np.linalg.norm(r))
    if theta == 0.0:
        return np.eye(3)
    k = r / theta
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(theta) * K + (1.0 - np.cos(theta)) * (K @ K)


def task_end_pose(mech: Any, frame: str, trajectory: Any) -> np.ndarray:
    """The pose (4 x 4 in O) the task ``frame`` ends at along a validated ``[trajectory]``
    (`mechbal.tables.ChainTrajectory`): ``law = "line"``: its pose at ``start`` moved by
    ``displacement`` [m] (O axes) and turned by ``rotation`` (rotation vector [rad], O axes,
    about the frame's origin): R1 = exp([rotation]x) R0, p1 = p0 + displacement; the
    rest-to-rest laws: its pose at ``end`` (joint positions)."""
    if trajectory.law != "line":
        return np.asarray(mech.frame_placement(np.asarray(trajectory.end, float), frame), float)
    T0 = np.asarray(mech.frame_placement(np.asarray(trajectory.start, float), frame), float)
    T1 = T0.copy()
    if trajectory.displacement is not None:
        T1[:3, 3] = T0[:3, 3] + np.asarray(trajectory.displacement, float)
    if trajectory.rotation is not None:
        T1[:3, :3] = _rotation_matrix(trajectory.rotation) @ T0[:3, :3]
    return T1


def mechanism_motion(mech: Mechanism, traj, t, q_guess=None):
    """(q, v, a, torque, extra) of a mechanism along a trajectory of its actuated joints: for an
    open mechanism the trajectory drives every coordinate and torque is the inverse dynamics; for a
    closed one the loops are solved instant by instant and torque is the actuated force C^T tau."""
    qa, va, aa = traj.evaluate_batch(t)
    if not mech.is_closed:
        return qa, va, aa, mech.inverse_dynamics(qa, va, aa), {}
    m = mech.closed_motion(qa, va, aa, q_guess=q_guess, with_forces=True)
    bad = (m.status & ~np.uint32(int(control.Status.singular))) != 0
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ConfigError("trajectory", f"the loops cannot be assembled at t = {t[k]:.4g} s (closure "
                                        f"residual {m.residual[k]:.3g}); check the geometry, the "
                                        "trajectory and trajectory.initial_guess", has_value=False)
    singular = (m.status & np.uint32(int(control.Status.singular))) != 0
    extra = {"min_rcond": float(np.min(m.rcond)), "singular_instants": int(np.sum(singular)),
             "max_closure_residual": float(np.max(m.residual)),
             "max_newton_iterations": int(np.max(m.iterations))}
    return m.q, m.v, m.a, m.actuated_force, extra


def start_assembly(mech: Mechanism, tr, traj):
    """The assembly of a closed mechanism at the trajectory's start (`mechbal.assembly.assemble`
    with ``[trajectory] branch`` and ``initial_guess``), or None for an open one."""
    if not mech.is_closed:
        return None
    from mechbal.assembly import assemble

    qa0 = np.atleast_2d(traj.evaluate_batch(np.zeros(1))[0])[0]
    return assemble(mech, qa0, branch=getattr(tr, "branch", None),
                    initial_guess=getattr(tr, "initial_guess", None))


def motion_summary(tr, traj) -> dict:
    """What summary.json says about a constant-speed motion (empty for the rest-to-rest laws)."""
    if getattr(tr, "law", None) != "constant_speed":
        return {}
    speed = np.asarray(traj.speed, float)
    return {"speed": speed, "rpm": speed * 60.0 / (2.0 * np.pi),
            "revolutions": float(np.max(np.abs(speed)) * traj.duration / (2.0 * np.pi))}


def _rotation_vector(R: np.ndarray) -> np.ndarray:
    """theta k of a rotation R = exp(theta [k]x), theta in [0, pi]."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(R).as_rotvec()


def frame_path(mech: Mechanism, frame: str, start, end, duration: float, law: str, t, *, end_pose=None):
    """The operational-space mode's path of ``frame`` at times ``t``: from its pose at the joint
    positions ``start`` to its pose at ``end`` (or to ``end_pose``, 4 x 4 in O, when given:
    `mechbal.case.task_end_pose`, the line law's) along the time law s(t) (0 to 1; ``law =
    "line"``: quintic), the origin on the straight line and the orientation about the fixed axis
    of the relative rotation (R(t) = exp(s theta [k]x) R0). Returns (position (N, 3), rotation
    (N, 3, 3), twist (N, 6), twist_rate (N, 6)), twists [v; w] of the origin in O axes."""
    from scipy.spatial.transform import Rotation

    from mechbal.trajectory import RestToRest

    law = "quintic" if law == "line" else law
    T0 = np.asarray(mech.frame_placement(np.asarray(start, float), frame))
    T1 = np.asarray(end_pose if end_pose is not None else mech.frame_placement(np.asarray(end, float), frame),
                    float)
    dp = T1[:3, 3] - T0[:3, 3]
    rv = _rotation_vector(T1[:3, :3] @ T0[:3, :3].T)
    s, sd, sdd = (np.asarray(x)[:, 0] for x in RestToRest([0.0], [1.0], duration, law).evaluate(t))
    position = T0[:3, 3] + s[:, None] * dp
    rotation = Rotation.from_rotvec(s[:, None] * rv).as_matrix() @ T0[:3, :3]
    twist = np.concatenate([sd[:, None] * dp, sd[:, None] * rv], axis=1)
    twist_rate = np.concatenate([sdd[:, None] * dp, sdd[:, None] * rv], axis=1)
    return position, rotation, twist, twist_rate
