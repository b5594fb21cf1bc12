"""The papers' mechanisms as data on the general model (mechbal.papers) against their closed forms,
kept as fast paths: the 2-DOF arm (Arakelian, Le Baron & Mottu 2011) against Arm2DofDynamics and
the disc arms (Coutinho & Hess Coelho) against the paper's two-stage coupling
(mechbal.papers.discs.coupling), along each case's trajectory; and the papers' claims re-checked on the
general model (balanced disc arms: mass matrix diagonal and constant, no gravity or velocity
torque; statically balanced 2-DOF arm: no gravity torque)."""
from functools import lru_cache

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.papers.discs import coupling as cp
from mechbal.papers.arm2dof.runner import arm_from_config
from mechbal.papers.discs.runner import _disc_bodies, parameters_from_config
from mechbal.config import read_case
from mechbal.papers import arm2dof_mechanism, disc_arm_mechanism, disc_design_mechanism
from mechbal.papers import discs as dz
from mechbal.papers import arm2dof as paper_arm2dof
from body_set import body_set_wrench

RTOL = 1e-12


def rel(a, b, floor=0.0):
    """max |a - b| over max |b| (or ``floor`` when larger: for quantities the paper makes zero)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), floor))


# ---- 2-DOF arm ----------------------------------------------------------------------------------
@lru_cache(maxsize=None)
def arm_case():
    config = read_case("arm2dof")
    arm = arm_from_config(config["arm"])
    tt = config["trajectory"]
    t = np.linspace(0.0, tt["duration"], tt["samples"])
    motion = {law: _core.RestToRestTrajectory(tt["start"], tt["end"], tt["duration"], tl).evaluate_batch(t)
              for law, tl in (("cubic", _core.TimeLaw.cubic), ("quintic", _core.TimeLaw.quintic))}
    m_cw1, m_cw2 = config["counterweights"]["m_cw1"], config["counterweights"]["m_cw2"]
    opt = paper_arm2dof.rms_optimal_radii(arm, m_cw1, m_cw2, *motion["cubic"])  # run C of the case
    counterweights = {
        "bare": None,
        "rms_optimal": _core.Arm2DofCounterweights(m_cw1, m_cw2, opt.r_cw1, opt.r_cw2),
        "static": _core.Arm2DofCounterweights(m_cw1, m_cw2, *paper_arm2dof.static_balancing_radii(arm, m_cw1, m_cw2)),
    }
    return arm, motion, counterweights


@pytest.mark.parametrize("law", ["cubic", "quintic"])
@pytest.mark.parametrize("variant", ["bare", "rms_optimal", "static"])
def test_arm2dof_general_model_equals_the_closed_form(variant, law):
    arm, motion, cws = arm_case()
    q, qd, qdd = motion[law]
    cw = cws[variant]
    mech = arm2dof_mechanism(arm, cw)
    fast = _core.Arm2DofDynamics(arm, cw if cw is not None else _core.Arm2DofCounterweights())
    assert mech.joint_names == ["shoulder", "elbow"]
    assert mech.body_names == (["link1", "link2"] if cw is None
                               else ["link1", "link2", "counterweight1", "counterweight2"])
    tau = fast.inverse_dynamics(q, qd, qdd)["tau"]
    assert rel(mech.inverse_dynamics(q, qd, qdd), tau) < RTOL
    general = _core.MechanismDynamics(mech.model)  # the C++ back end ComputedTorque drives
    assert rel(general.inverse_dynamics(q, qd, qdd)["tau"], tau) < RTOL
    M = np.array([fast.mass_matrix(x) for x in q])
    assert rel(mech.mass_matrix(q), M) < RTOL
    G = np.array([fast.gravity(x) for x in q])
    assert rel(mech.gravity_torque(q), G, floor=np.max(np.abs(tau))) < RTOL
    # KDL from the general model (counterweights lumped by KdlChainDynamics) as a third engine
    kdl = _core.KdlChainDynamics(mech.model)
    assert rel(kdl.inverse_dynamics(q, qd, qdd)["tau"], tau) < 1e-10


def test_arm2dof_static_balancing_cancels_gravity_on_the_general_model():
    """m_CW2 r2 = m2 l_S2, m_CW1 r1 = m1 l_S1 + (m2 + m_CW2) l1 (eqs 21-22, 30-31): no gravity
    torque in any pose, and the centre of mass stays on the shoulder axis."""
    arm, _, cws = arm_case()
    rng = np.random.default_rng(4)
    q = rng.uniform(-np.pi, np.pi, (200, 2))
    bare = np.max(np.abs(arm2dof_mechanism(arm).gravity_torque(q)))
    balanced = arm2dof_mechanism(arm, cws["static"])
    assert np.max(np.abs(balanced.gravity_torque(q))) < RTOL * bare
    assert np.max(np.abs(balanced.center_of_mass(q))) < 1e-14
    # and the optimum of run C does not cancel it (the check can fail)
    assert np.max(np.abs(arm2dof_mechanism(arm, cws["rms_optimal"]).gravity_torque(q))) > 1e-3 * bare


def test_arm2dof_computed_torque_drives_the_general_model_like_the_closed_form():
    arm, motion, cws = arm_case()
    q_d, qd_d, qdd_d = motion["cubic"]
    mech = arm2dof_mechanism(arm, cws["rms_optimal"])
    kp, kd = np.array([100.0, 100.0]), np.array([20.0, 20.0])
    fast = _core.Arm2DofDynamics(arm, cws["rms_optimal"])
    general = _core.MechanismDynamics(mech.model)
    ct_fast, ct_general = _core.ComputedTorque(fast, kp, kd), _core.ComputedTorque(general, kp, kd)
    rng = np.random.default_rng(6)
    q = q_d + rng.uniform(-0.05, 0.05, q_d.shape)
    qd = qd_d + rng.uniform(-0.1, 0.1, qd_d.shape)
    a = np.array([ct_fast.step(*x)[0] for x in zip(q, qd, q_d, qd_d, qdd_d)])
    b = np.array([ct_general.step(*x)[0] for x in zip(q, qd, q_d, qd_d, qdd_d)])
    assert rel(b, a) < RTOL


def test_arm2dof_mechanism_refuses_bad_parameters_naming_the_field():
    arm, _, _ = arm_case()
    with pytest.raises(ValueError, match="counterweights.r_cw2"):
        arm2dof_mechanism(arm, {"m_cw1": 1.0, "m_cw2": 1.0, "r_cw1": 0.1})
    with pytest.raises(ValueError, match="arm.l1"):
        arm2dof_mechanism({"m1": 1, "m2": 1, "l1": float("nan"), "l_s1": 0.1, "l_s2": 0.1,
                           "i_s1": 0.1, "i_s2": 0.1})
    with pytest.raises(ValueError, match="mass"):
        arm2dof_mechanism(arm, {"m_cw1": -1.0, "m_cw2": 1.0, "r_cw1": 0.1, "r_cw2": 0.1})


# ---- disc arms ----------------------------------------------------------------------------------
DISC_CASES = {"planar3r": "discs-3r", "spatial3r": "discs-spatial", "scara": "scara"}


@lru_cache(maxsize=None)
def disc_case(kind):
    config = read_case(DISC_CASES[kind])
    p = parameters_from_config(kind, config)
    tt = config["trajectory"]
    t = np.linspace(0.0, tt["duration"], tt["samples"])
    motion = _core.RestToRestTrajectory(tt["start"], tt["end"], tt["duration"],
                                        _core.TimeLaw.quintic).evaluate_batch(t)
    return config, p, motion


def _arm_with_spinning_discs(kind, d, q, qd, qdd):
    """Every body of a serial disc design along (q, qd, qdd): the links from the arm alone
    (`mechbal.papers.discs.arm_mechanism`, no discs), each disc written out by hand: it spins at
    ratio * q[joint] about its axis through its carrier's frame origin (rotation R_c Rot(axis,
    ratio q_j), omega = omega_c + ratio q_j' a, alpha = alpha_c + ratio q_j'' a + omega_c x ratio
    q_j' a), mass 0 (lumped into the carrier) and its own central inertia."""
    joints, links, discs = dz.serial_structure(kind, d)
    m = dz.arm_mechanism(joints, links).body_motion(q, qd, qdd)
    assert np.all(np.asarray(m.status) == 0)
    kin = dict(com=m.com, com_velocity=m.com_velocity, com_acceleration=m.com_acceleration,
               rotation=m.rotation, angular_velocity=m.angular_velocity,
               angular_acceleration=m.angular_acceleration)
    names = [f"link{i + 1}" for i in range(len(links))]
    mass = [b.mass for b in links]
    inertia = [np.asarray(b.inertia, float) for b in links]
    out = {k: [kin[k][:, i] for i in range(len(links))] for k in kin}
    for k, ds in enumerate(discs):
        c = ds.carrier
        Rc, o = m.link_rotation[:, c + 1], m.link_position[:, c + 1]  # link c is the model's link c + 1
        axis = np.asarray(ds.axis, float) / np.linalg.norm(ds.axis)
        a = Rc @ axis
        ang = ds.ratio * q[:, ds.joint]
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        Rrel = np.eye(3) + np.sin(ang)[:, None, None] * K + (1 - np.cos(ang))[:, None, None] * (K @ K)
        wc, alc = kin["angular_velocity"][:, c], kin["angular_acceleration"][:, c]
        spin = ds.ratio * qd[:, ds.joint, None] * a
        r = o - kin["com"][:, c]  # carrier CoM -> disc centre
        names.append(f"disc{k + 4}")
        mass.append(0.0)
        inertia.append(np.diag(ds.inertia))
        out["com"].append(o)
        out["com_velocity"].append(kin["com_velocity"][:, c] + np.cross(wc, r))
        out["com_acceleration"].append(kin["com_acceleration"][:, c] + np.cross(alc, r)
                                       + np.cross(wc, np.cross(wc, r)))
        out["rotation"].append(Rc @ Rrel)
        out["angular_velocity"].append(wc + spin)
        out["angular_acceleration"].append(alc + ds.ratio * qdd[:, ds.joint, None] * a + np.cross(wc, spin))
    return dict(names=names, mass=np.array(mass), inertia_body=np.array(inertia),
                **{k: np.stack(v, 1) for k, v in out.items()})


