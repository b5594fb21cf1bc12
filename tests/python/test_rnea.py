"""mechbal's own recursive Newton-Euler / CRBA (MechanismDynamics on serial chains) against Pinocchio, an independent
engine, on random 3-, 6- and 7-joint chains (revolute and prismatic, arbitrary axes): torques, base
support wrench, mass matrix, gravity, bias and Coriolis terms to 1e-9 relative."""
import numpy as np
import pytest

import mechbal
from conftest import chain_from_specs, random_chain_specs

pin = pytest.importorskip("pinocchio")
from test_pinocchio import (  # noqa: E402  (the same chains and checks as the KDL test)
    assert_chain_dynamics_match_pinocchio, random_chain_and_pinocchio)


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


@pytest.mark.parametrize("types,seed", [("RRR", 21), ("RPR", 22), ("RRRRRR", 23), ("PRRPRR", 24),
                                        ("RRRRRRR", 25), ("RRPRRRP", 26)])
def test_rnea_matches_pinocchio(types, seed):
    rng = np.random.default_rng(seed)
    model, pm = random_chain_and_pinocchio(rng, types, rotate_base=True)
    assert_chain_dynamics_match_pinocchio(mechbal.MechanismDynamics(model), pm, rng, N=15)


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
