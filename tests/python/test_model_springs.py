"""Springs as elements of the mechanism model (issue 11): the inverse dynamics with springs
against Pinocchio's rnea with the spring forces as external forces (an independent engine), the
spring joint forces against finite differences of the energy, [[mechanism.springs]] in TOML (DH
frames, strict keys), and `mechbal balance CASE --method springs` end to end: the balanced
mechanism written back with its springs, run by `mechbal run` with static torque ~0."""
from __future__ import annotations

import json
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.cli import main

sys.path.insert(0, str(Path(__file__).parent))
from random_trees import random_tree  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def random_springs(rng, links, n):
    out = []
    for i in range(n):
        a, b = rng.choice(len(links), 2, replace=False)
        out.append(_core.Spring(f"s{i}", links[a], rng.uniform(-0.3, 0.3, 3), links[b], rng.uniform(-0.3, 0.3, 3),
                                float(rng.uniform(50, 900)), float(rng.uniform(0, 0.2)) if i % 2 else 0.0,
                                float(rng.uniform(0, 10)) if i % 2 else 0.0, 1 + i % 3, [1.0, 2.0, 1.7][i % 3]))
    return out


# ---- an independent engine ---------------------------------------------------------------------
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_inverse_dynamics_with_springs_matches_pinocchio_rnea_with_external_forces(seed):
    """tau = ID(q, v, a) + K(q) equals Pinocchio's rnea(q, v, a, fext) with each spring's force
    on its two links as fext (computed here from Pinocchio's own placements), to 1e-9."""
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(seed)
    tree = random_tree(rng, 6, types="RRP")
    mech = tree.mechanism()
    springs = random_springs(rng, mech.link_names, 5)
    mech_s = mech.with_springs(springs)
    pm = pin.buildModelFromXML(tree.urdf())
    pd = pm.createData()
    idx = [pm.joints[pm.getJointId(n)].idx_q for n in mech.joint_names]
    jid = {n: (0 if n == mech.model.root_name else pm.getJointId(n)) for n in mech.link_names}
    for _ in range(5):
        q, v, a = (rng.uniform(-1.5, 1.5, mech.dof) for _ in range(3))
        qp, vp, ap = np.zeros(pm.nq), np.zeros(pm.nv), np.zeros(pm.nv)
        qp[idx], vp[idx], ap[idx] = q, v, a
        pin.forwardKinematics(pm, pd, qp)
        fext = [pin.Force.Zero() for _ in range(pm.njoints)]
        for s in springs:
            ends = []
            for link, anchor in ((s.link_a, s.anchor_a), (s.link_b, s.anchor_b)):
                M = pd.oMi[jid[link]]
                ends.append((jid[link], M.rotation, M.translation + M.rotation @ np.asarray(anchor), np.asarray(anchor)))
            r = ends[1][2] - ends[0][2]
            d = np.linalg.norm(r)
            keq = s.count * s.rate / s.pulley_ratio ** 2
            T = s.count * s.preload / s.pulley_ratio + keq * (d - s.free_length)
            f_a = T * r / d   # the spring pulls A towards B
            for (j, R, _, anchor), f in ((ends[0], f_a), (ends[1], -f_a)):
                if j == 0:
                    continue
                fl = R.T @ f
                fext[j] += pin.Force(fl, np.cross(anchor, fl))
        tau_pin = pin.rnea(pm, pd, qp, vp, ap, fext)[idx]
        tau = mech_s.inverse_dynamics(q, v, a)
        assert np.max(np.abs(tau - tau_pin)) < 1e-9 * max(1.0, np.max(np.abs(tau_pin)))
        # and the springs are what the model adds to the tree without them
        assert np.allclose(tau - mech.inverse_dynamics(q, v, a), mech_s.spring_torque(q), rtol=0, atol=1e-10)


def test_spring_torque_is_the_gradient_of_the_energy_through_the_python_api():
    rng = np.random.default_rng(4)
    mech = random_tree(rng, 7, types="RRPF", mimic=True).mechanism()
    m = mech.with_springs(random_springs(rng, mech.link_names, 6))
    q = rng.uniform(-1.5, 1.5, (30, m.dof))
    K = m.spring_torque(q)
    h = 1e-6
    fd = np.stack([(m.spring_energy(q + h * e) - m.spring_energy(q - h * e)) / (2 * h) for e in np.eye(m.dof)], axis=1)
    assert np.max(np.abs(K - fd)) < 1e-6 * max(1.0, np.max(np.abs(K)))
    # static torque = gradient of the total potential energy; gravity_torque stays gravity alone
    S = m.static_torque(q)
    fdV = np.stack([(m.potential_energy(q + h * e) - m.potential_energy(q - h * e)) / (2 * h) for e in np.eye(m.dof)],
                   axis=1)
    assert np.max(np.abs(S - fdV)) < 1e-6 * max(1.0, np.max(np.abs(S)))
    assert np.allclose(S, m.gravity_torque(q) + K, rtol=0, atol=1e-11)
    assert np.allclose(m.gravity_torque(q), mech.gravity_torque(q), rtol=0, atol=0)
    # one configuration gives the batch row; lengths are anchor distances
    assert np.allclose(m.spring_torque(q[3]), K[3], rtol=0, atol=0)
    assert m.spring_lengths(q).shape == (30, 6) and np.all(m.spring_lengths(q) >= 0)


