"""Motions that minimise shaking (mechbal.plan, issue 43): the planned RMS shaking force is below
the quintic's and within 1e-3 of an independent optimum (the four-bar: another parameterisation
and another solver; PAMINSA's legs and the UR5: the least RMS force of any rest-to-rest motion of
the centre of mass, m L sqrt(12) / T^2, which the centre-of-mass law attains), endpoints and
boundary velocities exact, limits held on a grid ten times finer, infeasible durations refused
with the shortest feasible one, gradients against finite differences, and the exported poses of a
`mechbal run` differentiated numerically give the reported shaking wrench."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

import mechbal.plan as plan
from mechbal.assembly import assemble
from mechbal.config import read_case, trajectory_from_config
from mechbal.errors import ConfigError
from mechbal.mechanism import Mechanism
from mechbal.plan.model import ActuatedModel
from mechbal.schema import validate_case


def _case(name):
    case = validate_case(read_case(name) if isinstance(name, str) else name, warn=False)
    return case, Mechanism.from_spec(case.spec, name=case.case.name)


@pytest.fixture(scope="module")
def four_bar():
    _, mech = _case("four-bar")
    return mech, assemble(mech, np.array([0.0]), branch="open").q


@pytest.fixture(scope="module")
def four_bar_plan(four_bar):
    mech, qg = four_bar
    return plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg)


def _rms_force(mech, qg, traj, t):
    q, v, a = traj.evaluate(t)
    F = ActuatedModel(mech, q_guess=qg).evaluate(q, v, a).wrench[:, :3]
    return float(np.sqrt(np.trapezoid(np.sum(F ** 2, axis=1), t) / (t[-1] - t[0])))


def test_four_bar_below_the_quintic_and_at_an_independent_optimum(four_bar, four_bar_plan):
    """Crank 0 -> pi rest to rest in 0.5 s. Independent optimiser: the crank angle as the cubic
    rest-to-rest law plus u^2 (1 - u)^2 times Chebyshev polynomials (not splines), its RMS force by
    the trapezoid rule on 1001 instants through Mechanism.closed_motion and shaking_wrench only,
    minimised by BFGS on finite-difference gradients (scipy's default)."""
    from numpy.polynomial import chebyshev as C
    from scipy.optimize import minimize

    mech, qg = four_bar
    r = four_bar_plan
    assert r.ok, r.message
    assert r.value < r.quintic_value
    assert r.reduction > 0.25          # a quarter or more of the quintic's RMS force is left on the table
    T, K = 0.5, 10
    t = np.linspace(0.0, T, 1001)
    u, x = t / T, 2 * t / T - 1
    basis = []
    for k in range(K):
        w = C.chebmul(C.chebmul([0.25, 0, -0.25], [0.25, 0, -0.25]), np.eye(K)[k][: k + 1]) * 16
        basis.append([C.chebval(x, w), C.chebval(x, C.chebder(w)) * 2 / T, C.chebval(x, C.chebder(w, 2)) * 4 / T ** 2])
    basis = np.array(basis)
    base = np.pi * np.array([3 * u ** 2 - 2 * u ** 3, (6 * u - 6 * u ** 2) / T, (6 - 12 * u) / T ** 2])

    def mean_square(c):
        q, v, a = base + np.einsum("k,kdn->dn", c, basis)
        m = mech.closed_motion(q[:, None], v[:, None], a[:, None], q_guess=qg)
        F = mech.shaking_wrench(m.q, m.v, m.a).shaking_force
        return np.trapezoid(np.sum(F ** 2, axis=1), t) / T

    independent = np.sqrt(minimize(mean_square, np.zeros(K), method="BFGS", options={"gtol": 1e-8}).fun)
    planned = _rms_force(mech, qg, r.trajectory, t)
    assert planned == pytest.approx(r.value, rel=1e-4)     # the reported value is the motion's
    assert abs(planned - independent) <= 1e-3 * independent, (planned, independent)


def _paminsa_unbalanced():
    pytest.importorskip("mechbal.papers.paminsa")
    from mechbal.papers.paminsa import paminsa_case_toml

    case, mech = _case(tomllib.loads(paminsa_case_toml("paminsa", balanced=False)))
    tr = case.trajectory
    qg = assemble(mech, np.array(tr.start), initial_guess=tr.initial_guess).q
    return mech, tr, qg


def _line_bound(mech, q_start, q_end, T):
    """The least RMS shaking force of any rest-to-rest motion: m |c1 - c0| sqrt(12) / T^2 (the
    centre of mass on the straight line with the cubic profile; F = m c'')."""
    c = mech.center_of_mass(np.array([q_start, q_end]))
    return mech.total_mass * np.linalg.norm(c[1] - c[0]) * np.sqrt(12.0) / T ** 2


def test_paminsa_legs_reach_the_least_rms_force():
    """PAMINSA without counterweights along the paper's cycle (rest to rest between the actuator
    positions of its start and end platform positions): the plan is below the quintic and within
    1e-3 of the bound that the centre-of-mass law (cubic profile) attains, an optimum found in
    another parameterisation (the centre of mass) with no optimiser at all."""
    mech, tr, qg = _paminsa_unbalanced()
    r = plan.min_shaking(mech, tr.start, tr.end, tr.duration, q_guess=qg, control_points=10)
    assert r.ok, r.message
    full = mech.closed_motion(np.array([tr.start, tr.end]), q_guess=qg).q
    bound = _line_bound(mech, full[0], full[1], tr.duration)
    com = plan.com_law(mech, tr.start, tr.end, tr.duration, profile="cubic", q_guess=qg, samples=2001)
    t = com.trajectory.t
    assert com.joints == [mech.actuated_names.index(n) for n in ("leg1_slider", "leg1_guide", "leg3_guide")]
    assert _rms_force(mech, qg, com.trajectory, t) == pytest.approx(bound, rel=1e-6)
    assert r.value < r.quintic_value
    assert bound * (1 - 1e-6) <= r.value <= bound * (1 + 1e-3), (r.value, bound)


def test_paminsa_bang_bang_centre_of_mass_law():
    """The published law: the centre of mass on its straight line with a bang-bang acceleration,
    |F| = 4 m L / T^2 at every instant (the least peak force of a rest-to-rest straight line)."""
    mech, tr, qg = _paminsa_unbalanced()
    com = plan.com_law(mech, tr.start, tr.end, tr.duration, q_guess=qg, samples=401)
    q, v, a = com.trajectory.evaluate(com.trajectory.t)
    F = ActuatedModel(mech, q_guess=qg).evaluate(q, v, a).wrench[:, :3]
    L = np.linalg.norm(com.com_end - com.com_start)
    np.testing.assert_allclose(np.linalg.norm(F, axis=1), 4 * mech.total_mass * L / tr.duration ** 2, rtol=1e-7)
    assert com.max_com_error < 1e-10
    np.testing.assert_allclose(q[[0, -1]], [tr.start, tr.end], atol=1e-9)
    np.testing.assert_allclose(v[[0, -1]], 0.0, atol=1e-9)


def test_ur5_joint_move_reaches_the_least_rms_force():
    """The UR5's joint move of ur5-dh.toml (six joints, 2 s): redundant for its centre of mass
    (the centre-of-mass law does not apply), the plan still reaches the bound within 1e-3."""
    case, mech = _case("ur5-dh")
    tr = case.trajectory
    r = plan.min_shaking(mech, tr.start, tr.end, tr.duration, control_points=16, samples=201)
    assert r.ok, r.message
    bound = _line_bound(mech, tr.start, tr.end, tr.duration)
    assert r.value < r.quintic_value
    assert bound * (1 - 1e-6) <= r.value <= bound * (1 + 1e-3), (r.value, bound)
    with pytest.raises(plan.ComLawNotApplicable, match="not an invertible function"):
        plan.com_law(mech, tr.start, tr.end, tr.duration)


def test_endpoints_and_boundary_velocities_are_exact(four_bar):
    mech, qg = four_bar
    r = plan.min_shaking(mech, [0.2], [2.9], 0.6, start_velocity=[1.5], end_velocity=[-0.5], q_guess=qg,
                         control_points=10)
    assert r.ok, r.message
    q, v, a = r.trajectory.evaluate(np.array([0.0, 0.6]))
    np.testing.assert_allclose(q[:, 0], [0.2, 2.9], rtol=0, atol=1e-9)
    np.testing.assert_allclose(v[:, 0], [1.5, -0.5], rtol=0, atol=1e-9)
    qq, vq, _ = r.quintic.evaluate(np.array([0.0, 0.6]))
    np.testing.assert_allclose(vq[:, 0], [1.5, -0.5], atol=1e-12)
    assert r.value <= r.quintic_value


def test_limits_are_held_on_a_ten_times_finer_grid(four_bar, four_bar_plan):
    """Torque, velocity and acceleration limits that the unconstrained plan exceeds: the plan
    touches them (active_limits) and never exceeds them on a grid ten times finer than the output
    samples (the torques), a hundred times (the spline's velocities and accelerations)."""
    mech, qg = four_bar
    am = ActuatedModel(mech, q_guess=qg)
    t = np.linspace(0.0, 0.5, 2001)
    q, v, a = four_bar_plan.trajectory.evaluate(t)
    free_tau = np.max(np.abs(am.full(q, v, a, torque=True)[3]))
    free_v, free_a = np.max(np.abs(v)), np.max(np.abs(a))
    limits = dict(torque_limit=0.9 * free_tau, velocity_limit=0.95 * free_v, acceleration_limit=0.9 * free_a)
    r = plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, samples=101, **limits)
    assert r.ok, r.message
    assert {a["kind"] for a in r.active_limits} & {"torque", "velocity", "acceleration"}
    assert r.checked_samples == 1001
    tau = am.full(*r.trajectory.evaluate(np.linspace(0.0, 0.5, 1001)), torque=True)[3]
    assert np.max(np.abs(tau)) <= limits["torque_limit"]
    q, v, a = r.trajectory.evaluate(np.linspace(0.0, 0.5, 10001))
    assert np.max(np.abs(v)) <= limits["velocity_limit"]
    assert np.max(np.abs(a)) <= limits["acceleration_limit"]
    assert four_bar_plan.value <= r.value < r.quintic_value


