"""The URDF reader (C++, urdfdom) against Pinocchio loading the same file: random trees written to
a file (branching, fixed and prismatic joints, continuous joints, rotated inertial frames, gear
couplings, a root inertial) and real robots from a PyPI data package (UR5 and Panda from
example-robot-data); and its errors."""
from __future__ import annotations

import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.config import ConfigError
from random_trees import random_tree
from pinocchio_checks import _base_fixed_mass_moment, _rel  # noqa: F401

pin = pytest.importorskip("pinocchio")

RTOL = 1e-9


# ---- helpers (comparison as in test_mechanism.py) ------------------------------------------------

class PinocchioState:
    """Maps mechbal's coordinates onto a Pinocchio model of the same URDF built without mimic
    joints: a gear-coupled joint is an independent joint there, set to ratio * q_master + offset
    (so tau = G^T tau_pin and M = G^T M_pin G), and a continuous joint has Pinocchio's (cos, sin)
    pair in q."""

    def __init__(self, mech, pm):
        self.pm = pm
        desc = {j.name: j for j in mech.model.description.joints}
        names = mech.joint_names
        self.G = np.zeros((pm.nv, mech.dof))
        self.offset = np.zeros(pm.nv)
        self.q_slots = []  # (q index in Pinocchio, nq of the joint, v index)
        for jid in range(1, pm.njoints):
            name = pm.names[jid]
            if pm.nvs[jid] == 0:
                continue
            assert pm.nvs[jid] == 1, name
            iv = pm.idx_vs[jid]
            j = desc[name]
            if j.mimic_joint:
                self.G[iv, names.index(j.mimic_joint)] = j.mimic_ratio
                self.offset[iv] = j.mimic_offset
            else:
                self.G[iv, names.index(name)] = 1.0
            self.q_slots.append((pm.idx_qs[jid], pm.nqs[jid], iv))

    def __call__(self, q, v, a):
        qv = self.G @ q + self.offset
        qp = np.zeros(self.pm.nq)
        for iq, nq, iv in self.q_slots:
            if nq == 2:  # continuous: (cos, sin)
                qp[iq], qp[iq + 1] = np.cos(qv[iv]), np.sin(qv[iv])
            else:
                qp[iq] = qv[iv]
        return qp, self.G @ v, self.G @ a


def compare_with_pinocchio(mech, pm, rng, count=4, q_scale=2.0):
    """Inverse dynamics, mass matrix, gravity, bias, centre of mass, momenta and their rates about
    O of `mech` against Pinocchio's model `pm` of the same URDF, at random states."""
    pd = pm.createData()
    state = PinocchioState(mech, pm)
    G = state.G
    worst = 0.0
    for _ in range(count):
        q = rng.uniform(-q_scale, q_scale, mech.dof)
        v, a = rng.normal(size=mech.dof), rng.normal(size=mech.dof)
        qp, vp, ap = state(q, v, a)
        errors = {}
        errors["rnea"] = _rel(mech.inverse_dynamics(q, v, a), G.T @ pin.rnea(pm, pd, qp, vp, ap))
        M = pin.crba(pm, pd, qp)
        M = np.triu(M) + np.triu(M, 1).T
        errors["crba"] = _rel(mech.mass_matrix(q), G.T @ M @ G)
        errors["gravity"] = _rel(mech.gravity_torque(q), G.T @ pin.computeGeneralizedGravity(pm, pd, qp))
        errors["nle"] = _rel(mech.bias_torque(q, v), G.T @ pin.nonLinearEffects(pm, pd, qp, vp))
        # centre of mass: Pinocchio's excludes bodies fixed to the base; mechbal's includes them
        m_pin = pin.computeTotalMass(pm)
        # (nothing moves when every joint is fixed: Pinocchio's centre of mass is then 0 / 0)
        c_pin = pin.centerOfMass(pm, pd, qp).copy() if m_pin > 0 else np.zeros(3)
        expected = (m_pin * c_pin + _base_fixed_mass_moment(mech, q)) / mech.total_mass
        errors["com"] = _rel(mech.center_of_mass(q), expected)
        # centroidal momentum and its rate, shifted from the centre of mass to O
        pin.computeCentroidalMomentumTimeVariation(pm, pd, qp, vp, ap)
        if m_pin > 0:
            c = pd.com[0]
            P, dP = pd.hg.linear.copy(), pd.dhg.linear.copy()
            H_O = pd.hg.angular + np.cross(c, P)
            dH_O = pd.dhg.angular + np.cross(c, dP)
        else:  # Pinocchio's centroidal quantities are 0 / 0 too
            P = dP = H_O = dH_O = np.zeros(3)
        sw = mech.shaking_wrench(q, v, a)
        errors["P"] = _rel(sw.linear_momentum, P)
        errors["H_O"] = _rel(sw.angular_momentum, H_O)
        errors["dP"] = _rel(sw.shaking_force, dP)
        errors["dH_O"] = _rel(sw.shaking_moment, dH_O)
        errors["A v"] = _rel(mech.momentum_matrix(q) @ v, np.r_[P, H_O])
        bad = {k: e for k, e in errors.items() if not e < RTOL}
        assert not bad, f"{mech.name}: relative errors above {RTOL}: {bad}"
        worst = max(worst, *errors.values())
    return worst