@pytest.mark.parametrize("balanced", [False, True], ids=["unbalanced", "balanced"])
@pytest.mark.parametrize("kind", list(DISC_CASES))
def test_disc_arm_general_model_equals_the_coupled_model(kind, balanced):
    config, p, (q, qd, qdd) = disc_case(kind)
    d = dz.design(kind, p, balanced)
    mech = disc_arm_mechanism(config, balanced)
    assert mech.joint_names == ["joint1", "joint2", "joint3"]
    n_discs = {"planar3r": 4, "spatial3r": 2, "scara": 2}[kind] if balanced else 0
    assert len(mech.body_names) == 3 + n_discs
    # the paper's two-stage coupling (arm model, then discs), Python, on every 10th sample: the
    # mechanism the case file describes equals it (mass matrix, gravity, velocity terms, torques)
    joints, links, discs = dz.serial_structure(kind, d)
    k = slice(None, None, 10)
    tau = mech.inverse_dynamics(q[k], qd[k], qdd[k])
    assert rel(_core.MechanismDynamics(mech.model).inverse_dynamics(q[k], qd[k], qdd[k])["tau"], tau) < RTOL
    peak = np.max(np.abs(tau))
    M_g, G_g = mech.mass_matrix(q[k]), mech.gravity_torque(q[k])
    V_g = mech.bias_torque(q[k], qd[k]) - G_g
    for i, (qi, qdi) in enumerate(zip(q[k], qd[k])):
        two_stage = cp.arm_with_discs(joints, links, discs, qi, qdi)
        assert rel(M_g[i], two_stage.mass) < RTOL
        assert rel(G_g[i], two_stage.gravity, floor=peak) < RTOL
        assert rel(V_g[i], two_stage.velocity, floor=peak) < RTOL
        assert rel(tau[i], two_stage.mass @ qdd[k][i] + two_stage.velocity + two_stage.gravity, floor=peak) < RTOL

    # every body's motion and the shaking wrench against the arm alone with each disc spun by hand
    # (its gear coupling written out), the wrench summed body by body in numpy
    bodies = _arm_with_spinning_discs(kind, d, q, qd, qdd)
    assert mech.body_names == bodies["names"]
    motion = mech.body_motion(q, qd, qdd)
    for key in ("rotation", "angular_velocity", "angular_acceleration"):
        assert rel(getattr(motion, key), bodies[key]) < RTOL, key
    for key in ("com", "com_velocity", "com_acceleration"):  # discs: massless, axle placed elsewhere
        assert rel(getattr(motion, key)[:, :3], bodies[key][:, :3]) < RTOL, key
    ref_w = body_set_wrench(bodies["mass"], bodies["inertia_body"], bodies["com"],
                            bodies["com_velocity"], bodies["com_acceleration"], bodies["rotation"],
                            bodies["angular_velocity"], bodies["angular_acceleration"])
    w = mech.shaking_wrench(q, qd, qdd)
    # (the balanced planar arms have no shaking force: its scale is sum m |a| of the bodies)
    force_scale = np.sum(bodies["mass"] * np.max(np.linalg.norm(bodies["com_acceleration"], axis=2), axis=0))
    assert rel(w.shaking_force, ref_w["force"], floor=force_scale) < RTOL
    assert rel(w.shaking_moment, ref_w["moment"]) < RTOL
    # the runner's bodies_*.npz: these bodies, and the wrench of their motion
    written = _disc_bodies(kind, d, q, qd, qdd)
    assert written["names"] == bodies["names"]
    assert np.array_equal(written["mass"], bodies["mass"]) and np.array_equal(written["inertia_body"],
                                                                              bodies["inertia_body"])
    for key in ("rotation", "angular_velocity", "angular_acceleration"):
        assert rel(written[key], bodies[key]) < RTOL, key
    assert rel(written["shaking_force"], ref_w["force"], floor=force_scale) < RTOL
    assert rel(written["shaking_moment"], ref_w["moment"]) < RTOL