def test_too_short_a_duration_is_refused_with_the_shortest_feasible_one(four_bar):
    mech, qg = four_bar
    with pytest.raises(plan.PlanInfeasible, match=r"shortest feasible duration found is [0-9.]+ s") as info:
        plan.min_shaking(mech, [0.0], [np.pi], 0.3, q_guess=qg, torque_limit=12.0, control_points=10)
    shortest = info.value.shortest_duration
    assert 0.3 < shortest < 0.5
    assert f"{shortest:.4g} s" in str(info.value)
    r = plan.min_shaking(mech, [0.0], [np.pi], shortest * 1.01, q_guess=qg, torque_limit=12.0, control_points=10)
    assert r.ok, r.message


def test_peak_and_weighted_objectives(four_bar, four_bar_plan):
    mech, qg = four_bar
    peak = plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, objective="force_peak", control_points=10)
    assert peak.ok, peak.message
    assert peak.value < peak.quintic_value
    assert peak.value < four_bar_plan.metrics["planned"]["peak_shaking_force"]   # the RMS plan's peak
    moment = plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, objective="moment_rms",
                              moment_point=(0.2, 0.0, 0.1), control_points=10)
    assert moment.ok and moment.value < moment.quintic_value
    w = plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, weights={"force": 1.0, "torque": 10.0},
                         control_points=10)
    assert w.objective == "weighted" and w.ok and w.value < w.quintic_value
    with pytest.raises(ValueError, match="objective must be one of"):
        plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, objective="force")
    with pytest.raises(ValueError, match="unknown key"):
        plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, weights={"forces": 1.0})


