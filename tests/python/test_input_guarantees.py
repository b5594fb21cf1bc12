"""Issue 14: nothing absurd passes as ok, nothing garbage leaves a binding.

Deterministic checks of each boundary (checked array conversion, named size errors, no unwritten
memory, NaN refused where there is no status, a status per batch instant, construction gaps),
then hypothesis property tests, one per real-time step, with the property "no crash, finite
output, a status for every rejected input" (bounded: max_examples per test, no deadline)."""
import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from mechbal import _core
from conftest import chain_from_specs, random_chain_specs

S = _core.Status


def flags(s):
    return int(s)


def has(s, flag):
    return bool(int(s) & int(flag))


def all_finite(d):
    return all(np.all(np.isfinite(np.asarray(v, dtype=float))) for k, v in d.items()
               if isinstance(v, np.ndarray) and v.dtype.kind in "fiu")


@pytest.fixture(scope="module")
def paminsa():
    return _core.PaminsaModel(_core.PaminsaParameters())


@pytest.fixture(scope="module")
def wrist_J():
    p = _core.PaminsaParameters()
    return [np.diag(v) for v in p.wrist_inertia]


@pytest.fixture(scope="module")
def chain():
    return chain_from_specs(random_chain_specs(np.random.default_rng(7), "RRPR"))


def five_bar():
    p = _core.FiveBarParameters(a1=0.3, a2=0.3, b1=0.4, b2=0.4, d=0.2, mp1=1.0, mp2=1.0, md1=0.8,
                                md2=0.8, mP=0.5, cp1=0.15, cp2=0.15, cd1=0.2, cd2=0.2, Jp1=0.01,
                                Jp2=0.01, Jd1=0.01, Jd2=0.01)
    return _core.FiveBarDynamics(p)


# ------------------------------------------------------------------------ checked conversion
def test_complex_string_bool_object_and_ragged_arrays_are_refused_naming_the_argument(chain, wrist_J):
    ct = _core.ComputedTorque(_core.Arm2DofDynamics(_core.Arm2DofParameters()), [100, 100], [20, 20])
    z = np.zeros(2)
    with pytest.raises(TypeError, match=r"v must be an array of real numbers.*complex"):
        ct.step(z, np.array([1 + 1j, 0]), z, z, z)
    with pytest.raises(TypeError, match=r"q_des must be .*strings"):
        ct.step(z, z, ["1.0", "2.0"], z, z)
    with pytest.raises(TypeError, match=r"q must be .*booleans"):
        ct.step(np.array([True, False]), z, z, z, z)
    with pytest.raises(TypeError, match=r"a_des must be .*objects"):
        ct.step(z, z, z, z, np.array([object(), object()]))
    with pytest.raises(TypeError, match=r"v_des must be .*not an array of numbers"):
        ct.step(z, z, z, [[1.0], [1.0, 2.0]], z)
    rne = _core.MechanismDynamics(chain)
    n = chain.dof
    with pytest.raises(TypeError, match=r"a must be .*complex"):
        rne.inverse_dynamics(np.zeros((1, n)), np.zeros((1, n)), np.zeros((1, n), complex))
    w = _core.ReactionlessWrist(*wrist_J, _core.ReactionlessWristConfig(), [1.5, 1.5, 1.5], [0, 0, 0])
    with pytest.raises(TypeError, match=r"D_dot must be .*strings"):
        w.step_euler([0.0, 0.0, 0.0], ["0", "0", "0"])
    with pytest.raises(TypeError, match=r"J2 must be .*complex"):
        _core.wrist_momentum_matrix(wrist_J[0], wrist_J[1] * 1j, wrist_J[2], [0.1, 0.2, 0.3])
    # integer arrays, lists and tuples of real numbers are accepted and equal the float result
    t_list, s_list = ct.step([0, 0], (0, 0), [1, 2], [0, 0], np.array([0, 0], dtype=np.int64))
    t_float, s_float = ct.step(z, z, np.array([1.0, 2.0]), z, z)
    assert s_list == s_float and np.array_equal(t_list, t_float)


