"""mechbal's own recursive Newton-Euler / CRBA (MechanismDynamics on serial chains) against Pinocchio, an independent
engine, on random 3-, 6- and 7-joint chains (revolute and prismatic, arbitrary axes): torques, base
support wrench, mass matrix, gravity, bias and Coriolis terms to 1e-9 relative."""
import numpy as np
import pytest

import mechbal
from conftest import chain_from_specs, random_chain_specs

pin = pytest.importorskip("pinocchio")
from test_pinocchio import pin_model  # noqa: E402  (same Pinocchio model builder as the KDL test)


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


@pytest.mark.parametrize("types,seed", [("RRR", 21), ("RPR", 22), ("RRRRRR", 23), ("PRRPRR", 24),
                                        ("RRRRRRR", 25), ("RRPRRRP", 26)])
def test_rnea_matches_pinocchio(types, seed):
    rng = np.random.default_rng(seed)
    specs = random_chain_specs(rng, types)
    base = np.eye(4)
    base[:3, :3], _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(base[:3, :3]) < 0:
        base[:3, 0] *= -1
    base[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    gravity = np.array([0.3, -0.2, -9.81])
    model = chain_from_specs(specs, gravity, base)
    pm = pin_model(specs, gravity, base)
    pd = pm.createData()
    rne = mechbal.MechanismDynamics(model)
    n = len(types)
    N = 15
    q, qd, qdd = (rng.uniform(-2, 2, (N, n)), rng.uniform(-1.5, 1.5, (N, n)),
                  rng.uniform(-3, 3, (N, n)))
    out = rne.inverse_dynamics(q, qd, qdd)
    assert out.ok
    for k in range(N):
        tau_pin = pin.rnea(pm, pd, q[k], qd[k], qdd[k])
        assert _rel(out.joint_torque[k], tau_pin) < 1e-9, (k, out.joint_torque[k], tau_pin)
        pin.forwardKinematics(pm, pd, q[k])
        f_world = pd.oMi[1].act(pd.f[1])
        assert _rel(out.support_force[k], f_world.linear) < 1e-9
        assert _rel(out.support_moment[k], f_world.angular) < 1e-9
        M_pin = pin.crba(pm, pd, q[k])
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        assert _rel(rne.mass_matrix(q[k]), M_pin) < 1e-9
        g_pin = pin.computeGeneralizedGravity(pm, pd, q[k])
        assert _rel(rne.gravity(q[k]), g_pin) < 1e-9
        b_pin = pin.nle(pm, pd, q[k], qd[k])
        assert _rel(rne.bias(q[k], qd[k]), b_pin) < 1e-9
        assert _rel(rne.coriolis(q[k], qd[k]), b_pin - g_pin) < 1e-9


def test_rnea_bad_input_names_the_argument():
    rng = np.random.default_rng(3)
    rne = mechbal.MechanismDynamics(chain_from_specs(random_chain_specs(rng, "RRR")))
    with pytest.raises(ValueError, match=r"v must have shape \(3,\) or \(N, 3\), got \(2, 4\)"):
        rne.inverse_dynamics(np.zeros((2, 3)), np.zeros((2, 4)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"q must have shape \(3,\).*got \(2,\)"):
        rne.mass_matrix(np.zeros(2))
    out = rne.inverse_dynamics(np.array([[0.0, np.nan, 0.0]]), np.zeros((1, 3)), np.zeros((1, 3)))
    assert int(np.bitwise_or.reduce(out.status)) == mechbal.Status.non_finite_input
    assert np.all(np.isfinite(out.joint_torque))


@pytest.mark.parametrize("types,seed", [("RRRRRR", 31), ("RRPRRRR", 32)])
def test_computed_torque_over_rne_agrees_with_kdl(types, seed):
    """ComputedTorque accepts any InverseDynamics back end: over mechbal's RNE it gives the torques
    of the same controller over KDL, and of the law tau = ID_KDL(q, qd, v) with
    v = qdd_d + Kp (q_d - q) + Kd (qd_d - qd) written here in numpy (Arakelian et al. 2011, eqs 2-4),
    to 1e-9 relative."""
    rng = np.random.default_rng(seed)
    chain = chain_from_specs(random_chain_specs(rng, types))
    n = len(types)
    kp, kd = rng.uniform(50.0, 150.0, n), rng.uniform(10.0, 30.0, n)
    rne, kdl = mechbal.MechanismDynamics(chain), mechbal.KdlChainDynamics(chain)
    assert isinstance(rne, mechbal.InverseDynamics) and isinstance(kdl, mechbal.InverseDynamics)
    ct_rne = mechbal.ComputedTorque(rne, kp, kd)
    ct_kdl = mechbal.ComputedTorque(kdl, kp, kd)
    del rne  # the controller keeps its model alive
    for _ in range(20):
        q, qd, q_d, qd_d, qdd_d = (rng.uniform(-1.5, 1.5, n) for _ in range(5))
        tau_rne, s_rne = ct_rne.step(q, qd, q_d, qd_d, qdd_d)
        tau_kdl, s_kdl = ct_kdl.step(q, qd, q_d, qd_d, qdd_d)
        assert s_rne == mechbal.Status.ok and s_kdl == mechbal.Status.ok
        v = qdd_d + kp * (q_d - q) + kd * (qd_d - qd)
        law = kdl.inverse_dynamics(q[None], qd[None], v[None]).joint_torque[0]
        assert _rel(tau_rne, tau_kdl) < 1e-9
        assert _rel(tau_rne, law) < 1e-9
        assert np.linalg.norm(tau_rne) > 1.0  # not a trivially zero command
    with pytest.raises(ValueError, match=rf"q must have shape \({n},\) \(the controller has {n} joints\), got \({n + 1},\)"):
        ct_rne.step(np.zeros(n + 1), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n))
    with pytest.raises(ValueError, match=rf"a_des must have shape \({n},\)"):
        ct_rne.step(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n, 1)))