def _urdf(tree, continuous=(), inertial_rpy=False, root_inertial=None):
    """`tree` as a URDF document, optionally with some revolute joints continuous, inertias given
    in a rotated inertial frame (origin rpy, principal moments), and an inertial on the root."""
    out = ['<robot name="random">']
    if root_inertial is None:
        out.append(f'  <link name="{tree.root}"/>')
    else:
        out.append(f'  <link name="{tree.root}">{root_inertial}</link>')
    for ln in tree.links:
        if inertial_rpy:
            rpy, I = ln.inertia_rpy, np.diag(ln.principal)
        else:
            rpy, I = np.zeros(3), ln.inertia_link
        out.append(f'  <link name="{ln.name}"><inertial><origin xyz="{_f(ln.com)}" rpy="{_f(rpy)}"/>'
                   f'<mass value="{float(ln.mass)!r}"/><inertia ixx="{float(I[0, 0])!r}" '
                   f'ixy="{float(I[0, 1])!r}" ixz="{float(I[0, 2])!r}" iyy="{float(I[1, 1])!r}" '
                   f'iyz="{float(I[1, 2])!r}" izz="{float(I[2, 2])!r}"/></inertial></link>')
        jt = ln.joint_type
        if ln.name in continuous:
            assert jt == "revolute"
            jt = "continuous"
        extra = ""
        if jt != "fixed":
            extra = f'<axis xyz="{_f(ln.axis)}"/><limit lower="-3" upper="3" effort="100" velocity="10"/>'
        if ln.mimic:
            extra += (f'<mimic joint="{ln.mimic[0]}_joint" multiplier="{float(ln.mimic[1])!r}" '
                      f'offset="{float(ln.mimic[2])!r}"/>')
        out.append(f'  <joint name="{ln.name}_joint" type="{jt}"><parent link="{ln.parent}"/>'
                   f'<child link="{ln.name}"/><origin xyz="{_f(ln.xyz)}" rpy="{_f(ln.rpy)}"/>{extra}</joint>')
    out.append("</robot>")
    return "\n".join(out)


def _f(v):
    return " ".join(repr(float(x)) for x in v)


def _load_both(tmp_path, text, name="robot"):
    path = tmp_path / f"{name}.urdf"
    path.write_text(text)
    return mechbal.Mechanism.from_urdf(path), pin.buildModelFromUrdf(str(path))


# ---- random trees --------------------------------------------------------------------------------

@pytest.mark.parametrize("types", ["R", "RP", "RRRPF", "RF"])
def test_random_trees_from_a_file_match_pinocchio(tmp_path, types):
    rng = np.random.default_rng(zlib.crc32(f"urdf{types}".encode()))
    for trial in range(5):
        tree = random_tree(rng, int(rng.integers(3, 10)), types=types)
        revolute = [ln.name for ln in tree.links if ln.joint_type == "revolute"]
        continuous = {n for n in revolute if rng.random() < 0.4}
        mech, pm = _load_both(tmp_path, _urdf(tree, continuous, inertial_rpy=bool(trial % 2)))
        compare_with_pinocchio(mech, pm, rng)
        # the same tree built directly from description objects gives the same numbers
        direct = tree.mechanism()
        q, v, a = rng.normal(size=(3, mech.dof))
        assert mech.joint_names == direct.joint_names
        assert _rel(mech.inverse_dynamics(q, v, a), direct.inverse_dynamics(q, v, a)) < 1e-12
        # continuous joints have no position limits, the others keep theirs
        lower = dict(zip(mech.joint_names, mech.model.lower_limits))
        for ln in tree.links:
            if ln.joint_type != "fixed":
                assert lower[ln.name + "_joint"] == (-np.inf if ln.name in continuous else -3.0)