def test_the_gradient_is_the_objectives(four_bar):
    """The chained model partials against central differences of the objective itself."""
    from mechbal.plan.min_shaking import _gauss_nodes, _Problem, model_limits
    from mechbal.plan.spline import SplineBasis

    mech, qg = four_bar
    basis = SplineBasis.make(0.5, 9)
    nodes, w = _gauss_nodes(basis.knots, 8)
    boundary = np.array([[0.0], [0.0], [np.pi], [0.0]])
    for objective, weights in (("force_rms", {}), ("moment_rms", {}), ("weighted", {"force": 1, "moment": 2, "torque": 3})):
        prob = _Problem(ActuatedModel(mech, q_guess=qg, moment_point=(0.1, 0, 0.3)), basis, boundary,
                        objective, weights, model_limits(mech), nodes, w)
        prob.need_torque = True
        x = np.linspace(0.3, 2.8, basis.free_count)
        _, g = prob.fun(x)
        h = 1e-6
        fd = np.array([(prob.fun(x + h * e)[0] - prob.fun(x - h * e)[0]) / (2 * h) for e in np.eye(x.size)])
        np.testing.assert_allclose(g, fd, rtol=1e-5, atol=1e-6 * np.max(np.abs(fd)))


def test_mechbal_run_writes_the_plan_and_its_poses_give_its_wrench(tmp_path):
    """`mechbal run four-bar-min-shaking`: motion.npz, the plot, summary.json's plan; the shaking
    wrench stored beside the poses of bodies_nominal.npz is what the poses give differentiated
    numerically (mechbal.export.shaking_wrench_by_finite_differences)."""
    from mechbal.cases import run_case
    from mechbal.export import read_bodies, shaking_wrench_by_finite_differences

    summary = run_case("four-bar-min-shaking", tmp_path / "out")
    out = tmp_path / "out"
    p = summary["plan"]
    assert summary["law"] == "min_shaking" and p["ok"] and p["objective"] == "force_rms"
    assert p["value"] < p["quintic_value"] and p["reduction"] == pytest.approx(1 - p["value"] / p["quintic_value"])
    assert "not_applicable" in p["com_law"]          # a one-joint crank: its centre of mass on a curve
    assert {"motion.npz", "plan_shaking_wrench.png"} <= set(summary["files"])
    motion = np.load(out / "motion.npz")
    assert motion["q"].shape == (501, 3) and list(motion["joint_names"]) == ["crank", "coupler", "rocker"]
    np.testing.assert_allclose(motion["q"][[0, -1], 0], [0.0, np.pi], atol=1e-9)
    data = read_bodies(out / "bodies_nominal.npz")
    F, M = shaking_wrench_by_finite_differences(data)
    inner = slice(2, -2)
    scale = np.max(np.abs(data["shaking_force"]))
    np.testing.assert_allclose(F[inner], data["shaking_force"][inner], atol=2e-3 * scale)
    np.testing.assert_allclose(M[inner], data["shaking_moment"][inner], atol=2e-3 * np.max(np.abs(data["shaking_moment"])))
    rms = np.sqrt(np.trapezoid(np.sum(data["shaking_force"] ** 2, axis=1), data["t"]) / 0.5)
    assert rms == pytest.approx(p["value"], rel=1e-3)


