"""One vocabulary (issue 25): Pinocchio's q, v, a and tau, typed results, and the names of earlier
releases kept one release as deprecated aliases. Each alias here must warn (DeprecationWarning
naming the new name) and give what the new name gives."""
from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import control, simulate, trajectory
from mechbal.balance import CounterweightSlot

ARM = str(Path(mechbal.__file__).parent / "cases" / "arm2link.toml")


@pytest.fixture(scope="module")
def arm() -> mechbal.Mechanism:
    return mechbal.Mechanism.from_toml(ARM)


def _same(old, new):
    if isinstance(new, np.ndarray):
        np.testing.assert_array_equal(np.asarray(old), np.asarray(new))
    else:
        assert old == new


# ---- keyword arguments -------------------------------------------------------------------------
def test_controller_step_and_run_accept_qd_names_with_a_warning(arm):
    ct = control.ComputedTorque(arm, kp=[100.0, 100.0], kd=[20.0, 20.0])
    q, v = np.array([0.1, -0.2]), np.array([0.3, 0.1])
    new = ct.step(q, v=v, q_des=q, v_des=v, a_des=np.ones(2))
    ct.reset()
    with pytest.warns(DeprecationWarning, match="'qd' is deprecated, use 'v'"):
        old = ct.step(q, qd=v, q_des=q, qd_des=v, qdd_des=np.ones(2))
    _same(old.joint_torque, new.joint_torque)
    Q = np.tile(q, (3, 1))
    with pytest.warns(DeprecationWarning, match="'qdd_des' is deprecated, use 'a_des'"):
        run = ct.run(Q, qd=Q * 0, q_des=Q, qd_des=Q * 0, qdd_des=Q * 0)
    _same(run.joint_torque, ct.run(Q, Q * 0, Q, Q * 0, Q * 0).joint_torque)
    with pytest.raises(TypeError, match="both 'qd'"):
        ct.step(q, v=v, q_des=q, v_des=v, a_des=v, qd=v)


def test_step_into_accepts_qd_names_with_a_warning(arm):
    """The fast tick keeps its C++ entry for positional calls; the old keywords go through a
    second overload that warns."""
    ct = control.ComputedTorque(arm, kp=[100.0, 100.0], kd=[20.0, 20.0])
    q, v, z = np.array([0.1, -0.2]), np.array([0.3, 0.1]), np.zeros(2)
    out_new, out_old = np.zeros(2), np.zeros(2)
    assert ct.step_into(q, v, q, v, z, out_new) == 0
    ct.reset()
    with pytest.warns(DeprecationWarning, match="step_into: 'qd_des' is deprecated, use 'v_des'"):
        assert ct.step_into(q, v, q, qd_des=v, a_des=z, out=out_old) == 0
    _same(out_old, out_new)
    with pytest.raises(TypeError, match=r"\(q, v, q_des, v_des, a_des, out\)"):
        ct.step_into(q, v, q, v, z)


def test_dynamics_backends_accept_qd_names_with_a_warning(arm):
    dyn = control.MechanismDynamics(arm.model)
    q, v = np.array([0.1, -0.2]), np.array([0.3, 0.1])
    with pytest.warns(DeprecationWarning, match="'qd' is deprecated, use 'v'"):
        old = dyn.bias(q, qd=v)
    _same(old, dyn.bias(q, v))
    with pytest.warns(DeprecationWarning, match="'qdd' is deprecated, use 'a'"):
        old_id = dyn.inverse_dynamics(q, v, qdd=np.ones(2))
    _same(old_id.joint_torque, dyn.inverse_dynamics(q, v, np.ones(2)).joint_torque)


def test_closed_loop_accepts_qd0_and_its_result_reads_qd_with_a_warning(arm):
    ct = control.ComputedTorque(arm, kp=[100.0, 100.0], kd=[20.0, 20.0])
    traj = trajectory.quintic([0.0, 0.0], [0.3, -0.2], 0.2)
    with pytest.warns(DeprecationWarning, match="'qd0' is deprecated, use 'v0'"):
        res = simulate.closed_loop(arm, ct, traj, q0=[0.01, 0.0], qd0=[0.0, 0.0], dt=1e-3)
    ct.reset()
    new = simulate.closed_loop(arm, ct, traj, q0=[0.01, 0.0], v0=[0.0, 0.0], dt=1e-3)
    _same(res.v, new.v)
    with pytest.warns(DeprecationWarning, match="'qd' is deprecated, use 'v'"):
        _same(res.qd, new.v)
    with pytest.warns(DeprecationWarning, match="'qd_des' is deprecated, use 'v_des'"):
        _same(res.qd_des, new.v_des)
    with pytest.raises(AttributeError):
        res.qdd  # noqa: B018 (never a name of ClosedLoopResult)


