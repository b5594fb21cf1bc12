"""2-DOF arm of Arakelian, Le Baron & Mottu 2011: closed form vs KDL vs Pinocchio vs the sympy
Lagrangian, RMS-optimal counterweights (Cardano vs scipy), the general RMS method on chains, closed loop,
and the `mechbal run arm2dof` case."""
import json

import numpy as np
import pytest

from mechbal import _core
from mechbal.balance import rms
from mechbal.papers import arm2dof as paper

pin = pytest.importorskip("pinocchio")

START, END = np.array([0.0, 1.1526]), np.array([0.5236, 1.6762])


def random_arm(rng):
    return _core.Arm2DofParameters(m1=rng.uniform(0.5, 3), m2=rng.uniform(0.5, 3),
                                   l1=rng.uniform(0.1, 0.6), l_s1=rng.uniform(-0.1, 0.3),
                                   l_s2=rng.uniform(-0.1, 0.3), i_s1=rng.uniform(0.01, 0.3),
                                   i_s2=rng.uniform(0.01, 0.3))


def pin_model_of_chain(chain):
    """Pinocchio model of a serial MechanismDescription with one body per joint, in joint order."""
    m = pin.Model()
    parent = 0
    for j, b in zip(chain.joints, chain.bodies):
        jid = m.addJoint(parent, pin.JointModelRevoluteUnaligned(np.asarray(j.axis)),
                         pin.SE3(j.placement[:3, :3], j.placement[:3, 3]), j.name)
        m.appendBodyToJoint(jid, pin.Inertia(b.mass, np.asarray(b.com), np.asarray(b.inertia)),
                            pin.SE3.Identity())
        parent = jid
    m.gravity.linear = np.asarray(chain.gravity)
    return m


def motion(law, N=201, T=1.0):
    t = np.linspace(0, T, N)
    return t, _core.RestToRestTrajectory(START, END, T, law).evaluate_batch(t)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_closed_form_kdl_and_pinocchio_agree(seed):
    rng = np.random.default_rng(seed)
    arm = _core.Arm2DofParameters() if seed == 0 else random_arm(rng)
    cw = _core.Arm2DofCounterweights(rng.uniform(0, 8), rng.uniform(0, 3), rng.uniform(-0.1, 0.4),
                                     rng.uniform(-0.1, 0.4))
    for c in (_core.Arm2DofCounterweights(), cw):
        chain = _core.arm2dof_description(arm, c)
        pm = pin_model_of_chain(chain)
        pd = pm.createData()
        N = 25
        q, qd, qdd = rng.uniform(-3, 3, (N, 2)), rng.uniform(-2, 2, (N, 2)), rng.uniform(-5, 5, (N, 2))
        t_cf = _core.Arm2DofDynamics(arm, c).inverse_dynamics(q, qd, qdd)["tau"]
        t_kdl = _core.KdlChainDynamics(_core.MechanismModel(chain)).inverse_dynamics(q, qd, qdd)["tau"]
        t_pin = np.array([pin.rnea(pm, pd, q[k], qd[k], qdd[k]) for k in range(N)])
        scale = np.maximum(1.0, np.linalg.norm(t_pin, axis=1))
        assert np.max(np.linalg.norm(t_cf - t_pin, axis=1) / scale) < 1e-9
        assert np.max(np.linalg.norm(t_kdl - t_pin, axis=1) / scale) < 1e-9