@pytest.mark.parametrize("kind", list(DISC_CASES))
def test_balanced_disc_arms_are_decoupled_on_the_general_model(kind):
    """The paper's claim (eqs 15-16, 26-27, 36-37), checked on the general model: with the gear
    couplings at beta (gamma), M is diagonal and constant (k_i), C(q, qd) qd = 0 and G = 0, so
    tau_i = k_i q''_i; and without the discs it is not."""
    config, p, (q_t, qd_t, qdd_t) = disc_case(kind)
    q, qd = dz.sample_states(kind, 300, np.random.default_rng(12))
    k = np.asarray(dz.BALANCE[kind](p)["k"])
    mech = disc_arm_mechanism(config, balanced=True)
    M = mech.mass_matrix(q)
    assert rel(M, np.broadcast_to(np.diag(k), M.shape)) < RTOL
    unbalanced = disc_arm_mechanism(config, balanced=False)
    g_scale = np.max(np.abs(unbalanced.gravity_torque(q)))
    assert np.max(np.abs(mech.gravity_torque(q))) < RTOL * g_scale
    tau = mech.inverse_dynamics(q_t, qd_t, qdd_t)
    assert rel(tau, qdd_t * k) < RTOL
    assert np.max(np.abs(mech.bias_torque(q, qd))) < RTOL * np.max(np.abs(unbalanced.bias_torque(q, qd)))
    # the check can fail: the unbalanced arm is coupled, and a 5 % gear-ratio error couples it
    Mu = unbalanced.mass_matrix(q)
    assert np.max(np.abs(Mu - np.einsum("nii->ni", Mu)[:, :, None] * np.eye(3))) > 1e-3 * np.max(k)
    off = disc_design_mechanism(kind, dz.perturbed_design(kind, p, "beta", 0.05)).mass_matrix(q)
    assert np.max(np.abs(off - np.einsum("nii->ni", off)[:, :, None] * np.eye(3))) > 1e-4 * np.max(k)


def test_disc_arm_mechanism_structure_and_refusals():
    config, _, _ = disc_case("planar3r")
    mech = disc_arm_mechanism(config)
    assert mech.body_names == ["link1", "link2", "link3", "disc4", "disc5", "disc6", "disc7"]
    joints = {j.name: j for j in mech.model.description.joints}
    beta = dz.balance_planar3r(parameters_from_config("planar3r", config))["beta"]
    assert (joints["disc5"].parent, joints["disc5"].mimic_joint) == ("joint1", "joint2")
    assert joints["disc5"].mimic_ratio == pytest.approx(beta)
    assert (joints["disc7"].parent, joints["disc7"].mimic_joint) == ("joint2", "joint3")
    assert not mech.model.is_serial_chain  # a tree with gear couplings: not for KDL
    with pytest.raises(ValueError, match="not a serial chain: link 'disc6' hangs from 'joint2'"):
        _core.KdlChainDynamics(mech.model)
    # by case name too; the five-bar is a closed loop, refused
    assert disc_arm_mechanism("scara", balanced=False).body_names == ["link1", "link2", "link3"]
    with pytest.raises(ValueError, match="closed loop"):
        disc_arm_mechanism("five-bar")
    assert isinstance(mech, mechbal.Mechanism)
