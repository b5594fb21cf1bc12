"""The general mechanism format -> MechanismSpec: trees, extra bodies, gear couplings, frames,
spherical joints, DH frames; cross-reference errors; serial specs on the general model and KDL."""
import copy
import math

import numpy as np
import pytest

import mechbal
from mechbal.config import ConfigError, read_case
from mechbal.spec import dh_origin, mechanism_spec, rotation_rpy, transform_xyz_rpy


def chain_from_config(table):
    """The general model of a ``[mechanism]`` table."""
    return mechbal.Mechanism.from_spec(mechanism_spec(table, "mechanism"))

INERTIA = [0.01, 0.02, 0.025]


def link(mass=1.0, com=(0.0, 0.0, 0.0)):
    return {"mass": mass, "com": list(com), "inertia": list(INERTIA)}


def motion(j, q):
    T = np.eye(4)
    if j.type == "revolute":
        a = j.axis
        K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
        T[:3, :3] = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K
    elif j.type == "prismatic":
        T[:3, 3] = q * j.axis
    return T


def forward_kinematics(spec, q):
    """Link frames in O from the spec alone (independent joints' values in ``q``)."""
    values = dict(zip(spec.independent_joints, q))
    for j in spec.joints:
        if j.mimic is not None:
            master, ratio, offset = j.mimic
            values[j.name] = ratio * values[master] + offset
    frames = {}
    for j in spec.joints:
        parent = np.eye(4) if j.parent == "base" else frames[j.parent]
        frames[j.name] = parent @ j.placement @ motion(j, values.get(j.name, 0.0))
    return frames


def test_two_branch_tree_with_bodies_frames_and_a_gear():
    spec = mechanism_spec({
        "gravity": [0.0, -9.81, 0.0],
        "base": {"xyz": [0.0, 0.0, 0.5]},
        "joints": [
            {"name": "hip", "axis": [0, 0, 2], "link": link(3.0, (0.1, 0, 0)),
             "limits": {"lower": -1.0, "upper": 2.0, "effort": 50.0}},
            {"name": "left", "origin": {"xyz": [0.2, 0.1, 0]}, "link": link()},
            {"name": "right", "parent": "hip", "origin": {"xyz": [0.2, -0.1, 0]}, "type": "prismatic",
             "axis": [1, 0, 0], "link": link()},
            {"name": "disc", "parent": "hip", "mimic": {"joint": "left", "ratio": -2.0, "offset": 0.1}},
        ],
        "bodies": [{"name": "cw", "kind": "counterweight", "link": "hip", "mass": 2.0,
                    "com": [-0.1, 0, 0], "inertia": [0.001, 0.001, 0.001]}],
        "frames": [{"name": "tool", "link": "left", "origin": {"xyz": [0.3, 0, 0]}}],
    })
    assert [j.name for j in spec.joints] == ["hip", "left", "right", "disc"]
    assert [j.parent for j in spec.joints] == ["base", "hip", "hip", "hip"]
    assert spec.independent_joints == ["hip", "left", "right"] and spec.dof == 3
    hip = spec.joint("hip")
    np.testing.assert_allclose(hip.placement, transform_xyz_rpy([0, 0, 0.5]))  # base applied to roots
    np.testing.assert_allclose(hip.axis, [0, 0, 1])
    assert (hip.lower, hip.upper, hip.effort, hip.velocity) == (-1.0, 2.0, 50.0, math.inf)
    np.testing.assert_allclose(spec.joint("right").placement, transform_xyz_rpy([0.2, -0.1, 0]))
    assert spec.joint("disc").mimic == ("left", -2.0, 0.1)
    np.testing.assert_allclose(spec.gravity, [0, -9.81, 0])
    assert [(b.name, b.kind, b.link) for b in spec.bodies] == [
        ("hip", "link", "hip"), ("left", "link", "left"), ("right", "link", "right"),
        ("cw", "counterweight", "hip")]
    np.testing.assert_allclose(spec.bodies[3].inertia, np.eye(3) * 0.001)
    assert spec.frames[0].link == "left"
    F = forward_kinematics(spec, [0.3, -0.4, 0.05])
    tool = F["left"] @ spec.frames[0].placement
    c, s = math.cos(0.3), math.sin(0.3)
    elbow = np.array([0.2 * c - 0.1 * s, 0.2 * s + 0.1 * c, 0.5])
    np.testing.assert_allclose(tool[:3, 3], elbow + 0.3 * np.array([math.cos(-0.1), math.sin(-0.1), 0]),
                               atol=1e-12)
    # KDL (the independent engine) takes serial chains only and names the branch
    with pytest.raises(ValueError, match=r"hangs from 'hip'.*tree with branches"):
        mechbal.KdlChainDynamics(mechbal.Mechanism.from_spec(spec).model)