def test_size_errors_name_the_argument_the_expected_and_the_received_shape(chain, wrist_J):
    dc = _core.DecoupledJointController([1.0, 2.0, 0.5], [100.0] * 3, [20.0] * 3)
    z = np.zeros(3)
    with pytest.raises(ValueError, match=r"v must have shape \(3,\) \(the controller has 3 joints\), got \(4,\)"):
        dc.step(z, np.zeros(4), z, z, z)
    w = _core.ReactionlessWrist(*wrist_J, _core.ReactionlessWristConfig(), [1.5, 1.5, 1.5], [0, 0, 0])
    with pytest.raises(ValueError, match=r"D_half must have shape \(3,\), got \(3, 1\)"):
        w.step(z, z, np.zeros((3, 1)), z)
    kdl = _core.KdlChainDynamics(chain)
    with pytest.raises(ValueError, match=r"v must have shape \(4,\) \(one value per joint\), got \(2,\)"):
        kdl.coriolis(np.zeros(4), np.zeros(2))
    with pytest.raises(ValueError, match=r"a must have shape \(5, 4\), got \(5, 3\)"):
        kdl.inverse_dynamics(np.zeros((5, 4)), np.zeros((5, 4)), np.zeros((5, 3)))


# --------------------------------------------------------------------- no unwritten memory
def test_kdl_per_sample_functions_raise_instead_of_returning_unwritten_memory(chain):
    kdl = _core.KdlChainDynamics(chain)
    n = chain.dof
    bad = np.array([0.1, np.nan, 0.0, 0.2])
    for call in (lambda: kdl.mass_matrix(bad), lambda: kdl.gravity(bad),
                 lambda: kdl.coriolis(bad, np.zeros(n)), lambda: kdl.coriolis(np.zeros(n), bad)):
        with pytest.raises(ValueError, match="NaN or infinite"):
            call()
    with pytest.raises(ValueError, match="overflowed"):
        kdl.coriolis(np.zeros(n), np.full(n, 1e200))
    M = kdl.mass_matrix(np.full(n, 0.3))
    assert np.all(np.isfinite(M)) and np.allclose(M, M.T)


def test_leg_points_give_zeros_and_a_status_on_failure(paminsa):
    p = _core.PaminsaParameters()
    good, s = paminsa.leg_points(p.nominal_platform)
    assert s == S.ok and np.all(np.isfinite(good)) and np.abs(good).max() > 0.1
    for P, expect in (([np.nan, 0.0, 0.6], S.non_finite_input), ([5.0, 5.0, 0.6], S.singular),
                      ([1e300, 0.0, 0.6], S.singular)):
        pts, s = paminsa.leg_points(np.array(P))
        assert s == expect
        assert np.array_equal(pts, np.zeros((3, 6, 3)))


def _platform_at_guide_pivot(model, p, leg=0):
    """P that puts A_i exactly on its guide pivot M_i: A_h = (k B_h - C_h)/(k - 1) with
    C_h = P_h + (C_i - P)_h, so C_h = k B_h - (k - 1) M_i."""
    j_off = [(-p.a, -p.b), (-p.a, p.b), (p.d, 0.0)][leg]
    B, M = model.slider_lines[leg], model.guide_pivots[leg]
    C = p.k * B - (p.k - 1.0) * M
    return np.array([C[0] - j_off[0], C[1] - j_off[1], p.nominal_platform[2]])


def test_paminsa_guide_pivot_is_singular_not_nan(paminsa):
    """Issue 14: angle_of of a zero vector (A_i on M_i) gave NaN with Status.ok."""
    p = _core.PaminsaParameters()
    P = _platform_at_guide_pivot(paminsa, p)
    pts, s = paminsa.leg_points(P)
    assert s == S.singular and np.all(pts == 0.0)
    z = np.zeros((1, 3))
    out = _core.paminsa_kinematics(paminsa, P[None], z, z, np.full((1, 3), 1.5), z, z)
    assert out["status_per_instant"][0] == flags(S.singular)
    assert all_finite(out)
    # a hair away from the pivot the leg is solved and finite
    pts, s = paminsa.leg_points(P + np.array([1e-6, 0.0, 0.0]))
    assert s == S.ok and np.all(np.isfinite(pts))


