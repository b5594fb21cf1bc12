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


@pytest.mark.parametrize("types,seed", [("RRR", 1), ("RPR", 2), ("RRRRRR", 3), ("PRRPRR", 4)])
def test_kdl_matches_pinocchio(types, seed):
    rng = np.random.default_rng(seed)
    specs = random_chain_specs(rng, types)
    base = np.eye(4)
    base[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    gravity = np.array([0.3, -0.2, -9.81])
    model = chain_from_specs(specs, gravity, base)
    pm = pin_model(specs, gravity, base)
    pd = pm.createData()
    kdl = mechbal.KdlChainDynamics(model)
    n = len(types)
    N = 20
    q, qd, qdd = (rng.uniform(-2, 2, (N, n)), rng.uniform(-1.5, 1.5, (N, n)),
                  rng.uniform(-3, 3, (N, n)))
    out = kdl.inverse_dynamics(q, qd, qdd)
    assert out.ok
    for k in range(N):
        tau_pin = pin.rnea(pm, pd, q[k], qd[k], qdd[k])
        rel = np.linalg.norm(out.joint_torque[k] - tau_pin) / max(1.0, np.linalg.norm(tau_pin))
        assert rel < 1e-9, (k, out.joint_torque[k], tau_pin)
        # wrench the base exerts on joint 1's subtree, in the world frame about the origin
        # (rnea does not update oMi: place the joints first)
        pin.forwardKinematics(pm, pd, q[k])
        f_world = pd.oMi[1].act(pd.f[1])
        F_ref = np.concatenate([f_world.linear, f_world.angular])
        F_mb = np.concatenate([out.support_force[k], out.support_moment[k]])
        assert np.linalg.norm(F_mb - F_ref) / max(1.0, np.linalg.norm(F_ref)) < 1e-9
        M_pin = pin.crba(pm, pd, q[k])
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        M_kdl = kdl.mass_matrix(q[k])
        assert np.linalg.norm(M_kdl - M_pin) / np.linalg.norm(M_pin) < 1e-9
        g_pin = pin.computeGeneralizedGravity(pm, pd, q[k])
        assert np.linalg.norm(kdl.gravity(q[k]) - g_pin) / max(1.0, np.linalg.norm(g_pin)) < 1e-9
        c_pin = pin.nle(pm, pd, q[k], qd[k]) - g_pin
        assert np.linalg.norm(kdl.coriolis(q[k], qd[k]) - c_pin) / max(1.0, np.linalg.norm(c_pin)) < 1e-9


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
