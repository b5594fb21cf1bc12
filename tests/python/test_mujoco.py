"""mechbal against MuJoCo through the MJCF export (mechbal.export.mjcf, mechbal.export.mujoco_engine).

Prescribed motion: MuJoCo's inverse dynamics of the exported model on mechbal's (q, v, a) gives
the same joint forces, gravity torques and base reaction (to 1e-9 relative; they agree to about
1e-13) for the UR5, random trees with gears and springs, the four-bar and PAMINSA. The base
reaction on MuJoCo's side is its ``cfrc_int`` of the bodies whose parent does not move, after
``mj_rnePostConstraint``, moved to O (and over every child of the world for the support reaction).
Simulated: the force-balanced four-bar and PAMINSA in MuJoCo at 1 kHz, residual shaking force
against the unbalanced peak, and what limits it.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.export import ExportError
from mechbal.export.mjcf import MINIMUM, TRIANGLE_MARGIN, mjcf_names

mujoco = pytest.importorskip("mujoco")

from mechbal.export.mujoco_engine import MujocoMechanism, co_simulate  # noqa: E402
from random_trees import random_tree  # noqa: E402

RTOL = 1e-9


def _rel(a, b, scale=None) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    s = np.max(np.abs(b)) if scale is None else scale
    return float(np.max(np.abs(a - b)) / max(s, 1e-300))


def agreement(mech, Q, V, A, q0=None) -> dict:
    """Largest relative differences MuJoCo - mechbal over the samples."""
    sim = MujocoMechanism(mech, q=Q[0] if q0 is None else q0)
    tau = mech.inverse_dynamics(Q, V, A)
    br = mech.base_reaction(Q, V, A)
    G = mech.gravity_torque(Q)
    S = mech.static_torque(Q)
    worst = dict.fromkeys(["tau", "force", "moment", "support_force", "support_moment", "gravity", "static"], 0.0)
    for k in range(len(Q)):
        inv = sim.inverse_dynamics(Q[k], V[k], A[k])
        worst["tau"] = max(worst["tau"], _rel(inv.joint_torque, tau[k], np.max(np.abs(tau))))
        worst["force"] = max(worst["force"], _rel(inv.base_reaction_force, br.base_reaction_force[k],
                                                  np.max(np.abs(br.base_reaction_force))))
        worst["moment"] = max(worst["moment"], _rel(inv.base_reaction_moment, br.base_reaction_moment[k],
                                                    np.max(np.abs(br.base_reaction_moment))))
        worst["support_force"] = max(worst["support_force"], _rel(inv.support_force, br.support_force[k],
                                                                  np.max(np.abs(br.support_force))))
        worst["support_moment"] = max(worst["support_moment"], _rel(inv.support_moment, br.support_moment[k],
                                                                    np.max(np.abs(br.support_moment))))
        worst["gravity"] = max(worst["gravity"], _rel(sim.gravity_torque(Q[k]), G[k], np.max(np.abs(tau))))
        worst["static"] = max(worst["static"], _rel(sim.static_torque(Q[k]), S[k], np.max(np.abs(tau))))
    return worst


def _ur5():
    from test_urdf import ROBOTS, _robot_file

    return mechbal.Mechanism.from_urdf(_robot_file(*ROBOTS["ur5"]))


def test_ur5_inverse_dynamics_and_base_reaction_match_mujoco():
    mech = _ur5()
    rng = np.random.default_rng(5)
    Q, V, A = rng.normal(size=(3, 20, mech.dof)) * np.array([2.0, 1.0, 3.0])[:, None, None]
    worst = agreement(mech, Q, V, A)
    assert max(worst.values()) < RTOL, worst
    # the fixed base_link (4 kg, on the root) is the base's own: the base reaction excludes its
    # weight, the support reaction includes it (MuJoCo agrees with both, above)
    q = np.zeros(mech.dof)
    r = mech.base_reaction(q, q, q)
    assert r.support_force[2] - r.base_reaction_force[2] == pytest.approx(4.0 * 9.81, rel=1e-12)
    assert r.base_reaction_force[2] == pytest.approx((mech.total_mass - 4.0) * 9.81, rel=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_random_trees_with_gears_and_springs_match_mujoco(seed):
    rng = np.random.default_rng(100 + seed)
    tree = random_tree(rng, 7, mimic=True)
    mech = tree.mechanism(merge_fixed=bool(seed % 2))
    assert any(j.mimic_joint for j in mech.model.description.joints)
    links = mech.link_names
    springs = [_core.Spring(f"s{i}", links[int(a)], rng.uniform(-0.2, 0.2, 3), links[int(b)],
                            rng.uniform(-0.2, 0.2, 3), float(rng.uniform(50, 500)), float(rng.uniform(0.05, 0.1)),
                            float(rng.uniform(0.0, 1.0)), int(rng.integers(1, 3)), float(rng.uniform(0.5, 2.0)))
               for i, (a, b) in enumerate([(0, len(links) - 1), (1, len(links) - 2)]) if links[a] != links[b]]
    mech = mech.with_springs(springs)
    Q, V, A = rng.normal(size=(3, 15, mech.dof))
    worst = agreement(mech, Q, V, A)
    assert max(worst.values()) < RTOL, worst
    # the springs are in MuJoCo as tendons: their passive forces are mechbal's spring torques
    sim = MujocoMechanism(mech)
    assert sim.model.ntendon == len(springs) and sim.model.neq == 1
    sim.set_state(Q[0])
    mujoco.mj_forward(sim.model, sim.data)
    assert _rel(-sim.G.T @ sim.data.qfrc_passive, mech.spring_torque(Q[0])) < RTOL
    assert _rel(sim.data.ten_length, mech.spring_lengths(Q[0])) < 1e-12


def _case_motion(name, step=10):
    from mechbal.balance.run import evaluate, balance_case

    bc = balance_case(name)
    ev = evaluate(bc, bc.mechanism)
    s = slice(None, None, step)
    return bc, ev["q"][s], ev["v"][s], ev["a"][s]


@pytest.mark.parametrize("case", ["four-bar", "paminsa-linkage", "paminsa", "discs-3r", "rpsp", "orthoglide"])
def test_cases_match_mujoco_inverse_dynamics(case):
    bc, Q, V, A = _case_motion(case, step=25)
    mech = bc.mechanism
    worst = agreement(mech, Q, V, A)
    tol = {"gravity": 1e-9, "static": 1e-9}
    assert all(v < tol.get(k, RTOL) for k, v in worst.items()), worst
    # the closed mechanism: MuJoCo's tree forces projected with mechbal's coupling matrix are the
    # actuated forces
    if mech.is_closed:
        sim = MujocoMechanism(mech, q=Q[0])
        idx = [mech.joint_names.index(n) for n in mech.actuated_names]
        m = mech.closed_motion(Q[:, idx], V[:, idx], A[:, idx], q_guess=Q[0], with_forces=True)
        for k in range(len(Q)):
            inv = sim.inverse_dynamics(Q[k], V[k], A[k])
            assert _rel(m.projection[k].T @ inv.joint_torque, m.actuated_force[k],
                        np.max(np.abs(m.actuated_force))) < RTOL


def test_mjcf_structure_names_bodies_and_mass_matrix():
    bc, Q, V, A = _case_motion("four-bar")
    mech = bc.mechanism.with_bodies([_core.Body("motor", "crank", 0.3, np.zeros(3), 1e-4 * np.eye(3), "motor"),
                                     _core.Body("rotor", "rocker", 0.0, np.zeros(3), np.diag([1e-4, 2e-4, 1e-4]), "disc"),
                                     _core.Body("nothing", "coupler", 0.0, np.zeros(3), np.zeros((3, 3)), "payload")])
    sim = MujocoMechanism(mech, q=Q[0])
    m = sim.model
    name = lambda kind, i: mujoco.mj_id2name(m, kind, i)  # noqa: E731
    bodies = {name(mujoco.mjtObj.mjOBJ_BODY, i) for i in range(m.nbody)}
    assert {"crank", "coupler", "rocker", "crank_counterweight", "motor", "rotor"} <= bodies
    assert "nothing" not in bodies   # zero mass and inertia: left out, with a comment
    # the comment names the body by its index (no name is written into an XML comment: issue 40)
    index = [b.name for b in mech.model.description.bodies].index("nothing")
    assert f"<!-- bodies[{index}]: zero mass and inertia, left out -->" in sim.xml
    assert {name(mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(m.njnt)} == {"crank", "coupler", "rocker"}
    assert {name(mujoco.mjtObj.mjOBJ_SITE, i) for i in range(m.nsite)} == {"coupler_tip", "rocker_tip"}
    assert m.neq == 1 and m.eq_type[0] == mujoco.mjtEq.mjEQ_CONNECT and m.nu == 1
    # every body with its own mass; the rotor keeps its inertia with zero mass
    for b in mech.bodies:
        if b.name == "nothing":
            continue
        i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, b.name)
        assert m.body_mass[i] == pytest.approx(b.mass, abs=0.0)
        # exact, but for the margin on the triangle inequality (the flat rotor is on its boundary)
        margin = TRIANGLE_MARGIN * float(np.trace(b.inertia))
        assert np.sort(m.body_inertia[i]) == pytest.approx(np.sort(np.linalg.eigvalsh(b.inertia)), rel=1e-12,
                                                           abs=max(1e-18, 1.01 * margin))
    # the keyframe is the assembled pose, the loop closed there
    mujoco.mj_resetDataKeyframe(m, sim.data, sim.key)
    mujoco.mj_forward(m, sim.data)
    assert np.max(np.abs(sim.data.efc_pos[:sim.data.ne])) < 1e-12
    # the mass matrix of the tree
    for q in Q[::20]:
        sim.set_state(q)
        mujoco.mj_forward(m, sim.data)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, sim.data, M)
        assert _rel(sim.G.T @ M @ sim.G, mech.mass_matrix(q)) < 1e-12


def test_massless_moving_links_get_the_minimum_body():
    # a link carrying nothing but a point mass: MuJoCo refuses a moving body with a zero principal
    # moment; the export adds MINIMUM kg and kg m^2 at its origin
    j = [_core.Joint("j1", _core.JointType.revolute, "base", np.eye(4), np.array([0.0, 0.0, 1.0])),
         _core.Joint("j2", _core.JointType.revolute, "j1", np.eye(4), np.array([0.0, 1.0, 0.0]))]
    b = [_core.Body("p", "j2", 2.0, np.array([0.3, 0.0, 0.0]), np.zeros((3, 3)))]
    mech = mechbal.Mechanism.from_description(j, b)
    assert mjcf_names(mech).minimum == ["j1_minimum", "j2_minimum"]
    sim = MujocoMechanism(mech)
    i = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, "j2_minimum")
    assert sim.model.body_mass[i] == MINIMUM
    rng = np.random.default_rng(1)
    Q, V, A = rng.normal(size=(3, 5, 2))
    worst = agreement(mech, Q, V, A)
    assert max(worst.values()) < RTOL, worst


def test_export_refusals_are_one_line():
    bc, Q, *_ = _case_motion("four-bar")
    with pytest.raises(ExportError, match="loop closure") as err:
        bc.mechanism.to_urdf()
    assert "\n" not in str(err.value)
    j = [_core.Joint("j1", _core.JointType.revolute, "base", np.eye(4), np.array([0.0, 0.0, 1.0]))]
    b = [_core.Body("l", "j1", 1.0, np.array([0.3, 0.0, 0.0]), 0.01 * np.eye(3))]
    sp = _core.Spring("s", "base", np.array([0.0, 0.1, 0.0]), "j1", np.array([0.3, 0.0, 0.0]), 100.0, 0.0, 50.0)
    mech = mechbal.Mechanism.from_description(j, b, springs=[sp])
    with pytest.raises(ExportError, match="spring"):
        mech.to_urdf()
    with pytest.raises(ExportError, match="negative length"):   # preload 50 N at zero free length
        mech.to_mjcf()


def test_urdf_round_trips_keep_names_frames_and_bodies(tmp_path):
    mech = _ur5()
    back = mechbal.Mechanism.from_urdf_string(mech.to_urdf())
    assert back.joint_names == mech.joint_names
    assert sorted(back.frame_names) == sorted(mech.frame_names)   # tool0, ee_link, base_link, world
    assert back.model.description.root_name == "world"
    assert {b.name for b in back.bodies} == {b.name for b in mech.bodies if b.mass > 0 or np.any(b.inertia)}
    q = np.random.default_rng(2).normal(size=(10, mech.dof))
    assert np.max(np.abs(back.mass_matrix(q) - mech.mass_matrix(q))) < 1e-12
    assert np.max(np.abs(back.gravity_torque(q) - mech.gravity_torque(q))) < 1e-12
    for name in ("tool0", "ee_link"):
        assert np.allclose(back.frame_placement(q[0], name), mech.frame_placement(q[0], name), atol=1e-14)


def _builtin_cases() -> list[str]:
    from mechbal.cases import available

    return [name for name, _, _ in available()]


@pytest.mark.parametrize("case", _builtin_cases())
def test_every_builtin_case_round_trips_through_urdf_or_says_why(case):
    """from_urdf(to_urdf(m)) is m (mass matrix and gravity torque to 1e-12 relative, joints
    matched by name) for every built-in case URDF can express; the others are refused in one line
    naming what URDF cannot hold."""
    from mechbal.balance.run import balance_case

    mech = balance_case(case).mechanism
    if mech.is_closed or mech.springs:
        with pytest.raises(ExportError, match="loop closure|spring") as err:
            mech.to_urdf()
        assert "\n" not in str(err.value)
        return
    back = mechbal.Mechanism.from_urdf_string(mech.to_urdf())
    perm = [back.joint_names.index(n) for n in mech.joint_names]
    q = np.random.default_rng(3).normal(size=(10, mech.dof))
    qb = np.zeros_like(q)
    qb[:, perm] = q
    M, Mb = mech.mass_matrix(q), back.mass_matrix(qb)[:, perm][:, :, perm]
    assert np.max(np.abs(M - Mb)) < 1e-12 * max(1.0, np.max(np.abs(M)))
    G, Gb = mech.gravity_torque(q), back.gravity_torque(qb)[:, perm]
    assert np.max(np.abs(G - Gb)) < 1e-12 * max(1.0, np.max(np.abs(G)))


@pytest.mark.parametrize("case", _builtin_cases())
def test_balanced_toml_is_the_balanced_model(case, tmp_path):
    """The balanced.toml that ``mechbal balance`` writes (by the case's method, or its default
    design's) reads back as the balanced mechanism through the case reader (any case kind): the
    same bodies, mass matrix and static torque to 1e-12 relative, joints matched by name."""
    from mechbal.balance.run import _balanced_toml, balance_case, run_method

    bc = balance_case(case)
    method = getattr(bc.table, "method", None) if bc.table is not None else None
    if method is None and bc.default_design:
        method = next(iter(bc.default_design))
    if method is None:   # nothing to balance by: no balanced.toml
        assert bc.table is None and not bc.default_design
        return
    result = run_method(bc, method)
    balanced = result.balanced
    path = tmp_path / "balanced.toml"
    path.write_text(_balanced_toml(bc, result, method))
    back = balance_case(str(path)).mechanism
    assert sorted(back.body_names) == sorted(balanced.body_names)
    perm = [back.joint_names.index(n) for n in balanced.joint_names]
    q = np.random.default_rng(5).normal(size=(10, balanced.dof))
    qb = np.zeros((10, back.dof))
    qb[:, perm] = q
    M, Mb = balanced.mass_matrix(q), back.mass_matrix(qb)[:, perm][:, :, perm]
    assert np.max(np.abs(M - Mb)) < 1e-12 * max(1.0, np.max(np.abs(M)))
    if sorted(back.spring_names) != sorted(balanced.spring_names):
        # a paper kind that keeps its springs in its own table, not in the mechanism (the
        # Orthoglide's [[springs]] rate, N/m): the written rates are the sized ones
        sized = {sp.name: sp.rate for sp in balanced.springs if sp.name not in bc.mechanism.spring_names}
        written = {sp["name"]: sp["rate"] for sp in _toml_loads(path.read_text())["springs"]}
        assert written == sized and not back.springs
        return
    S, Sb = balanced.static_torque(q), back.static_torque(qb)[:, perm]
    assert np.max(np.abs(S - Sb)) < 1e-12 * max(1.0, np.max(np.abs(S)))


def _toml_loads(text: str) -> dict:
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    return tomllib.loads(text)


def test_balance_writes_mjcf_and_a_urdf_that_keeps_the_discs(tmp_path):
    from mechbal.cli import main

    out = tmp_path / "d3"
    assert main(["balance", "discs-3r", "--out", str(out), "-q", "--allow-partial"]) == 0   # a partial balance (exit 5 without)
    summary = json.loads((out / "summary.json").read_text())
    assert {"balanced.xml", "balanced.urdf", "balanced.toml"} <= set(summary["files"])
    toml = mechbal.Mechanism.from_toml(out / "balanced.toml")
    urdf = mechbal.Mechanism.from_urdf(out / "balanced.urdf")
    q = np.random.default_rng(4).normal(size=(10, toml.dof))
    assert urdf.joint_names == toml.joint_names
    assert np.max(np.abs(urdf.mass_matrix(q) - toml.mass_matrix(q))) < 1e-12
    assert "<link name=\"disc6\"/>" not in (out / "balanced.urdf").read_text()
    m = mujoco.MjModel.from_xml_path(str(out / "balanced.xml"))   # MuJoCo accepts the discs
    assert m.nq == toml.dof + 4


def test_balance_of_a_loop_says_why_no_urdf(tmp_path):
    from mechbal.cli import main

    out = tmp_path / "fb"
    assert main(["balance", "four-bar", "--out", str(out), "-q"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert "balanced.xml" in summary["files"] and "balanced.urdf" not in summary["files"]
    assert "loop closure" in summary["urdf"]
    mujoco.MjModel.from_xml_path(str(out / "balanced.xml"))


def test_cli_export(tmp_path, capsys):
    from mechbal.cli import main

    assert main(["export", "paminsa-linkage", "--out", str(tmp_path / "p.xml"), "-q"]) == 0
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "p.xml"))
    assert m.neq == 12
    assert main(["export", "ur5-dh", "--format", "urdf", "--out", str(tmp_path / "u.urdf"), "-q"]) == 0
    assert mechbal.Mechanism.from_urdf(tmp_path / "u.urdf").dof == 6
    assert main(["export", "four-bar", "--format", "urdf", "--out", str(tmp_path / "f.urdf")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "loop closure" in err


def test_force_balanced_four_bar_in_mujoco_at_1khz():
    """What limits the force-balanced four-bar's simulated shaking force in MuJoCo (fraction of
    the unbalanced peak, 1 kHz computed torque, RK4 at 1 ms): its soft loop. MuJoCo's defaults
    (impedance 0.9-0.95, its own inverse weights): about 6e-2; the export's impedance 0.9999:
    about 5e-5; with the co-simulation's constraint weight 1e-4 as well: about 3e-8; 4 substeps of
    0.25 ms take it lower still; a first-order integrator (Euler) at 1 ms leaves about 3e-4."""
    from mechbal.balance.run import balance_case, run_method
    from mechbal.config import trajectory_from_config
    from mechbal.control import ComputedTorque
    from mechbal.simulate import closed_loop

    bc = balance_case("four-bar")
    balanced = run_method(bc, "force").balanced
    table = {k: v for k, v in bc.trajectory_table.items() if k != "initial_guess"}
    traj, _ = trajectory_from_config(table, 1)
    peaks = {}
    for label, mech, opts in (("unbalanced", bc.mechanism, {}), ("balanced", balanced, {}),
                              ("mujoco_defaults", balanced, {"solimp": (0.9, 0.95, 0.001), "constraint_weight": 1.0}),
                              ("export_impedance", balanced, {"constraint_weight": 1.0}),
                              ("substeps", balanced, {"substeps": 4}), ("euler", balanced, {"integrator": "Euler"})):
        r = closed_loop(mech, ComputedTorque(mech, [400.0], [40.0], q_guess=bc.q_guess), traj,
                        engine="mujoco", q_guess=bc.q_guess, **opts)
        assert r.ok and r.mujoco is not None and r.t.size == 1001
        cs = r.mujoco
        peaks[label] = np.max(np.abs(cs.shaking_force))
        if label == "unbalanced":   # MuJoCo's realised force is mechbal's prediction, up to tracking
            assert _rel(cs.shaking_force, cs.predicted_shaking_force) < 0.02
            assert np.max(np.abs(r.tracking_error)) < 1e-3
    fraction = {k: v / peaks["unbalanced"] for k, v in peaks.items()}
    assert fraction["balanced"] < 1e-6, fraction
    assert 1e-2 < fraction["mujoco_defaults"], fraction
    assert 1e-6 < fraction["export_impedance"] < 1e-3, fraction
    assert fraction["substeps"] < fraction["balanced"], fraction
    assert fraction["balanced"] < fraction["euler"] < 1e-2, fraction


def test_paminsa_force_balanced_in_mujoco():
    """PAMINSA's massless guides: MuJoCo's solver needs mass on them (the co-simulation gives
    massless moving links 1e-6 of the total mass; mechbal's prediction is of that mechanism) and
    weights their loops like the others. The force-balanced robot's simulated shaking force is
    then below 1e-4 of the unbalanced peak (MuJoCo's own constraint weights: about 3e-3)."""
    from mechbal.balance.run import balance_case, run_method
    from mechbal.config import trajectory_from_config
    from mechbal.control import ComputedTorque

    bc = balance_case("paminsa")
    balanced = run_method(bc, "force").balanced
    n = len(bc.mechanism.actuated_names)
    table = {k: v for k, v in bc.trajectory_table.items() if k != "initial_guess"}
    traj, _ = trajectory_from_config(table, n)
    peaks = {}
    for label, mech, opts in (("unbalanced", bc.mechanism, {}), ("balanced", balanced, {}),
                              ("mujoco_weights", balanced, {"constraint_weight": 1.0})):
        cs = co_simulate(mech, ComputedTorque(mech, [400.0] * n, [40.0] * n, q_guess=bc.q_guess), traj,
                         q_guess=bc.q_guess, duration=0.25, **opts)
        assert np.all(cs.status == 0) and np.max(cs.constraint_violation) < 1e-4
        peaks[label] = np.max(np.abs(cs.shaking_force))
    assert peaks["balanced"] < 1e-4 * peaks["unbalanced"]
    assert peaks["balanced"] < peaks["mujoco_weights"] < 1e-2 * peaks["unbalanced"]



@pytest.mark.parametrize("torque, first_bad", [(1e30, 20), (1e9, 21)])
def test_co_simulation_stops_where_mujoco_refuses_the_torque_or_resets(torque, first_bad):
    """MuJoCo does not fail on a bad tick: it zeroes a huge control (1e30: mjWARN_BADCTRL, the
    tick's own wrench is then without it) and resets a state its step made diverge (1e9:
    mjWARN_BADQACC, back to the model's rest pose), then goes on. The co-simulation stops at that
    tick (steps_completed 20, Status.out_of_range from the first bad row on) and the later rows
    repeat the last one written, as mechbal's own simulator does; before, it ran to the end with
    every status 0."""
    from mechbal.balance.run import balance_case
    from mechbal.config import trajectory_from_config

    bc = balance_case("four-bar")
    mech = bc.mechanism
    n = len(mech.actuated_names)
    traj, _ = trajectory_from_config({k: v for k, v in bc.trajectory_table.items() if k != "initial_guess"}, n)

    class Runaway:   # a controller whose torque blows up at its 21st tick (k = 20)
        ticks = 0

        def step(self, q, v, q_des, v_des, a_des):
            self.ticks += 1
            return np.full(n, torque if self.ticks > 20 else 0.0), 0

    cs = co_simulate(mech, Runaway(), traj, q_guess=bc.q_guess, duration=0.1)
    assert cs.steps_completed == 20 and len(cs.t) == 101
    bad = (cs.status & int(_core.Status.out_of_range)) != 0
    assert not bad[:first_bad].any() and bad[first_bad:].all()
    for series in (cs.q, cs.v, cs.joint_torque, cs.base_reaction_force, cs.base_reaction_moment, cs.q_full,
                   cs.a_full, cs.constraint_violation):
        assert np.array_equal(series[21:], np.broadcast_to(series[20], series[21:].shape))
    assert np.all(np.isfinite(cs.q)) and abs(cs.q[20, 0] - cs.q[19, 0]) < 1e-2   # not MuJoCo's reset pose

def test_verify_four_bar(tmp_path):
    from mechbal.cli import main

    out = tmp_path / "v"
    assert main(["verify", "four-bar", "--out", str(out), "-q"]) == 0
    s = json.loads((out / "summary.json").read_text())
    for variant in ("unbalanced", "balanced"):
        for key in ("shaking_force", "shaking_moment", "gravity_torque", "actuator_force"):
            assert s["variants"][variant][key]["relative_difference"] < RTOL
    assert s["variants"]["balanced"]["shaking_force"]["simulated_peak_fraction_of_unbalanced"] < 1e-6
    assert s["mujoco_options"]["integrator"] == "RK4" and s["mujoco_options"]["timestep"] == pytest.approx(1e-3)
    # the files written are the export as `mechbal export` writes it: they hold, and say how
    xml = (out / "balanced.xml").read_text()
    assert 'integrator="RK4"' in xml and 'timestep="0.00025"' in xml
    assert (out / "shaking_wrench.png").stat().st_size > 10_000
    assert math.isfinite(s["variants"]["unbalanced"]["simulation"]["max_constraint_violation"])


def test_run_with_the_mujoco_engine(tmp_path):
    from mechbal.cli import main

    out = tmp_path / "r"
    assert main(["run", "four-bar", "--engine", "mujoco", "--out", str(out), "-q"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["ok"] and s["engine"] == "mujoco"
    # MuJoCo's integrator and step of the run (issue 39), as MuJoCo had them
    assert s["mujoco_options"]["integrator"] == "RK4" and s["mujoco_options"]["timestep"] == pytest.approx(1e-3)
    assert s["mujoco_options"]["solref"] == [0.02, 1.0]
    br = s["base_reaction"]
    # MuJoCo's simulated base reaction is mechbal's prediction up to the tracking error
    assert br["max_force_difference"] < 0.02 * br["peak_force_mechbal"]
    data = np.load(out / "cosimulation.npz")
    assert data["base_reaction_force"].shape == (1001, 3)
    assert (out / "base_reaction.png").stat().st_size > 10_000
    mujoco.MjModel.from_xml_path(str(out / "mechanism.xml"))


def test_decoupled_control_of_the_disc_balanced_arm_in_mujoco():
    """The decoupled joint controller tau_i = k_i (a_des_i + Kp e_i + Kd e'_i) (Coutinho & Hess
    Coelho) ticked at 1 kHz against MuJoCo: on the 3R arm with its discs sized (mass matrix
    diagonal and constant, gravity balanced) it tracks as computed torque does (measured: 2.5e-5
    rad both, the zero-order hold); on the arm without the discs (off-diagonal inertia 0.185 kg m^2)
    the same law leaves the path by about 1e-2 rad. MuJoCo integrates the discs as geared joints
    (equality constraints): the independent engine confirms the decoupling."""
    from mechbal.balance.run import balance_case, run_method
    from mechbal.config import trajectory_from_config
    from mechbal.control import ComputedTorque, DecoupledJointController
    from mechbal.simulate import closed_loop

    bc = balance_case("discs-3r")
    balanced = run_method(bc, "moment").balanced
    n = bc.mechanism.dof
    table = {k: v for k, v in bc.trajectory_table.items() if k != "initial_guess"}
    traj, _ = trajectory_from_config(table, n)
    q0 = traj.evaluate(0.0)[0]
    error = {}
    for label, mech, make in (
            ("unbalanced", bc.mechanism, lambda m: DecoupledJointController(np.diag(m.mass_matrix(q0)), [400.0] * n,
                                                                            [40.0] * n)),
            ("balanced", balanced, lambda m: DecoupledJointController(np.diag(m.mass_matrix(q0)), [400.0] * n,
                                                                      [40.0] * n)),
            ("balanced_ct", balanced, lambda m: ComputedTorque(m, [400.0] * n, [40.0] * n))):
        r = closed_loop(mech, make(mech), traj, engine="mujoco")
        assert r.ok and r.mujoco is not None
        error[label] = float(np.max(np.abs(r.tracking_error)))
    assert error["balanced"] < 1.5 * error["balanced_ct"] < 1e-4, error
    assert error["unbalanced"] > 100 * error["balanced"], error