def test_the_case_format_takes_min_shaking_only_with_its_keys():
    raw = read_case("four-bar-min-shaking")
    case = validate_case(raw, warn=False)
    assert case.trajectory.law == "min_shaking" and case.trajectory.objective == "force_rms"
    bad = {**raw, "trajectory": {**raw["trajectory"], "law": "quintic"}}
    with pytest.raises(ConfigError, match=r"trajectory\.objective.*is for law = 'min_shaking'"):
        validate_case(bad, warn=False)
    both = {**raw, "trajectory": {**raw["trajectory"], "weights": {"force": 1.0}}}
    with pytest.raises(ConfigError, match="objective or weights, not both"):
        validate_case(both, warn=False)
    with pytest.raises(ConfigError, match=r"trajectory\.law.*planned motion"):
        trajectory_from_config(case.trajectory, 1)
    short = {**raw, "trajectory": {**raw["trajectory"], "start_velocity": [1.0, 2.0]}}
    from mechbal.plan.case import plan_from_table

    case = validate_case(short, warn=False)
    with pytest.raises(ConfigError, match=r"trajectory\.start_velocity: must have 1 values"):
        plan_from_table(Mechanism.from_spec(case.spec), case.trajectory)


@pytest.mark.parametrize("which", ["four-bar", "ur5-dh"])
def test_exact_partials_against_finite_differences_of_the_library(which, four_bar):
    """The forward-mode partials (mechbal.plan.exact) of the shaking wrench (moment about a point
    off O) and of the actuated torques in the actuated q, v and a, against central differences of
    the library's own Mechanism.closed_motion / inverse_dynamics and shaking_wrench (an
    independent path: no expression graph); the graph's values are the library's."""
    if which == "four-bar":
        mech, qg = four_bar
    else:
        mech, qg = _case("ur5-dh")[1], None
    p = np.array([0.1, -0.2, 0.3])
    am = ActuatedModel(mech, q_guess=qg, moment_point=p)
    assert am.exact is not None and am.exact.nodes > 0
    rng = np.random.default_rng(7)
    na = am.na
    # a closed mechanism's instants in order (each loop solve starts from the one before: one branch)
    qa = np.linspace(0.3, 2.5, 5)[:, None] if mech.is_closed else rng.uniform(-2, 2, (5, na))
    va, aa = rng.normal(0, 3, (5, na)), rng.normal(0, 20, (5, na))
    ev = am.evaluate(qa, va, aa, torque=True, partials=True)

    def library(qa, va, aa):   # [F; M_p] and the actuated torques by the library alone
        if mech.is_closed:
            m = mech.closed_motion(qa, va, aa, q_guess=qg, with_forces=True)
            q, v, a, tau = m.q, m.v, m.a, m.actuated_force
        else:
            q, v, a, tau = qa, va, aa, mech.inverse_dynamics(qa, va, aa)
        sw = mech.shaking_wrench(q, v, a)
        F, M = np.asarray(sw.shaking_force), np.asarray(sw.shaking_moment)
        return np.concatenate([F, M - np.cross(p, F), np.asarray(tau)], axis=1)

    base = library(qa, va, aa)
    graph = am.exact(np.asarray(ev.q), va, aa)
    np.testing.assert_allclose(graph["wrench"], base[:, :6], rtol=0, atol=1e-10 * np.max(np.abs(base[:, :6])))
    np.testing.assert_allclose(graph["torque"], base[:, 6:], rtol=0, atol=1e-10 * np.max(np.abs(base[:, 6:])))
    exact = {"q": np.concatenate([ev.dq, ev.torque_dq], axis=1), "v": np.concatenate([ev.dv, ev.torque_dv], axis=1),
             "a": np.concatenate([ev.da, ev.torque_da], axis=1)}
    for name, h in (("q", 1e-6), ("v", 1e-4), ("a", 1e-3)):
        fd = np.zeros_like(exact[name])
        for j in range(na):
            args_p, args_m = [qa.copy(), va.copy(), aa.copy()], [qa.copy(), va.copy(), aa.copy()]
            k = "qva".index(name)
            args_p[k][:, j] += h
            args_m[k][:, j] -= h
            fd[:, :, j] = (library(*args_p) - library(*args_m)) / (2 * h)
        # per output: the differences' error (truncation h^2, rounding eps |x| / h) against its scale
        scale = np.max(np.abs(fd), axis=(0, 2), keepdims=True)
        err = np.abs(exact[name] - fd)
        assert np.all(err <= 2e-6 * scale + 1e-12 * np.max(scale)), (name, float(np.max(err / (scale + 1e-300))))


