"""The 3(RPSP)-S robot of Heydari & Enferadi as data on the general model (rpsp.toml): the general
loop solve against the paper's closed-form inverse kinematics (eqs 1-13), the closed form's
derivatives against finite differences, the counterweights of eqs 29-31 against a sympy
derivation from first principles and against the general force-balancing method, the balanced
shaking force recomputed from the exported poses, the conditioning survey of the whole period."""
import copy
import json
from functools import lru_cache

import numpy as np
import pytest

from mechbal import _core
from mechbal.papers.rpsp import runner as runner
from mechbal.config import ConfigError, read_case
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences
from mechbal.mechanism import Mechanism
from mechbal.papers import rpsp as paper
from mechbal.schema import validate_case

GEOMETRY = paper.RpspGeometry.paper()


@lru_cache(maxsize=None)
def case():
    return validate_case(read_case("rpsp"), warn=False)


@lru_cache(maxsize=None)
def mechanisms():
    c = case()
    full = c.spec
    unbal = runner.unbalanced_spec(full, c.balancing)
    return (Mechanism.from_spec(runner.driven_by_platform(full, "platform")),
            Mechanism.from_spec(runner.driven_by_platform(unbal, "platform")))


def guess():
    c = case()
    return dict(zip(c.spec.independent_joints, c.motion.initial_guess))


# ---- the paper's closed forms ---------------------------------------------------------------------

def test_closed_form_derivatives_match_finite_differences():
    t = np.array([0.3, 1.7, 2.3, 4.9])
    h = 1e-5
    ik = [paper.inverse_kinematics(GEOMETRY, *paper.paper_motion(t + d)) for d in (-h, 0.0, h)]
    for key in ("theta", "l", "b"):
        scale = np.max(np.abs(ik[1][key + "_dot"])) + 1.0
        fd1 = (ik[2][key] - ik[0][key]) / (2 * h)
        fd2 = (ik[2][key] - 2 * ik[1][key] + ik[0][key]) / h ** 2
        assert np.max(np.abs(fd1 - ik[1][key + "_dot"])) < 1e-7 * scale, key
        assert np.max(np.abs(fd2 - ik[1][key + "_ddot"])) < 1e-3 * (np.max(np.abs(ik[1][key + "_ddot"])) + 1), key
    # eq 2 holds and e_i is the unit vector of eq 12 in the leg's plane
    for s in range(len(t)):
        R = paper.platform_rotation(paper.paper_motion(t)[0][s])
        for i in range(3):
            u = np.array([np.cos(GEOMETRY.lam[i]), np.sin(GEOMETRY.lam[i]), 0.0])
            e = ik[1]["e"][s, i]
            th = ik[1]["theta"][s, i]
            assert np.allclose(e, [u[1] * np.sin(th), -u[0] * np.sin(th), np.cos(th)], atol=1e-14)
            assert abs(u @ e) < 1e-14
            v = R @ np.array([np.cos(GEOMETRY.alpha[i]), np.sin(GEOMETRY.alpha[i]), 0.0])
            lhs = np.array([0, 0, GEOMETRY.h]) + ik[1]["b"][s, i] * v
            assert np.allclose(lhs, GEOMETRY.a[i] * u + ik[1]["l"][s, i] * e, atol=1e-14)


def test_degenerate_configurations_are_reported_not_garbage():
    # platform turned 90 deg about z: every v_i is perpendicular to its u_i, eq 8's denominator
    # vanishes; 45 deg: nothing degenerates
    out = paper.inverse_kinematics(GEOMETRY, [[np.pi / 2, 0.0, 0.0], [np.pi / 4, 0.0, 0.0]],
                                   [[0.3, 0.0, 0.1]] * 2, [[0.0, 0.0, 0.0]] * 2)
    assert out["degenerate"].tolist() == [[True] * 3, [False] * 3]
    for key in ("b", "l", "theta", "theta_dot", "theta_ddot"):
        assert np.all(np.isfinite(out[key])) and np.all(out[key][0] == 0.0)
    assert np.all(out["b"][1] > 0)
    # a leg of zero length (the tip on A_i): e_i undefined
    g = paper.RpspGeometry(a=(0.303,) * 3, h=0.0, lam=GEOMETRY.lam, alpha=GEOMETRY.alpha)
    out = paper.inverse_kinematics(g, [[0.0, 0.0, 0.0]])
    assert out["degenerate"][0].tolist() == [True, True, True]
    assert np.all(np.isfinite(out["theta"]))


