"""`mechbal balance CASE --method M --out DIR` (issue 11): the built-in cases' regression numbers in
summary.json, the exported poses' shaking force, the balanced mechanism written back as TOML (runs
with `mechbal run`) and URDF (Pinocchio's gravity of it is ~0), one-line errors."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mechbal.export.common import rpy_of
from mechbal.export.toml import toml_text
from mechbal.export.urdf import urdf_text
from mechbal.cli import main
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences
from mechbal.mechanism import Mechanism
from mechbal.spec import mechanism_spec, rotation_rpy

from cli_checks import one_line_error, summary_of




@pytest.fixture(scope="module")
def arm2dof_rms(tmp_path_factory):
    out = tmp_path_factory.mktemp("balance") / "arm2dof"
    assert main(["balance", "arm2dof", "--method", "rms", "--out", str(out), "-q"]) == 0
    return out


def test_arm2dof_rms_reproduces_the_radii(arm2dof_rms):
    s = summary_of(arm2dof_rms)
    d = s["balance"]["design"]
    assert d["counterweight1"]["signed_distance"] == pytest.approx(0.2509, abs=5e-5)
    assert d["counterweight2"]["signed_distance"] == pytest.approx(0.1913, abs=5e-5)
    assert d["counterweight1"]["position"] == pytest.approx([-0.25091, 0, 0], abs=1e-5)
    assert s["balance"]["exact"] and s["method"] == "rms"
    assert sorted(s["files"] + ["summary.json"]) == sorted(p.name for p in arm2dof_rms.iterdir())
    # the balanced arm written back as a mechanism case runs
    text = (arm2dof_rms / "balanced.toml").read_text()
    assert tomllib.loads(text)["case"]["kind"] == "mechanism"
    assert main(["run", str(arm2dof_rms / "balanced.toml"), "--out", str(arm2dof_rms.parent / "rerun"), "-q"]) == 0


def test_four_bar_force_balance_from_exported_poses(tmp_path):
    """The built-in four-bar's [balance]: complete force balance; the shaking force of the
    exported balanced poses (finite differences) against the unbalanced peak."""
    out = tmp_path / "fb"
    assert main(["balance", "four-bar", "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    assert s["method"] == "force" and s["balance"]["exact"]
    assert "balanced.urdf" not in s["files"]          # a closed mechanism: TOML only
    ub, b = read_bodies(out / "bodies_unbalanced.npz"), read_bodies(out / "bodies_balanced.npz")
    peak = np.max(np.abs(ub["shaking_force"]))
    assert np.max(np.abs(b["shaking_force"])) < 1e-9 * peak            # analytic, of those poses
    F_fd, _ = shaking_wrench_by_finite_differences(b)
    F_fd_ub, _ = shaking_wrench_by_finite_differences(ub)
    assert np.max(np.abs(F_fd[2:-2])) < 1e-6 * peak      # central differences of the exported poses
    assert np.max(np.abs(F_fd_ub[2:-2] - ub["shaking_force"][2:-2])) < 1e-3 * peak     # FD resolves it
    assert s["before_after"]["shaking_force"]["balanced"]["peak"] == pytest.approx(
        np.max(np.abs(b["shaking_force"]), axis=0).tolist(), abs=1e-15)
    assert main(["run", str(out / "balanced.toml"), "--out", str(tmp_path / "rerun"), "-q"]) == 0
    assert summary_of(tmp_path / "rerun")["peak_shaking_force"]["nominal"] == pytest.approx([0, 0, 0], abs=1e-9)


def random_arm_table(seed: int) -> dict:
    """A spatial 4R arm with random placements and axes (and rpy), for the URDF round trip."""
    rng = np.random.default_rng(seed)
    joints = []
    for i in range(4):
        joints.append({"name": f"j{i + 1}", "origin": {"xyz": rng.uniform(-0.3, 0.3, 3).tolist(),
                                                        "rpy": rng.uniform(-1.5, 1.5, 3).tolist()},
                       "axis": rng.normal(size=3).tolist(),
                       "link": {"mass": float(rng.uniform(0.5, 3.0)), "com": rng.uniform(-0.2, 0.2, 3).tolist(),
                                "inertia": [0.02, 0.03, 0.04]}})
    return {"gravity": [0.0, 0.0, -9.81], "joints": joints}


def pin_gravity(urdf: Path, mech, q: np.ndarray) -> np.ndarray:
    """Pinocchio's generalized gravity at mechbal's coordinates q (N, dof), in mechbal's order
    (continuous joints are (cos, sin) in Pinocchio)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(urdf))
    model.gravity.linear = mech.gravity
    data = model.createData()
    out = np.zeros_like(q)
    order = [model.getJointId(n) for n in mech.joint_names]
    for k in range(len(q)):
        qp = pin.neutral(model)
        for i, jid in enumerate(order):
            j = model.joints[jid]
            if j.nq == 2:
                qp[j.idx_q:j.idx_q + 2] = [math.cos(q[k, i]), math.sin(q[k, i])]
            else:
                qp[j.idx_q] = q[k, i]
        g = pin.computeGeneralizedGravity(model, data, qp)
        out[k] = [g[model.joints[jid].idx_v] for jid in order]
    return out


