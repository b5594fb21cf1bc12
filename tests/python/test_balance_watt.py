"""The Watt six-bar of the guide (issue 41): a closed linkage of two loops balanced by five
counterweights, the lightest complete shaking-force balance the slots allow with its certificate,
checked against an independent computation: the linkage's own closed-form kinematics (circle
intersections, read from the case file with tomllib, no mechbal) gives the total centre of mass
over a full crank turn (stationary for the balanced design) and the shaking force along the case's
constant-speed motion (its second derivative, spectral, against mechbal's loop solve and
momentum). The certificate is tested as a bound: random designs that balance completely within the
bounds all weigh at least the dual bound, and the textbook design (counterweights on the three
ground-pivoted links only, Berkof-Lowen per loop) is heavier than the certified lightest one:
provably not the lightest."""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from mechbal.balance import CounterweightSlot, force, fronts
from mechbal.balance.run import balance_case, slots_from_table
from mechbal.config import case_path

pytest.importorskip("clarabel")

CASE = case_path("watt-six-bar")
RAW = tomllib.loads(CASE.read_text())
LINKS = ("crank", "coupler", "rocker", "coupler2", "output")


def _xz(v):
    return np.array([v[0], v[2]], float)


def _rot(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s], [s, c]])


def _circle(P, r1, Q, r2):
    """The intersection of circles (P, r1) and (Q, r2) on the left of P -> Q (this assembly)."""
    d = Q - P
    L = np.linalg.norm(d)
    x = (L * L + r1 * r1 - r2 * r2) / (2 * L)
    e = d / L
    return P + x * e + math.sqrt(r1 * r1 - x * x) * np.array([-e[1], e[0]])


def linkage_geometry():
    """Pivots, pins and lengths read from the case file (x-z plane, all axes along -y: a joint
    angle turns +x towards +z, a plain 2-D rotation of (x, z))."""
    j = {x["name"]: x for x in RAW["mechanism"]["joints"]}
    fr = {x["name"]: _xz(x["origin"]["xyz"]) for x in RAW["mechanism"]["frames"]}
    return dict(O2=_xz(j["crank"]["origin"]["xyz"]), O4=_xz(j["rocker"]["origin"]["xyz"]),
                O6=_xz(j["output"]["origin"]["xyz"]), a=_xz(j["coupler"]["origin"]["xyz"])[0],
                C=_xz(j["coupler2"]["origin"]["xyz"]), b=fr["coupler_B"][0], B=fr["rocker_B"],
                f=fr["coupler2_D"][0], g=fr["output_D"][0])


def link_poses(theta):
    """(origin (2,), absolute angle) of each moving link at crank angle theta."""
    G = linkage_geometry()
    A = G["O2"] + _rot(theta) @ np.array([G["a"], 0.0])
    B = _circle(A, G["b"], G["O4"], np.linalg.norm(G["B"]))
    t4 = math.atan2(B[1] - G["O4"][1], B[0] - G["O4"][0]) - math.atan2(G["B"][1], G["B"][0])
    C = G["O4"] + _rot(t4) @ G["C"]
    D = _circle(C, G["f"], G["O6"], G["g"])
    ang = lambda v: math.atan2(v[1], v[0])  # noqa: E731
    return {"crank": (G["O2"], theta), "coupler": (A, ang(B - A)), "rocker": (G["O4"], t4),
            "coupler2": (C, ang(D - C)), "output": (G["O6"], ang(D - G["O6"]))}


def point_masses(design=None):
    """[(link, mass, position (x, z) in the link frame)]: the links' own and the counterweights'."""
    out = [(j["name"], j["link"]["mass"], _xz(j["link"]["com"])) for j in RAW["mechanism"]["joints"]]
    for d in (design or {}).values():
        out.append((d.link, float(d.mass), _xz(d.position)))
    return out


def mass_moment(theta, masses):
    """sum m r over the linkage at crank angle theta (x, z) [kg m]."""
    poses = link_poses(theta)
    return sum(m * (poses[link][0] + _rot(poses[link][1]) @ p) for link, m, p in masses)


