"""The lightest counterweight design is the lightest (issue 41), against an independent solver.

50 random trees carry random slots, several on a parent and child link with their balls around
the child's joint axis: a mass on that axis acts the same on either link, so the two slots share
undetermined combinations (the shared axis that made the static method return 46.8 kg on the
Talos arm where 23.6 kg suffice). Some instances have bounds that exclude the least squares
(the lexicographic stage 1: least residual within the bounds, then the lightest among its designs).

The independent optimum: the gravity torque's columns are taken by differences of the public
gravity torque with a 1 kg body added (not from the regressors); the program is written in the
slots' physical unknowns (m, h = m p) in the link frames, each radius as ``|h - m c| <= R m``, and
solved by cvxpy (a modelling layer and its own canonicalisation; Clarabel underneath): first the
least residual ``min |A x + b|``, then the least mass among the designs with the same ``A x``
(the row space of A fixed at the stage 1 solution). Within 1e-6 relative of ours in residual and
in mass.

The Talos arm of the issue: three slots, the lightest design of the best residual.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mechbal import _core
from mechbal.balance import CounterweightSlot, static
from mechbal.mechanism import Mechanism
from mechbal.spec import mechanism_spec

cp = pytest.importorskip("cvxpy")
pytestmark = pytest.mark.filterwarnings("ignore:Solution may be inaccurate")
pytest.importorskip("clarabel")


def random_tree(seed: int) -> Mechanism:
    """4 to 6 revolute joints, each on a random earlier joint's link (or the base)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 7))
    joints = []
    for i in range(n):
        parent = "base" if i == 0 else (f"j{int(rng.integers(0, i)) + 1}" if rng.random() < 0.4 else f"j{i}")
        joints.append({"name": f"j{i + 1}", "parent": parent,
                       "origin": {"xyz": rng.uniform(-0.3, 0.3, 3).tolist(), "rpy": rng.uniform(-1.5, 1.5, 3).tolist()},
                       "axis": rng.normal(size=3).tolist(),
                       "link": {"mass": float(rng.uniform(0.5, 3.0)), "com": rng.uniform(-0.2, 0.2, 3).tolist(),
                                "inertia": [0.02, 0.03, 0.04]}})
    return Mechanism.from_spec(mechanism_spec({"gravity": [0.0, 0.0, -9.81], "joints": joints}))


def random_slots(seed: int, mech: Mechanism):
    """Slots on a parent link and its child's link whose balls both reach the child's joint axis
    (centres on or near the axis line), plus a few elsewhere; mass bounds sometimes tight enough to
    exclude the least squares; a budget now and then."""
    rng = np.random.default_rng(5000 + seed)
    d = mech.model.description
    joints = {j.name: j for j in d.joints}
    children = [j for j in d.joints if j.parent in joints]       # a joint whose parent link moves
    slots: list[CounterweightSlot] = []
    for j in rng.permutation(children)[:2]:
        axis = np.array(j.axis, float)
        axis = axis / np.linalg.norm(axis)
        P = np.asarray(j.placement, float)
        # a point of the child's axis, in the child's frame and in the parent's
        s = float(rng.uniform(-0.15, 0.15))
        on_child = s * axis
        on_parent = P[:3, :3] @ on_child + P[:3, 3]
        tight = rng.random() < 0.35
        for link, c in ((j.parent, on_parent), (j.name, on_child)):
            name = f"{link}_cw{len(slots)}"
            if any(x.link == link for x in slots):
                continue
            kw = dict(max_radius=float(rng.uniform(0.05, 0.25)),
                      mass_max=float(rng.uniform(0.3, 2.0) if tight else rng.uniform(5.0, 40.0)),
                      center=tuple(c + rng.normal(scale=0.01, size=3)))
            slots.append(CounterweightSlot(name, link, **kw))
    for link in rng.permutation(mech.link_names[1:])[:2]:
        if any(x.link == link for x in slots):
            continue
        kw = dict(max_radius=float(rng.uniform(0.05, 0.3)), mass_max=float(rng.uniform(2.0, 40.0)),
                  center=tuple(rng.uniform(-0.1, 0.1, 3)))
        if rng.random() < 0.3:
            kw["direction"] = tuple(rng.normal(size=3))
        slots.append(CounterweightSlot(f"{link}_cw{len(slots)}", link, **kw))
    budget = float(rng.uniform(5.0, 60.0)) if rng.random() < 0.3 else None
    return slots, budget


