"""Spring static balancing (mechbal.balance.springs): the spring torques against finite
differences of the spring energy and against Jacobians taken at frames placed on the anchors,
exact balance where the slots allow it (potential energy constant to 1e-9 J, gravity + spring
torque zero to 1e-9 N m), the residual reported where they do not, free anchors, closed loops,
and catalogue selection against Martini et al. 2015, Tables 1-2."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.balance import SpringSlot
from mechbal.balance import springs as sp

ROOT = Path(__file__).resolve().parents[2]
UR5 = ROOT / "examples" / "ur5_springs" / "ur5_like.toml"
G = 9.81
R = _core.JointType.revolute
EX = np.array([1.0, 0.0, 0.0])


def _T(y=0.0):
    T = np.eye(4)
    T[1, 3] = y
    return T


def pendulum(mass=2.0, com=0.3):
    """One link about the horizontal x axis at O, centre of mass along its y axis."""
    j = [_core.Joint("j1", R, "base", np.eye(4), EX)]
    b = [_core.Body("l1", "j1", mass, np.array([0.0, com, 0.0]), np.diag([0.01, 0.001, 0.01]))]
    return mechbal.Mechanism.from_description(j, b)


def planar_2r(l1=0.4, m1=3.0, c1=0.2, m2=1.5, c2=0.15):
    """Two links about x in the vertical y-z plane; centres of mass along the links."""
    j = [_core.Joint("j1", R, "base", np.eye(4), EX), _core.Joint("j2", R, "j1", _T(l1), EX)]
    b = [_core.Body("l1", "j1", m1, np.array([0.0, c1, 0.0]), np.diag([0.02, 0.002, 0.02])),
         _core.Body("l2", "j2", m2, np.array([0.0, c2, 0.0]), np.diag([0.01, 0.001, 0.01]))]
    return mechbal.Mechanism.from_description(j, b)


def springs_2r(l1=0.4):
    """The classic ZFL balancer of a 2R arm: base-link1, base-link2 (base anchors on the vertical
    above the shoulder) and link1-link2 (anchor behind the elbow) to cancel the cos(q2) terms."""
    return [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.1, 0)),
            SpringSlot("s2", "base", (0, 0, 0.15), "j2", (0, 0.1, 0)),
            SpringSlot("s3", "j1", (0, 0.1, 0), "j2", (0, -0.1, 0))]


def _rng(seed=0):
    return np.random.default_rng(seed)


# ---- spring torques: two independent computations --------------------------------------------
def test_spring_torque_is_the_gradient_of_the_spring_energy():
    """dV/dq by central differences equals J_A^T f - J_B^T f, with free lengths, preloads,
    clusters and pulleys, on a spatial arm (UR5-like, anchors given in DH frames)."""
    m = mechbal.Mechanism.from_toml(UR5)
    springs = [SpringSlot("a", "dh1", (0.02, 0.15, 0.01), "dh2", (0.225, 0.01, 0.03), rate=800.0,
                          free_length=0.05, preload=20.0, count=3, pulley_ratio=2.0),
               SpringSlot("b", "base", (0.1, 0.0, 0.5), "wrist_2", (0.0, 0.02, 0.05), rate=300.0),
               SpringSlot("c", "dh2", (0.3, 0.0, 0.0), "dh3", (0.45, 0.0, 0.0), rate=1500.0, free_length=0.01)]
    q = _rng(1).uniform(-np.pi, np.pi, (20, m.dof))
    tau = sp.spring_torque(m, springs, q)
    h = 1e-6
    fd = np.zeros_like(tau)
    for k in range(m.dof):
        e = np.zeros(m.dof)
        e[k] = h
        fd[:, k] = (sp.spring_energy(m, springs, q + e) - sp.spring_energy(m, springs, q - e)) / (2 * h)
    assert np.max(np.abs(tau - fd)) < 1e-6 * max(1.0, np.max(np.abs(tau)))
    # one configuration gives the same as the batch row
    assert np.allclose(sp.spring_torque(m, springs, q[3]), tau[3], rtol=0, atol=1e-12)


def test_spring_torque_matches_jacobians_at_frames_on_the_anchors():
    """The anchor Jacobian shifted from the link origin equals frame_jacobian at a frame placed
    on the anchor (a copy of the description with those frames)."""
    m = mechbal.Mechanism.from_toml(UR5)
    s = SpringSlot("a", "shoulder_lift", (0.05, -0.1, 0.2), "wrist_1", (0.01, 0.03, -0.02), rate=500.0,
                   free_length=0.02)
    d = m.model.description
    fa, fb = np.eye(4), np.eye(4)
    fa[:3, 3], fb[:3, 3] = s.anchor_a, s.anchor_b
    m2 = mechbal.Mechanism.from_description(d.joints, d.bodies, list(d.frames) + [
        _core.Frame("A", s.link_a, fa), _core.Frame("B", s.link_b, fb)], d.gravity)
    q = _rng(2).uniform(-np.pi, np.pi, (15, m.dof))
    pa, pb = m2.frame_placement(q, "A")[:, :3, 3], m2.frame_placement(q, "B")[:, :3, 3]
    Ja, Jb = m2.frame_jacobian(q, "A")[:, :3], m2.frame_jacobian(q, "B")[:, :3]
    r = pb - pa
    d_ab = np.linalg.norm(r, axis=1)
    f = -(s.rate * (d_ab - s.free_length))[:, None] * r / d_ab[:, None]   # force on B
    expected = np.einsum("nij,ni->nj", Ja, f) - np.einsum("nij,ni->nj", Jb, f)
    assert np.allclose(sp.spring_torque(m, [s], q), expected, rtol=0, atol=1e-11)
    assert np.allclose(sp.spring_lengths(m, [s], q)[:, 0], d_ab, rtol=0, atol=1e-14)


def test_equivalent_rate_of_clusters_and_pulleys_by_virtual_work():
    """n springs behind a ratio-k block and tackle act at the anchors as one spring of rate
    n rate / k^2, and each spring carries k/n of the anchor tension (virtual work)."""
    m = planar_2r()
    q = _rng(3).uniform(-np.pi, np.pi, (10, 2))
    cluster = SpringSlot("s", "base", (0, 0, 0.2), "j2", (0, 0.1, 0), rate=5009.0, count=8, pulley_ratio=4.0)
    single = dataclasses.replace(cluster, rate=8 * 5009.0 / 16, count=1, pulley_ratio=1.0)
    assert sp.equivalent_rate(cluster) == pytest.approx(2504.5)
    assert np.allclose(sp.spring_torque(m, [cluster], q), sp.spring_torque(m, [single], q), atol=1e-12)
    # virtual work: tension x anchor displacement = n x spring force x spring stretch
    d = sp.spring_lengths(m, [cluster], q)[:, 0]
    T = sp.spring_tension(m, [cluster], q)[:, 0]
    spring_stretch = d / cluster.pulley_ratio          # ZFL: the springs stretch d/k
    spring_force = cluster.rate * spring_stretch
    assert np.allclose(T, cluster.count * spring_force / cluster.pulley_ratio, rtol=1e-14)


# ---- exact balance --------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["pendulum", "planar_2r", "ur5_arm_with_wrist_mass"])
def test_exact_spring_balance(name, tmp_path):
    """Rates by least squares: potential energy constant to 1e-9 J and gravity + spring torque
    zero to 1e-9 N m over 1000 random poses, re-evaluated with the public helpers."""
    if name == "pendulum":
        m, springs = pendulum(), [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0))]
    elif name == "planar_2r":
        m, springs = planar_2r(), springs_2r()
    else:
        m, springs = _ur5_three_joints(tmp_path), _ur5_springs()
    q = _rng(4).uniform(-np.pi, np.pi, (1000, m.dof))
    r = sp.balance(m, springs, q)
    assert r.exact, r.limited_by
    assert r.rank == r.unknowns == len(springs)
    sized = r.elements
    assert all(s.rate > 0 for s in sized)
    q_check = _rng(5).uniform(-np.pi, np.pi, (1000, m.dof))     # poses the sizing did not see
    V = sp.potential_energy(m, sized, q_check)
    static = m.gravity_torque(q_check) + sp.spring_torque(m, sized, q_check)
    assert np.ptp(V) < 1e-9
    assert np.max(np.abs(static)) < 1e-9
    assert r.residual < 1e-9 and r.residual_before > 1.0
    assert np.ptp(sp.gravity_potential_energy(m, q_check)) > 1.0     # gravity alone is not constant
    if name == "pendulum":   # closed form: K a b = m g r
        assert sized[0].rate == pytest.approx(2.0 * G * 0.3 / (0.2 * 0.25), rel=1e-12)


def _ur5_three_joints(tmp_path):
    """The UR5-like arm's first three joints with the wrist's mass lumped on the wrist axis."""
    text = UR5.read_text().split("[[mechanism.joints]]\nname = \"wrist_1\"")[0]
    text += """[[mechanism.bodies]]
