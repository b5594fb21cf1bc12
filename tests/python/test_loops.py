"""Closed loops on the general model (issue 10): invariants on a four-bar, a five-bar, a spatial
R-U-S-R and a parallelogram, and Pinocchio's constrained dynamics (an independent engine, loading
the same tree from URDF with the same closures as rigid point constraints)."""
from __future__ import annotations

import numpy as np
import pytest

from mechbal import _core
import linkages as L

LINKAGES = {"four_bar": L.four_bar, "five_bar": L.five_bar, "rusr": L.rusr,
            "parallelogram": L.parallelogram}
SINGULAR = int(_core.Status.singular)


def _start(lk, mech):
    g = lk.q_guess(mech)
    qa = np.array([g[mech.joint_names.index(a + "_joint")] for a in lk.actuated])
    return g, qa


def _trajectory(qa0, t):
    """A smooth excursion of the actuated joints around qa0 (rad), with exact derivatives."""
    w = 2.0 * np.pi / t[-1]
    amp = 0.25 * (1 + np.arange(len(qa0)))
    q = qa0 + amp * np.sin(w * t)[:, None]
    v = amp * w * np.cos(w * t)[:, None]
    a = -amp * w * w * np.sin(w * t)[:, None]
    return q, v, a


def _rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / max(1.0, np.abs(b).max())


@pytest.mark.parametrize("name", sorted(LINKAGES))
def test_closure_velocities_accelerations_and_virtual_power(name):
    lk = LINKAGES[name]()
    mech = lk.mechanism()
    g, qa0 = _start(lk, mech)
    t = np.linspace(0.0, 1.0, 2001)
    qa, va, aa = _trajectory(qa0, t)
    m = mech.closed_motion(qa, va, aa, q_guess=g, with_forces=True)
    assert np.all(m.status == 0), m.status
    assert m.residual.max() < 1e-12
    # the closure itself, recomputed from the frames of the solved poses
    motion = mech.body_motion(m.q)
    fp = motion.frame_placement
    assert np.abs(fp[:, 0, :3, 3] - fp[:, 1, :3, 3]).max() < 1e-12
    # velocities and accelerations against finite differences of the solved positions
    dt = t[1] - t[0]
    v_fd = (m.q[2:] - m.q[:-2]) / (2 * dt)
    a_fd = (m.q[2:] - 2 * m.q[1:-1] + m.q[:-2]) / dt ** 2
    assert _rel(m.v[1:-1], v_fd) < 1e-5
    assert _rel(m.a[1:-1], a_fd) < 1e-4
    # virtual power: tau# . v# = d/dt (kinetic + potential) of the whole mechanism
    M = mech.mass_matrix(m.q)
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", m.v, M, m.v)
    potential = -mech.total_mass * mech.center_of_mass(m.q) @ mech.gravity
    energy = kinetic + potential
    power_fd = (energy[2:] - energy[:-2]) / (2 * dt)
    power = np.sum(m.actuated_force * va, axis=1)[1:-1]
    assert np.abs(power - power_fd).max() < 1e-5 * max(1.0, np.abs(power).max())
    # shaking wrench = derivative of the momenta along the closed motion
    sw = mech.shaking_wrench(m.q, m.v, m.a)
    P, H = sw.linear_momentum, sw.angular_momentum
    assert _rel(sw.shaking_force[1:-1], (P[2:] - P[:-2]) / (2 * dt)) < 1e-5
    assert _rel(sw.shaking_moment[1:-1], (H[2:] - H[:-2]) / (2 * dt)) < 1e-5