def shaking_force_independent(masses, omega, n=360):
    """|F| = omega^2 |d^2 S / d theta^2| at theta = 2 pi k / n (spectral derivative of the periodic
    mass moment S)."""
    th = 2 * np.pi * np.arange(n) / n
    S = np.array([mass_moment(t, masses) for t in th])
    k = np.fft.fftfreq(n, 1.0 / n)
    d2 = np.real(np.fft.ifft(-(k ** 2)[:, None] * np.fft.fft(S, axis=0), axis=0))
    return omega ** 2 * np.linalg.norm(d2, axis=1)


@pytest.fixture(scope="module")
def case():
    return balance_case("watt-six-bar")


@pytest.fixture(scope="module")
def lightest(case):
    slots = slots_from_table(case.table)
    return force.balance(case.mechanism, slots, 200, q_guess=case.q_guess, certified=True)


def test_independent_kinematics_matches_the_loop_solve(case):
    """The two computations agree before any balancing: joint angles along the case's motion, and
    the unbalanced linkage's shaking force (mechbal: loop solve + momentum derivative; here the
    second derivative of sum m r over the crank angle)."""
    mech = case.mechanism
    assert mech.is_closed and mech.dof == 5 and list(mech.actuated_names) == ["crank"]
    from mechbal.balance.run import evaluate

    ev = evaluate(case, mech)
    q = ev["q"]
    theta = case.motion[0][:, 0]
    absolute = np.c_[q[:, 0], q[:, 0] + q[:, 1], q[:, 2], q[:, 2] + q[:, 3], q[:, 4]]
    for k in range(0, len(theta), 15):
        poses = link_poses(theta[k])
        mine = np.array([poses[name][1] for name in LINKS])
        assert np.max(np.abs(np.angle(np.exp(1j * (mine - absolute[k]))))) < 1e-8
    omega = float(case.motion[1][0, 0])
    F = shaking_force_independent(point_masses(), omega)
    theirs = np.linalg.norm(ev["shaking_force"], axis=1)[:360]
    assert np.max(np.abs(theirs - F)) <= 1e-6 * np.max(F)


def test_lightest_complete_force_balance_is_certified_and_balances(case, lightest):
    r = lightest
    opt = r.metrics["optimality"]
    masses = {k: d.mass for k, d in r.design.items()}
    total = sum(masses.values())
    # certified: the duality gap is tiny against the mass, the dual objective a lower bound
    assert opt["duality_gap"] <= 1e-8 * total
    last = opt["stages"][-1]
    assert last["dual_objective"] <= total * (1 + 1e-9)
    # within the bounds
    for d in r.design.values():
        assert -1e-12 <= d.mass <= 3.0 + 1e-9 and d.radius <= 0.10 + 1e-9
    # complete: the linkage's centre of mass, from the independent kinematics, is still over a turn
    th = np.linspace(0.0, 2 * np.pi, 73)
    S = np.array([mass_moment(t, point_masses(r.design)) for t in th])
    S0 = np.array([mass_moment(t, point_masses()) for t in th])
    assert np.ptp(S, axis=0).max() <= 1e-9 * np.ptp(S0, axis=0).max()
    assert r.residual <= 1e-9 * r.residual_before


def _balance_program(case):
    """cvxpy: (x, m, constraints) of a complete force balance within the case's bounds, over the
    balance conditions the rows hold (their SVD's range)."""
    cp = pytest.importorskip("cvxpy")
    prob = force.problem(case.mechanism, slots_from_table(case.table), 200, q_guess=case.q_guess)
    U, sv, _ = np.linalg.svd(prob.A, full_matrices=False)
    keep = sv > 1e-10 * sv[0]
    A, b = U[:, keep].T @ prob.A, U[:, keep].T @ prob.b
    x = cp.Variable(A.shape[1])
    m = x[0::4]
    cons = [A @ x + b == 0, m <= 3.0]
    for k in range(5):
        cons.append(cp.norm(x[4 * k + 1:4 * k + 4]) <= 0.10 * x[4 * k])
    return cp, x, m, cons