def test_dh_carry_with_a_body_and_a_frame_on_the_dh_link():
    """Standard DH: link i's frame is Rz(theta + q) Tz(d) Tx(a) Rx(alpha) after the previous one;
    what the user puts on a dh link (com, inertia, frames, children) is in that frame."""
    p1 = dict(a=0.4, alpha=math.pi / 2, d=0.1, theta=0.2)
    p2 = dict(a=0.3, alpha=-0.3, d=0.05, theta=-0.1)
    com = np.array([-0.2, 0.01, 0.03])
    inertia = np.array([[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]])
    spec = mechanism_spec({"joints": [
        {"name": "j1", "dh": p1, "link": {"mass": 2.0, "com": com.tolist(), "inertia": inertia.tolist()}},
        {"name": "j2", "dh": p2, "link": link()},
    ], "bodies": [{"name": "motor2", "kind": "motor", "link": "j1", "mass": 0.5, "com": [0.0, 0.0, 0.02],
                   "inertia": [1e-4, 1e-4, 1e-4], "rpy": [0.0, 0.3, 0.0]}],
        "frames": [{"name": "flange", "link": "j2", "origin": {"xyz": [0.0, 0.0, 0.01]}}]})

    def dh(p, q):
        O, X = dh_origin(p["a"], p["alpha"], p["d"], p["theta"] + q, modified=False)
        return O @ X

    q = [0.7, -1.1]
    F = forward_kinematics(spec, q)
    A1 = dh(p1, q[0])
    A2 = A1 @ dh(p2, q[1])
    b1 = spec.bodies[0]
    np.testing.assert_allclose(F["j1"][:3, :3] @ b1.com + F["j1"][:3, 3], A1[:3, :3] @ com + A1[:3, 3], atol=1e-12)
    np.testing.assert_allclose(F["j1"][:3, :3] @ b1.inertia @ F["j1"][:3, :3].T,
                               A1[:3, :3] @ inertia @ A1[:3, :3].T, atol=1e-12)
    motor = next(b for b in spec.bodies if b.name == "motor2")
    R = A1[:3, :3] @ rotation_rpy([0.0, 0.3, 0.0])
    np.testing.assert_allclose(F["j1"][:3, :3] @ motor.inertia @ F["j1"][:3, :3].T,
                               R @ np.eye(3) * 1e-4 @ R.T, atol=1e-15)
    np.testing.assert_allclose(F["j1"][:3, :3] @ motor.com + F["j1"][:3, 3], A1[:3, :3] @ [0, 0, 0.02] + A1[:3, 3],
                               atol=1e-12)
    flange = F["j2"] @ spec.frames[0].placement
    np.testing.assert_allclose(flange, A2 @ transform_xyz_rpy([0, 0, 0.01]), atol=1e-12)
    # and the general model built from it agrees
    kin = chain_from_config({"joints": [
        {"name": "j1", "dh": p1, "link": {"mass": 2.0, "com": com.tolist(), "inertia": inertia.tolist()}},
        {"name": "j2", "dh": p2, "link": link()}]}).body_motion(np.array([q]), np.zeros((1, 2)), np.zeros((1, 2)))
    np.testing.assert_allclose(kin.com[0, 0], A1[:3, :3] @ com + A1[:3, 3], atol=1e-12)