@pytest.mark.parametrize("name", sorted(LINKAGES))
def test_virtual_power_exactly_at_one_instant(name):
    """tau# . v# equals d/dt(T + V) computed from the tree's mass matrix along the exact motion
    (central differences in time of the energy with the loops solved at t +- h)."""
    lk = LINKAGES[name]()
    mech = lk.mechanism()
    g, qa0 = _start(lk, mech)
    rng = np.random.default_rng(1)
    va, aa = rng.normal(size=qa0.size), rng.normal(size=qa0.size)
    h = 1e-5

    def energy(tt):
        m = mech.closed_motion(qa0 + va * tt + 0.5 * aa * tt * tt, va + aa * tt, aa, q_guess=g)
        M = mech.mass_matrix(m.q)
        return 0.5 * m.v @ M @ m.v - mech.total_mass * mech.center_of_mass(m.q) @ mech.gravity

    power_fd = (energy(h) - energy(-h)) / (2 * h)
    tau = mech.actuated_forces(qa0, va, aa, q_guess=g)
    assert abs(tau @ va - power_fd) < 1e-7 * max(1.0, abs(power_fd))


@pytest.mark.parametrize("name", ["four_bar", "five_bar"])
def test_forward_dynamics_matches_pinocchio_constraint_dynamics(name):
    pin = pytest.importorskip("pinocchio")
    lk = LINKAGES[name]()
    mech = lk.mechanism()
    g, qa0 = _start(lk, mech)
    pm = pin.buildModelFromXML(lk.tree.urdf())
    pm.gravity.linear = lk.gravity
    pd = pm.createData()
    idx = [pm.idx_qs[pm.getJointId(n)] for n in mech.joint_names]
    constraints = pin.StdVec_RigidConstraintModel()
    for cname, _, (la, pa), (lb, pb) in lk.closures:
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, pm, pm.getJointId(la + "_joint"),
                                      pin.SE3(np.eye(3), np.array(pa, float)), pm.getJointId(lb + "_joint"),
                                      pin.SE3(np.eye(3), np.array(pb, float)), pin.ReferenceFrame.LOCAL)
        constraints.append(cm)
    cdatas = pin.StdVec_RigidConstraintData()
    for c in constraints:
        cdatas.append(c.createData())
    pin.initConstraintDynamics(pm, pd, constraints, cdatas)
    settings = pin.ProximalSettings(1e-14, 1e-10, 200)
    rng = np.random.default_rng(2)
    act = [mech.joint_names.index(a + "_joint") for a in lk.actuated]
    for _ in range(5):
        qa = qa0 + rng.uniform(-0.2, 0.2, qa0.size)
        va, tau_a = rng.normal(size=qa0.size), rng.normal(size=qa0.size) * 3
        fd = _core.mechanism_closed_forward_dynamics(mech.model, qa, va, tau_a, g)
        assert fd["status"] == 0
        m = mech.closed_motion(qa, va, np.zeros_like(qa), q_guess=g)
        qp, vp, taup = np.zeros(pm.nq), np.zeros(pm.nv), np.zeros(pm.nv)
        qp[idx], vp[idx] = m.q, m.v
        taup[[idx[i] for i in act]] = tau_a
        ddq = pin.constraintDynamics(pm, pd, qp, vp, taup, constraints, cdatas, settings)
        a_full = mech.closed_motion(qa, va, fd["a_actuated"], q_guess=g).a
        assert _rel(a_full, ddq[idx]) < 1e-9


def test_parallel_singularity_is_reported():
    """The parallelogram with its links collinear (crank at 0): A° is singular; the status says so."""
    lk = L.parallelogram()
    mech = lk.mechanism()
    g, qa0 = _start(lk, mech)
    qa = np.linspace(qa0[0], 1e-4, 200)[:, None]
    m = mech.closed_motion(qa, np.ones_like(qa), np.zeros_like(qa), q_guess=g)
    assert m.status[0] == 0 and m.rcond[0] > 0.1
    assert m.rcond[-1] < 1e-3 * m.rcond[0]
    strict = mech.closed_motion(qa[-1:], np.ones((1, 1)), np.zeros((1, 1)), q_guess=m.q[-2],
                                singular_rcond=1e-2)
    assert strict.status[0] & SINGULAR
    assert np.isfinite(m.q).all() and np.isfinite(m.v).all()