def test_static_balance_urdf_checked_by_pinocchio(tmp_path):
    """A random spatial arm balanced statically (a counterweight within a radius on each link:
    exact); the balanced URDF read by Pinocchio has gravity torque below 1e-9 N m over 1000
    random poses, while the unbalanced one does not."""
    table = random_arm_table(3)
    case = {"case": {"name": "random-arm", "kind": "mechanism"}, "mechanism": table,
            "trajectory": {"start": [0.0] * 4, "end": [0.5] * 4, "duration": 1.0, "samples": 51},
            "balance": {"method": "static", "samples": 300,
                        "counterweights": [{"name": f"cw{i + 1}", "link": f"j{i + 1}", "max_radius": 0.4}
                                           for i in range(4)]}}
    path = tmp_path / "arm.toml"
    path.write_text(toml_text(case))
    out = tmp_path / "out"
    assert main(["balance", str(path), "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    assert s["balance"]["exact"], s["balance"]["limited_by"]
    mech = Mechanism.from_toml(out / "balanced.toml")
    q = np.random.default_rng(9).uniform(-math.pi, math.pi, (1000, 4))
    assert np.max(np.abs(mech.gravity_torque(q))) < 1e-9
    G = pin_gravity(out / "balanced.urdf", mech, q)
    assert np.max(np.abs(G)) < 1e-9
    unbalanced = Mechanism.from_spec(mechanism_spec(table))
    (tmp_path / "unbalanced.urdf").write_text(urdf_text(unbalanced))
    G0 = pin_gravity(tmp_path / "unbalanced.urdf", unbalanced, q[:50])
    assert np.max(np.abs(G0 - unbalanced.gravity_torque(q[:50]))) < 1e-9 * np.max(np.abs(G0))
    assert np.max(np.abs(G0)) > 1.0


def test_ur5_dh_static_case(tmp_path):
    """The UR5-like arm (UR's DH table): counterweights on links 2-3 cannot hold the wrist, so
    the balance is a least squares: its residual is the recomputed one, said so in limited_by;
    positions are in the DH frames (beyond the shoulder and elbow axes)."""
    out = tmp_path / "ur5"
    assert main(["balance", "ur5-dh", "--out", str(out), "-q"]) == 5      # not reached: exit 5, results written
    s = summary_of(out)
    b = s["balance"]
    assert not b["exact"] and b["limited_by"][0].startswith("impossible")
    assert b["design"]["upper_arm_counterweight"]["position"][0] > 0.425
    assert b["design"]["forearm_counterweight"]["position"][0] > 0.39225
    ba = s["before_after"]["gravity_torque"]
    assert ba["balanced"]["peak"][1] < 0.1 * ba["unbalanced"]["peak"][1]
    assert ba["balanced"]["peak"][2] < 0.15 * ba["unbalanced"]["peak"][2]


def test_rpy_round_trip():
    rng = np.random.default_rng(1)
    for rpy in [rng.uniform(-3, 3, 3) for _ in range(50)] + [np.array([0.3, math.pi / 2, -0.2])]:
        R = rotation_rpy(rpy)
        assert np.allclose(rotation_rpy(rpy_of(R)), R, atol=1e-12)


def test_toml_text_round_trips():
    data = {"case": {"name": "x \"y\"", "kind": "mechanism"}, "mechanism": {
        "gravity": [0.0, 0.0, -9.81], "base": {"xyz": [0.1, 0.2, 0.3]},
        "joints": [{"name": "a", "origin": {"xyz": [1e-17, 0.1, 2.0]}, "limits": {"lower": -1.0}}]}}
    assert tomllib.loads(toml_text(data, "a header\nline two")) == data


def test_balance_errors_are_one_line(capsys, tmp_path):
    out = str(tmp_path / "o")
    # moment reads its own design keys through design_from_table(table, mechanism)
    assert main(["balance", "arm2link", "--method", "moment", "--out", out]) == 2
    one_line_error(capsys, "balance.discs", "no disc or inertia slots")
    assert main(["balance", "paminsa", "--method", "moment", "--out", out]) == 2
    one_line_error(capsys, "balance.discs")
    assert main(["balance", "discs-3r", "--method", "static", "--out", out]) == 2
    one_line_error(capsys, "balance.counterweights", "no counterweight slots")
    bad = tmp_path / "bad.toml"
    text = (Path(__file__).parents[2] / "python/mechbal/cases/arm2link.toml").read_text()
    bad.write_text(text.replace('link = "elbow"\nmax_radius', 'link = "elbo"\nmax_radius'))
    assert main(["balance", str(bad), "--out", out]) == 2
    one_line_error(capsys, "balance.counterweights[1].link", "did you mean 'elbow'")
    bad.write_text(text.replace("max_radius = 0.25", "max_radus = 0.25"))
    assert main(["balance", str(bad), "--out", out]) == 2
    one_line_error(capsys, "balance.counterweights[0].max_radus: unknown key (did you mean 'max_radius'?)")
    bad.write_text(text.replace('method = "static"', ""))
    assert main(["balance", str(bad), "--out", out]) == 2
    one_line_error(capsys, "--method")
    assert main(["balance", str(tmp_path / "robot.urdf"), "--out", out]) == 2
    one_line_error(capsys)
    assert not (tmp_path / "o").exists()


def test_ur5_urdf_with_a_design_file(tmp_path):
    """The README example: UR5 (example-robot-data) with docs/examples/ur5_balance.toml; slots
    named by URDF link (positions in those frames); Pinocchio's gravity of the written URDF is
    mechbal's; the residual is the least squares' (the wrist cannot be held)."""
    from test_urdf import ROBOTS, _robot_file

    urdf = _robot_file(*ROBOTS["ur5"])
    design = Path(__file__).parents[2] / "docs" / "examples" / "ur5_balance.toml"
    out = tmp_path / "ur5"
    assert main(["balance", str(urdf), "--design", str(design), "--out", str(out), "-q"]) == 5   # the wrist cannot be held: exit 5
    b = summary_of(out)["balance"]
    assert b["design"]["upper_arm_counterweight"]["position"] == pytest.approx([0, 0, -0.25], abs=1e-9)
    assert b["design"]["upper_arm_counterweight"]["frame"].startswith("frame 'upper_arm_link'")
    assert b["residual"] == pytest.approx(b["metrics"]["least_squares_residual"], rel=1e-6)
    assert b["residual"] < 0.01 * b["residual_before"]
    mech = Mechanism.from_urdf(out / "balanced.urdf")
    q = np.random.default_rng(2).uniform(-math.pi, math.pi, (200, mech.dof))
    G = pin_gravity(out / "balanced.urdf", mech, q)
    assert np.max(np.abs(G - mech.gravity_torque(q))) < 1e-9


def test_ur5_urdf_balanced_by_springs(tmp_path):
    """The README example: UR5 (example-robot-data) with docs/examples/ur5_springs.toml through
    the CLI: three zero-free-length springs behind blocks and tackles, anchors in the URDF link
    frames; the residual is wrist 3's off-axis mass (without it the same slots balance the arm
    exactly: static torque 1e-9 N m, potential energy constant to 1e-9 J); balanced.toml carries
    the springs and reproduces the balanced static torque; catalogue clusters per spring."""
    from test_urdf import ROBOTS, _robot_file

    from mechbal import _core
    from mechbal.balance import springs as sp
    from mechbal.balance.run import balance_case

    urdf = _robot_file(*ROBOTS["ur5"])
    design = Path(__file__).parents[2] / "docs" / "examples" / "ur5_springs.toml"
    out = tmp_path / "ur5"
    assert main(["balance", str(urdf), "--design", str(design), "--method", "springs", "--out", str(out), "-q"]) == 5   # exit 5: a residual
    summary = summary_of(out)
    b = summary["balance"]
    assert b["method"] == "springs" and b["rank"] == 3 and b["unknowns"] == 3
    assert set(b["design"]) == {"upper_arm_spring", "forearm_spring", "elbow_spring"}
    assert b["design"]["forearm_spring"]["pulley_ratio"] == 4.0
    # the published numbers (README): peak static torque over the 2000 poses, before and after
    before, after = b["metrics"]["static_torque_before"], b["metrics"]["static_torque_after"]
    assert before["shoulder_lift_joint"]["peak"] == pytest.approx(59.31, abs=0.01)
    assert before["elbow_joint"]["peak"] == pytest.approx(15.86, abs=0.01)
    for j in ("shoulder_lift_joint", "elbow_joint"):
        assert after[j]["peak"] == pytest.approx(0.18, abs=0.005)
    assert b["residual"] == pytest.approx(0.1797, abs=1e-3) and not b["exact"]
    assert any(m.startswith("impossible") for m in b["limited_by"])
    g = summary["before_after"]["gravity_torque"]
    assert g["unbalanced"]["peak"][1] == pytest.approx(44.42, abs=0.01)
    assert max(g["balanced"]["peak"][1:3]) < 0.18
    assert all(b["metrics"]["catalogue"]["springs"][n] for n in b["design"])
    assert not (out / "balanced.urdf").exists() and "no balanced.urdf" in summary["urdf"]
    # balanced.toml: the arm with its springs, holding the arm as the balanced mechanism does
    balanced = Mechanism.from_toml(out / "balanced.toml")
    assert sorted(balanced.spring_names) == sorted(b["design"])
    q = np.random.default_rng(4).uniform(-math.pi, math.pi, (300, balanced.dof))
    assert np.max(np.abs(balanced.static_torque(q)[:, 1:3])) < 0.2
    # the residual is wrist 3's centre of mass, 0.095 m off the wrist-1 axis: without it, exact
    bc = balance_case(str(urdf), str(design))
    bodies = [x if x.name != "wrist_3_link" else _core.Body(x.name, x.link, 0.0, np.asarray(x.com),
                                                             np.asarray(x.inertia), x.kind)
              for x in bc.mechanism.model.description.bodies]
    light = bc.mechanism.with_bodies(bodies, replace=True)
    slots, samples, _ = sp.design_from_table(bc.table, light)
    r = sp.balance(light, slots, samples)
    assert r.exact and r.residual < 1e-9 and r.metrics["potential_energy_variation_after"] < 1e-9
    assert np.max(np.abs(r.balanced.static_torque(q))) < 1e-9
