"""Every robot of example-robot-data that mechbal loads exports to an MJCF that MuJoCo loads (issue
39): among them anymal_c, icub, icub_reduced, romeo_small and romeo_laas_small, whose inertias on
the triangle inequality's boundary (or across it by rounding) MuJoCo refused. The export's mass
matrix and bias forces (MuJoCo) agree with Pinocchio's on the original URDF to 1e-9 of the mass
matrix's scale, the repaired files included (a warning names each repair: the nearest physical
inertia of a negligible body, far below that tolerance).

About 10 s on one core (68 files)."""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal.config import ConfigError
from mechbal.mechanism import UrdfRepairWarning

pin = pytest.importorskip("pinocchio")
mujoco = pytest.importorskip("mujoco")

#: the files MuJoCo refused before issue 39
ONCE_REFUSED = ["anymal.urdf", "icub.urdf", "icub_reduced.urdf", "romeo_small.urdf", "romeo_laas_small.urdf"]


def _robots_dir() -> Path:
    for entry in sys.path:
        robots = Path(entry) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if robots.is_dir():
            return robots
    pytest.skip("example-robot-data is not installed (pip install '.[test]')")


def _pin_state(pm, names, theta, omega):
    """Pinocchio's q, v of the joint values ``theta`` and rates ``omega`` by joint name
    (a continuous joint's q is cos, sin), and the index in v of each name."""
    q, v, idx = pin.neutral(pm), np.zeros(pm.nv), {}
    for j, name in zip(pm.joints[1:], pm.names[1:]):
        if name not in names:
            continue
        k = names.index(name)
        if j.nq == 2:
            q[j.idx_q:j.idx_q + 2] = np.cos(theta[k]), np.sin(theta[k])
        else:
            q[j.idx_q] = theta[k]
        v[j.idx_v] = omega[k]
        idx[name] = j.idx_v
    return q, v, idx


def _with_repairs(path: Path, mech, messages: list[str]) -> str:
    """The URDF text of ``path`` with the inertials of the links the repair ``messages`` name
    replaced by mechbal's bodies of those links (centre of mass and inertia in the link frame)."""
    import re
    import xml.etree.ElementTree as ET

    links = {m.group(1) for text in messages for m in [re.search(r"URDF link '([^']+)' <inertial>", text)] if m}
    bodies = {b.name: b for b in mech.bodies}
    frames = {f.name: f for f in mech.model.description.frames}
    root = ET.parse(path).getroot()
    for link in root.iter("link"):
        name = link.get("name")
        if name not in links:
            continue
        inertial = link.find("inertial")
        if name not in bodies:            # a dropped root placeholder
            link.remove(inertial)
            continue
        b = bodies[name]
        # mechbal's body is in the frame of the link that carries it; the URDF link's frame is
        # the frame of that name on it
        T = np.asarray(frames[name].placement, float)
        R, p = T[:3, :3], T[:3, 3]
        for child in list(inertial):
            if child.tag in ("origin", "inertia"):
                inertial.remove(child)
        com = R.T @ (np.asarray(b.com, float) - p)
        ET.SubElement(inertial, "origin", xyz=" ".join(repr(float(x)) for x in com), rpy="0 0 0")
        I = R.T @ np.asarray(b.inertia, float) @ R
        ET.SubElement(inertial, "inertia", **{k: repr(float(I[i, j])) for k, (i, j) in
                                              dict(ixx=(0, 0), iyy=(1, 1), izz=(2, 2), ixy=(0, 1),
                                                   ixz=(0, 2), iyz=(1, 2)).items()})
    return ET.tostring(root, encoding="unicode")


def _compare(pm, m, rng) -> float:
    """Largest difference of M and of the bias forces (C v + g) between MuJoCo's ``m`` and
    Pinocchio's ``pm`` at three random states, relative to max(1, |M|, |bias|)."""
    d = mujoco.MjData(m)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)]
    dof = [int(m.jnt_dofadr[j]) for j in range(m.njnt)]
    assert sorted(names) == sorted(n for n in pm.names[1:] if pm.joints[pm.getJointId(n)].nv == 1), \
        "the moving joints keep their names"
    worst = 0.0
    pd = pm.createData()
    for _ in range(3):
        theta, omega = rng.uniform(-1.0, 1.0, (2, len(names)))
        lo, hi = m.jnt_range[:, 0], m.jnt_range[:, 1]
        theta = np.where(m.jnt_limited.astype(bool), lo + (hi - lo) * (theta + 1.0) / 2.0, theta)
        d.qpos[:] = [theta[names.index(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j))]
                     for j in range(m.njnt)]
        d.qvel[:] = omega
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        q, v, idx = _pin_state(pm, names, theta, omega)
        Mp = pin.crba(pm, pd, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        bp = pin.rnea(pm, pd, q, v, np.zeros(pm.nv))
        order = [idx[n] for n in names]
        Mp, bp = Mp[np.ix_(order, order)], bp[order]
        M, b = M[np.ix_(dof, dof)], np.asarray(d.qfrc_bias)[dof]
        scale = max(1.0, float(np.max(np.abs(Mp))), float(np.max(np.abs(bp))))
        worst = max(worst, float(np.max(np.abs(M - Mp))) / scale, float(np.max(np.abs(b - bp))) / scale)
    return worst


def test_every_example_robot_exports_to_an_mjcf_that_mujoco_loads():
    robots = _robots_dir()
    rng = np.random.default_rng(39)
    exported, failures, differ, seen, repairs = 0, [], {}, set(), {}
    for path in sorted(robots.rglob("*.urdf")):
        try:
            pm = pin.buildModelFromUrdf(str(path))
        except Exception:  # noqa: BLE001 - what Pinocchio refuses is out of scope
            continue
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                mech = mechbal.Mechanism.from_urdf(path, allow_massless=True)
        except ConfigError:
            continue   # test_urdf_robots: none is refused
        repaired = [w for w in caught if issubclass(w.category, UrdfRepairWarning)
                    and "kinematics only" not in str(w.message)]
        name = str(path.relative_to(robots))
        try:
            m = mujoco.MjModel.from_xml_string(mech.to_mjcf())
        except ValueError as exc:
            failures.append(f"{name}: {exc}")
            continue
        exported += 1
        seen.add(path.name)
        if repaired:   # Pinocchio on the file with mechbal's repaired inertias in place
            repairs[name] = len(repaired)
            pm = pin.buildModelFromXML(_with_repairs(path, mech, [str(w.message) for w in repaired]))
        if m.nv:       # mimic joints compared as the tree's (Pinocchio reads them as independent)
            differ[name] = _compare(pm, m, rng)
    assert not failures, "\n".join(failures)
    assert exported > 30 and set(ONCE_REFUSED) <= seen, sorted(set(ONCE_REFUSED) - seen)
    worst = max(differ, key=differ.get)
    assert differ[worst] < 1e-9, (worst, differ[worst])
    assert repairs   # the repaired files are among them (their repairs are on negligible bodies)