def test_corrected_eq14_is_the_lagrangian_and_printed_one_is_not():
    """Sympy: Lagrange's equations of the arm (+ counterweights) give corrected eqs 14-15/23-24;
    the printed eq 14 (-k32 theta2'^2 without sin theta2) does not."""
    sp = pytest.importorskip("sympy")
    t = sp.symbols("t")
    m1, m2, l1, ls1, ls2, Is1, Is2, g, mc1, mc2, r1, r2 = sp.symbols(
        "m1 m2 l1 ls1 ls2 Is1 Is2 g mc1 mc2 r1 r2", real=True)
    th1, th2 = sp.Function("th1")(t), sp.Function("th2")(t)

    def pt(x):  # position, z up, in the x-z plane
        return sp.Matrix([x[0], x[1]])

    u1 = sp.Matrix([sp.cos(th1), sp.sin(th1)])
    u12 = sp.Matrix([sp.cos(th1 + th2), sp.sin(th1 + th2)])
    B = l1 * u1
    pts = [(m1, ls1 * u1), (m2, B + ls2 * u12), (mc1, -r1 * u1), (mc2, B - r2 * u12)]
    T = sum(m * (p.diff(t).dot(p.diff(t))) / 2 for m, p in pts)
    T += Is1 * th1.diff(t) ** 2 / 2 + Is2 * (th1.diff(t) + th2.diff(t)) ** 2 / 2
    V = sum(m * g * p[1] for m, p in pts)
    L = T - V
    tau = [sp.expand(L.diff(q.diff(t)).diff(t) - L.diff(q)) for q in (th1, th2)]
    arm = dict(m1=2.5, m2=2.0, l1=0.4, l_s1=0.1, l_s2=0.1, i_s1=0.15, i_s2=0.1)
    cw = (7.4, 2.0, 0.23, 0.17)
    subs_par = {m1: 2.5, m2: 2.0, l1: 0.4, ls1: 0.1, ls2: 0.1, Is1: 0.15, Is2: 0.1, g: 9.81,
                mc1: cw[0], mc2: cw[1], r1: cw[2], r2: cw[3]}
    rng = np.random.default_rng(4)
    dyn = _core.Arm2DofDynamics(_core.Arm2DofParameters(**arm), _core.Arm2DofCounterweights(*cw))
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2), rng.uniform(-3, 3, 2)
        s = {th1.diff(t, 2): qdd[0], th2.diff(t, 2): qdd[1]}
        s2 = {th1.diff(t): qd[0], th2.diff(t): qd[1]}
        s3 = {th1: q[0], th2: q[1]}
        ref = [float(e.subs(s).subs(s2).subs(s3).subs(subs_par)) for e in tau]
        got = dyn.inverse_dynamics(q[None], qd[None], qdd[None])["tau"][0]
        assert np.allclose(got, ref, rtol=1e-12, atol=1e-12)
        # printed eq 14 (bare arm): -k32 theta2'^2 instead of -k32 theta2'^2 sin theta2
        ref_bare = float(tau[0].subs(s).subs(s2).subs(s3).subs({**subs_par, mc1: 0, mc2: 0}))
        bare = _core.Arm2DofDynamics(_core.Arm2DofParameters(**arm))
        correct = bare.inverse_dynamics(q[None], qd[None], qdd[None])["tau"][0][0]
        k32 = 2.0 * 0.4 * 0.1  # eq 20: k32 = m2 l1 l_S2
        printed = correct + k32 * qd[1] ** 2 * np.sin(q[1]) - k32 * qd[1] ** 2
        assert abs(correct - ref_bare) < 1e-12 * max(1.0, abs(ref_bare))
        assert abs(printed - ref_bare) > 1e-6


def test_eqs_33_38_match_three_point_interpolation_of_the_dynamics():
    arm = _core.Arm2DofParameters()
    _, (q, qd, qdd) = motion(_core.TimeLaw.cubic)
    r2 = 0.17
    c11, c12, c13, c21, c22 = paper.cw_coefficients(arm, 7.4, 2.0, r2, q, qd, qdd)
    tau0 = paper.arm_torques(arm, None, q, qd, qdd)
    a1, b1, g1 = rms.quadratic_in_radius(
        lambda r: paper.arm_torques(arm, _core.Arm2DofCounterweights(7.4, 2.0, r, r2), q, qd, qdd)[:, 0])
    a2, b2, g2 = rms.quadratic_in_radius(
        lambda r: paper.arm_torques(arm, _core.Arm2DofCounterweights(7.4, 2.0, 0.0, r), q, qd, qdd)[:, 1])
    for x, y in ((a1, c11), (b1, c12), (g1, tau0[:, 0] + c13), (a2, c21), (b2, c22), (g2, tau0[:, 1])):
        assert np.max(np.abs(x - y)) < 1e-10