# ---- TOML --------------------------------------------------------------------------------------
ARM = """#:schema ./mechbal.schema.json
[case]
name = "arm2r-springs"
kind = "mechanism"
title = "2R arm in a vertical plane, zero-free-length springs"

[mechanism]
gravity = [0.0, 0.0, -9.81]

[[mechanism.joints]]
name = "shoulder"
axis = [1.0, 0.0, 0.0]
link = { mass = 3.0, com = [0.0, 0.2, 0.0], inertia = [0.02, 0.002, 0.02] }

[[mechanism.joints]]
name = "elbow"
axis = [1.0, 0.0, 0.0]
origin = { xyz = [0.0, 0.4, 0.0] }
link = { mass = 1.5, com = [0.0, 0.15, 0.0], inertia = [0.01, 0.001, 0.01] }

[trajectory]
start = [0.2, -0.5]
end = [1.4, 0.9]
duration = 1.0
samples = 101

[balance]
samples = 300
seed = 3
{catalogue}
[[balance.springs]]
name = "s1"
link_a = "base"
anchor_a = [0.0, 0.0, 0.2]
link_b = "shoulder"
anchor_b = [0.0, 0.1, 0.0]

[[balance.springs]]
name = "s2"
link_a = "base"
anchor_a = [0.0, 0.0, 0.15]
link_b = "elbow"
anchor_b = [0.0, 0.1, 0.0]

[[balance.springs]]
name = "s3"
link_a = "shoulder"
anchor_a = [0.0, 0.1, 0.0]
link_b = "elbow"
anchor_b = [0.0, -0.1, 0.0]
"""


def write_arm(tmp_path, catalogue=""):
    path = tmp_path / "arm2r_springs.toml"
    path.write_text(ARM.replace("{catalogue}", catalogue))
    return path


def test_mechanism_springs_in_dh_frames_are_placed_like_bodies(tmp_path):
    """A [[mechanism.springs]] anchor on a `dh` joint is in the DH frame, as a body's com: its
    length equals the distance between two bodies' centres of mass given at the anchors."""
    text = (ROOT / "python" / "mechbal" / "cases" / "ur5-dh.toml").read_text()
    assert "[[mechanism.springs]]" not in text
    cfg = tomllib.loads(text)
    joints = [j["name"] for j in cfg["mechanism"]["joints"]]
    text += f"""
[[mechanism.bodies]]
name = "marker_a"
link = "{joints[1]}"
mass = 0.0
com = [0.1, 0.02, 0.03]
inertia = [0.0, 0.0, 0.0]

[[mechanism.bodies]]
name = "marker_b"
link = "{joints[2]}"
mass = 0.0
com = [-0.2, 0.01, 0.05]
inertia = [0.0, 0.0, 0.0]

[[mechanism.springs]]
name = "lift"
link_a = "{joints[1]}"
anchor_a = [0.1, 0.02, 0.03]
link_b = "{joints[2]}"
anchor_b = [-0.2, 0.01, 0.05]
rate = 1000.0
"""
    path = tmp_path / "ur5_spring.toml"
    path.write_text(text)
    m = mechbal.Mechanism.from_toml(path)
    q = np.random.default_rng(5).uniform(-3, 3, (20, m.dof))
    com, _ = m.body_poses(q)
    ia, ib = m.body_names.index("marker_a"), m.body_names.index("marker_b")
    d = np.linalg.norm(com[:, ib] - com[:, ia], axis=1)
    assert np.allclose(m.spring_lengths(q)[:, 0], d, rtol=0, atol=1e-12)
    assert m.spring_names == ["lift"] and "1 springs" in repr(m)


@pytest.mark.parametrize("table, key, typo, hint", [
    ("mechanism.springs", "anchor_a", "anchr_a", "anchor_a"),
    ("balance.springs", "pulley_ratio", "puley_ratio", "pulley_ratio"),
])
def test_misspelled_spring_keys_are_refused_with_the_field_named(tmp_path, capsys, table, key, typo, hint):
    text = ARM
    if table == "mechanism.springs":
        text = text.replace("[trajectory]", """[[mechanism.springs]]
name = "k"
link_a = "base"
anchr_a = [0.0, 0.0, 0.2]
link_b = "shoulder"
anchor_b = [0.0, 0.1, 0.0]
rate = 10.0

[trajectory]""")
    else:
        text = text.replace('anchor_b = [0.0, -0.1, 0.0]\n', 'anchor_b = [0.0, -0.1, 0.0]\npuley_ratio = 2.0\n')
    path = tmp_path / "bad.toml"
    path.write_text(text.replace("{catalogue}", ""))
    assert main(["balance", str(path), "--method", "springs", "--out", str(tmp_path / "out"), "-q"]) != 0
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert table in err and typo in err and hint in err, err


