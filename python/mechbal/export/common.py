"""What the URDF and MJCF writers share: names of links, orientations, merged inertias, the
tree's joint values from a mechanism's coordinates.

Link names. In a `mechbal.Mechanism` a link is named after the joint that moves it (the
root after ``root_name``); a URDF read by mechbal also has every URDF link as a frame of identity
placement on its link. `link_labels` gives each link the name of such a frame when there is
one (so ``upper_arm_link`` stays ``upper_arm_link``, not ``shoulder_lift_joint``; a link with a
frame of its own name keeps it: a URDF's root ``world``), the link's own name otherwise; names
are unique. Only a mechanism whose root is a frame of identity placement of the same name (what
mechbal's URDF reader makes) is renamed so: a TOML mechanism's links keep their joints' names.
"""
from __future__ import annotations

import math

import numpy as np

from mechbal import _core


class ExportError(ValueError):
    """The mechanism cannot be written in the asked format (one line: what and why)."""


def rpy_of(R: np.ndarray) -> list[float]:
    """Roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll) (mechbal and URDF's convention)."""
    R = np.asarray(R, float)
    cp = math.hypot(R[0, 0], R[1, 0])
    pitch = math.atan2(-R[2, 0], cp)   # not asin: well conditioned near +-pi/2 too
    if cp > 1e-15:
        roll, yaw = math.atan2(R[2, 1], R[2, 2]), math.atan2(R[1, 0], R[0, 0])
    else:  # gimbal lock: roll and yaw turn about the same axis
        roll, yaw = 0.0, math.atan2(-R[0, 1], R[1, 1])
    return [roll, pitch, yaw]


def quat_of(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method), w >= 0."""
    R = np.asarray(R, float)
    tr = np.trace(R)
    if tr > 0.0:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(max(1.0 + R[i, i] - R[j, j] - R[k, k], 0.0))
        q = [0.0] * 4
        q[0] = (R[k, j] - R[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (R[j, i] + R[i, j]) / s
        q[1 + k] = (R[k, i] + R[i, k]) / s
    q = np.array(q)
    q /= np.linalg.norm(q)
    return q if q[0] >= 0.0 else -q


def inertia_is_zero(b) -> bool:
    return float(b.mass) == 0.0 and not np.any(np.asarray(b.inertia, float))


def merged_inertial(bodies) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it) of bodies on one link, in the link frame: exact
    for the dynamics. Bodies of zero mass keep their rotational inertia (a disc's rotor); with a
    total mass of zero the centre of mass is the origin."""
    m = sum(float(b.mass) for b in bodies)
    c = sum(float(b.mass) * np.asarray(b.com, float) for b in bodies) / m if m > 0.0 else np.zeros(3)
    I = np.zeros((3, 3))
    for b in bodies:
        r = np.asarray(b.com, float) - c
        I += np.asarray(b.inertia, float) + float(b.mass) * (r @ r * np.eye(3) - np.outer(r, r))
    return m, c, 0.5 * (I + I.T)


def _identity(T) -> bool:
    return bool(np.array_equal(np.asarray(T, float), np.eye(4)))


def link_labels(mech) -> dict[str, str]:
    """mechbal link name -> the name a file gives it (module docstring). A link takes the name of
    its frame of identity placement (its own name first), whatever other joints are called (a
    URDF whose link names are other joints' names keeps every frame where it was); a link without
    one keeps its own name, suffixed where a frame's name took it: the names are unique."""
    d = mech.model.description
    links = [d.root_name] + [j.name for j in d.joints]
    labels = {n: n for n in links}
    named = {f.link for f in d.frames if f.name == f.link and _identity(f.placement)}
    if d.root_name not in named:   # not read from a URDF (whose every link is a frame, the root's too)
        return labels
    wanted: dict[str, str] = {n: n for n in named}
    for f in d.frames:
        if f.link not in wanted and _identity(f.placement):
            wanted[f.link] = f.name
    taken = set(wanted.values())   # frame names: unique
    for n in links:
        if n in wanted:
            labels[n] = wanted[n]
            continue
        label = n
        while label in taken:
            label += "_link"
        taken.add(label)
        labels[n] = label
    return labels


def full_joint_values(mech, q) -> dict[str, float]:
    """Value of every moving joint of the tree (gear-coupled ones from their master) at the
    coordinates q (dof,)."""
    q = np.asarray(q, float).reshape(-1)
    coords = dict(zip(mech.joint_names, q))
    out: dict[str, float] = {}
    for j in mech.model.description.joints:
        if j.type == _core.JointType.fixed:
            continue
        if j.mimic_joint:
            out[j.name] = float(j.mimic_ratio) * coords[j.mimic_joint] + float(j.mimic_offset)
        else:
            out[j.name] = float(coords[j.name])
    return out


def fixed_to_root(mech) -> set[str]:
    """Links that do not move: the root and the links joined to it by fixed joints only."""
    d = mech.model.description
    still = {d.root_name}
    for j in d.joints:  # parents first
        if j.type == _core.JointType.fixed and j.parent in still:
            still.add(j.name)
    return still


def assembled_pose(mech, q=None, q_guess=None) -> np.ndarray:
    """Coordinates (dof,) of an assembled pose: ``q`` when given (a closed mechanism's checked
    for closure), else zeros for a tree; for a closed mechanism without ``q``, the loops solved
    from ``q_guess`` (zeros by default) with the actuated joints at the guess's values.
    ExportError when the loops do not close."""
    if q is not None:
        q = np.asarray(q, float).reshape(-1)
        if q.shape != (mech.dof,):
            raise ExportError(f"q must have {mech.dof} values (the coordinates {mech.joint_names}), got {q.size}")
    if not mech.is_closed:
        return np.zeros(mech.dof) if q is None else q
    guess = np.zeros(mech.dof) if q_guess is None else np.asarray(q_guess, float)
    start = q if q is not None else guess
    idx = [mech.joint_names.index(n) for n in mech.actuated_names]
    m = mech.closed_motion(start[idx], q_guess=start)
    if int(m.status) & ~int(_core.Status.singular) or not m.residual < 1e-9:
        raise ExportError(f"{mech.name}: the loops do not close from the given pose (residual "
                          f"{float(m.residual):.3g}): give an assembled pose q")
    return np.asarray(m.q, float)
