"""Closed-loop simulation of any mechanism (issue 10): the controllers drive MechanismDynamics
(open trees and closed loops) as plant and as model, RK4 at the controller rate."""
from __future__ import annotations

import numpy as np
import pytest

from mechbal import _core
import linkages as L
from random_trees import random_tree


def _start(lk, mech):
    g = lk.q_guess(mech)
    return g, np.array([g[mech.joint_names.index(a + "_joint")] for a in lk.actuated])


@pytest.mark.parametrize("name", ["four_bar", "five_bar"])
def test_computed_torque_on_a_closed_linkage_follows_the_error_dynamics(name):
    """With an exact model, e'' + Kd e' + Kp e = 0 (Arakelian et al. 2011, eq 6) per actuated joint,
    up to RK4's truncation error, when the law is evaluated in every stage."""
    lk = getattr(L, name)()
    mech = lk.mechanism()
    g, qa0 = _start(lk, mech)
    plant = _core.MechanismDynamics(mech.model, g)
    model = _core.MechanismDynamics(mech.model, g)
    n = qa0.size
    kp, kd = np.full(n, 100.0), np.full(n, 20.0)
    ct = _core.ComputedTorque(model, kp, kd)
    desired = _core.RestToRestTrajectory(qa0, qa0 + 0.3, 1.0, _core.TimeLaw.quintic)
    e0 = np.full(n, 0.02)
    log = _core.simulate_closed_loop(plant, ct, desired, qa0 - e0, np.zeros(n), 1e-3, 1.0, "every_rk4_stage")
    assert log["steps_completed"] == 1000
    err = log["q_des"] - log["q"]
    expected = np.array([[_core.pd_error_analytic(e0[i], 0.0, kp[i], kd[i], np.array([t]))[0]
                          for i in range(n)] for t in log["t"]])
    assert np.abs(err - expected).max() < 1e-8
    # the plant's own loops stayed closed: the last solved pose satisfies the closure
    m = mech.closed_motion(log["q"][-1], np.zeros(n), np.zeros(n), q_guess=plant.solved_position)
    assert m.status == 0 and m.residual < 1e-12


def test_decoupled_controller_drives_an_open_tree_plant():
    """DecoupledJointController (tau = k (qdd_d + Kp e + Kd e')) on a plant whose mass matrix is not
    k: the loop runs, stays finite and tracks; ComputedTorque over the same model tracks better."""
    rng = np.random.default_rng(4)
    mech = random_tree(rng, 4, types="R").mechanism()
    n = mech.dof
    plant = _core.MechanismDynamics(mech.model)
    q0 = np.zeros(n)
    desired = _core.RestToRestTrajectory(q0, q0 + 0.2, 1.0, _core.TimeLaw.quintic)
    k = np.diag(mech.mass_matrix(q0)).copy()
    dec = _core.DecoupledJointController(k, np.full(n, 400.0), np.full(n, 40.0))
    log_dec = _core.simulate_closed_loop(plant, dec, desired, q0, np.zeros(n), 1e-3, 1.0)
    ct = _core.ComputedTorque(_core.MechanismDynamics(mech.model), np.full(n, 400.0), np.full(n, 40.0))
    log_ct = _core.simulate_closed_loop(plant, ct, desired, q0, np.zeros(n), 1e-3, 1.0)
    for log in (log_dec, log_ct):
        assert log["steps_completed"] == 1000 and np.isfinite(log["q"]).all()
    e_dec = np.abs(log_dec["q_des"] - log_dec["q"]).max()
    e_ct = np.abs(log_ct["q_des"] - log_ct["q"]).max()
    assert e_ct < 1e-3 and e_ct < e_dec


def test_forward_dynamics_inverts_inverse_dynamics_on_a_closed_linkage():
    lk = L.five_bar()
    mech = lk.mechanism()
    g, qa = _start(lk, mech)
    dyn = _core.MechanismDynamics(mech.model, g)
    rng = np.random.default_rng(8)
    v, a = rng.normal(size=qa.size), rng.normal(size=qa.size)
    tau = dyn.inverse_dynamics(qa[None], v[None], a[None])["tau"][0]
    assert np.allclose(dyn.forward_dynamics(qa, v, tau), a, rtol=0, atol=1e-10)
    with pytest.raises(ValueError, match="open mechanism with passive joints"):
        tree = random_tree(rng, 3, types="R").mechanism()
        d = tree.model.description
        import mechbal

        under = mechbal.Mechanism.from_description(d.joints, d.bodies, actuated=[tree.joint_names[0]])
        _core.MechanismDynamics(under.model)