def test_gear_couplings_from_urdf_mimic_match_pinocchio(tmp_path):
    rng = np.random.default_rng(23)
    checked = 0
    for trial in range(20):
        tree = random_tree(rng, 6, types="RRP", mimic=True)
        if not any(ln.mimic for ln in tree.links):
            continue
        mech, pm = _load_both(tmp_path, _urdf(tree, inertial_rpy=True))
        follower = next(ln for ln in tree.links if ln.mimic)
        assert follower.name + "_joint" not in mech.joint_names
        assert mech.dof == pm.nv - 1  # Pinocchio without mimic keeps the follower as a joint
        compare_with_pinocchio(mech, pm, rng, count=3)
        checked += 1
    assert checked >= 5


def test_root_inertial_is_a_body_on_the_base(tmp_path):
    rng = np.random.default_rng(29)
    tree = random_tree(rng, 6, types="RRRPF")
    root_inertial = ('<inertial><origin xyz="0.1 -0.2 0.3" rpy="0.4 -0.5 0.6"/><mass value="7.5"/>'
                     '<inertia ixx="0.3" ixy="0" ixz="0" iyy="0.4" iyz="0" izz="0.5"/></inertial>')
    mech, pm = _load_both(tmp_path, _urdf(tree, root_inertial=root_inertial))
    base = mech.bodies[mech.body_names.index(tree.root)]
    assert base.link == mech.model.root_name == tree.root
    assert base.mass == 7.5
    assert np.allclose(base.com, [0.1, -0.2, 0.3], atol=1e-15)
    from random_trees import rpy_matrix
    R = rpy_matrix([0.4, -0.5, 0.6])
    assert np.allclose(base.inertia, R @ np.diag([0.3, 0.4, 0.5]) @ R.T, atol=1e-15)
    assert mech.total_mass == pytest.approx(7.5 + sum(ln.mass for ln in tree.links), rel=1e-15)
    compare_with_pinocchio(mech, pm, rng)
    # the base's weight is in neither the shaking wrench nor the base reaction (the wrench the base
    # exerts on the moving mechanism), only in the support reaction (everything, the base included)
    q, v, a = rng.normal(size=(3, mech.dof))
    without = mechbal.Mechanism.from_urdf_string(_urdf(tree))
    assert _rel(mech.shaking_wrench(q, v, a).shaking_force, without.shaking_wrench(q, v, a).shaking_force) < 1e-12
    r, r0 = mech.base_reaction(q, v, a), without.base_reaction(q, v, a)
    assert _rel(r.base_reaction_force, r0.base_reaction_force) < 1e-12
    assert _rel(r.base_reaction_moment, r0.base_reaction_moment) < 1e-12
    assert np.allclose(r.support_force - r0.support_force, -7.5 * mech.gravity, rtol=1e-12, atol=1e-12)
    c = np.array([0.1, -0.2, 0.3])   # the base's centre of mass: its weight's moment about O
    assert np.allclose(r.support_moment - r0.support_moment, np.cross(c, -7.5 * mech.gravity), rtol=1e-12,
                       atol=1e-12)


def test_every_urdf_link_is_a_frame(tmp_path):
    rng = np.random.default_rng(31)
    tree = random_tree(rng, 7, types="RRPF")
    mech, pm = _load_both(tmp_path, _urdf(tree))
    pd = pm.createData()
    state = PinocchioState(mech, pm)
    assert set(mech.frame_names) == {tree.root, *(ln.name for ln in tree.links)}
    q = rng.normal(size=mech.dof)
    qp, _, _ = state(q, q, q)
    pin.framesForwardKinematics(pm, pd, qp)
    for ln in tree.links:
        T = mech.frame_placement(q, ln.name)
        oMf = pd.oMf[pm.getFrameId(ln.name)]
        assert _rel(T[:3, :3], oMf.rotation) < 1e-12 and _rel(T[:3, 3], oMf.translation) < 1e-12
        pin.computeJointJacobians(pm, pd, qp)
        J = pin.getFrameJacobian(pm, pd, pm.getFrameId(ln.name), pin.LOCAL_WORLD_ALIGNED)
        assert _rel(mech.frame_jacobian(q, ln.name), J @ state.G) < 1e-12


# ---- real robots ---------------------------------------------------------------------------------

def _robot_file(*parts) -> Path:
    for entry in sys.path:
        robots = Path(entry) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if (robots / Path(*parts)).is_file():
            return robots / Path(*parts)
        # the cmeel sitelib sits three levels below the prefix
        robots = Path(entry).parents[2] / "share" / "example-robot-data" / "robots" if len(Path(entry).parents) > 2 else None
        if robots is not None and (robots / Path(*parts)).is_file():
            return robots / Path(*parts)
    pytest.skip("example-robot-data is not installed (pip install '.[test]')")