def columns(mech: Mechanism, slots, q):
    """(A, b): gravity torque = A x + b for x = (m, h) per slot in its link frame, by differences
    of the public gravity torque with a 1 kg body at 0 and at e_i."""
    b = mech.gravity_torque(q).reshape(-1)
    cols = []
    for s in slots:
        def G(p):
            body = _core.Body("probe_cw", s.link, 1.0, np.asarray(p, float), np.zeros((3, 3)), "counterweight")
            return mech.with_bodies([body]).gravity_torque(q).reshape(-1) - b
        g0 = G(np.zeros(3))
        cols += [g0] + [G(e) - g0 for e in np.eye(3)]
    return np.array(cols).T, b


def independent(A, b, slots, budget):
    """(least RMS residual, least mass among its designs, the solver's status of the latter) by
    cvxpy in (m, h) per slot."""
    K = len(slots)
    m = cp.Variable(K)
    h = cp.Variable((K, 3))
    x = cp.hstack([cp.hstack([m[k], h[k, 0], h[k, 1], h[k, 2]]) for k in range(K)])
    cons = [m >= 0]
    for k, s in enumerate(slots):
        c = np.asarray(s.center, float)
        cons.append(m[k] <= s.mass_max)
        off = h[k] - m[k] * c
        if s.direction is not None:
            u = np.asarray(s.direction, float) / np.linalg.norm(s.direction)
            W = np.linalg.svd(np.eye(3) - np.outer(u, u))[0][:, :2]
            cons += [W.T @ off == 0, cp.abs(u @ off) <= s.max_radius * m[k]]
        else:
            cons.append(cp.norm(off) <= s.max_radius * m[k])
    if budget is not None:
        cons.append(cp.sum(m) <= budget)
    scale = np.linalg.norm(b)
    p1 = cp.Problem(cp.Minimize(cp.sum_squares(A @ x + b) / scale ** 2), cons)   # a QP
    _solve(p1)
    x1 = np.asarray(x.value, float)
    rms1 = float(np.sqrt(np.mean((A @ x1 + b) ** 2)))
    U, sv, Vt = np.linalg.svd(A, full_matrices=False)
    r = int(np.sum(sv > 1e-10 * sv[0]))
    x_ls = Vt[:r].T @ ((U[:, :r].T @ -b) / sv[:r])
    rows = Vt[:r] * sv[:r, None] / scale
    # the least-squares set, when it meets the bounds: its lightest design
    p2 = cp.Problem(cp.Minimize(cp.sum(m)), cons + [rows @ x == rows @ x_ls])
    p2.solve(solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
    if p2.status in ("optimal", "optimal_inaccurate"):
        return float(np.sqrt(np.mean((A @ x.value + b) ** 2))), float(p2.value), p2.status
    # else the lightest design within 1e-6 (relative) of the least residual (the documented
    # order): |A x + b| <= (1 + e) T written about the least residual's vector r1 (|r1| = T), with
    # u.r = T (1 + e a) and the rest T sqrt(2 e) v: |v|^2 + (e / 2) a^2 <= 1 + e / 2 - a
    e = 1e-6
    r1 = A @ x1 + b
    T = float(np.linalg.norm(r1))
    u = r1 / T
    Up = np.linalg.svd(np.eye(len(u)) - np.outer(u, u))[0][:, :len(u) - 1]
    r = A @ x + b
    a = (u @ r - T) / (T * e)
    v = (Up.T @ r) / (T * math.sqrt(2 * e))
    p3 = cp.Problem(cp.Minimize(cp.sum(m)), cons + [cp.sum_squares(cp.hstack([v, math.sqrt(e / 2) * a]))
                                                    <= 1 + e / 2 - a])
    _solve(p3)
    return rms1, float(p3.value), p3.status


def _solve(p):
    for tol in (1e-12, 1e-10):
        try:
            p.solve(solver=cp.CLARABEL, tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol)
        except cp.error.SolverError:
            continue
        if p.status in ("optimal", "optimal_inaccurate"):
            return
    raise AssertionError(f"the independent solver failed ({p.status})")


@pytest.mark.parametrize("seed", range(50))
def test_lightest_design_matches_an_independent_solver(seed):
    mech = random_tree(seed)
    slots, budget = random_slots(seed, mech)
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (20, mech.dof))
    r = static.balance(mech, slots, q, mass_budget=budget)
    A, b = columns(mech, slots, q)
    x = np.concatenate([[d.mass, *(d.mass * np.asarray(d.position))] for d in (r.design[s.name] for s in slots)])
    ours_rms = float(np.sqrt(np.mean((A @ x + b) ** 2)))
    ours_mass = sum(d.mass for d in r.design.values())
    rms, mass, status = independent(A, b, slots, budget)
    scale = float(np.sqrt(np.mean(b ** 2)))
    # as good a balance: the least residual, or within 1e-6 of it when the bounds exclude the least
    # squares (the documented order)
    assert ours_rms <= rms * (1 + 1e-6 + 1e-9) + 1e-9 * scale, (ours_rms, rms)
    # as light, to 1e-6 relative; where cvxpy itself reports its optimum inaccurate (it leaves the
    # radii violated by ~1e-9 m, which the thin residual band turns into ~1e-6 of mass), to 5e-6
    tol = 1e-6 if status == "optimal" else 5e-6
    assert abs(ours_mass - mass) <= tol * max(mass, 1e-3), (ours_mass, mass, status)
    # within the bounds (to the solver's tolerance), and the certificate says so
    for s in slots:
        d = r.design[s.name]
        assert -1e-9 <= d.mass <= s.mass_max * (1 + 1e-8)
        assert d.mass * d.radius <= d.mass * s.max_radius * (1 + 1e-7) + 1e-9
    if budget is not None:
        assert ours_mass <= budget * (1 + 1e-8)
    cert = r.metrics["optimality"]
    assert cert["duality_gap"] <= 1e-6 * max(ours_mass, 1.0)