def test_eqs_29_31_are_the_first_principles_balance_conditions():
    sp = pytest.importorskip("sympy")
    m = sp.symbols("m_E m_Q m_H m_K m_P m_N m_F")
    r = sp.symbols("r_H r_K r_P r_N r_Q r_F")
    mE, mQ, mH, mK, mP, mN, mF = m
    rH, rK, rP, rN, rQ, rF = r
    # positions relative to the fixed A_i: D, C on the linkage, E on the rotary arm (3 free vectors)
    D, C, E = (sp.Matrix(sp.symbols(f"{n}x {n}y {n}z")) for n in "DCE")
    points = {mH: rH * D, mP: rP * D, mK: D + rK * (C - D), mN: D + rN * (C - D),
              mQ: C + rQ * E, mE: E, mF: rF * E}
    total = sum((mass * p for mass, p in points.items()), sp.zeros(3, 1))
    # balanced for every motion iff the coefficients of D, C, E vanish
    conditions = [sp.expand(total[0]).coeff(sym) for sym in (D[0], C[0], E[0])]
    sol = sp.solve(conditions, [mP, mN, mF], dict=True)[0]
    printed = paper.counterweights_eqs_29_31(mE, mQ, mH, mK, rH, rK, rP, rN, rQ, rF)
    for key, s in (("m_P", mP), ("m_N", mN), ("m_F", mF)):
        assert sp.simplify(sol[s] - printed[key]) == 0, key
    # and the paper's numbers: m_F agrees, m_N and m_P do not
    p = case().paper
    values = paper.counterweights_eqs_29_31(p.m_E, p.m_Q, p.m_H, p.m_K, p.r_H, p.r_K, p.r_P, p.r_N, p.r_Q, p.r_F)
    assert values["m_F"] == pytest.approx(4.5, abs=1e-12)
    assert values["m_N"] == pytest.approx(2.85, abs=1e-12)
    assert values["m_P"] == pytest.approx(17.97, abs=1e-12)
    assert paper.balance_coefficients(**values, m_E=p.m_E, m_Q=p.m_Q, m_H=p.m_H, m_K=p.m_K, r_H=p.r_H,
                                      r_K=p.r_K, r_P=p.r_P, r_N=p.r_N, r_Q=p.r_Q, r_F=p.r_F) == \
        pytest.approx((0, 0, 0), abs=1e-12)
    # the printed m_P is the exact condition evaluated with the printed (wrong) m_N
    m_P_from_printed_m_N = -(p.m_H * p.r_H + p.m_K * (1 - p.r_K) + 2.76 * (1 - p.r_N)) / p.r_P
    assert m_P_from_printed_m_N == pytest.approx(17.61, abs=1e-9)


def test_table_consistency_flags_the_inconsistent_cells():
    cons = paper.table_consistency()
    flagged = {(ax, r["t"]) for ax, v in cons.items() for r in v["rows"] if not r["consistent"]}
    assert flagged == {("x", 0.102), ("y", 0.0), ("y", 0.1), ("y", 0.102), ("z", 0.052), ("z", 0.1)}
    # the proposed readings reconcile them
    assert 100 * (1 - 5.0244 / 27.1848) == pytest.approx(81.5176, abs=1e-3)
    assert 100 * (1 - 10.7603 / 56.5087) == pytest.approx(80.9582, abs=1e-3)
    assert 100 * (1 - 1.6137 / 235.936) == pytest.approx(99.316, abs=1e-3)


# ---- the case file encodes the paper's robot ----------------------------------------------------