def test_cubic_roots_against_numpy():
    rng = np.random.default_rng(7)
    three = 0
    for _ in range(500):
        a, b, c = rng.normal(size=3) * rng.choice([0.1, 1, 10])
        ours = np.sort(rms.cubic_real_roots(a, b, c))
        ref = np.roots([1, a, b, c])
        ref = np.sort(ref[np.abs(ref.imag) < 1e-7 * max(1, np.max(np.abs(ref)))].real)
        if len(ref) != len(ours):  # near-confluent: numpy's tiny imaginary parts
            continue
        three += len(ours) == 3
        assert np.allclose(ours, ref, atol=1e-8 * max(1, np.max(np.abs(ref))))
    assert three > 50
    # confluent case: (z - 1)^2 (z + 2) = z^3 - 3z + 2
    assert np.allclose(sorted(rms.cubic_real_roots(0.0, -3.0, 2.0)), [-2.0, 1.0])


@pytest.mark.parametrize("case", ["paper", "quintic", "random"])
def test_cardano_optimum_matches_scipy_and_beats_every_root(case):
    rng = np.random.default_rng(3)
    arm = random_arm(rng) if case == "random" else _core.Arm2DofParameters()
    law = _core.TimeLaw.quintic if case == "quintic" else _core.TimeLaw.cubic
    m1, m2 = (rng.uniform(1, 8), rng.uniform(0.5, 3)) if case == "random" else (7.4, 2.0)
    _, (q, qd, qdd) = motion(law, N=1001 if case == "paper" else 301)
    res = paper.rms_optimal_radii(arm, m1, m2, q, qd, qdd)
    r_num = paper.rms_optimal_radii_numerical(arm, m1, m2, q, qd, qdd)
    assert abs(res.r_cw1 - r_num[0]) < 1e-6 and abs(res.r_cw2 - r_num[1]) < 1e-6

    def ms(r1, r2):
        tau = paper.arm_torques(arm, _core.Arm2DofCounterweights(m1, m2, r1, r2), q, qd, qdd)
        return np.mean(tau ** 2, axis=0)

    best = ms(res.r_cw1, res.r_cw2)
    for r in res.roots2:
        assert best[1] <= ms(0.0, r)[1] + 1e-12
    for r in res.roots1:
        assert best[0] <= ms(r, res.r_cw2)[0] + 1e-12
    assert best[1] <= ms(*r_num)[1] + 1e-12 and best[0] <= ms(r_num[0], res.r_cw2)[0] + 1e-12
    # and no nearby radius does better (it is a minimum, not just a stationary point)
    for dr in (-1e-3, 1e-3):
        assert best[1] < ms(res.r_cw1, res.r_cw2 + dr)[1]
        assert best[0] < ms(res.r_cw1 + dr, res.r_cw2)[0]
    if case == "paper":
        assert abs(res.r_cw1 - 0.25) < 2e-3          # paper: 0.25 m, reproduced
        assert abs(res.r_cw2 - 0.147) > 0.04          # paper: 0.147 m, NOT reproduced (0.191)


def test_cubic_with_three_real_roots_keeps_the_least_rms():
    # alpha r^2 + beta r + d with a double-well: Delta tau has two minima; the deeper one wins
    alpha = np.array([1.0, 1.0, 0.5])
    beta = np.array([0.0, 0.3, -0.1])
    d = np.array([-1.0, -1.2, -0.4])
    a, b, c = rms.stationarity_cubic(alpha, beta, d)
    roots = rms.cubic_real_roots(a, b, c)
    assert len(roots) == 3
    vals = [rms.squared_sum(alpha, beta, d, r) for r in roots]
    grid = np.linspace(-5, 5, 200001)
    best_grid = grid[np.argmin([(np.sum((alpha * x * x + beta * x + d) ** 2)) for x in grid[::100]]) * 100]
    assert abs(roots[int(np.argmin(vals))] - best_grid) < 0.01