ROBOTS = {
    "ur5": ("ur_description", "urdf", "ur5_robot.urdf"),
    "panda": ("panda_description", "urdf", "panda.urdf"),
}


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_real_robots_match_pinocchio(robot):
    path = _robot_file(*ROBOTS[robot])
    mech = mechbal.Mechanism.from_urdf(path)
    pm = pin.buildModelFromUrdf(str(path))
    rng = np.random.default_rng(zlib.crc32(robot.encode()))
    worst = compare_with_pinocchio(mech, pm, rng, count=10, q_scale=3.0)
    assert worst < RTOL
    if robot == "ur5":
        assert mech.dof == 6
        assert mech.joint_names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                    "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    else:
        # the second finger follows the first through <mimic>: 7 arm joints + 1 finger coordinate
        assert mech.dof == 8
        assert mech.joint_names == [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
        finger2 = next(j for j in mech.model.description.joints if j.name == "panda_finger_joint2")
        assert (finger2.mimic_joint, finger2.mimic_ratio, finger2.mimic_offset) == ("panda_finger_joint1", 1.0, 0.0)
    # limits come from the file
    assert np.all(np.isfinite(mech.model.lower_limits)) and np.all(mech.model.effort_limits > 0)


def test_panda_matches_pinocchio_with_its_mimic_joints():
    """Where this Pinocchio has mimic joints, the coupled models agree directly (same q)."""
    path = _robot_file(*ROBOTS["panda"])
    try:
        pm = pin.buildModelFromUrdf(str(path), mimic=True)
    except TypeError:  # pragma: no cover - Pinocchio without mimic support
        pytest.skip("this Pinocchio has no mimic joints")
    mech = mechbal.Mechanism.from_urdf(path)
    if pm.nv != mech.dof:  # pragma: no cover
        pytest.skip("this Pinocchio keeps mimic joints in v")
    pd = pm.createData()
    idx = [pm.idx_vs[pm.getJointId(n)] for n in mech.joint_names]
    rng = np.random.default_rng(37)
    for _ in range(5):
        q, v, a = rng.uniform(-2, 2, mech.dof), rng.normal(size=mech.dof), rng.normal(size=mech.dof)
        qp, vp, ap = np.zeros(pm.nq), np.zeros(pm.nv), np.zeros(pm.nv)
        qp[idx], vp[idx], ap[idx] = q, v, a
        assert _rel(mech.inverse_dynamics(q, v, a), pin.rnea(pm, pd, qp, vp, ap)[idx]) < RTOL
        M = pin.crba(pm, pd, qp)
        M = (np.triu(M) + np.triu(M, 1).T)[np.ix_(idx, idx)]
        assert _rel(mech.mass_matrix(q), M) < RTOL


# ---- errors --------------------------------------------------------------------------------------

_GOOD = """<robot name="two">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <link name="hand"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="20" velocity="3"/></joint>
  <joint name="elbow" type="revolute"><parent link="arm"/><child link="hand"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
</robot>"""


def _error(tmp_path, text):
    """The error of the strict reading (the lenient one repairs some of these with a warning:
    tests/python/test_urdf_robots.py)."""
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        mechbal.Mechanism.from_urdf(path, strict=True)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"URDF file '{path}': "), message
    return message


def test_good_file_loads(tmp_path):
    path = tmp_path / "two.urdf"
    path.write_text(_GOOD)
    mech = mechbal.Mechanism.from_urdf(path)
    assert mech.name == "two" and mech.dof == 2 and mech.body_names == ["arm", "hand"]
    assert mech.frame_names == ["base", "arm", "hand"]
    assert mechbal.Mechanism.from_urdf_string(_GOOD).dof == 2


def test_unknown_parent_link_names_it(tmp_path):
    m = _error(tmp_path, _GOOD.replace('<parent link="arm"/>', '<parent link="amr"/>'))
    assert "parent link [amr] of joint [elbow] not found" in m


def test_floating_joint_is_refused(tmp_path):
    m = _error(tmp_path, _GOOD.replace('type="revolute"><parent link="arm"/>',
                                       'type="floating"><parent link="arm"/>'))
    assert "URDF joint 'elbow': type floating is not supported" in m


def test_planar_joint_is_refused(tmp_path):
    m = _error(tmp_path, _GOOD.replace('type="revolute"><parent link="arm"/>',
                                       'type="planar"><parent link="arm"/>'))
    assert "URDF joint 'elbow': type planar is not supported" in m


