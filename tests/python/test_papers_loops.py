"""The existing closed loops as data (issue 10): the five-bar of the discs case and PAMINSA on the
general model (mechbal.papers.discs.five_bar, mechbal.papers.paminsa: trees + loop closures, solved by
the general loop solve) against their closed forms (FiveBarDynamics and the five-bar's bodies in
closed form; PaminsaModel / paminsa_kinematics), their momenta summed body by body in numpy
(body_set.py), to 1e-10 relative along the cases' trajectories; and the shipped TOML files are
exactly what the generators produce."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np

from mechbal.config import case_path
import pytest

from mechbal import Mechanism, _core
from mechbal.config import read_case
from body_set import body_set_wrench
from generated_text import text_differences

TOL = 1e-10
_ROTATIONAL = ("rotation", "angular_velocity", "angular_acceleration")
_MOTION = ("com", "com_velocity", "com_acceleration") + _ROTATIONAL


def _rel(a, b, scale: float = 0.0) -> float:
    """max |a - b| over max(max |b|, scale): relative, with a floor for quantities balanced to zero."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), scale, 1e-300))


def _momenta(b: dict) -> dict:
    """Linear and angular momentum (about O), shaking force and moment of a closed form's bodies:
    the tests' numpy sum over the bodies (body_set.py), independent of the general model."""
    w = body_set_wrench(b["mass"], b["inertia_body"], b["com"], b["com_velocity"], b["com_acceleration"],
                        b["rotation"], b["angular_velocity"], b["angular_acceleration"])
    assert all(np.isfinite(x).all() for x in w.values())
    return {"linear_momentum": w["linear_momentum"], "angular_momentum": w["angular_momentum"],
            "shaking_force": w["force"], "shaking_moment": w["moment"]}


def _compare_bodies(mech: Mechanism, motion, closed: dict, names, inertia) -> dict:
    """Max relative difference per motion quantity over every body (rotations only of bodies with
    rotational inertia: a point mass's frame is a convention, the closed forms keep it fixed)."""
    idx = [mech.body_names.index(n) for n in names]
    spinning = np.abs(np.asarray(inertia)).reshape(len(names), -1).max(axis=1) > 0
    out = {}
    for key in _MOTION:
        general, reference = getattr(motion, key)[:, idx], np.asarray(closed[key])
        if key in _ROTATIONAL:
            general, reference = general[:, spinning], reference[:, spinning]
        out[key] = _rel(general, reference)
    return out


