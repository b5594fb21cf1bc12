"""KDL chain dynamics (through mechbal) against Pinocchio, an independent engine, on random 3- and
6-joint chains: torques, base wrench, mass matrix, gravity and Coriolis terms to 1e-9 relative."""
import numpy as np
import pytest

import mechbal
from conftest import chain_from_specs, random_chain_specs

pin = pytest.importorskip("pinocchio")


def pin_model(specs, gravity, base):
    model = pin.Model()
    parent = 0
    for i, s in enumerate(specs):
        placement = s["origin"] if i > 0 else base @ s["origin"]
        if s["prismatic"]:
            jm = pin.JointModelPrismaticUnaligned(s["axis"])
        else:
            jm = pin.JointModelRevoluteUnaligned(s["axis"])
        jid = model.addJoint(parent, jm, pin.SE3(placement[:3, :3], placement[:3, 3]), s["name"])
        model.appendBodyToJoint(jid, pin.Inertia(s["mass"], s["com"], s["inertia"]), pin.SE3.Identity())
        parent = jid
    model.gravity.linear = np.asarray(gravity, float)
    return model


def _rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / max(1.0, np.linalg.norm(b))


def random_chain_and_pinocchio(rng, types, rotate_base=False):
    """A random chain (conftest.random_chain_specs) on a random base (turned too when
    `rotate_base`) with a tilted gravity: mechbal's model and Pinocchio's of the same chain."""
    specs = random_chain_specs(rng, types)
    base = np.eye(4)
    if rotate_base:
        base[:3, :3], _ = np.linalg.qr(rng.normal(size=(3, 3)))
        if np.linalg.det(base[:3, :3]) < 0:
            base[:3, 0] *= -1
    base[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    gravity = np.array([0.3, -0.2, -9.81])
    return chain_from_specs(specs, gravity, base), pin_model(specs, gravity, base)


def assert_chain_dynamics_match_pinocchio(dynamics, pm, rng, N):
    """A joint-space back end (KdlChainDynamics, MechanismDynamics) against Pinocchio at N random
    states, 1e-9 relative: torques (rnea), the wrench the base exerts on joint 1's subtree (in
    the world frame about the origin), mass matrix (crba), gravity, Coriolis and, when the back
    end has it, the bias."""
    pd = pm.createData()
    n = pm.nq  # one coordinate per joint
    q, qd, qdd = (rng.uniform(-2, 2, (N, n)), rng.uniform(-1.5, 1.5, (N, n)),
                  rng.uniform(-3, 3, (N, n)))
    out = dynamics.inverse_dynamics(q, qd, qdd)
    assert out.ok
    for k in range(N):
        tau_pin = pin.rnea(pm, pd, q[k], qd[k], qdd[k])
        assert _rel(out.joint_torque[k], tau_pin) < 1e-9, (k, out.joint_torque[k], tau_pin)
        # (rnea does not update oMi: place the joints first)
        pin.forwardKinematics(pm, pd, q[k])
        f_world = pd.oMi[1].act(pd.f[1])
        assert _rel(out.support_force[k], f_world.linear) < 1e-9
        assert _rel(out.support_moment[k], f_world.angular) < 1e-9
        M_pin = pin.crba(pm, pd, q[k])
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        assert np.linalg.norm(dynamics.mass_matrix(q[k]) - M_pin) / np.linalg.norm(M_pin) < 1e-9
        g_pin = pin.computeGeneralizedGravity(pm, pd, q[k])
        assert _rel(dynamics.gravity(q[k]), g_pin) < 1e-9
        b_pin = pin.nle(pm, pd, q[k], qd[k])
        if hasattr(dynamics, "bias"):
            assert _rel(dynamics.bias(q[k], qd[k]), b_pin) < 1e-9
        assert _rel(dynamics.coriolis(q[k], qd[k]), b_pin - g_pin) < 1e-9


@pytest.mark.parametrize("types,seed", [("RRR", 1), ("RPR", 2), ("RRRRRR", 3), ("PRRPRR", 4)])
def test_kdl_matches_pinocchio(types, seed):
    rng = np.random.default_rng(seed)
    model, pm = random_chain_and_pinocchio(rng, types)
    assert_chain_dynamics_match_pinocchio(mechbal.KdlChainDynamics(model), pm, rng, N=20)


def test_shaking_wrench_matches_pinocchio_momentum_rate():
    """mechbal's shaking wrench of a serial chain (the general model's algorithm) against
    Pinocchio's centroidal momentum rate, moved to the base origin."""
    rng = np.random.default_rng(9)
    specs = random_chain_specs(rng, "RRPRRR")
    model = chain_from_specs(specs)
    pm = pin_model(specs, (0, 0, -9.81), np.eye(4))
    pd = pm.createData()
    n = len(specs)
    q, qd, qdd = rng.uniform(-2, 2, (1, n)), rng.uniform(-1, 1, (1, n)), rng.uniform(-2, 2, (1, n))
    sw = mechbal.Mechanism(model).shaking_wrench(q, qd, qdd)
    w = {"force": sw.shaking_force, "moment": sw.shaking_moment, "angular_momentum": sw.angular_momentum}
    dh = pin.computeCentroidalMomentumTimeVariation(pm, pd, q[0], qd[0], qdd[0])
    hg = pd.hg
    c = pd.com[0]
    # about the centre of mass -> about O: H_O = H_G + c x P; dH_O/dt = dH_G/dt + c x dP/dt (+ v_c x P = 0)
    dP = dh.linear
    dHO = dh.angular + np.cross(c, dP)
    HO = hg.angular + np.cross(c, hg.linear)
    assert np.allclose(w["force"][0], dP, rtol=1e-9, atol=1e-9)
    assert np.allclose(w["moment"][0], dHO, rtol=1e-9, atol=1e-9)
    assert np.allclose(w["angular_momentum"][0], HO, rtol=1e-9, atol=1e-9)