@pytest.mark.parametrize("old,new,expected", [
    ('<mass value="0.5"/>', '<mass value="-0.5"/>', "URDF link 'hand' inertial.mass must be a finite number >= 0, got -0.5"),
    ('ixx="0.001"', 'ixx="0.01"', "URDF link 'hand' inertial.inertia violates the triangle inequality"),
    ('ixx="0.01"', 'ixx="-0.01"', "URDF link 'arm' inertial.inertia must be positive semi-definite"),
])
def test_bad_inertia_names_the_link_and_value(tmp_path, old, new, expected):
    assert expected in _error(tmp_path, _GOOD.replace(old, new))


def test_unknown_mimic_joint_names_it(tmp_path):
    m = _error(tmp_path, _GOOD.replace('velocity="3"/></joint>\n</robot>',
                                       'velocity="3"/><mimic joint="sholder"/></joint>\n</robot>'))
    assert "URDF joint 'elbow': mimic joint 'sholder' does not exist" in m


def test_missing_file_names_it(tmp_path):
    path = tmp_path / "nothere.urdf"
    with pytest.raises(ConfigError, match=r"^URDF file '.*nothere\.urdf': not found$"):
        mechbal.Mechanism.from_urdf(path)
    with pytest.raises(ValueError, match=r"nothere\.urdf': cannot be read"):
        _core.mechanism_from_urdf(str(path))


def test_malformed_document_from_a_string():
    with pytest.raises(ConfigError, match=r"^URDF: "):
        mechbal.Mechanism.from_urdf_string("<robot name='x'><link name='a'></robot>")
    with pytest.raises(ConfigError, match=r"^URDF joint 'elbow': type floating"):
        mechbal.Mechanism.from_urdf_string(_GOOD.replace('type="revolute"><parent link="arm"/>',
                                                         'type="floating"><parent link="arm"/>'))


# ---- the command line ----------------------------------------------------------------------------

def test_run_a_urdf_file_writes_the_usual_outputs(tmp_path, capsys):
    import json

    from mechbal.cli import main
    from mechbal.export import read_bodies, shaking_wrench_by_finite_differences

    path = _robot_file(*ROBOTS["ur5"])
    out = tmp_path / "ur5"
    assert main(["run", str(path), "--out", str(out), "--samples", "201", "--duration", "1.5"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["kind"] == "urdf" and summary["dof"] == 6 and summary["samples"] == 201
    assert summary["duration"] == 1.5
    assert np.allclose(summary["end"], 0.5)  # UR5 joints have +-2 pi: 0.5 rad each
    for name in summary["files"]:
        assert (out / name).stat().st_size > 1000
    data = read_bodies(out / "bodies_nominal.npz")
    assert list(data["names"]) == summary["body_names"]
    assert data["com"].shape == (201, len(summary["body_names"]), 3)
    F, M = data["shaking_force"], data["shaking_moment"]
    assert np.allclose(summary["peak_shaking_force"]["nominal"], np.abs(F).max(axis=0))
    # what the file claims: the wrench of the poses saved beside it
    F_fd, M_fd = shaking_wrench_by_finite_differences(data)
    inner = slice(3, -3)
    assert np.abs(F_fd[inner] - F[inner]).max() < 1e-3 * np.abs(F).max()
    assert np.abs(M_fd[inner] - M[inner]).max() < 1e-3 * np.abs(M).max()
    # the torques are the inverse dynamics of the exported motion
    mech = mechbal.Mechanism.from_urdf(path)
    assert _rel(data["torque"], mech.inverse_dynamics(data["q"], data["qd"], data["qdd"])) < 1e-12


def test_run_default_trajectory_respects_the_limits(tmp_path):
    from mechbal.cases import run_case
    from mechbal.trajectory import default_motion

    mech = mechbal.Mechanism.from_urdf(_robot_file(*ROBOTS["panda"]))
    start, end = default_motion(mech)
    lo, hi = mech.model.lower_limits, mech.model.upper_limits
    assert np.all(lo <= start) and np.all(start <= hi) and np.all(lo <= end) and np.all(end <= hi)
    assert np.all(np.abs(end - start) > 0.01)
    path = tmp_path / "two.urdf"
    path.write_text(_GOOD)
    summary = run_case(path, tmp_path / "out")
    assert summary["samples"] == 501 and summary["duration"] == 2.0


def test_run_flags_are_for_urdf_files_only(tmp_path, capsys):
    from mechbal.cli import main

    assert main(["run", "arm2link", "--out", str(tmp_path), "--samples", "11"]) == 2
    assert "--samples: only applies to URDF files" in capsys.readouterr().err
    path = tmp_path / "two.urdf"
    path.write_text(_GOOD)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--samples", "2"]) == 2
    assert "trajectory.samples (--samples)" in capsys.readouterr().err