def test_case_file_is_the_papers_robot():
    c = case()
    p = c.paper
    full, unbal = mechanisms()
    assert full.dof == 18 and unbal.dof == 12
    assert sorted(full.actuated_names) == ["platform_x", "platform_y", "platform_z"]
    assert not any(n.startswith(("AD_", "DC_")) for n in unbal.joint_names)
    assert sorted(unbal.body_names) == sorted(["platform"] + [f"{x}_{i}" for x in "EQ" for i in (1, 2, 3)])
    motor = Mechanism.from_spec(c.spec)
    assert motor.actuated_names == ["theta_1", "theta_2", "theta_3"]
    bodies = {b.name: b for b in full.bodies}
    for i in (1, 2, 3):
        assert bodies[f"E_{i}"].mass == p.m_E and bodies[f"Q_{i}"].mass == p.m_Q
        assert bodies[f"H_{i}"].mass == p.m_H and bodies[f"K_{i}"].mass == p.m_K
        assert np.allclose(bodies[f"E_{i}"].com, [0, 0, p.AE])
        assert np.allclose(bodies[f"F_{i}"].com, [0, 0, p.r_F * p.AE])
        assert np.allclose(bodies[f"Q_{i}"].com, [0, 0, p.r_Q * p.AE])
        assert np.allclose(bodies[f"H_{i}"].com, [0, 0, p.r_H * p.AD])
        assert np.allclose(bodies[f"P_{i}"].com, [0, 0, p.r_P * p.AD])
        assert np.allclose(bodies[f"K_{i}"].com, [0, 0, p.r_K * p.DC])
        assert np.allclose(bodies[f"N_{i}"].com, [0, 0, p.r_N * p.DC])
    assert bodies["platform"].mass == p.m_p and np.allclose(bodies["platform"].com, 0)


# ---- the general loop solve against the closed form -----------------------------------------------

@pytest.mark.parametrize("which", ["full", "unbalanced"])
def test_general_solve_equals_closed_form_inverse_kinematics(which):
    full, unbal = mechanisms()
    mech = full if which == "full" else unbal
    # with the extra linkage: the first assemblable span; without: through leg 3's near-singularity
    t = np.linspace(0.0, 1.0 if which == "full" else 2.6, 261)
    m = runner.solve(mech, case().motion, t, guess())
    assert np.all((m.status & ~np.uint32(int(_core.Status.singular))) == 0)
    agree = runner.ik_agreement(mech, m, GEOMETRY, case().motion, t)
    assert agree["instants_compared"] == len(t)
    for key in ("theta", "l", "b"):
        assert agree[f"max_abs_error_{key}"] < 1e-12, (key, agree)
        assert agree[f"max_abs_error_{key}_dot"] < 1e-9, (key, agree)
        assert agree[f"max_abs_error_{key}_ddot"] < 1e-8 * max(1.0, agree[f"max_abs_{key}_ddot"]), (key, agree)
    assert agree["max_eq2_residual"] < 1e-12
    assert agree["max_loop_residual"] < 1e-12


def test_forward_kinematics_with_the_motors_actuated_recovers_the_platform():
    """The same TOML with its own actuated joints (the motors): theta_i of the closed form in, the
    platform's orientation out. Started away from t = 0: the home pose R = I (every leg vertical)
    is a parallel singularity of the motor-driven robot (locked motors let the platform roll and
    pitch to first order), where the direct kinematics branches."""
    c = case()
    full, _ = mechanisms()
    motor = Mechanism.from_spec(c.spec)
    t = np.linspace(0.1, 0.45, 36)
    start = runner.solve(full, c.motion, t[:1], guess())
    phi, dphi, ddphi = paper.paper_motion(t)
    ik = paper.inverse_kinematics(GEOMETRY, phi, dphi, ddphi)
    order = [int(n[-1]) - 1 for n in motor.actuated_names]
    q0 = start.q[0][[full.joint_names.index(n) for n in motor.joint_names]]
    m = motor.closed_motion(ik["theta"][:, order], ik["theta_dot"][:, order], ik["theta_ddot"][:, order],
                            q_guess=q0, tolerance=1e-14)
    assert np.all(m.status == 0)
    names = motor.joint_names
    for k, axis in enumerate("zyx"):
        col = names.index(f"platform_{axis}")
        assert np.max(np.abs(m.q[:, col] - phi[:, k])) < 1e-11
        assert np.max(np.abs(m.v[:, col] - dphi[:, k])) < 1e-8
        assert np.max(np.abs(m.a[:, col] - ddphi[:, k])) < 1e-6
    # and at the home pose the motor-driven solve is (near) singular, the platform-driven one is not
    rc = runner.motor_rcond(c.spec, full, runner.solve(full, c.motion, np.array([0.0, 0.3]), guess()).q)
    assert rc[0] < 1e-6 < 1e-3 < rc[1]


# ---- balancing ------------------------------------------------------------------------------------