def test_spherical_joint_expands_into_three_revolutes():
    spec = mechanism_spec({"joints": [
        {"name": "arm", "axis": [0, 1, 0], "link": link(2.0, (0.25, 0, 0))},
        {"name": "wrist", "type": "spherical", "origin": {"xyz": [0.5, 0, 0]}, "link": link(1.0, (0.05, 0, 0))},
        {"name": "tool", "type": "fixed", "origin": {"xyz": [0.1, 0, 0]}, "link": link(0.2)},
    ], "bodies": [{"name": "camera", "link": "wrist", "mass": 0.1, "inertia": [0, 0, 0]}],
        "frames": [{"name": "tcp", "link": "wrist"}]})
    assert [(j.name, j.type, j.parent) for j in spec.joints] == [
        ("arm", "revolute", "base"), ("wrist_z", "revolute", "arm"), ("wrist_y", "revolute", "wrist_z"),
        ("wrist_x", "revolute", "wrist_y"), ("tool", "fixed", "wrist_x")]
    for name, axis in (("wrist_z", [0, 0, 1]), ("wrist_y", [0, 1, 0]), ("wrist_x", [1, 0, 0])):
        np.testing.assert_allclose(spec.joint(name).axis, axis)
    np.testing.assert_allclose(spec.joint("wrist_z").placement, transform_xyz_rpy([0.5, 0, 0]))
    np.testing.assert_allclose(spec.joint("wrist_y").placement, np.eye(4))
    assert {b.name: b.link for b in spec.bodies} == {"arm": "arm", "wrist": "wrist_x", "tool": "tool",
                                                     "camera": "wrist_x"}
    assert spec.bodies_on("wrist_z") == [] and spec.bodies_on("wrist_y") == []
    assert spec.frames[0].link == "wrist_x"
    assert spec.independent_joints == ["arm", "wrist_z", "wrist_y", "wrist_x"]
    F = forward_kinematics(spec, [0.2, 0.3, -0.4, 0.5])
    R = F["arm"][:3, :3] @ rotation_rpy([0.5, -0.4, 0.3])  # Rz(a) Ry(b) Rx(c) = rpy (c, b, a)
    np.testing.assert_allclose(F["wrist_x"][:3, :3], R, atol=1e-12)
    # a serial chain with a fixed joint: the general model carries the tool on the wrist's last
    # link; the bodies that move with wrist_x (wrist, tool, camera) have their centre of mass there
    mech = mechbal.Mechanism.from_spec(spec)
    assert mech.dof == 4
    kin = mech.body_motion(np.array([[0.2, 0.3, -0.4, 0.5]]), np.zeros((1, 4)), np.zeros((1, 4)))
    Fx = F["wrist_x"]
    parts = [(1.0, Fx[:3, :3] @ [0.05, 0, 0] + Fx[:3, 3]), (0.2, (Fx @ transform_xyz_rpy([0.1, 0, 0]))[:3, 3]),
             (0.1, Fx[:3, 3])]
    com = sum(m * c for m, c in parts) / sum(m for m, _ in parts)
    names = mech.body_names
    on_wrist = [names.index(b) for b in ("wrist", "tool", "camera")]
    masses = np.array([b.mass for b in mech.bodies])
    np.testing.assert_allclose(masses[on_wrist] @ kin.com[0, on_wrist] / masses[on_wrist].sum(), com, atol=1e-12)
    np.testing.assert_allclose(masses[on_wrist].sum(), 1.3)
    np.testing.assert_allclose(masses[names.index("arm")], 2.0)


def test_merged_bodies_give_the_same_dynamics_as_one_body():
    """A counterweight on a link (extra body) = the link's own inertia merged by hand."""
    cfg = read_case("arm2link")["mechanism"]
    extra = copy.deepcopy(cfg)
    extra["bodies"] = [{"name": "cw", "kind": "counterweight", "link": "shoulder", "mass": 3.0,
                        "com": [-0.2, 0.0, 0.0], "inertia": [0.0, 0.0, 0.0]}]
    merged = copy.deepcopy(cfg)
    m1, c1 = 4.0, np.array([0.25, 0, 0])
    m, c = 7.0, (4.0 * c1 + 3.0 * np.array([-0.2, 0, 0])) / 7.0
    I = np.diag([0.004, 0.09, 0.09])
    for mi, ci in ((m1, c1), (3.0, np.array([-0.2, 0, 0]))):
        d = ci - c
        I = I + mi * (d @ d * np.eye(3) - np.outer(d, d))
    merged["joints"][0]["link"] = {"mass": m, "com": c.tolist(), "inertia": I.tolist()}
    q = np.array([[0.3, -0.5], [1.0, 0.2]])
    qd, qdd = np.ones_like(q), -np.ones_like(q)
    tau = [mechbal.KdlChainDynamics(chain_from_config(x).model).inverse_dynamics(q, qd, qdd).joint_torque
           for x in (extra, merged)]
    np.testing.assert_allclose(tau[0], tau[1], rtol=1e-12, atol=1e-12)


