"""The operational-space mode's path ends (``[control] task_frame``): `task_end_pose`.

Layer: the case (docs/architecture.md)."""
from __future__ import annotations

from typing import Any

import numpy as np


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
