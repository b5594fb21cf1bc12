"""The general mechanism model against Pinocchio (an independent engine, loading the same random
trees from URDF) and against its own invariants (finite differences of momentum, mass matrix
from inverse dynamics, regressors times parameters)."""
from __future__ import annotations

import zlib

import numpy as np
import pytest

import mechbal
from mechbal import _core
from random_trees import random_tree
from pinocchio_checks import _base_fixed_mass_moment, _rel  # noqa: F401

pin = pytest.importorskip("pinocchio")

RTOL = 1e-9


def _pin_model(tree):
    model = pin.buildModelFromXML(tree.urdf())
    return model, model.createData()


def _index(pm, mech):
    """Pinocchio's q index of each mechbal coordinate (matched by joint name)."""
    return [pm.idx_qs[pm.getJointId(n)] for n in mech.joint_names]


def _states(rng, mech, pm, idx, count):
    for _ in range(count):
        q, v, a = rng.uniform(-2, 2, mech.dof), rng.normal(size=mech.dof), rng.normal(size=mech.dof)
        qp, vp, ap = np.zeros(pm.nq), np.zeros(pm.nv), np.zeros(pm.nv)
        qp[idx], vp[idx], ap[idx] = q, v, a
        yield q, v, a, qp, vp, ap


@pytest.mark.parametrize("types", ["R", "RP", "RRRPF", "RF"])
@pytest.mark.parametrize("merge_fixed", [False, True])
def test_random_trees_match_pinocchio(types, merge_fixed):
    rng = np.random.default_rng(zlib.crc32(f"{types}{merge_fixed}".encode()))
    for trial in range(6):
        tree = random_tree(rng, int(rng.integers(3, 10)), types=types)
        mech = tree.mechanism(merge_fixed=merge_fixed)
        pm, pd = _pin_model(tree)
        idx = _index(pm, mech)
        for q, v, a, qp, vp, ap in _states(rng, mech, pm, idx, 4):
            assert _rel(mech.inverse_dynamics(q, v, a), pin.rnea(pm, pd, qp, vp, ap)[idx]) < RTOL
            M = pin.crba(pm, pd, qp)
            M = (np.triu(M) + np.triu(M, 1).T)[np.ix_(idx, idx)]
            assert _rel(mech.mass_matrix(q), M) < RTOL
            assert _rel(mech.gravity_torque(q), pin.computeGeneralizedGravity(pm, pd, qp)[idx]) < RTOL
            assert _rel(mech.bias_torque(q, v), pin.nonLinearEffects(pm, pd, qp, vp)[idx]) < RTOL
            # centre of mass: Pinocchio's excludes bodies fixed to the base; mechbal's includes them
            c_pin = pin.centerOfMass(pm, pd, qp).copy()
            m_pin = pin.computeTotalMass(pm)
            expected = (m_pin * c_pin + _base_fixed_mass_moment(mech, q)) / mech.total_mass
            assert _rel(mech.center_of_mass(q), expected) < RTOL
            # centroidal momentum and its rate, shifted from the centre of mass to O
            pin.computeCentroidalMomentumTimeVariation(pm, pd, qp, vp, ap)
            c = pd.com[0]
            P, dP = pd.hg.linear.copy(), pd.dhg.linear.copy()
            H_O = pd.hg.angular + np.cross(c, P)
            dH_O = pd.dhg.angular + np.cross(c, dP)
            sw = mech.shaking_wrench(q, v, a)
            assert _rel(sw.linear_momentum, P) < RTOL
            assert _rel(sw.angular_momentum, H_O) < RTOL
            assert _rel(sw.shaking_force, dP) < RTOL
            assert _rel(sw.shaking_moment, dH_O) < RTOL
            assert _rel(mech.momentum_matrix(q) @ v, np.r_[P, H_O]) < RTOL


def test_gear_couplings_match_pinocchio_mimic():
    rng = np.random.default_rng(7)
    checked = 0
    for trial in range(30):
        tree = random_tree(rng, 6, types="RRP", mimic=True)
        if not any(ln.mimic for ln in tree.links):
            continue
        mech = tree.mechanism()
        try:
            pm = pin.buildModelFromXML(tree.urdf(), mimic=True)
        except TypeError:  # pragma: no cover - older Pinocchio without mimic support
            pytest.skip("this Pinocchio has no mimic joints")
        # Pinocchio 3 keeps mimic joints out of q (nq == mechbal's dof) ...
        if pm.nq != mech.dof:
            pytest.skip("this Pinocchio keeps mimic joints in q")
        pd = pm.createData()
        idx = _index(pm, mech)
        for q, v, a, qp, vp, ap in _states(rng, mech, pm, idx, 3):
            assert _rel(mech.inverse_dynamics(q, v, a), pin.rnea(pm, pd, qp, vp, ap)[idx]) < RTOL
            M = pin.crba(pm, pd, qp)
            M = (np.triu(M) + np.triu(M, 1).T)[np.ix_(idx, idx)]
            assert _rel(mech.mass_matrix(q), M) < RTOL
        checked += 1
    assert checked >= 5