def test_mimic_and_cross_reference_errors_name_the_field():
    def joints(*js, **extra):
        return dict({"joints": list(js)}, **extra)

    a = {"name": "shoulder", "link": link()}
    cases = [
        (joints(a, {"name": "elbow", "parent": "shouldr"}),
         "mechanism.joints[1].parent: unknown parent joint (did you mean 'shoulder'?) (got 'shouldr')"),
        (joints(a, {"name": "shoulder"}), "mechanism.joints[1].name: duplicate name"),
        (joints(a, {"name": "base"}), "mechanism.joints[1].name: 'base' is the name of the fixed base"),
        (joints({"name": "a", "parent": "b"}, {"name": "b", "parent": "a"}),
         "mechanism.joints[0].parent: joints form a cycle: a -> b -> a (got 'b')"),
        (joints({"name": "a", "parent": "a"}), "mechanism.joints[0].parent: a joint cannot be its own parent"),
        (joints(a, {"name": "f", "type": "fixed"}, {"name": "g", "mimic": {"joint": "f"}}),
         "mechanism.joints[2].mimic.joint: mimics a fixed joint"),
        (joints(a, {"name": "g", "mimic": {"joint": "g"}}), "mechanism.joints[1].mimic.joint: a joint cannot mimic itself"),
        (joints(a, {"name": "g", "mimic": {"joint": "shoulder"}}, {"name": "h", "mimic": {"joint": "g"}}),
         "mechanism.joints[2].mimic.joint: mimics 'g', itself a mimic of 'shoulder'"),
        (joints(a, {"name": "g", "mimic": {"joint": "sholder"}}),
         "mechanism.joints[1].mimic.joint: unknown joint (did you mean 'shoulder'?)"),
        (joints(a, {"name": "w", "type": "spherical"}, {"name": "g", "mimic": {"joint": "w"}}),
         "mechanism.joints[2].mimic.joint: 'w' is a spherical joint: name one of w_z, w_y, w_x"),
        (joints(a, {"name": "w", "type": "spherical"}, {"name": "w_y"}), "mechanism.joints[2].name: duplicate name"),
        (joints(a, {"name": "f", "type": "fixed", "axis": [1, 0, 0]}), "mechanism.joints[1].axis: a fixed joint has no axis"),
        (joints(a, {"name": "g", "limits": {"lower": 1.0, "upper": 0.0}}),
         "mechanism.joints[1].limits.upper: must be >= lower = 1.0 (got 0.0)"),
        (joints(a, bodies=[{"name": "cw", "link": "shouldr", "mass": 1.0, "inertia": [0, 0, 0]}]),
         "mechanism.bodies[0].link: unknown link (did you mean 'shoulder'?)"),
        (joints(a, bodies=[{"name": "shoulder", "link": "base", "mass": 1.0, "inertia": [0, 0, 0]}]),
         "mechanism.bodies[0].name: duplicate body name: 'shoulder' is also mechanism.joints[0].link"),
        (joints(a, bodies=[{"name": "cw", "link": "shoulder", "mass": 1.0, "inertia": [0, 0, 0], "knd": "motor"}]),
         "mechanism.bodies[0].knd: unknown key (did you mean 'kind'?)"),
        (joints(a, frames=[{"name": "tool", "link": "elbow"}]), "mechanism.frames[0].link: unknown link"),
        (joints(a, frames=[{"name": "t", "link": "base"}, {"name": "t", "link": "shoulder"}]),
         "mechanism.frames[1].name: duplicate frame name"),
    ]
    for table, message in cases:
        with pytest.raises(ConfigError) as exc:
            mechanism_spec(table)
        assert str(exc.value).startswith(message), (message, str(exc.value))


def test_the_briefs_message_examples():
    cfg = read_case("arm2link")["mechanism"]
    cfg["joints"].append({"name": "wrist", "origin": {"xyz": [0.4, 0, 0]}, "axis": [0, -1, 0],
                          "link": {"mass": 0.5, "cmo": [0.05, 0, 0], "inertia": [1e-4, 1e-4, 1e-4]}})
    with pytest.raises(ConfigError) as exc:
        mechanism_spec(cfg)
    assert str(exc.value) == "mechanism.joints[2].link.cmo: unknown key (did you mean 'com'?)"
    assert exc.value.field == "mechanism.joints[2].link.cmo"


def test_kind_mechanism_runs_with_the_serial_chain_runner(tmp_path):
    from mechbal.cases import run_case
    from mechbal.config import CASES_DIR

    text = (CASES_DIR / "arm2link.toml").read_text().replace('kind = "serial_chain"', 'kind = "mechanism"')
    text = text.replace("[trajectory]", '[[mechanism.bodies]]\nname = "cw"\nkind = "counterweight"\n'
                                        'link = "shoulder"\nmass = 1.0\ncom = [-0.1, 0.0, 0.0]\n'
                                        'inertia = [0.0, 0.0, 0.0]\n\n[trajectory]').replace("samples = 1001", "samples = 51")
    p = tmp_path / "mech.toml"
    p.write_text(text)
    summary = run_case(p, tmp_path / "out")
    assert summary["kind"] == "mechanism"
    assert summary["total_mass"] == pytest.approx(7.0)