def test_every_balancing_design_weighs_at_least_the_dual_bound(case, lightest):
    """The certificate as a bound: designs that balance completely within the bounds (found with
    random objectives, each checked by the independent kinematics) never weigh less than the dual
    objective."""
    cp, x, m, cons = _balance_program(case)
    dual = lightest.metrics["optimality"]["stages"][-1]["dual_objective"]
    rng = np.random.default_rng(1)
    for _ in range(6):
        c = rng.normal(size=x.shape[0])
        cp.Problem(cp.Minimize(c @ x), cons + [cp.sum(m) <= 15.0]).solve(solver=cp.CLARABEL)
        xv = np.asarray(x.value, float)
        mv, h = xv[0::4], xv.reshape(-1, 4)[:, 1:]
        design = {f"s{k}": type("D", (), {"link": LINKS[k], "mass": mv[k], "position": h[k] / mv[k]})()
                  for k in range(5) if mv[k] > 1e-9}
        S = np.array([mass_moment(t, point_masses(design)) for t in (0.0, 1.0, 2.5, 4.0)])
        assert np.ptp(S, axis=0).max() < 1e-6          # it balances (independently checked)
        assert mv.sum() >= dual * (1 - 1e-7)


def test_an_independent_solver_finds_the_same_optimum(case, lightest):
    """cvxpy with SCS (a first-order splitting method: another algorithm and modelling layer) on
    the lightest complete force balance over the same rows."""
    cp, x, m, cons = _balance_program(case)
    cp.Problem(cp.Minimize(cp.sum(m)), cons).solve(solver=cp.SCS, eps=1e-10, max_iters=200000)
    ours = sum(d.mass for d in lightest.design.values())
    assert float(np.sum(m.value)) == pytest.approx(ours, rel=1e-5)


def test_the_textbook_design_is_provably_not_the_lightest(case, lightest):
    """Counterweights on the three ground-pivoted links only (Berkof-Lowen, loop by loop: the
    balance conditions fix their mass moments, each at its largest radius) balance the linkage
    too, but the certified five-slot design is lighter: the primal design (independently checked
    above) proves the textbook one is not the lightest, and the dual bound proves nothing lighter
    than it exists."""
    slots = [s for s in slots_from_table(case.table) if s.link in ("crank", "rocker", "output")]
    textbook = force.balance(case.mechanism, slots, 200, q_guess=case.q_guess, certified=True)
    assert textbook.residual <= 1e-9 * textbook.residual_before
    th = np.linspace(0.0, 2 * np.pi, 37)
    S = np.array([mass_moment(t, point_masses(textbook.design)) for t in th])
    assert np.ptp(S, axis=0).max() <= 1e-9
    heavy = sum(d.mass for d in textbook.design.values())
    light = sum(d.mass for d in lightest.design.values())
    dual = lightest.metrics["optimality"]["stages"][-1]["dual_objective"]
    assert dual <= light * (1 + 1e-9) < heavy * (1 - 1e-3)


def test_watt_force_front(case, lightest):
    """The force front of the six-bar: monotone, from the unbalanced linkage to the lightest
    complete balance, each point certified; shaking force along the case's motion agrees with the
    independent kinematics at the knee."""
    slots = slots_from_table(case.table)
    lo, hi = np.min(case.motion[0], axis=0), np.max(case.motion[0], axis=0)
    fr = fronts.front(case.mechanism, slots, 4, method="force", samples=200, lower=lo, upper=hi,
                      q_guess=case.q_guess, motion=case.motion)
    r = [p.residual for p in fr.points]
    assert all(b <= a * (1 + 1e-9) for a, b in zip(r, r[1:]))
    assert fr.points[0].added_mass == 0.0
    assert fr.points[-1].added_mass == pytest.approx(sum(d.mass for d in lightest.design.values()), rel=1e-6)
    assert all(p.result.metrics["optimality"]["duality_gap"] <= 1e-7 * max(p.added_mass, 1.0) for p in fr.points)
    p = fr.points[fr.knee]
    F = shaking_force_independent(point_masses(p.result.design), float(case.motion[1][0, 0]))
    assert p.shaking_force_peak == pytest.approx(np.max(F), rel=1e-6)