def chain_mechanism(chain):
    """A serial chain's general model (its base placement folded into the first joint) as a
    Mechanism."""
    import mechbal

    return mechbal.Mechanism(chain, name="chain")


def mean_square_torque(mech, slots, design, q, qd, qdd):
    """sum_j mean_i tau_j^2 of ``mech`` with point masses (mass, signed distance) on the slots' lines."""
    bodies = [_core.Body(s.name, s.link, float(m), r * np.asarray(s.direction) / np.linalg.norm(s.direction),
                         np.zeros((3, 3)), "counterweight") for s, (m, r) in zip(slots, design)]
    return float(np.sum(np.mean(mech.with_bodies(bodies).inverse_dynamics(q, qd, qdd) ** 2, axis=0)))


def test_rms_method_with_mass_budget_on_a_3_joint_chain():
    """The general RMS method (all slots together, masses free under a budget) on a random 3R
    chain: no random feasible design beats its optimum, and the budget holds."""
    from conftest import chain_from_specs, random_chain_specs
    from mechbal.balance import CounterweightSlot

    rng = np.random.default_rng(5)
    mech = chain_mechanism(chain_from_specs(random_chain_specs(rng, "RRR")))
    links = [j.name for j in mech.model.description.joints]
    t = np.linspace(0, 1, 101)
    q, qd, qdd = _core.RestToRestTrajectory(np.zeros(3), np.array([0.8, -0.5, 0.6]), 1.0,
                                            _core.TimeLaw.cubic).evaluate_batch(t)
    fixed = [CounterweightSlot(f"cw{i}", links[i], 1.0, 1.0, max_radius=0.5, direction=(1.0, 0.3 * i, 0.0))
             for i in range(3)]
    free = [CounterweightSlot(f"cw{i}", links[i], 0.0, 2.0, max_radius=0.5, direction=(1.0, 0.3 * i, 0.0))
            for i in range(3)]
    best_fixed = rms.balance(mech, fixed, (q, qd, qdd), coupling="total", starts=4)
    best_budget = rms.balance(mech, free, (q, qd, qdd), coupling="total", mass_budget=2.0, starts=4)
    J = lambda res: float(np.sum(np.asarray(res.metrics["rms_torque_after"]) ** 2))  # noqa: E731
    masses = [best_budget.design[f"cw{i}"]["mass"] for i in range(3)]
    assert sum(masses) <= 2.0 + 1e-6 and min(masses) >= -1e-9
    for _ in range(50):  # no random feasible design beats the optimum
        r = rng.uniform(-0.5, 0.5, 3)
        assert J(best_fixed) <= mean_square_torque(mech, fixed, zip(np.ones(3), r), q, qd, qdd) + 1e-9
        m = rng.dirichlet(np.ones(3)) * 2.0
        assert J(best_budget) <= mean_square_torque(mech, free, zip(m, r), q, qd, qdd) + 1e-9