def test_exact_and_differenced_partials_plan_the_same_motion(four_bar):
    """The plan with exact partials and the plan with central differences in the positions reach
    the same optimum (the objective to 1e-6), and each says which it used."""
    mech, qg = four_bar
    exact = plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, control_points=10)
    diff = plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, control_points=10, derivatives="differences")
    assert exact.ok and diff.ok
    assert (exact.derivatives, diff.derivatives) == ("exact", "differences")
    assert exact.summary(mech.actuated_names)["derivatives"] == "exact"
    assert exact.value == pytest.approx(diff.value, rel=1e-6)
    with pytest.raises(ValueError, match="derivatives must be 'exact' or 'differences'"):
        plan.min_shaking(mech, [0.0], [np.pi], 0.5, q_guess=qg, derivatives="forward")


def test_the_compiled_and_the_numpy_partials_agree(four_bar, monkeypatch):
    """The graph's function compiled (the installed C++ compiler) and interpreted by numpy (no
    compiler) give the same numbers."""
    from mechbal.codegen import compiler
    from mechbal.plan.exact import _build

    mech, qg = four_bar
    if compiler() is None:
        pytest.skip("no C++ compiler: only the numpy function")
    compiled = _build(mech, np.array([0.1, 0.0, 0.2]))
    monkeypatch.setenv("MECHBAL_PLAN_NO_COMPILE", "1")
    interpreted = _build(mech, np.array([0.1, 0.0, 0.2]))
    assert hasattr(compiled._f, "library") and not hasattr(interpreted._f, "library")
    qa = np.linspace(0.2, 2.8, 7)[:, None]
    va, aa = np.full((7, 1), 2.0), np.linspace(-30, 30, 7)[:, None]
    q = ActuatedModel(mech, q_guess=qg).full(qa, va, aa)[0]
    a, b = compiled(q, va, aa), interpreted(q, va, aa)
    for k in a:
        np.testing.assert_allclose(a[k], b[k], rtol=1e-12, atol=1e-12 * np.max(np.abs(b[k])), err_msg=k)