def test_functions_without_a_status_refuse_nan(wrist_J):
    q = [0.1, 0.2, 0.3]
    with pytest.raises(ValueError, match="angles must be finite"):
        _core.wrist_momentum_matrix(*wrist_J, [0.1, np.nan, 0.3])
    with pytest.raises(ValueError, match="J3 must be finite"):
        _core.wrist_momentum_matrix(wrist_J[0], wrist_J[1], np.where(wrist_J[2] > 0, np.inf, 0.0), q)
    with pytest.raises(ValueError, match="rates must be finite"):
        _core.wrist_momentum_bias(*wrist_J, q, [np.inf, 0.0, 0.0])
    arm = _core.Arm2DofDynamics(_core.Arm2DofParameters())
    for call in (lambda: arm.mass_matrix([np.nan, 0.0]), lambda: arm.gravity([0.0, np.inf]),
                 lambda: arm.coriolis_matrix([0.0, 0.0], [np.nan, 0.0]),
                 lambda: arm.kinetic_energy([0.0, 0.0], [0.0, np.nan]),
                 lambda: arm.potential_energy([np.nan, 0.0])):
        with pytest.raises(ValueError, match="must be finite"):
            call()
    with pytest.raises(ValueError, match="overflowed"):
        arm.kinetic_energy([0.0, 0.0], [1e200, 1e200])
    traj = _core.RestToRestTrajectory([0.0, 0.0], [1.0, 2.0], 1.0)
    with pytest.raises(ValueError, match="t must be finite"):
        traj.evaluate(np.nan)
    with pytest.raises(ValueError, match="times must be finite"):
        traj.evaluate_batch(np.array([0.0, np.inf]))


# ------------------------------------------------------------------ per-instant batch status
def _three_rows(n, good):
    """Rows: good, NaN, finite but overflowing (speeds of 1e200)."""
    q = np.tile(good, (3, 1)).astype(float)
    qd = np.tile(0.3 * good, (3, 1)).astype(float)
    q[1, 0] = np.nan
    qd[2, :] = 1e200
    return q, qd


def test_batch_functions_return_a_status_per_instant_and_never_ok_on_overflow(chain, paminsa):
    n = chain.dof
    q, qd = _three_rows(n, np.linspace(0.2, 0.5, n))
    qdd = np.ones((3, n))
    expect = [flags(S.ok), flags(S.non_finite_input), flags(S.out_of_range)]
    outs = {
        "MechanismDynamics.inverse_dynamics (chain)": _core.MechanismDynamics(chain).inverse_dynamics(q, qd, qdd),
        "KdlChainDynamics.inverse_dynamics": _core.KdlChainDynamics(chain).inverse_dynamics(q, qd, qdd),
    }
    # the model's batch kinematics (every body's motion) reports its status per instant in `status`;
    # a failed instant is NaN (rotations: identity), never numbers that pass for a result
    kin = _core.mechanism_kinematics(chain, q, qd, qdd)
    assert list(kin["status"]) == expect
    for key, value in kin.items():
        if key != "status" and np.ndim(value) >= 2:
            assert np.all(np.isfinite(value[0])), key   # the good instant is whole
    for key in ("com", "com_velocity", "com_acceleration"):
        assert np.all(np.isnan(kin[key][1])) and np.all(np.isnan(kin[key][2])), key
    assert np.array_equal(kin["rotation"][1], np.broadcast_to(np.eye(3), kin["rotation"][1].shape))
    arm = _core.Arm2DofDynamics(_core.Arm2DofParameters())
    q2, qd2 = _three_rows(2, np.array([0.3, -0.4]))
    outs["Arm2DofDynamics.inverse_dynamics"] = arm.inverse_dynamics(q2, qd2, np.ones((3, 2)))
    outs["Arm2DofDynamics.forward_dynamics"] = arm.forward_dynamics(q2, qd2, np.ones((3, 2)))
    fb = five_bar()
    q5, qd5 = _three_rows(2, np.array([1.9, 1.2]))
    outs["FiveBarDynamics.inverse_dynamics"] = fb.inverse_dynamics(q5, qd5, np.ones((3, 2)))
    outs["FiveBarDynamics.motion"] = fb.motion(q5, qd5, np.ones((3, 2)))
    outs["FiveBarDynamics.evaluate"] = fb.evaluate(q5, qd5)
    from mechbal.papers import disc_arm_mechanism

    discs = _core.MechanismDynamics(disc_arm_mechanism("discs-3r").model)  # geared discs
    q3, qd3 = _three_rows(3, np.array([0.1, 0.2, 0.3]))
    outs["MechanismDynamics.inverse_dynamics"] = discs.inverse_dynamics(q3, qd3, np.ones((3, 3)))
    # the model's shaking wrench and base reaction: the same per-instant statuses; a failed instant
    # is NaN, the good one whole
    sw = _core.mechanism_shaking_wrench(chain, q, qd, qdd, True)
    assert list(sw["status"]) == expect
    for key, value in sw.items():
        if key != "status":
            assert np.all(np.isfinite(value[0])) and np.all(np.isnan(value[1:])), key
    # PAMINSA kinematics: a good pose, NaN, wrist rates of 1e200
    P = np.tile(_core.PaminsaParameters().nominal_platform, (3, 1))
    z3 = np.zeros((3, 3))
    qw = np.full((3, 3), 1.5)
    qw[1, 1] = np.nan
    qdw = np.zeros((3, 3))
    qdw[2] = 1e200
    outs["paminsa_kinematics"] = _core.paminsa_kinematics(paminsa, P, z3, z3, qw, qdw, z3)
    for name, out in outs.items():
        assert list(out["status_per_instant"]) == expect, name
        assert flags(out["status"]) == expect[1] | expect[2], name
        assert all_finite(out), name