def test_trajectory_motion_is_named_and_reads_qd_qdd_with_a_warning():
    m = trajectory.quintic([0.0, 0.0], [1.0, -1.0], 1.0).evaluate(np.linspace(0, 1, 5))
    q, v, a = m  # still a tuple
    assert m.q is q and m.v is v and m.a is a
    with pytest.warns(DeprecationWarning, match="'qd' is deprecated, use 'v'"):
        _same(m.qd, v)
    with pytest.warns(DeprecationWarning, match="'qdd' is deprecated, use 'a'"):
        _same(m.qdd, a)


def test_paper_functions_accept_qd_names_with_a_warning():
    from mechbal.papers import arm2dof

    arm = arm2dof.Arm2DofParameters()
    q, v, a = trajectory.quintic([0.0, 0.0], [1.0, -1.0], 1.0).evaluate(np.linspace(0, 1, 7))
    with pytest.warns(DeprecationWarning, match="'qdd' is deprecated, use 'a'"):
        old = arm2dof.arm_torques(arm, None, q, qd=v, qdd=a)
    _same(old, arm2dof.arm_torques(arm, None, q, v, a))


# ---- typed results that replace dicts ----------------------------------------------------------
def test_mechanism_dynamics_inverse_dynamics_is_typed_accepts_1d_and_keeps_the_dict_keys(arm):
    dyn = control.MechanismDynamics(arm.model)
    q, v, a = np.array([0.1, -0.2]), np.array([0.3, 0.1]), np.array([1.0, -1.0])
    one = dyn.inverse_dynamics(q, v, a)
    assert isinstance(one, control.InverseDynamicsResult)
    assert one.joint_torque.shape == (2,) and one.support_force.shape == (3,) and one.status == 0
    # the same as Mechanism's inverse dynamics, one sample and a batch
    np.testing.assert_allclose(one.joint_torque, arm.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-12)
    Q, V, A = (np.tile(x, (4, 1)) for x in (q, v, a))
    batch = dyn.inverse_dynamics(Q, V, A)
    assert batch.joint_torque.shape == (4, 2) and batch.status.shape == (4,) and batch.ok
    np.testing.assert_allclose(batch.joint_torque, np.tile(one.joint_torque, (4, 1)), rtol=1e-12)
    with pytest.raises(ValueError, match="input rejected"):
        dyn.inverse_dynamics(np.array([np.nan, 0.0]), v, a)
    with pytest.raises(ValueError, match=r"v has shape \(4, 2\), which does not match q \(2,\)"):
        dyn.inverse_dynamics(q, V, a)
    # the dict of earlier releases
    for key, value in (("tau", batch.joint_torque), ("support_force", batch.support_force),
                       ("support_moment", batch.support_moment),
                       ("status_per_instant", batch.status)):
        with pytest.warns(DeprecationWarning, match=rf"result\['{key}'\] is deprecated"):
            _same(batch[key], value)
    with pytest.warns(DeprecationWarning):
        assert batch["status"] == 0
    with pytest.warns(DeprecationWarning, match="'tau' is deprecated, use 'joint_torque'"):
        _same(batch.tau, batch.joint_torque)


def test_kdl_inverse_dynamics_is_the_same_typed_result(arm):
    kdl = control.KdlChainDynamics(arm.model)
    q, v, a = np.array([0.1, -0.2]), np.array([0.3, 0.1]), np.array([1.0, -1.0])
    r = kdl.inverse_dynamics(q, v, a)
    assert isinstance(r, control.InverseDynamicsResult)
    np.testing.assert_allclose(r.joint_torque, arm.inverse_dynamics(q, v, a), rtol=1e-9, atol=1e-9)