def test_a_pose_that_cannot_be_assembled_gives_a_status_and_no_pose():
    """A four-bar whose crank is driven where the coupler cannot reach the rocker."""
    lk = L.four_bar(a=0.2, b=0.3, c=0.2, d=0.6)  # crank at pi: distance 0.8 > b + c
    mech = lk.mechanism()
    g = np.zeros(mech.dof)
    m = mech.closed_motion(np.array([np.pi]), np.zeros(1), np.zeros(1), q_guess=g)
    assert m.status & int(_core.Status.solver_error)
    assert np.all(np.isnan(m.q)) and np.all(np.isnan(m.v))  # never zeros that pass for a pose
    with pytest.raises(ValueError, match="cannot be solved"):
        mech.actuated_forces(np.array([np.pi]), np.zeros(1), np.zeros(1), q_guess=g)


def test_planar_point_closure_equals_the_point_closure():
    lk = L.four_bar()
    point, planar = lk.mechanism(), lk.mechanism(loop_type="planar_point")
    assert point.model.num_constraints == 3 and planar.model.num_constraints == 2
    g, qa0 = _start(lk, point)
    t = np.linspace(0, 1, 50)
    qa, va, aa = _trajectory(qa0, t)
    a = point.closed_motion(qa, va, aa, q_guess=g, with_forces=True)
    b = planar.closed_motion(qa, va, aa, q_guess=g, with_forces=True)
    assert np.all(a.status == 0) and np.all(b.status == 0)
    assert _rel(a.q, b.q) < 1e-12 and _rel(a.a, b.a) < 1e-10
    assert _rel(a.actuated_force, b.actuated_force) < 1e-10


def test_loop_model_errors_name_the_field():
    lk = L.four_bar()
    d = lk.mechanism().model.description
    import mechbal

    with pytest.raises(ValueError, match="actuated: a mechanism with loops must name its actuated joints"):
        mechbal.Mechanism.from_description(d.joints, d.bodies, d.frames, loops=d.loops)
    with pytest.raises(ValueError, match=r"actuated\[0\]: 'crank' is not a joint.*did you mean 'crank_joint'"):
        mechbal.Mechanism.from_description(d.joints, d.bodies, d.frames, loops=d.loops, actuated=["crank"])
    bad = [_core.LoopConstraint("tip", _core.LoopType.point, "tip_a", "tip_c")]
    with pytest.raises(ValueError, match=r"loops\[0\] \(tip\)\.frame_b: no frame named 'tip_c' \(did you mean"):
        mechbal.Mechanism.from_description(d.joints, d.bodies, d.frames, loops=bad, actuated=["crank_joint"])


def test_run_a_user_linkage_toml(tmp_path):
    """`mechbal run four-bar` (a TOML linkage with a counterweight): the loop closes along the run,
    and the exported shaking wrench is that of the exported poses (finite differences)."""
    import json

    from mechbal.cases import run_case
    from mechbal.export import read_bodies, shaking_wrench_by_finite_differences

    out = tmp_path / "fb"
    run_case("four-bar", out)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["closed"] and summary["actuated"] == ["crank"]
    assert summary["loops"]["max_closure_residual"] < 1e-12 and summary["loops"]["singular_instants"] == 0
    data = read_bodies(out / "bodies_nominal.npz")
    F, M = shaking_wrench_by_finite_differences(data)
    scale_F, scale_M = np.abs(data["shaking_force"]).max(), np.abs(data["shaking_moment"]).max()
    assert np.abs(F[2:-2] - data["shaking_force"][2:-2]).max() < 1e-4 * scale_F
    assert np.abs(M[2:-2] - data["shaking_moment"][2:-2]).max() < 1e-4 * scale_M
    # the base reaction differs from the shaking force by the weight
    m = data["mass"].sum()
    assert np.allclose(data["base_reaction_force"] - data["shaking_force"], [0, 0, 9.81 * m], atol=1e-9)