# ------------------------------------------------------------------------------------------------
# five-bar
# ------------------------------------------------------------------------------------------------
def _five_bar_closed_form_bodies(d: dict, q, qd, qdd) -> dict:
    """The five-bar's bodies along (q, qd, qdd) of (theta1, theta2) in closed form: the passive
    angles, rates and accelerations of FiveBarDynamics.motion (p = C p#, p' = C p#'' + cbar) and
    each link's centre of mass on its line, B + L e(t) with its derivatives (proximal/distal links
    about x, the end-effector point mass at FiveBarDynamics' tip)."""
    from mechbal.papers import discs as dz

    N = len(q)
    m = dz.fivebar_dynamics(d).motion(q, qd, qdd)
    assert np.all(m.status == 0)
    th, w, al = m.q, m.v, m.a
    names, mass, inertia = [], [], []
    com, vel, acc, rot, omg, alp = ([] for _ in range(6))
    e = lambda t: np.stack([np.zeros_like(t), np.cos(t), np.sin(t)], -1)  # noqa: E731
    nv = lambda t: np.stack([np.zeros_like(t), -np.sin(t), np.cos(t)], -1)  # noqa: E731

    def Rx(t):
        R = np.zeros((len(t), 3, 3))
        R[:, 0, 0] = 1.0
        R[:, 1, 1] = R[:, 2, 2] = np.cos(t)
        R[:, 2, 1], R[:, 1, 2] = np.sin(t), -np.sin(t)
        return R

    def point(base, L, t, td, tdd):  # base + L e(t) and its derivatives
        return (base[0] + L * e(t), base[1] + L * td[:, None] * nv(t),
                base[2] + L * (tdd[:, None] * nv(t) - td[:, None] ** 2 * e(t)))

    ax = np.array([1.0, 0.0, 0.0])
    for i, leg in ((1, 0), (2, 1)):
        A = (np.tile([0.0, d["d"] if i == 2 else 0.0, 0.0], (N, 1)), np.zeros((N, 3)), np.zeros((N, 3)))
        t1, t1d, t1dd = th[:, 2 * leg], w[:, 2 * leg], al[:, 2 * leg]
        phi = t1 + th[:, 2 * leg + 1]
        phid, phidd = t1d + w[:, 2 * leg + 1], t1dd + al[:, 2 * leg + 1]
        B = point(A, d[f"a{i}"], t1, t1d, t1dd)
        for name, base, L, t, td, tdd, key, mk in (
                (f"proximal{i}", A, d[f"cp{i}"], t1, t1d, t1dd, f"p{i}", f"mp{i}"),
                (f"distal{i}", B, d[f"cd{i}"], phi, phid, phidd, f"d{i}", f"md{i}")):
            G = point(base, L, t, td, tdd)
            names.append(name)
            mass.append(d[mk])
            inertia.append(np.diag(d[f"inertia_{key}"]))
            com.append(G[0]), vel.append(G[1]), acc.append(G[2]), rot.append(Rx(t))
            omg.append(td[:, None] * ax), alp.append(tdd[:, None] * ax)
    names.append("end_effector")
    mass.append(d["mP"])
    inertia.append(np.zeros((3, 3)))
    z = np.zeros((N, 1))
    com.append(np.hstack([z, m.end_effector]))
    vel.append(np.hstack([z, m.end_effector_velocity]))
    acc.append(np.hstack([z, m.end_effector_acceleration]))
    rot.append(np.tile(np.eye(3), (N, 1, 1)))
    omg.append(np.zeros((N, 3))), alp.append(np.zeros((N, 3)))
    stack = lambda xs: np.stack(xs, 1)  # noqa: E731
    return dict(names=names, mass=np.array(mass), inertia_body=np.array(inertia), com=stack(com),
                com_velocity=stack(vel), com_acceleration=stack(acc), rotation=stack(rot),
                angular_velocity=stack(omg), angular_acceleration=stack(alp))


def _five_bar_run(balanced: bool):
    from mechbal.papers.discs.runner import _disc_bodies, _torques, parameters_from_config
    from mechbal.papers.discs.five_bar import five_bar_design_mechanism, five_bar_initial_guess
    from mechbal.papers import discs as dz

    config = read_case("five-bar")
    p = parameters_from_config("fivebar", config)
    d = dz.design("fivebar", p, balanced)
    mech = five_bar_design_mechanism(d)
    tr = config["trajectory"]
    t = np.linspace(0.0, tr["duration"], tr["samples"])
    q, qd, qdd = _core.RestToRestTrajectory(np.array(tr["start"], float), np.array(tr["end"], float),
                                            tr["duration"], _core.TimeLaw.quintic).evaluate_batch(t)
    solved = mech.closed_motion(q, qd, qdd, q_guess=five_bar_initial_guess(mech, d, q[0]), with_forces=True)
    closed = _five_bar_closed_form_bodies(d, q, qd, qdd)
    return dict(mech=mech, d=d, q=q, qd=qd, qdd=qdd, solved=solved, closed=closed,
                runner=_disc_bodies("fivebar", d, q, qd, qdd), torque=_torques("fivebar", d, q, qd, qdd))