def test_rms_method_honours_the_chain_base_placement():
    """Issue 11: the old n-joint sizing ignored the chain's base transform. On the general model
    (the base folded into the first joint) a tilted base changes the gravity torques; the RMS method's torques before
    and after are those of KDL on the same (tilted) chain, without and with the counterweight."""
    from conftest import chain_from_specs, random_chain_specs
    from mechbal.balance import CounterweightSlot
    from mechbal.spec import transform_xyz_rpy

    rng = np.random.default_rng(8)
    specs = random_chain_specs(rng, "RRR")
    base = transform_xyz_rpy((0.1, -0.2, 0.3), (0.7, -0.4, 0.2))
    chain = chain_from_specs(specs, base=base)
    t = np.linspace(0, 1, 41)
    q, qd, qdd = _core.RestToRestTrajectory(np.zeros(3), np.array([0.8, -0.5, 0.6]), 1.0,
                                            _core.TimeLaw.cubic).evaluate_batch(t)
    mech = chain_mechanism(chain)
    link = mech.model.description.joints[1].name
    res = rms.balance(mech, [CounterweightSlot("m", link, 1.5, 1.5, max_radius=0.5, center=(0.05, 0.0, 0.0),
                                               direction=(1.0, 0.2, 0.0))], (q, qd, qdd), coupling="total")
    kdl = _core.KdlChainDynamics(chain).inverse_dynamics(q, qd, qdd)["tau"]
    rms_of = lambda tau: np.sqrt(np.mean(tau ** 2, axis=0))  # noqa: E731
    np.testing.assert_allclose(res.metrics["rms_torque_before"], rms_of(kdl), rtol=1e-9)
    level = _core.KdlChainDynamics(chain_from_specs(specs)).inverse_dynamics(q, qd, qdd)["tau"]
    assert np.max(np.abs(level - kdl)) > 1e-2
    np.testing.assert_allclose(res.metrics["rms_torque_after"], rms_of(res.balanced.inverse_dynamics(q, qd, qdd)),
                               rtol=1e-12)


def test_closed_loop_exact_model_follows_eq6_and_controller_holds_on_nan():
    arm = _core.Arm2DofParameters()
    plant, model = _core.Arm2DofDynamics(arm), _core.Arm2DofDynamics(arm)
    ctrl = _core.ComputedTorque(model, np.array([100.0, 100.0]), np.array([20.0, 20.0]))
    traj = _core.RestToRestTrajectory(START, END, 1.0, _core.TimeLaw.cubic)
    e0 = np.array([0.05, -0.03])
    log = _core.simulate_computed_torque(plant, ctrl, traj, START - e0, np.zeros(2), 1e-3, 2.0,
                                         "every_rk4_stage")
    assert log["status"] == _core.Status.ok
    e_ref = np.stack([_core.pd_error_analytic(e0[j], 0.0, 100.0, 20.0, log["t"]) for j in range(2)], 1)
    assert np.max(np.abs(log["q_des"] - log["q"] - e_ref)) < 1e-6
    tau, st = ctrl.step(START, np.zeros(2), END, np.zeros(2), np.zeros(2))
    assert st == _core.Status.ok
    held, st = ctrl.step(np.array([np.nan, 0.0]), np.zeros(2), END, np.zeros(2), np.zeros(2))
    assert st == _core.Status.non_finite_input and np.array_equal(held, tau)
    with pytest.raises(ValueError, match="kp"):
        _core.ComputedTorque(model, np.array([100.0, -1.0]), np.array([20.0, 20.0]))
    with pytest.raises(ValueError, match="sampling"):
        _core.simulate_computed_torque(plant, ctrl, traj, START, np.zeros(2), 1e-3, 1.0, "bogus")


@pytest.fixture(scope="module")
def arm2dof_run(tmp_path_factory):
    from mechbal.cases import run_case

    out = tmp_path_factory.mktemp("arm2dof")
    return out, run_case("arm2dof", out)


