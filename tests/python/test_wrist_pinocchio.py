"""The reactionless wrist's momentum matrix N (Briot & Arakelian 2009, eq 23 as corrected) and its
rate term against Pinocchio, an independent engine: the z-x-z wrist built as a serial chain
(three slides for the platform, then revolute z, x, z) with the paper's wrist inertias."""
import numpy as np
import pytest

from mechbal import _core

pin = pytest.importorskip("pinocchio")


def wrist_in_pinocchio(inertias):
    model = pin.Model()
    parent = 0
    for axis in ("X", "Y", "Z"):  # the platform translates (massless here: only rotation matters)
        parent = model.addJoint(parent, getattr(pin, f"JointModelP{axis}")(), pin.SE3.Identity(), f"p{axis}")
    for joint, J in zip((pin.JointModelRZ(), pin.JointModelRX(), pin.JointModelRZ()), inertias):
        parent = model.addJoint(parent, joint, pin.SE3.Identity(), "")
        # zero mass, centre of mass at the wrist centre, body-frame inertia J (link frame = joint frame)
        model.appendBodyToJoint(parent, pin.Inertia(0.0, np.zeros(3), J), pin.SE3.Identity())
    return model


def test_wrist_momentum_matrix_matches_pinocchio():
    p = _core.PaminsaParameters()
    J = [np.diag(v) for v in p.wrist_inertia]
    model = wrist_in_pinocchio(J)
    data = model.createData()
    rng = np.random.default_rng(11)
    for _ in range(20):
        x, xd, xdd = rng.uniform(-0.5, 0.5, 3), rng.normal(size=3), rng.normal(size=3)
        q, qd, qdd = rng.uniform(-3, 3, 3), rng.normal(size=3), rng.normal(size=3)
        Q, V, A = (np.concatenate(v) for v in ((x, q), (xd, qd), (xdd, qdd)))
        # total mass is zero: Pinocchio's centroidal frame is ill-defined, so take the angular
        # momentum of each body about its own centre from the spatial quantities directly
        pin.forwardKinematics(model, data, Q, V, A)
        H, dH = np.zeros(3), np.zeros(3)
        for j in range(4, 7):
            R = data.oMi[j].rotation
            Iw = R @ J[j - 4] @ R.T
            w = R @ data.v[j].angular
            wdot = R @ data.a[j].angular  # classical = spatial for the angular part
            H += Iw @ w
            dH += Iw @ wdot + np.cross(w, Iw @ w)
        N = _core.wrist_momentum_matrix(*J, q)
        bias = _core.wrist_momentum_bias(*J, q, qd)
        np.testing.assert_allclose(N @ qd, H, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(N @ qdd + bias, dH, rtol=1e-11, atol=1e-11)
        # the wrist's momentum matrix is the angular block of Pinocchio's centroidal-like map:
        # dH/dqd computed by Pinocchio's joint Jacobians
        pin.computeJointJacobians(model, data, Q)
        N_pin = np.zeros((3, 3))
        for j in range(4, 7):
            Jj = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            R = data.oMi[j].rotation
            N_pin += R @ J[j - 4] @ R.T @ Jj[3:, 3:]
        np.testing.assert_allclose(N, N_pin, rtol=1e-12, atol=1e-12)