def test_gear_coupling_equals_projection_of_the_free_tree():
    """A gear-coupled model equals the uncoupled tree projected by G: tau = G^T tau_free(G q + o),
    M = G^T M_free G. Independent of Pinocchio's mimic support."""
    rng = np.random.default_rng(11)
    for trial in range(10):
        tree = random_tree(rng, 6, types="RRP", mimic=True)
        if not any(ln.mimic for ln in tree.links):
            continue
        coupled = tree.mechanism()
        follower = next(ln for ln in tree.links if ln.mimic)
        master, ratio, offset = follower.mimic
        follower.mimic = None
        free = tree.mechanism()
        names_free, names = free.joint_names, coupled.joint_names
        G = np.zeros((free.dof, coupled.dof))
        o = np.zeros(free.dof)
        for i, n in enumerate(names_free):
            if n == follower.name + "_joint":
                G[i, names.index(master + "_joint")] = ratio
                o[i] = offset
            else:
                G[i, names.index(n)] = 1.0
        for _ in range(4):
            q, v, a = rng.normal(size=coupled.dof), rng.normal(size=coupled.dof), rng.normal(size=coupled.dof)
            qf, vf, af = G @ q + o, G @ v, G @ a
            assert _rel(coupled.inverse_dynamics(q, v, a), G.T @ free.inverse_dynamics(qf, vf, af)) < 1e-12
            assert _rel(coupled.mass_matrix(q), G.T @ free.mass_matrix(qf) @ G) < 1e-12
            sw, swf = coupled.shaking_wrench(q, v, a), free.shaking_wrench(qf, vf, af)
            assert _rel(sw.shaking_moment, swf.shaking_moment) < 1e-12
            assert _rel(coupled.momentum_matrix(q), free.momentum_matrix(qf) @ G) < 1e-12


def test_momentum_rate_is_the_derivative_of_momentum():
    """Finite differences of P and H_O along q(t) = q0 + v0 t + a0 t^2 / 2 give the shaking wrench."""
    rng = np.random.default_rng(3)
    h = 1e-5
    for trial in range(8):
        mech = random_tree(rng, 7).mechanism(merge_fixed=bool(trial % 2))
        q0, v0, a0 = rng.normal(size=mech.dof), rng.normal(size=mech.dof), rng.normal(size=mech.dof)

        def mom(t):
            m = mech.momentum(q0 + v0 * t + 0.5 * a0 * t * t, v0 + a0 * t)
            return np.r_[m.linear_momentum, m.angular_momentum]

        fd = (mom(h) - mom(-h)) / (2 * h)
        sw = mech.shaking_wrench(q0, v0, a0)
        assert _rel(np.r_[sw.shaking_force, sw.shaking_moment], fd) < 1e-7


def test_mass_matrix_is_symmetric_positive_definite_and_equals_inverse_dynamics_columns():
    rng = np.random.default_rng(5)
    for trial in range(8):
        mech = random_tree(rng, 8).mechanism(merge_fixed=True)
        q = rng.normal(size=mech.dof)
        M = mech.mass_matrix(q)
        assert np.allclose(M, M.T, atol=0, rtol=0)
        assert np.linalg.eigvalsh(M).min() > 0
        zero = np.zeros(mech.dof)
        bias = mech.inverse_dynamics(q, zero, zero)
        cols = np.array([mech.inverse_dynamics(q, zero, e) - bias for e in np.eye(mech.dof)]).T
        assert _rel(M, cols) < 1e-12


def test_regressors_times_parameters_equal_the_dynamics():
    rng = np.random.default_rng(9)
    for trial in range(8):
        mech = random_tree(rng, 7, mimic=True).mechanism(merge_fixed=True)
        pi = mech.inertial_parameters()
        q, v, a = rng.normal(size=mech.dof), rng.normal(size=mech.dof), rng.normal(size=mech.dof)
        assert _rel(mech.torque_regressor(q, v, a) @ pi, mech.inverse_dynamics(q, v, a)) < 1e-12
        assert _rel(mech.gravity_regressor(q) @ pi, mech.gravity_torque(q)) < 1e-12
        m = mech.momentum(q, v)
        assert _rel(mech.momentum_regressor(q, v) @ pi, np.r_[m.linear_momentum, m.angular_momentum]) < 1e-12