def platform_samples(mech, c, t):
    """(phi, phi', q_guess) of the paper's motion in ``mech.actuated_names`` order: the samples of
    mechbal.balance.force on the platform-driven robot."""
    phi, dphi, _ = runner.platform_motion(c.motion, t)
    order = {"platform_z": 0, "platform_y": 1, "platform_x": 2}
    cols = [order[n] for n in mech.actuated_names]
    g = guess()
    return phi[:, cols], dphi[:, cols], np.array([g[n] for n in mech.joint_names], float)


def test_general_method_finds_the_eqs_29_31_masses_and_balances_the_robot():
    c = case()
    full, unbal = mechanisms()
    t = np.linspace(0.0, 1.0, 201)
    m = runner.solve(full, c.motion, t, guess())
    slots = [*c.balancing.m_P, *c.balancing.m_N, *c.balancing.m_F, *c.balancing.platform]
    masses, res = runner.size_counterweights(full, c.spec, slots, *platform_samples(full, c, t))
    assert res.rank == res.unknowns == len(slots) and res.exact and not res.undetermined
    residual, before = res.residual, res.residual_before
    p = c.paper
    eqs = paper.counterweights_eqs_29_31(p.m_E, p.m_Q, p.m_H, p.m_K, p.r_H, p.r_K, p.r_P, p.r_N, p.r_Q, p.r_F)
    for key, names in (("m_P", c.balancing.m_P), ("m_N", c.balancing.m_N), ("m_F", c.balancing.m_F)):
        for n in names:
            assert masses[n] == pytest.approx(eqs[key], rel=1e-7), n
    # zero by the condition: held at its bound (mass_min 0), never a negative round-off mass
    assert 0.0 <= masses["platform_counterweight"] < 1e-7
    assert residual < 1e-10 * before
    bal = Mechanism.from_spec(runner.driven_by_platform(runner.with_masses(c.spec, masses), "platform"))
    F = bal.shaking_wrench(m.q, m.v, m.a).shaking_force
    F_paper = full.shaking_wrench(m.q, m.v, m.a).shaking_force      # the TOML holds the paper's masses
    mu = runner.solve(unbal, c.motion, t, guess())
    F0 = unbal.shaking_wrench(mu.q, mu.v, mu.a).shaking_force
    assert np.all(np.max(np.abs(F), axis=0) < 1e-6 * np.max(np.abs(F0), axis=0))
    assert np.max(np.abs(F_paper)) > 1e-3 * np.max(np.abs(F0))       # the printed masses leave a residual


def test_platform_counterweight_is_sized_when_the_platform_is_not_balanced():
    c = case()
    spec = c.spec
    offset = 0.02
    spec = runner.dataclasses.replace(spec, bodies=[runner.dataclasses.replace(b, com=np.array([0, 0, offset]))
                                                    if b.name == "platform" else b for b in spec.bodies])
    mech = Mechanism.from_spec(runner.driven_by_platform(spec, "platform"))
    t = np.linspace(0.0, 0.5, 101)
    slots = [*c.balancing.m_P, *c.balancing.m_N, *c.balancing.m_F, *c.balancing.platform]
    masses, _ = runner.size_counterweights(mech, spec, slots, *platform_samples(mech, c, t))
    # m_cw * 0.1 m = m_p * offset (the counterweight at -0.1 m on the platform's z axis)
    assert masses["platform_counterweight"] == pytest.approx(c.paper.m_p * offset / 0.1, rel=1e-7)


def test_schema_refuses_unknown_names_and_keys():
    raw = read_case("rpsp")
    bad = copy.deepcopy(raw)
    bad["balancing"]["m_P"][0] = "P_9"
    with pytest.raises(ConfigError, match=r"balancing\.m_P\[0\]: no such body"):
        validate_case(bad)
    bad = copy.deepcopy(raw)
    bad["motion"]["initial_guess"] = bad["motion"]["initial_guess"][:-1]
    with pytest.raises(ConfigError, match=r"motion\.initial_guess: must have 18 values"):
        validate_case(bad)
    bad = copy.deepcopy(raw)
    bad["motion"]["platform"] = "theta_1"
    with pytest.raises(ConfigError, match=r"motion\.platform: must name a spherical joint"):
        validate_case(bad)