def test_bad_spring_values_name_the_field_and_value(tmp_path):
    from mechbal.config import ConfigError
    from mechbal.spec import mechanism_spec

    cfg = tomllib.loads(ARM.replace("{catalogue}", ""))["mechanism"]
    spring = {"name": "k", "link_a": "base", "anchor_a": [0, 0, 0.2], "link_b": "sholder", "anchor_b": [0, 0.1, 0],
              "rate": 10.0}
    with pytest.raises(ConfigError, match=r"mechanism.springs\[0\].link_b: unknown link \(did you mean 'shoulder'\?\) \(got 'sholder'\)"):
        mechanism_spec({**cfg, "springs": [spring]})
    with pytest.raises(ConfigError, match=r"mechanism.springs\[0\].rate.*-3"):
        mechanism_spec({**cfg, "springs": [{**spring, "link_b": "shoulder", "rate": -3.0}]})
    with pytest.raises(ConfigError, match=r"mechanism.springs\[0\].link_b.*same link"):
        mechanism_spec({**cfg, "springs": [{**spring, "link_a": "shoulder", "link_b": "shoulder"}]})
    with pytest.raises(ValueError, match=r"springs\[0\] \(k\).rate: must be >= 0 \[N/m\], got -1"):
        mechbal.Mechanism.from_description([_core.Joint("j1")], springs=[_core.Spring("k", "base", np.zeros(3), "j1",
                                                                                       np.ones(3), -1.0)])


# ---- mechbal balance --method springs, end to end ------------------------------------------------
@pytest.fixture(scope="module")
def balanced_arm(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("springs")
    case = write_arm(tmp, 'catalogue = "shipped"\n')
    out = tmp / "out"
    assert main(["balance", str(case), "--method", "springs", "--out", str(out), "-q"]) == 0
    return case, out


def test_balance_springs_cli_is_exact_and_writes_the_springs_back(balanced_arm, tmp_path):
    case, out = balanced_arm
    s = json.loads((out / "summary.json").read_text())
    b = s["balance"]
    assert b["exact"], b["limited_by"]
    assert b["residual"] < 1e-9 and b["residual_before"] > 1.0
    assert set(b["design"]) == {"s1", "s2", "s3"} and all(v["rate"] > 0 for v in b["design"].values())
    assert b["metrics"]["potential_energy_variation_after"] < 1e-9
    assert set(b["metrics"]["catalogue"]["springs"]) == {"s1", "s2", "s3"}
    # the trajectory evaluation uses the balanced mechanism's springs: static torque ~0
    ga = s["before_after"]["gravity_torque"]
    assert max(ga["balanced"]["peak"]) < 1e-9 and max(ga["unbalanced"]["peak"]) > 1.0
    # no URDF that would drop the springs, and the summary says why
    assert not (out / "balanced.urdf").exists() and "springs" in s["urdf"]
    assert sorted(s["files"] + ["summary.json"]) == sorted(p.name for p in out.iterdir())
    # balanced.toml carries the springs: potential energy constant, static torque zero on poses
    # the sizing did not see (issue 11's evidence, through the model)
    data = tomllib.loads((out / "balanced.toml").read_text())
    assert [x["name"] for x in data["mechanism"]["springs"]] == ["s1", "s2", "s3"]
    assert "balance" not in data
    m = mechbal.Mechanism.from_toml(out / "balanced.toml")
    assert m.spring_names == ["s1", "s2", "s3"]
    q = np.random.default_rng(11).uniform(-np.pi, np.pi, (1000, 2))
    assert np.ptp(m.potential_energy(q)) < 1e-9
    assert np.max(np.abs(m.static_torque(q))) < 1e-9
    assert np.max(np.abs(m.gravity_torque(q))) > 1.0
    # and `mechbal run` runs it: its torques include the springs
    assert main(["run", str(out / "balanced.toml"), "--out", str(tmp_path / "run"), "-q"]) == 0
    r = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert r["springs"] == ["s1", "s2", "s3"]
    assert max(r["peak_static_torque"]["nominal"]) < 1e-9
    unbalanced = mechbal.Mechanism.from_toml(case)
    traj_peak = np.max(np.abs(unbalanced.static_torque(np.linspace([0.2, -0.5], [1.4, 0.9], 50))))
    assert traj_peak > 1.0


def test_simulating_the_spring_balanced_arm_it_stays_put_without_torque(balanced_arm):
    """Forward dynamics of the balanced arm at rest with zero motor torque: no acceleration
    (the springs hold it), while the arm without its springs falls."""
    _, out = balanced_arm
    m = mechbal.Mechanism.from_toml(out / "balanced.toml")
    dyn = _core.MechanismDynamics(m.model)
    bare = _core.MechanismDynamics(m.with_springs([], replace=True).model)
    q = np.array([0.7, -0.4])
    assert np.max(np.abs(dyn.forward_dynamics(q, np.zeros(2), np.zeros(2)))) < 1e-8
    assert np.max(np.abs(bare.forward_dynamics(q, np.zeros(2), np.zeros(2)))) > 1.0