def test_arm2dof_dynamics_returns_arrays_like_mechanism_and_keeps_the_dict_keys():
    from mechbal.papers import arm2dof

    dyn = arm2dof.Arm2DofDynamics(arm2dof.Arm2DofParameters())
    mech = arm2dof.arm2dof_mechanism(arm2dof.Arm2DofParameters())
    q, v, a = trajectory.quintic([0.0, 0.0], [1.0, -1.0], 1.0).evaluate(np.linspace(0, 1, 7))
    tau = dyn.inverse_dynamics(q, v, a)
    assert tau.shape == (7, 2) and np.all(tau.status == 0)
    np.testing.assert_allclose(tau, mech.inverse_dynamics(q, v, a), rtol=1e-10, atol=1e-10)
    one = dyn.inverse_dynamics(q[3], v[3], a[3])
    assert one.shape == (2,)
    acc = dyn.forward_dynamics(q, v, tau)   # the round trip gives the accelerations back
    np.testing.assert_allclose(acc, a, rtol=1e-9, atol=1e-9)
    assert dyn.forward_dynamics(q[3], v[3], one).shape == (2,)
    with pytest.warns(DeprecationWarning, match=r"result\['tau'\] is deprecated"):
        _same(tau["tau"], np.asarray(tau))
    with pytest.warns(DeprecationWarning, match=r"result\['qdd'\] is deprecated"):
        _same(acc["qdd"], np.asarray(acc))
    with pytest.warns(DeprecationWarning, match=r"result\['status'\] is deprecated"):
        assert tau["status"] == 0


@pytest.fixture(scope="module")
def five_bar():
    """The balanced five-bar of the shipped case, its typed dynamics and the raw binding (the dict
    of earlier releases), and N states along a quintic, away from the flat poses."""
    from mechbal import _core
    from mechbal.config import read_case
    from mechbal.papers import discs

    d = discs.design("fivebar", discs.parameters_from_config("fivebar", read_case("five-bar")), True)
    typed = discs.fivebar_dynamics(d)
    raw = _core.FiveBarDynamics(typed.parameters)
    q, v, a = trajectory.quintic([0.6, 1.9], [0.9, 2.3], 1.0).evaluate(np.linspace(0, 1, 7))
    return typed, raw, q, v, a