@pytest.mark.parametrize("balanced", [False, True], ids=["unbalanced", "balanced"])
def test_five_bar_general_model_equals_the_closed_form(balanced):
    """Every body's motion, the momenta, the shaking force and moment and the actuated torques of
    the general five-bar (loop solve + projection) equal the closed form (FiveBarDynamics and the
    five-bar's bodies in closed form, summed by numpy) to 1e-10 relative along the case's
    trajectory; so do the bodies and the shaking wrench the discs runner writes
    (bodies_*.npz, from the general model)."""
    r = _five_bar_run(balanced)
    mech, m, closed = r["mech"], r["solved"], r["closed"]
    assert np.all(m.status == 0) and m.residual.max() < 1e-12
    # positions, velocities, accelerations (and rotations) of every body
    diffs = _compare_bodies(mech, mech.body_motion(m.q, m.v, m.a), closed, closed["names"], closed["inertia_body"])
    # momenta and the shaking wrench (a balanced force is ~0: compared on the unbalanced scale)
    reference = _momenta(closed)
    sw = mech.shaking_wrench(m.q, m.v, m.a)
    baseline = _five_bar_run(False) if balanced else r  # scales of the quantities balancing zeroes
    scale = {k: np.abs(v).max() for k, v in _momenta(baseline["closed"]).items()}
    for key in ("linear_momentum", "angular_momentum", "shaking_force", "shaking_moment"):
        diffs[key] = _rel(getattr(sw, key), reference[key], scale[key])
    # actuated torques: C^T tau of the tree = FiveBarDynamics' M' qdd + v' + g'
    diffs["actuated_torque"] = _rel(m.actuated_force, r["torque"])
    # what the discs runner writes: the same bodies, and the wrench of those bodies' motion
    runner = r["runner"]
    assert runner["names"] == closed["names"]
    diffs.update({f"runner_{k}": v for k, v in _compare_bodies(
        mech, SimpleNamespace(**{k: runner[k] for k in _MOTION}), closed, closed["names"],
        closed["inertia_body"]).items()})
    diffs["runner_shaking_force"] = _rel(runner["shaking_force"], reference["shaking_force"], scale["shaking_force"])
    diffs["runner_shaking_moment"] = _rel(runner["shaking_moment"], reference["shaking_moment"],
                                          scale["shaking_moment"])
    # reduced mass matrix and gravity: C^T M C, C^T G = FiveBarDynamics.evaluate's M', g'
    from mechbal.papers import discs as dz

    M, _, g = dz.evaluate("fivebar", r["d"], r["q"][::10], r["qd"][::10] * 0.0)
    g_scale = np.abs(dz.evaluate("fivebar", baseline["d"], r["q"][::10], r["qd"][::10] * 0.0)[2]).max()
    Mr, gr = mech.reduced_mass_matrix(r["q"][::10], q_guess=m.q[0])
    diffs["reduced_mass_matrix"], diffs["reduced_gravity"] = _rel(Mr, M), _rel(gr, g, g_scale)
    assert max(diffs.values()) < TOL, " ".join(f"{k}={v:.1e}" for k, v in diffs.items())