# ---------------------------------------------------------------------- construction gaps
def test_construction_refuses_what_would_give_infinite_or_zero_results(chain):
    with pytest.raises(ValueError, match="rate_hz"):
        _core.ReactionlessWristConfig(rate_hz=5e-324)
    with pytest.raises(ValueError, match="max_rate"):
        _core.ReactionlessWristConfig(max_rate=np.inf)
    with pytest.raises(ValueError, match="duration"):
        _core.RestToRestTrajectory([0.0], [1.0], 5e-324)
    with pytest.raises(ValueError, match="max_speed"):
        _core.DecoupledJointController([1.0], [1.0], [1.0], max_speed=np.nan)
    with pytest.raises(ValueError, match="max_speed"):
        _core.DecoupledJointController([1.0], [1.0], [1.0], max_speed=0.0)
    # no hidden limit (issue 37): undeclared (and +inf) means none
    _core.DecoupledJointController([1.0], [1.0], [1.0], max_speed=np.inf)
    arm = _core.Arm2DofDynamics(_core.Arm2DofParameters())
    assert np.all(_core.ComputedTorque(arm, [1, 1], [1, 1]).torque_limit == np.inf)
    assert np.all(_core.ComputedTorque(arm, [1, 1], [1, 1], [np.inf, 3.0]).torque_limit == [np.inf, 3.0])
    # an axis of 1e300 is normalised (its norm overflowed to inf, and the axis to zero)
    specs = random_chain_specs(np.random.default_rng(11), "RR")
    big = [dict(s, axis=s["axis"] * 1e300) for s in specs]
    tau_unit = _core.MechanismDynamics(chain_from_specs(specs)).inverse_dynamics(
        np.ones((1, 2)), np.ones((1, 2)), np.ones((1, 2)))
    tau_big = _core.MechanismDynamics(chain_from_specs(big)).inverse_dynamics(
        np.ones((1, 2)), np.ones((1, 2)), np.ones((1, 2)))
    assert tau_big["status"] == S.ok and np.allclose(tau_big["tau"], tau_unit["tau"], rtol=1e-12)
    # the model scales an axis by its largest component before normalising: an axis of 1e-300 is
    # the unit axis (no underflow to zero); a zero axis is refused, naming the field
    tiny = [dict(s, axis=s["axis"] * 1e-300) for s in specs]
    tau_tiny = _core.MechanismDynamics(chain_from_specs(tiny)).inverse_dynamics(
        np.ones((1, 2)), np.ones((1, 2)), np.ones((1, 2)))
    assert tau_tiny["status"] == S.ok and np.allclose(tau_tiny["tau"], tau_unit["tau"], rtol=1e-12)
    with pytest.raises(ValueError, match=r"joints\[0\] \(j1\)\.axis"):
        chain_from_specs([dict(specs[0], axis=np.zeros(3))])
    assert _core.status_name(S.out_of_range) == "out_of_range"


# ------------------------------------------------------------ property tests (hypothesis)
ANY = st.one_of(st.floats(-5.0, 5.0), st.floats(allow_nan=True, allow_infinity=True),
                st.sampled_from([0.0, 5e-324, 1e5, -2e4, 1e155, 1e300, -1e300]))
MODERATE = st.floats(-5.0, 5.0)