name = "wrist"
link = "elbow"
mass = 2.6259
com = [0.0, 0.0, 0.12]
inertia = [0.003, 0.003, 0.003]

[[mechanism.frames]]
name = "dh1"
link = "shoulder_pan"

[[mechanism.frames]]
name = "dh2"
link = "shoulder_lift"

[[mechanism.frames]]
name = "dh3"
link = "elbow"
"""
    path = tmp_path / "ur5_3.toml"
    path.write_text(text)
    return mechbal.Mechanism.from_toml(path)


def _ur5_springs():
    return [SpringSlot("shoulder", "dh1", (0, 0.15, 0), "dh2", (0.225, 0, 0)),
            SpringSlot("forearm", "dh1", (0, 0.1, 0), "dh3", (0.19225, 0, 0)),
            SpringSlot("elbow", "dh2", (0.325, 0, 0), "dh3", (0.49225, 0, 0))]


def test_ur5_like_arm_residual_is_the_wrist():
    """With springs on the shoulder and elbow only, the wrist's off-axis centres of mass leave a
    residual: reported as impossible, and equal to what the helpers recompute."""
    m = mechbal.Mechanism.from_toml(UR5)
    q = _rng(6).uniform(-np.pi, np.pi, (500, m.dof))
    r = sp.balance(m, _ur5_springs(), q)
    assert not r.exact and any(x.startswith("impossible") for x in r.limited_by)
    static = m.gravity_torque(q) + sp.spring_torque(m, r.elements, q)
    assert np.max(np.abs(static)) == pytest.approx(r.residual, rel=1e-12)
    assert r.residual < 0.05 * r.residual_before
    # the wrist joints cannot be helped by these springs: their torque is unchanged
    assert np.allclose(static[:, 3:], m.gravity_torque(q)[:, 3:], atol=1e-12)


def test_real_springs_leave_a_residual_and_it_is_reported():
    """A spring with a free length cannot balance the pendulum exactly (V is not linear in
    cos q): the result says so and its residual is the one recomputed."""
    m = pendulum()
    q = _rng(7).uniform(-np.pi, np.pi, (400, 1))
    s = SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0), free_length=0.03, preload=2.0)
    r = sp.balance(m, [s], q)
    assert not r.exact
    static = m.gravity_torque(q) + sp.spring_torque(m, r.elements, q)
    assert np.max(np.abs(static)) == pytest.approx(r.residual, rel=1e-12)
    assert 1e-6 < r.residual < r.residual_before


def test_rate_bound_is_reported():
    m = pendulum()
    q = _rng(8).uniform(-np.pi, np.pi, (200, 1))
    r = sp.balance(m, [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0), rate_max=50.0)], q)
    assert r.elements[0].rate == pytest.approx(50.0)
    assert any("bound: s1.rate" in x for x in r.limited_by)
    assert not r.exact


def test_free_anchor_by_nonlinear_least_squares():
    """Rate fixed, the base anchor's height free within bounds: the search finds K a b = m g r;
    a box that excludes that height stops on its bound and says so."""
    m = pendulum()
    q = _rng(9).uniform(-np.pi, np.pi, (200, 1))
    s = SpringSlot("s1", "base", (0, 0, 0.05), "j1", (0, 0.25, 0), rate=100.0,
                   anchor_a_bounds=((0, 0, 0.0), (0, 0, 1.0)))
    r = sp.balance(m, [s], q)
    assert r.exact, r.limited_by
    assert r.elements[0].anchor_a[2] == pytest.approx(2.0 * G * 0.3 / (100.0 * 0.25), rel=1e-9)
    tight = dataclasses.replace(s, anchor_a_bounds=((0, 0, 0.0), (0, 0, 0.1)))
    r2 = sp.balance(m, [tight], q)
    assert not r2.exact and r2.elements[0].anchor_a[2] == pytest.approx(0.1)
    assert any("bound: s1.anchor_a[2]" in x for x in r2.limited_by)


def test_closed_loop_parallelogram_balanced_in_actuated_coordinates():
    """A parallelogram four-bar (loop solved by closed_motion): ZFL springs from the base to the
    crank and to the rocker, anchors along their mass moments; C^T (G + tau_s) = 0 and the
    potential energy is constant on the loop-solved configurations."""
    import sys
    sys.path.insert(0, str(Path(__file__).parent))
    from linkages import parallelogram

    lk = parallelogram()
    m = lk.mechanism()
    bodies = {b.name: b for b in m.bodies}
    # gravity along -y: the crank carries its own mass moment plus the (translating) coupler's
    # mass at the crank tip; the rocker its own. Anchor on the link along that mass moment.
    names = m.link_names
    crank = [b for b in m.bodies if b.link == names[1]]
    rocker_link = [n for n in names if n.startswith("rocker")][0]
    a = 0.3
    coupler_mass = sum(b.mass for b in m.bodies if b.link.startswith("coupler"))
    mc_crank = sum(b.mass * np.asarray(b.com) for b in crank) + coupler_mass * np.array([a, 0, 0])
    mc_rocker = sum(b.mass * np.asarray(b.com) for b in m.bodies if b.link == rocker_link)
    springs = [SpringSlot("crank", "base", (0, 0.2, 0), names[1], tuple(0.1 * mc_crank / np.linalg.norm(mc_crank))),
               SpringSlot("rocker", "base", (0.5, 0.2, 0), rocker_link,
                          tuple(0.1 * mc_rocker / np.linalg.norm(mc_rocker)))]
    theta = np.linspace(0.4, 2.6, 120)[:, None]
    q_guess = lk.q_guess(m)
    r = sp.balance(m, springs, theta, q_guess=q_guess)
    assert r.exact, r.limited_by
    assert r.residual < 1e-9 * max(1, r.residual_before) and r.residual_before > 1.0
    motion = m.closed_motion(theta, q_guess=q_guess)
    assert np.ptp(sp.potential_energy(m, r.elements, motion.q)) < 1e-9
    assert bodies  # the linkage has bodies


def test_bad_slots_are_named():
    m = pendulum()
    q = np.zeros((3, 1))
    with pytest.raises(ValueError, match=r"springs.s1.link_b: no link or frame named 'j11' \(did you mean 'j1'\?\)"):
        sp.balance(m, [SpringSlot("s1", "base", (0, 0, 0.2), "j11", (0, 0.25, 0))], q)
    with pytest.raises(ValueError, match="springs.s1.pulley_ratio"):
        sp.balance(m, [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0), pulley_ratio=0.0)], q)
    with pytest.raises(ValueError, match="samples: must have shape"):
        sp.balance(m, [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0))], np.zeros((3, 2)))
    with pytest.raises(ValueError, match="springs.s1.rate: not set"):
        sp.spring_torque(m, [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0))], np.zeros(1))


# ---- catalogue ------------------------------------------------------------------------------
# Martini et al. 2015, Table 1 (theoretical row) and Table 2
DISTAL = dict(rate=2.510e3, peak=2321.0, offset=0.150)       # K_D [N/m], f_D,max [N], delta_y [m]
PROXIMAL = dict(rate=11.131e3, peak=4470.0, offset=0.130)    # K_P, f_P,max, eps_y


@pytest.mark.parametrize("device, spring_rate, count, moving_pulleys, table1, table2", [
    (DISTAL, 5.009, 8, 2, dict(rate=2.505, offset_mm=150.30, peak=2318.0), dict(force=1159.0, mass=8.087)),
    (PROXIMAL, 5.501, 8, 1, dict(rate=11.002, offset_mm=131.52, peak=4424.0), dict(force=1105.0, mass=8.450)),
])
def test_catalogue_reproduces_martini_tables_1_2(device, spring_rate, count, moving_pulleys, table1, table2):
    """The paper's clusters (8 springs behind 2 or 1 moving pulleys) are among the ranked
    candidates of the shipped catalogue, with Table 1's second row (equivalent rate, corrected
    anchor offset, peak force) and Table 2 (force per spring, total mass)."""
    cands = sp.select_springs(device["rate"], device["peak"], anchor_offset=device["offset"], max_candidates=200)
    match = [c for c in cands if c.count == count and c.moving_pulleys == moving_pulleys
             and abs(c.spring.rate / 1e3 - spring_rate) < 1e-9]
    assert len(match) == 1
    c = match[0]
    assert c.equivalent_rate / 1e3 == pytest.approx(table1["rate"], abs=6e-4)     # 2.5045 -> 2.505
    assert c.anchor_offset * 1e3 == pytest.approx(table1["offset_mm"], abs=0.05)
    assert c.peak_force == pytest.approx(table1["peak"], rel=2e-3)     # same peak stretch assumed
    assert c.force_per_spring == pytest.approx(table2["force"], rel=2e-3)
    assert c.total_mass == pytest.approx(table2["mass"], rel=0.01)     # catalogue masses from wire geometry
    assert c.force_per_spring <= c.spring.max_force
    # K delta is what balances (eq 18): the corrected offset keeps it
    assert c.equivalent_rate * c.anchor_offset == pytest.approx(device["rate"] * device["offset"], rel=1e-12)


def test_catalogue_candidates_are_feasible_and_ranked():
    cands = sp.select_springs(DISTAL["rate"], DISTAL["peak"], anchor_offset=DISTAL["offset"], max_candidates=500)
    assert cands
    for c in cands:
        assert abs(c.rate_error) <= 0.02
        assert c.equivalent_rate == pytest.approx(c.count * c.spring.rate / c.pulley_ratio ** 2, rel=1e-14)
        assert c.force_per_spring == pytest.approx(c.peak_force * c.pulley_ratio / c.count, rel=1e-14)
        assert c.force_per_spring <= c.spring.max_force
        assert c.total_mass == pytest.approx(c.count * c.spring.mass)
    masses = [c.total_mass for c in cands]
    assert masses == sorted(masses)
    # brute force: no feasible combination is lighter than the first candidate
    best = min(n * s.mass for s in sp.load_catalogue() for n in range(1, 13) for k in (1, 2, 4, 8)
               if abs(n * s.rate / k ** 2 / DISTAL["rate"] - 1) <= 0.02
               and DISTAL["peak"] * (n * s.rate / k ** 2) / DISTAL["rate"] * k / n <= s.max_force)
    assert cands[0].total_mass == pytest.approx(best)
    assert sp.select_springs(1e9, 1.0) == []       # nothing that stiff


def test_shipped_catalogue_is_physically_consistent():
    """The shipped CSV's rates and masses follow from its wire geometry (G = 79.3 GPa, 7850 kg/m^3)."""
    import csv
    from importlib import resources

    text = resources.files("mechbal").joinpath("data/springs.csv").read_text()
    rows = list(csv.DictReader(ln for ln in text.splitlines() if ln and not ln.startswith("#")))
    assert len(rows) >= 20
    for row in rows:
        d, n = float(row["wire_diameter_mm"]) * 1e-3, float(row["active_coils"])
        D = float(row["outer_diameter_mm"]) * 1e-3 - d
        assert float(row["rate_N_per_mm"]) * 1e3 == pytest.approx(79.3e9 * d ** 4 / (8 * D ** 3 * n), rel=0.02)
        assert float(row["mass_g"]) * 1e-3 == pytest.approx(7850 * math.pi ** 2 * d ** 2 * D * (n + 2) / 4, rel=0.02)
    assert len(sp.load_catalogue()) == len(rows)