def test_shared_axis_instances_are_there():
    """The instances exercise what the issue names: a parent and child slot pair in most trees,
    and both stages (least squares reached, and bounds that exclude it)."""
    pairs, limited = 0, 0
    for seed in range(50):
        mech = random_tree(seed)
        slots, budget = random_slots(seed, mech)
        parents = {j.name: j.parent for j in mech.model.description.joints}
        links = {s.link for s in slots}
        pairs += any(parents.get(l) in links for l in links)
    assert pairs >= 35
    for seed in range(25):
        mech = random_tree(seed)
        slots, budget = random_slots(seed, mech)
        q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (20, mech.dof))
        r = static.balance(mech, slots, q, mass_budget=budget)
        limited += any(a.startswith("bound:") for a in r.limited_by)
    assert 1 <= limited <= 24          # both: bounds that exclude the least squares, and not


def talos_arm(tmp_path: Path) -> Mechanism:
    """example-robot-data's Talos left arm with the <mimic> tags on its fixed gripper joints
    removed (a fixed joint has no coordinate to couple)."""
    import re
    import sys

    for entry in sys.path:
        path = Path(entry) / "cmeel.prefix" / "share" / "example-robot-data" / "robots" / "talos_data" / "robots" / \
            "talos_left_arm.urdf"
        if path.is_file():
            break
    else:
        pytest.skip("example-robot-data is not installed (pip install '.[test]')")
    text = path.read_text()
    text = re.sub(r"(<joint[^>]*type=\"fixed\"[^>]*>(?:(?!</joint>).)*?)<mimic[^>]*/>", r"\1", text, flags=re.S)
    out = tmp_path / "talos_left_arm.urdf"
    out.write_text(text)
    return Mechanism.from_urdf(str(out))


TALOS_SLOTS = [CounterweightSlot("shoulder_cw", "arm_left_2_link", max_radius=0.10, mass_max=20.0),
               CounterweightSlot("upper_arm_cw", "arm_left_3_link", max_radius=0.2, mass_max=30.0),
               CounterweightSlot("forearm_cw", "arm_left_4_link", max_radius=0.12, mass_max=6.0)]


def test_talos_left_arm_lightest_design(tmp_path):
    """The issue's acceptance: <= 23.84 kg at the best residual (the bounds exclude the least
    squares), each slot within its bounds; the uncertified path (cuts and SLSQP) agrees."""
    mech = talos_arm(tmp_path)
    r = static.balance(mech, TALOS_SLOTS, 1000)
    mass = r.metrics["added_mass"]
    assert mass <= 23.84, mass
    for s in TALOS_SLOTS:
        d = r.design[s.name]
        assert 0.0 <= d.mass <= s.mass_max * (1 + 1e-9) and d.radius <= s.max_radius * (1 + 1e-8)
    cert = r.metrics["optimality"]
    # the bounds exclude the least squares: the lightest design within 1e-6 of the least residual
    assert cert["least_residual"] <= r.residual <= cert["least_residual"] * (1 + 1e-6 + 1e-9)
    assert cert["duality_gap"] < 1e-8
    # the uncertified path (the exact least-residual set, by cuts and SLSQP) is as light to 1e-3
    # (the 1e-6 residual band buys ~1e-4 of mass)
    r2 = static.balance(mech, TALOS_SLOTS, 1000, certified=False)
    assert r2.residual >= cert["least_residual"] * (1 - 1e-7)
    assert r2.metrics["added_mass"] == pytest.approx(mass, rel=1e-3)