def _vectors(n):
    """Mostly in-range vectors (so that ok, saturated and singular ticks are exercised too), one
    draw in four with any float: NaN, inf, subnormal, absurd."""
    inside = st.lists(MODERATE, min_size=n, max_size=n).map(np.array)
    return st.one_of(inside, inside, inside, st.lists(ANY, min_size=n, max_size=n).map(np.array))


VEC3 = _vectors(3)
VEC2 = _vectors(2)
BOUNDED = settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _nonfinite(*xs):
    return any(not np.all(np.isfinite(x)) for x in xs)


def _peak(*xs):
    return max(float(np.max(np.abs(x))) for x in xs)


@BOUNDED
@given(D=VEC3, Dd=VEC3, Dh=VEC3, Dn=VEC3,
       q0=st.lists(st.floats(-3.2, 3.2), min_size=3, max_size=3).map(np.array),
       rk4=st.booleans())
def test_property_reactionless_wrist_tick(wrist_J, D, Dd, Dh, Dn, q0, rk4):
    cfg = _core.ReactionlessWristConfig(
        integrator=_core.WristIntegrator.rk4 if rk4 else _core.WristIntegrator.euler)
    w = _core.ReactionlessWrist(*wrist_J, cfg, q0, np.zeros(3))
    s = w.step(D, Dd, Dh, Dn)
    event(f"status {_core.status_name(s)}")
    c = w.command
    for v in (c.angles, c.rates, c.accelerations, c.next_angles, w.angles):
        assert np.all(np.isfinite(v))
    assert np.isfinite(c.condition_number)
    assert np.max(np.abs(c.rates)) <= cfg.max_rate * (1 + 1e-12)
    assert np.max(np.abs(c.accelerations)) <= cfg.max_acceleration * (1 + 1e-12)
    used = (D, Dd, Dh, Dn) if rk4 else (D, Dd)
    momenta = (D, Dh, Dn) if rk4 else (D,)
    if _nonfinite(*used):
        assert s == S.non_finite_input
    elif _peak(*momenta) > cfg.max_momentum or _peak(Dd) > cfg.max_moment:
        assert s == S.out_of_range
    else:
        assert flags(s) & ~(flags(S.singular) | flags(S.saturated)) == 0
        if s == S.ok:  # the wrist cancels the mechanism's momentum: N(q0) qdot = 0 - D
            N = _core.wrist_momentum_matrix(*wrist_J, q0)
            assert np.linalg.norm(N @ c.rates + D) <= 1e-9 * (1.0 + np.linalg.norm(D))
    if flags(s) & ~(flags(S.singular) | flags(S.saturated)):
        assert np.array_equal(w.angles, q0) and np.all(c.rates == 0.0)  # held


#: a declared input range of the joint controllers (none is the default: issue 37)
DECLARED = dict(max_position=1e3, max_speed=1e2, max_acceleration=1e4)


def _joint_property(ctl, k_or_none, q, qd, q_des, qd_des, qdd_des, held):
    tau, s = ctl.step(q, qd, q_des, qd_des, qdd_des)
    event(f"status {_core.status_name(s)}")
    limit = ctl.torque_limit
    assert np.all(np.isfinite(tau)) and np.all(np.abs(tau) <= limit)
    if _nonfinite(q, qd, q_des, qd_des, qdd_des):
        assert s == S.non_finite_input and np.array_equal(tau, held)
    elif (_peak(q, q_des) > 1e3 or _peak(qd, qd_des) > 1e2 or _peak(qdd_des) > 1e4):
        assert s == S.out_of_range and np.array_equal(tau, held)
    else:
        assert s in (S.ok, S.saturated)
        return tau, s
    return tau, None


@BOUNDED
@given(q=VEC2, qd=VEC2, q_des=VEC2, qd_des=VEC2, qdd_des=VEC2)
def test_property_computed_torque_tick(q, qd, q_des, qd_des, qdd_des):
    arm = _core.Arm2DofDynamics(_core.Arm2DofParameters())
    kp, kd = np.array([100.0, 80.0]), np.array([20.0, 15.0])
    ct = _core.ComputedTorque(arm, kp, kd, [1e4, 1e4], **DECLARED)  # declared limits (none by default)
    held, s0 = ct.step([0.1, 0.2], [0.0, 0.0], [0.3, 0.1], [0.0, 0.0], [0.0, 0.0])
    assert s0 == S.ok
    tau, s = _joint_property(ct, None, q, qd, q_des, qd_des, qdd_des, held)
    if s is not None:  # eqs 2-4 evaluated independently, then clipped
        v = qdd_des + kp * (q_des - q) + kd * (qd_des - qd)
        law = arm.inverse_dynamics(q[None], qd[None], v[None])["tau"][0]
        expected = np.clip(law, -ct.torque_limit, ct.torque_limit)
        assert np.allclose(tau, expected, rtol=1e-12, atol=1e-9)
        assert (s == S.saturated) == bool(np.any(np.abs(law) > ct.torque_limit))