# ---- the whole run --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def rpsp_run(tmp_path_factory):
    from mechbal.case.load import LoadedCase
    from mechbal.cases import run_case
    import mechbal.cases as cases

    raw = read_case("rpsp")
    raw["motion"]["samples"] = 501
    raw["motion"]["survey_samples"] = 801
    out = tmp_path_factory.mktemp("rpsp") / "out"
    original = cases.load_case
    cases.load_case = lambda _name, **_: LoadedCase(copy.deepcopy(raw))
    try:
        summary = run_case("rpsp", out)
    finally:
        cases.load_case = original
    return out, summary


def test_run_summary_has_the_issue_fields(rpsp_run):
    out, summary = rpsp_run
    written = json.loads((out / "summary.json").read_text())
    for key in ("counterweight_masses", "paper_counterweight_masses", "peak_shaking_force", "rms_shaking_force",
                "mean_reduction_pct", "tables", "added_mass", "discrepancies", "survey", "ik_agreement"):
        assert key in written, key
    assert set(written["counterweight_masses"]) == {"m_P", "m_N", "m_F"}
    for v in ("unbalanced", "balanced"):
        assert len(written["peak_shaking_force"][v]) == 3 and len(written["rms_shaking_force"][v]) == 3
    assert [r["t"] for r in written["tables"]["x"]] == [0.0, 0.052, 0.1, 0.152, 0.2]
    assert all(r > 99.99 for r in written["mean_reduction_pct"])
    assert written["counterweight_masses"]["m_N"] == pytest.approx(2.85, rel=1e-7)
    # sized by mechbal.balance.force, eqs 29-31 beside it
    c = written["counterweights"]
    assert c["general_method"] == written["counterweight_masses"]
    assert c["closed_form"] == pytest.approx({"m_P": 17.97, "m_N": 2.85, "m_F": 4.5}, abs=1e-12)
    assert c["max_abs_difference"] < 1e-7 and c["tolerance"] == 1e-6
    assert written["general_method"]["exact"] and written["general_method"]["rank"] == 10
    assert written["added_mass"] == pytest.approx(
        3 * (3.27 + 3.3 + 17.97 + 2.85 + 4.5), rel=1e-7)
    assert "non_finite_values" not in written
    for f in written["files"]:
        assert (out / f).is_file(), f


def test_balanced_force_recomputed_from_exported_poses(rpsp_run):
    out, summary = rpsp_run
    unbal = read_bodies(out / "bodies_unbalanced.npz")
    bal = read_bodies(out / "bodies_balanced.npz")
    F0, _ = shaking_wrench_by_finite_differences(unbal)
    F1, _ = shaking_wrench_by_finite_differences(bal)
    peak0 = np.max(np.abs(unbal["shaking_force"]), axis=0)
    # the exported unbalanced force is the force of its poses (interior: central differences)
    inner = slice(5, -5)
    assert np.max(np.abs(F0[inner] - unbal["shaking_force"][inner])) < 1e-3 * np.max(peak0)
    assert np.all(np.max(np.abs(F1), axis=0) <= 1e-6 * peak0)
    assert np.all(np.max(np.abs(bal["shaking_force"]), axis=0) <= 1e-9 * peak0)


def test_survey_reports_the_near_singularity_and_never_nan(rpsp_run):
    _, summary = rpsp_run
    s = summary["survey"]
    r = s["robot"]
    assert s["nan_free"]
    assert r["failed_instants"] == 0 and r["closed_form_degenerate_instants"] == 0
    assert r["shortest_leg_at_min_rcond"] == 3
    assert 2.2 < r["t_min_rcond"] < 2.5
    assert min(r["min_leg_length"]) < 0.03
    assert r["near_singular_intervals"] and all(a < 2.35 < b for a, b in r["near_singular_intervals"][:1])
    agree = r["ik_agreement"]
    assert agree["max_abs_error_theta"] < 1e-12 and agree["max_abs_error_l"] < 1e-12
    assert agree["max_loop_residual"] < 1e-12
    w = s["with_extra_linkage"]
    # the linkage (0.5 m reach) cannot follow legs 2 and 3 beyond 0.5 m: the solve says so
    assert w["unreachable_intervals"] and w["failed_instants"] > 0
    for a, b in w["unreachable_intervals"]:
        assert any(fa <= a + 0.01 and fb >= b - 0.01 for fa, fb in w["failed_intervals"]), (a, b)