def test_five_bar_inverse_dynamics_returns_arrays_like_mechanism(five_bar):
    from mechbal.mechanism import BatchArray
    from mechbal.papers import discs

    dyn, raw, q, v, a = five_bar
    assert isinstance(dyn, discs.FiveBarDynamics) and mechbal.FiveBarDynamics is discs.FiveBarDynamics
    tau = dyn.inverse_dynamics(q, v, a)
    assert isinstance(tau, BatchArray) and tau.shape == (7, 2) and np.all(tau.status == 0)
    # tau = M' a + v' + g' of evaluate, and the raw binding's torques
    terms = dyn.evaluate(q, v)
    np.testing.assert_allclose(tau, np.einsum("nij,nj->ni", terms.mass_matrix, a) + terms.coriolis_torque
                               + terms.gravity_torque, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(tau, raw.inverse_dynamics(q, v, a)["tau"])
    one = dyn.inverse_dynamics(q[3], v[3], a[3])      # one sample, as Mechanism
    assert one.shape == (2,)
    np.testing.assert_allclose(one, tau[3], rtol=1e-14)
    with pytest.raises(ValueError, match="input rejected"):
        dyn.inverse_dynamics(np.array([np.nan, 1.0]), v[3], a[3])
    bad = dyn.inverse_dynamics(np.vstack([q[:1], [[np.nan, 1.0]]]), v[:2], a[:2])
    assert list(bad.ok) == [True, False] and bad.status[1] != 0
    with pytest.warns(DeprecationWarning, match="'qdd' is deprecated, use 'a'"):
        _same(dyn.inverse_dynamics(q, qd=v, qdd=a), np.asarray(tau))


@pytest.mark.parametrize("key", ["tau", "status", "status_per_instant"])
def test_five_bar_inverse_dynamics_keeps_each_dict_key_with_a_warning(five_bar, key):
    dyn, raw, q, v, a = five_bar
    old = raw.inverse_dynamics(q, v, a)[key]
    new = dyn.inverse_dynamics(q, v, a)
    with pytest.warns(DeprecationWarning, match=rf"result\['{key}'\] is deprecated"):
        value = new[key]
    _same(value, np.asarray(old) if isinstance(old, np.ndarray) else int(old))


@pytest.mark.parametrize("key", ["mass", "velocity", "gravity", "reciprocal_condition", "ok", "status",
                                 "status_per_instant"])
def test_five_bar_evaluate_is_typed_and_keeps_each_dict_key_with_a_warning(five_bar, key):
    from mechbal.papers import discs

    dyn, raw, q, v, _ = five_bar
    new = dyn.evaluate(q, v)
    assert isinstance(new, discs.FiveBarTerms) and new.mass_matrix.shape == (7, 2, 2)
    old = raw.evaluate(q, v)[key]
    with pytest.warns(DeprecationWarning, match=rf"result\['{key}'\] is deprecated \(the result is no "
                                                r"longer a dict\), use result\."):
        value = new[key]
    _same(value, np.asarray(old) if isinstance(old, np.ndarray) else int(old))
    assert key in new and key in new.keys()


@pytest.mark.parametrize("key", ["angles", "rates", "accelerations", "end_effector", "end_effector_velocity",
                                 "end_effector_acceleration", "status", "status_per_instant"])
def test_five_bar_motion_is_typed_and_keeps_each_dict_key_with_a_warning(five_bar, key):
    from mechbal.papers import discs

    dyn, raw, q, v, a = five_bar
    new = dyn.motion(q, v, a)
    assert isinstance(new, discs.FiveBarMotion) and new.q.shape == (7, 4) and new.end_effector.shape == (7, 2)
    old = raw.motion(q, v, a)[key]
    with pytest.warns(DeprecationWarning, match=rf"result\['{key}'\] is deprecated"):
        value = new[key]
    _same(value, np.asarray(old) if isinstance(old, np.ndarray) else int(old))


def test_five_bar_single_samples_drop_the_batch_axis(five_bar):
    dyn, _, q, v, a = five_bar
    terms, motion = dyn.evaluate(q[2], v[2]), dyn.motion(q[2], v[2], a[2])
    batch_terms, batch_motion = dyn.evaluate(q, v), dyn.motion(q, v, a)
    assert terms.mass_matrix.shape == (2, 2) and terms.status.shape == () and bool(terms.ok)
    np.testing.assert_allclose(terms.mass_matrix, batch_terms.mass_matrix[2], rtol=1e-14)
    assert motion.q.shape == (4,) and motion.end_effector.shape == (2,)
    np.testing.assert_allclose(motion.a, batch_motion.a[2], rtol=1e-14)
    np.testing.assert_allclose(motion.q[[0, 2]], q[2], rtol=1e-14)   # the actuated angles are q
    with pytest.raises(ValueError, match="singularity"):
        dyn.motion(np.array([0.4, 0.4]), v[2], a[2])   # the flat pose of the parallelogram


def test_balance_design_is_typed_and_keeps_the_dict_access(arm):
    from mechbal.balance import CounterweightDesign, static

    r = static.balance(arm, [CounterweightSlot("cw1", "shoulder", max_radius=0.5),
                             CounterweightSlot("cw2", "elbow", max_radius=0.5)], samples=50)
    d = r.design["cw2"]
    assert isinstance(d, CounterweightDesign) and d.mass > 0 and d.position.shape == (3,)
    with pytest.warns(DeprecationWarning, match=r"design\[...\]\['mass'\] is deprecated"):
        assert d["mass"] == d.mass
    with pytest.warns(DeprecationWarning):
        assert d.get("method") is None and d.get("link") == d.link
    assert "mass" in d and "method" not in d
    # the plain form (summary.json) is unchanged: the dict of earlier releases
    plain = r.summary()["design"]["cw2"]
    assert plain["mass"] == d.mass and plain["link"] == d.link and "tied_to" not in plain
    assert r.balanced is not None and isinstance(r.balanced, mechbal.Mechanism)


# ---- import mechbal ------------------------------------------------------------------------------
def test_import_mechbal_brings_sweep_export_and_the_balancing_methods():
    code = ("import mechbal; import sys; "
            "print(mechbal.sweep.Sweep.__name__, mechbal.export.__name__, "
            "mechbal.balance.static.balance.__name__, mechbal.balance.rms.__name__)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["Sweep", "mechbal.export", "balance", "mechbal.balance.rms"]


def test_no_deprecation_warning_from_the_new_names(arm):
    """The package's own calls use the new names: a run with warnings as errors passes."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        ct = control.ComputedTorque(arm, kp=[100.0, 100.0], kd=[20.0, 20.0])
        traj = trajectory.quintic([0.0, 0.0], [0.3, -0.2], 0.1)
        simulate.closed_loop(arm, ct, traj, dt=1e-3)
        control.MechanismDynamics(arm.model).inverse_dynamics(np.zeros(2), np.zeros(2), np.zeros(2))
        from mechbal.config import read_case
        from mechbal.papers import discs

        fb = discs.fivebar_dynamics(discs.design("fivebar", discs.parameters_from_config(
            "fivebar", read_case("five-bar")), True))
        q = np.array([[0.6, 1.9]])
        fb.inverse_dynamics(q, q, q), fb.evaluate(q, q), fb.motion(q, q, q)