@BOUNDED
@given(q=VEC3, qd=VEC3, q_des=VEC3, qd_des=VEC3, qdd_des=VEC3)
def test_property_decoupled_joint_controller_tick(q, qd, q_des, qd_des, qdd_des):
    k, kp, kd = np.array([1.0, 2.0, 0.5]), np.array([100.0, 120.0, 150.0]), np.array([20.0, 22.0, 25.0])
    dc = _core.DecoupledJointController(k, kp, kd, [50.0, np.inf, 80.0], **DECLARED)
    held, s0 = dc.step([0.1, 0.2, 0.3], np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3))
    assert s0 == S.ok
    tau, s = _joint_property(dc, k, q, qd, q_des, qd_des, qdd_des, held)
    if s is not None:  # Coutinho & Hess Coelho eqs 15, 26, 36, clipped
        raw = k * (qdd_des + kp * (q_des - q) + kd * (qd_des - qd))
        assert np.allclose(tau, np.clip(raw, -dc.torque_limit, dc.torque_limit), rtol=1e-12, atol=1e-9)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(dP=st.lists(VEC3, min_size=5, max_size=5), Pd=st.lists(VEC3, min_size=5, max_size=5),
       Pdd=st.lists(VEC3, min_size=5, max_size=5), rk4=st.booleans())
def test_property_paminsa_controller_tick(paminsa, dP, Pd, Pdd, rk4):
    """PaminsaController ticks through paminsa_reactionless_run (2 ticks + the reset, platform
    samples every dt/2): every output finite, a status per tick, bad samples flagged."""
    nominal = _core.PaminsaParameters().nominal_platform
    P = nominal + 0.01 * np.array(dP)  # NaN, inf and absurd offsets stay so
    Pd, Pdd = np.array(Pd), np.array(Pdd)
    cfg = _core.ReactionlessWristConfig(
        integrator=_core.WristIntegrator.rk4 if rk4 else _core.WristIntegrator.euler)
    out = _core.paminsa_reactionless_run(paminsa, cfg, [np.pi / 2] * 3, P, Pd, Pdd)
    assert all_finite(out)
    status = out["status_per_instant"]
    assert status.shape == (3,)
    for x in status:
        event(f"tick status {_core.status_name(int(x))}")
    assert np.all(np.abs(out["wrist_rates"]) <= cfg.max_rate * (1 + 1e-12))
    for n in range(3):
        used = [2 * n] + ([min(2 * n + 1, 4), min(2 * n + 2, 4)] if rk4 else [])
        if _nonfinite(*(x[j] for x in (P, Pd, Pdd) for j in used)):
            assert status[n] & flags(S.non_finite_input)
        elif _peak(*(Pd[j] for j in used)) > 10.0 or _peak(*(Pdd[j] for j in used)) > 1000.0:
            assert status[n] & flags(S.out_of_range)
        if status[n] != 0 and not status[n] & (flags(S.singular) | flags(S.saturated)):
            assert np.all(out["wrist_rates"][n] == 0.0)  # held: zero rates


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rows=st.lists(st.lists(ANY, min_size=12, max_size=12), min_size=1, max_size=6))
def test_property_batch_inverse_dynamics(chain, rows):
    a = np.array(rows)
    q, qd, qdd = a[:, :4], a[:, 4:8], a[:, 8:]
    for dyn in (_core.MechanismDynamics(chain), _core.KdlChainDynamics(chain)):
        out = dyn.inverse_dynamics(q, qd, qdd)
        assert all_finite(out)
        per = out["status_per_instant"]
        for x in per:
            event(f"instant status {_core.status_name(int(x))}")
        for k in range(len(rows)):
            if _nonfinite(q[k], qd[k], qdd[k]):
                assert per[k] == flags(S.non_finite_input)
            if per[k] != 0:
                assert np.all(out["tau"][k] == 0.0)
        assert flags(out["status"]) == int(np.bitwise_or.reduce(per))