def test_case_reproduces_the_paper_or_records_why_not(arm2dof_run):
    out, s = arm2dof_run
    s = json.loads((out / "summary.json").read_text())
    for key in ("r_cw_general", "paper_r_cw", "rms_joint_torque", "peak_joint_torque", "rms_reduction_pct",
                "peak_reduction_pct", "first_step_readings", "max_tracking_error",
                "discrepancies"):
        assert key in s
    for k in ("A", "B", "C"):
        assert len(s["rms_joint_torque"][k]) == 2 and len(s["peak_joint_torque"][k]) == 2
    assert np.allclose(s["r_cw_general"], s["r_cw_numerical"], atol=1e-6)
    # sized by mechbal.balance.rms (Cardano on the torque regressor), the paper's cubic beside it
    r = s["r_cw"]
    assert r["general_method"] == s["r_cw_general"] and r["general_method"] == pytest.approx([0.2509, 0.1913], abs=5e-5)
    assert r["max_abs_difference"] < 1e-10 < r["tolerance"]
    assert np.allclose(r["general_method"], r["closed_form"], atol=1e-10)
    assert r["method"]["coupling"] == "per_joint" and r["method"]["exact"]
    assert all("Cardano" in how for how in r["method"]["how"])
    # step 1 = law B + counterweights at the static radii: the paper's 71/59 % and 63/50 %
    r2 = s["first_step_readings"]["reading_2_B_with_cw_at_static_radii_vs_A"]
    assert np.array_equal(np.floor(r2["rms_reduction_pct"]), [71, 59])
    assert np.array_equal(np.floor(r2["peak_reduction_pct"]), [63, 50])
    r1 = s["first_step_readings"]["reading_1_trajectory_only_B_vs_A"]
    assert max(r1["rms_reduction_pct"]) < 20 and max(r1["peak_reduction_pct"]) < 0
    # paper radii: peaks within one point of the paper's 67/66 %
    assert np.allclose(s["peak_reduction_pct"]["C_paper_radii_vs_A"], [67, 66], atol=1.0)
    # our optimum beats the paper's radii on RMS at both joints
    assert np.all(np.array(s["rms_joint_torque"]["C"]) < np.array(s["rms_joint_torque"]["C_paper_radii"]))
    assert any("0.147" in d for d in s["discrepancies"])
    assert s["kdl_vs_closed_form_max_rel_dev"] < 1e-9
    assert s["general_model_vs_closed_form_max_rel_dev"] < 1e-12
    cl = s["closed_loop"]
    dev = cl["with_initial_error"]["max_deviation_from_eq6"]
    assert dev["exact_every_rk4_stage"] < 1e-6
    assert 1e-6 < dev["exact_zero_order_hold"] < 1e-3
    assert dev["perturbed_worst_corner"] > 1e-3
    trk = s["max_tracking_error"]
    assert trk["exact"] < 1e-3 < trk["perturbed"] < 0.1
    assert cl["saturated_ticks"] > 0


def test_case_bodies_files_follow_the_schema(arm2dof_run):
    from mechbal.export import read_bodies, shaking_wrench_by_finite_differences

    out, _ = arm2dof_run
    for k, nb in (("A", 2), ("B", 2), ("C", 4)):
        d = read_bodies(out / f"bodies_{k}.npz")
        assert d["mass"].shape == (nb,)
        F, M = shaking_wrench_by_finite_differences(d)
        sl = slice(5, -5)  # the cubic law's acceleration jumps at the ends
        scale = np.max(np.abs(d["shaking_force"]))
        assert np.max(np.abs(F[sl] - d["shaking_force"][sl])) < 2e-3 * scale
        assert np.max(np.abs(M[sl] - d["shaking_moment"][sl])) < 2e-3 * np.max(np.abs(d["shaking_moment"]))
    c = read_bodies(out / "bodies_C.npz")
    assert list(c["names"])[2:] == ["counterweight1", "counterweight2"]


def test_case_config_errors_name_the_field(tmp_path):
    from mechbal.cases import run_case
    from mechbal.config import ConfigError, case_path

    text = case_path("arm2dof").read_text()
    for old, new, field in (("m1 = 2.5", "m1 = -2.5", "arm.m1"),
                            ("kp = [100.0, 100.0]", "kp = [100.0]", "controller.kp")):
        bad = tmp_path / f"bad_{field}.toml"
        bad.write_text(text.replace(old, new, 1))
        with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
            run_case(bad, tmp_path / "out")