def test_user_catalogue_and_its_errors(tmp_path):
    good = tmp_path / "mine.csv"
    good.write_text("# my springs\ncode,rate_N_per_mm,max_force_N,free_length_mm,mass_g,outer_diameter_mm\n"
                    "A1,1.0,100,50,20,12\nA2,2.0,150,60,30,14\n")
    cat = sp.load_catalogue(good)
    assert [s.code for s in cat] == ["A1", "A2"] and cat[1].rate == 2000.0 and cat[0].mass == 0.02
    c = sp.select_springs(1000.0, 150.0, good)
    # one A1 would carry 150 N > 100 N; four A1 behind k = 2 weigh 80 g; two A2 behind k = 2, 60 g
    assert (c[0].spring.code, c[0].count, c[0].pulley_ratio) == ("A2", 2, 2.0)
    assert c[0].force_per_spring == pytest.approx(150.0) and c[0].total_mass == pytest.approx(0.06)
    assert ("A1", 4, 2.0) in [(x.spring.code, x.count, x.pulley_ratio) for x in c]
    bad = tmp_path / "bad.csv"
    bad.write_text("code,rate_N_per_mm,max_force_N,free_length_mm,mass_g,outer_diameter_mm\nA1,x,100,50,20,12\n")
    with pytest.raises(ValueError, match=r"bad.csv: row 1, rate_N_per_mm: not a number \('x'\)"):
        sp.load_catalogue(bad)
    missing = tmp_path / "missing.csv"
    missing.write_text("code,rate_N_per_mm\nA1,1\n")
    with pytest.raises(ValueError, match="missing column"):
        sp.load_catalogue(missing)


def test_selection_for_a_sized_mechanism():
    """From a balance result to catalogue clusters: the peak force is recomputed on the
    mechanism with the corrected anchor, and the corrected design still balances exactly."""
    m = pendulum(mass=20.0)
    q = _rng(10).uniform(-np.pi, np.pi, (300, 1))
    r = sp.balance(m, [SpringSlot("s1", "base", (0, 0, 0.2), "j1", (0, 0.25, 0))], q)
    choices = sp.select_for_result(m, r, q, offsets={"s1": ("a", 2)}, rate_tolerance=0.05)
    assert choices["s1"]
    c = choices["s1"][0]
    s = r.elements[0]
    corrected = dataclasses.replace(s, rate=c.spring.rate, count=c.count, pulley_ratio=c.pulley_ratio,
                                    anchor_a=(0, 0, c.anchor_offset))
    static = m.gravity_torque(q) + sp.spring_torque(m, [corrected], q)
    assert np.max(np.abs(static)) < 1e-9
    assert c.peak_force == pytest.approx(np.max(sp.spring_tension(m, [corrected], q)), rel=1e-12)