def test_five_bar_linkage_toml_is_the_generated_mechanism_and_runs(tmp_path):
    """five-bar-linkage.toml is five_bar_case_toml("five-bar") byte for byte, reads back as the
    same model, and `mechbal run` closes its loop along the whole run."""
    import json

    from mechbal.cases import run_case
    from mechbal.papers._toml import same_model
    from mechbal.papers.discs.five_bar import five_bar_case_toml, five_bar_mechanism

    path = case_path("five-bar-linkage")
    assert path.read_text() == five_bar_case_toml("five-bar"), "regenerate five-bar-linkage.toml"
    assert same_model(Mechanism.from_toml(path), five_bar_mechanism("five-bar", balanced=True)) == []
    run_case("five-bar-linkage", tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["closed"] and summary["actuated"] == ["theta1", "theta2"]
    assert summary["loops"]["max_closure_residual"] < 1e-12 and summary["loops"]["singular_instants"] == 0
    # leg-wise static balancing on the general model: the shaking force stays zero
    assert max(summary["peak_shaking_force"]["nominal"]) < 1e-10


# ------------------------------------------------------------------------------------------------
# PAMINSA
# ------------------------------------------------------------------------------------------------
def _paminsa_run(balanced: bool, samples: int = 251):
    from mechbal.papers.paminsa.runner import parameters_from_config, trajectory_from_config
    from mechbal.papers import paminsa as pp

    config = read_case("paminsa")
    params = parameters_from_config(config)
    built = pp.closed_form_counterweights(params).apply(params) if balanced else params
    model = _core.PaminsaModel(built)
    mech = pp.paminsa_mechanism(params, balanced)
    traj = trajectory_from_config(config)
    t = np.linspace(0.0, traj.duration, samples)
    P, Pd, Pdd = traj.evaluate_batch(t)
    # the wrist moves too (its bodies ride on the platform): a smooth excursion from the case's start
    w = 2.0 * np.pi / traj.duration
    amp = np.array([0.4, 0.2, 0.8])
    W = np.asarray(config["wrist"]["initial_angles"], float) + amp * np.sin(w * t)[:, None]
    Wd, Wdd = amp * w * np.cos(w * t)[:, None], -amp * w * w * np.sin(w * t)[:, None]
    closed = _core.paminsa_kinematics(model, P, Pd, Pdd, W, Wd, Wdd)
    assert np.all(closed["status_per_instant"] == 0)
    qa, va, aa = pp.paminsa_actuated_motion(mech, params, P, Pd, Pdd, W, Wd, Wdd)
    solved = mech.closed_motion(qa, va, aa, q_guess=pp.paminsa_initial_guess(mech, params, P[0], W[0]))
    return dict(mech=mech, model=model, params=params, closed=closed, solved=solved, P=P)


@pytest.mark.parametrize("balanced", [False, True], ids=["unbalanced", "force_balanced"])
def test_paminsa_general_model_equals_the_closed_form(balanced):
    """PAMINSA as 38 bodies on a tree with 9 loop closures, driven by the paper's actuators (M_1,
    M_3, M_v) and the wrist along the paper's cycle: every body's motion, the momenta, D of eq 19
    and its rate, and the shaking force and moment equal the closed forms to 1e-10 relative."""
    r = _paminsa_run(balanced)
    mech, model, closed, m = r["mech"], r["model"], r["closed"], r["solved"]
    assert np.all(m.status == 0), np.unique(m.status)
    assert m.residual.max() < 1e-12 and m.rcond.min() > 1e-3
    assert mech.body_names == list(model.body_names)
    assert np.allclose(mech.model.bodies[0].mass, model.masses[0])
    assert np.array_equal([b.mass for b in mech.model.bodies], model.masses)
    motion = mech.body_motion(m.q, m.v, m.a)
    np.testing.assert_allclose(motion.com[:, 0], r["P"], atol=1e-12)  # the platform is at P
    names = list(model.body_names)
    diffs = _compare_bodies(mech, motion, closed, names, model.inertia_body)
    bodies = dict(closed, mass=np.asarray(model.masses), inertia_body=np.asarray(model.inertia_body))
    reference = _momenta(bodies)
    sw = mech.shaking_wrench(m.q, m.v, m.a)
    # force balancing zeroes the linear momentum and the shaking force: their unbalanced scales
    baseline = _paminsa_run(False) if balanced else r
    scale = {k: np.abs(v).max() for k, v in _momenta(dict(
        baseline["closed"], mass=np.asarray(baseline["model"].masses),
        inertia_body=np.asarray(baseline["model"].inertia_body))).items()}
    for key in ("linear_momentum", "angular_momentum", "shaking_force", "shaking_moment"):
        diffs[key] = _rel(getattr(sw, key), reference[key], scale[key])
    diffs["shaking_force_vs_paminsa_kinematics"] = _rel(sw.shaking_force, closed["shaking_force"],
                                                        scale["shaking_force"])
    diffs["shaking_moment_vs_paminsa_kinematics"] = _rel(sw.shaking_moment, closed["shaking_moment"])
    # D (eq 19: every body's angular momentum but the wrist's rotation) and dD/dt, the closed-form
    # momentum path of the 1 kHz tick (paminsa_mechanism_momentum)
    wrist = [names.index(f"wrist{k}") for k in (1, 2, 3)]
    Rw = motion.rotation[:, wrist]
    Iw = np.einsum("nbij,bjk,nblk->nbil", Rw, np.asarray(model.inertia_body)[wrist], Rw)
    ww, aw = motion.angular_velocity[:, wrist], motion.angular_acceleration[:, wrist]
    Hw = np.einsum("nbij,nbj->ni", Iw, ww)
    Mw = np.einsum("nbij,nbj->ni", Iw, aw) + np.cross(ww, np.einsum("nbij,nbj->nbi", Iw, ww)).sum(axis=1)
    diffs["D"] = _rel(sw.angular_momentum - Hw, closed["D"])
    diffs["D_dot"] = _rel(sw.shaking_moment - Mw, closed["D_dot"])
    assert max(diffs.values()) < TOL, " ".join(f"{k}={v:.1e}" for k, v in diffs.items())


def test_paminsa_actuators_are_the_papers():
    """M_1, M_3 (revolute, in-plane) and M_v (linear, vertical) plus the wrist are actuated; M_2 and
    every joint of the legs passive; legs 2 and 3's sliders and the vertical counter-mass follow M_v
    through gear couplings; the solved actuator angles are the closed form's inverse kinematics."""
    r = _paminsa_run(True, samples=11)
    mech, model, m = r["mech"], r["model"], r["solved"]
    assert sorted(mech.actuated_names) == sorted(["leg1_guide", "leg3_guide", "leg1_slider", "wrist_phi",
                                                  "wrist_theta", "wrist_psi"])
    assert "leg2_guide" in mech.passive_names and "leg2_slider" not in mech.joint_names  # a gear
    assert mech.dof == 28 and len(mech.passive_names) == 22
    for q, P in zip(m.q, r["P"]):
        ik = model.inverse_kinematics(P)
        j = {n: q[i] for i, n in enumerate(mech.joint_names)}
        assert abs(j["leg2_guide"] - ik["alpha2"]) < 1e-10
        assert np.allclose([j[f"leg{i}_stroke"] for i in (1, 2, 3)], ik["stroke"], atol=1e-10)
        assert np.allclose([j["platform_x"], j["platform_y"], j["platform_z"]], P, atol=1e-12)


def test_paminsa_linkage_toml_is_the_generated_mechanism_and_force_balanced(tmp_path):
    """paminsa-linkage.toml is paminsa_case_toml("paminsa") byte for byte, reads back as the same
    model, and its run through `mechbal run` closes the nine loops with the closed-form
    counterweights cancelling the shaking force on the general model too."""
    import json

    from mechbal.cases import run_case
    from mechbal.papers.paminsa.runner import parameters_from_config
    from mechbal.papers._toml import same_model
    from mechbal.papers.paminsa import paminsa_case_toml, paminsa_mechanism

    path = case_path("paminsa-linkage")
    assert text_differences(path.read_text(), paminsa_case_toml("paminsa")) == [], \
        "regenerate paminsa-linkage.toml"
    generated = paminsa_mechanism(parameters_from_config(read_case("paminsa")), balanced=True)
    assert same_model(Mechanism.from_toml(path), generated) == []
    run_case("paminsa-linkage", tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["closed"] and summary["loops"]["singular_instants"] == 0
    assert summary["loops"]["max_closure_residual"] < 1e-12
    assert max(summary["peak_shaking_force"]["nominal"]) < 1e-9  # 27.6 N unbalanced