def test_frame_jacobian_matches_finite_differences_and_pinocchio():
    rng = np.random.default_rng(13)
    tree = random_tree(rng, 7, types="RRP")
    base = tree.mechanism()
    d = base.model.description
    tip = d.joints[-1].name
    frame = _core.Frame("tool", tip, np.array([[0, -1, 0, 0.1], [1, 0, 0, 0.2], [0, 0, 1, -0.05], [0, 0, 0, 1.0]]))
    mech = mechbal.Mechanism.from_description(d.joints, d.bodies, [frame])
    q, v = rng.normal(size=mech.dof), rng.normal(size=mech.dof)
    J = mech.frame_jacobian(q, "tool")
    h = 1e-6
    T1, T0 = mech.frame_placement(q + h * v, "tool"), mech.frame_placement(q - h * v, "tool")
    lin = (T1[:3, 3] - T0[:3, 3]) / (2 * h)
    dR = (T1[:3, :3] - T0[:3, :3]) / (2 * h)
    W = dR @ mech.frame_placement(q, "tool")[:3, :3].T
    ang = np.array([W[2, 1], W[0, 2], W[1, 0]])
    assert _rel(J @ v, np.r_[lin, ang]) < 1e-7
    with pytest.raises(ValueError, match="did you mean 'tool'"):
        mech.frame_jacobian(q, "tol")


def test_batch_equals_single_samples_and_flags_bad_instants():
    rng = np.random.default_rng(17)
    mech = random_tree(rng, 6).mechanism()
    Q, V, A = rng.normal(size=(5, mech.dof)), rng.normal(size=(5, mech.dof)), rng.normal(size=(5, mech.dof))
    Q[2, 0] = np.nan
    V[3, :] = 1e300  # finite but overflows the dynamics
    tau = mech.inverse_dynamics(Q, V, A)
    status = _core.mechanism_inverse_dynamics(mech.model, Q, V, A)["status"]
    assert np.array_equal(tau.status, status)  # the batch result carries its statuses
    assert status[0] == 0 and status[2] == int(_core.Status.non_finite_input)
    assert status[3] == int(_core.Status.out_of_range)
    # a failed instant is NaN, never zeros that pass for a result (issue 24); the others finite
    assert np.all(np.isnan(tau[2])) and np.all(np.isnan(tau[3])) and np.isfinite(tau[tau.ok]).all()
    for k in (0, 1, 4):
        assert np.array_equal(tau[k], mech.inverse_dynamics(Q[k], V[k], A[k]))
    with pytest.raises(ValueError, match="non_finite_input"):
        mech.inverse_dynamics(Q[2], V[2], A[2])
    n = mech.dof
    with pytest.raises(ValueError, match=rf"q must have shape \({n},\) or \(N, {n}\), got \({n - 1},\)"):
        mech.gravity_torque(np.zeros(n - 1))
    with pytest.raises(TypeError, match="real numeric"):
        mech.gravity_torque(np.zeros(n, dtype=complex))


def test_model_construction_errors_name_the_field():
    J, B = _core.Joint, _core.Body
    with pytest.raises(ValueError, match=r"joints\[1\] \(b\)\.parent: no link named 'aa' \(did you mean 'a'\?\)"):
        mechbal.Mechanism.from_description([J("a"), J("b", parent="aa")])
    with pytest.raises(ValueError, match=r"joints\[0\] \(a\)\.axis must be a finite non-zero vector"):
        mechbal.Mechanism.from_description([J("a", axis=np.zeros(3))])
    with pytest.raises(ValueError, match="a cycle"):
        mechbal.Mechanism.from_description([J("a", parent="b"), J("b", parent="a")])
    with pytest.raises(ValueError, match=r"bodies\[0\] \(w\)\.link: no link named 'x'"):
        mechbal.Mechanism.from_description([J("a")], [B("w", "x", 1.0)])
    with pytest.raises(ValueError, match=r"mimic: no joint named 'c'"):
        mechbal.Mechanism.from_description([J("a"), J("b", mimic_joint="c")])
    with pytest.raises(ValueError, match="used by two joints"):
        mechbal.Mechanism.from_description([J("a"), J("a")])
    with pytest.raises(ValueError, match="mass"):
        mechbal.Mechanism.from_description([J("a")], [B("w", "a", -1.0)])
    # an axis of 1e300 is scaled before it is normalised (no overflow to a zero axis)
    m = mechbal.Mechanism.from_description([J("a", axis=np.array([0, 0, 1e300]))], [B("w", "a", 1.0, [1, 0, 0])])
    assert np.allclose(m.model.description.joints[0].axis, [0, 0, 1])
