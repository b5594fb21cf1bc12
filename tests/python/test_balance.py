"""Balancing by method (issue 11): static balancing and shaking-force balancing by counterweights
and RMS / peak torque minimisation, on the general model, against closed forms (the 2-DOF arm's
static and RMS-optimal radii, a four-bar's force-balancing conditions), finite differences of
exported poses, and their own reported residuals."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mechbal import _core
from mechbal.balance import CounterweightSlot as Slot, method
from mechbal.balance import force, rms, static
from mechbal.config import CASES_DIR
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences, write_bodies
from mechbal.mechanism import Mechanism
from mechbal.spec import mechanism_spec

#: the 2-DOF arm of Arakelian, Le Baron & Mottu 2011 (arm2dof.toml) as a mechanism TOML table
ARM = dict(m1=2.5, m2=2.0, l1=0.4, l_s1=0.1, l_s2=0.1, i_s1=0.15, i_s2=0.1)


def arm_table(arm=ARM):
    return {"joints": [
        {"name": "shoulder", "axis": [0.0, -1.0, 0.0],
         "link": {"mass": arm["m1"], "com": [arm["l_s1"], 0.0, 0.0], "inertia": [0.0, arm["i_s1"], arm["i_s1"]]}},
        {"name": "elbow", "origin": {"xyz": [arm["l1"], 0.0, 0.0]}, "axis": [0.0, -1.0, 0.0],
         "link": {"mass": arm["m2"], "com": [arm["l_s2"], 0.0, 0.0], "inertia": [0.0, arm["i_s2"], arm["i_s2"]]}}]}


@pytest.fixture(scope="module")
def arm():
    return Mechanism.from_spec(mechanism_spec(arm_table()), name="arm2dof")


@pytest.fixture(scope="module")
def four_bar():
    return Mechanism.from_toml(CASES_DIR / "four-bar.toml")


FOUR_BAR_GUESS = np.array([1.0, -0.6, 1.3])
MINUS_X = (-1.0, 0.0, 0.0)


def random_poses(mech, n, seed):
    return np.random.default_rng(seed).uniform(-math.pi, math.pi, (n, mech.dof))


# ---- static --------------------------------------------------------------------------------------

def test_static_fixed_masses_give_the_papers_static_radii(arm):
    """m_CW2 r_CW2 = m2 l_S2 and m_CW1 r_CW1 = m1 l_S1 + (m2 + m_CW2) l1 (Arakelian et al. 2011,
    eqs 21-22 and 30-31), and gravity torque ~0 over 1000 other random poses."""
    res = static.balance(arm, [Slot("cw1", "shoulder", 7.4, 7.4, direction=MINUS_X),
                               Slot("cw2", "elbow", 2.0, 2.0, direction=MINUS_X)], 200)
    r1, r2 = res.design["cw1"].signed_distance, res.design["cw2"].signed_distance
    assert r2 == pytest.approx(2.0 * 0.1 / 2.0, abs=1e-12)
    assert r1 == pytest.approx((2.5 * 0.1 + (2.0 + 2.0) * 0.4) / 7.4, abs=1e-12)
    assert res.exact and res.limited_by == [] and res.rank == res.unknowns == 2
    assert res.residual < 1e-12
    G = res.balanced.gravity_torque(random_poses(arm, 1000, 7))
    assert np.max(np.abs(G)) < 1e-9
    # positions are given back in the user's frame and the design round-trips
    assert np.allclose(res.design["cw1"].position, [-r1, 0, 0], atol=1e-14)


def test_static_lightest_design_and_undetermined_combinations(arm):
    """Free masses within a radius: the lightest exact design puts each counterweight at its
    radius (m = |h| / R); what gravity cannot see is listed as undetermined."""
    res = static.balance(arm, [Slot("cw1", "shoulder", max_radius=0.2), Slot("cw2", "elbow", max_radius=0.1)], 300)
    assert res.exact
    assert res.design["cw2"].mass == pytest.approx(2.0 * 0.1 / 0.1, rel=1e-8)
    assert res.design["cw1"].mass == pytest.approx((2.5 * 0.1 + (2.0 + 2.0) * 0.4) / 0.2, rel=1e-8)
    assert res.design["cw1"].active_bounds == ["max_radius"]
    assert res.active_bounds == ["cw1.max_radius", "cw2.max_radius"]
    # a mass at the shoulder axis, y mass moments (along the axes), and 1 kg at the elbow vs
    # l1 = 0.4 kg m of link 1's mass moment along x
    assert res.rank == 4 and res.unknowns == 8
    assert "cw1.mass" in res.undetermined and "cw1.mass_moment_y" in res.undetermined
    assert "cw2.mass_moment_y" in res.undetermined
    assert any("cw2.mass" in u and "cw1.mass_moment_x" in u and "0.4" in u for u in res.undetermined)
    assert np.max(np.abs(res.balanced.gravity_torque(random_poses(arm, 1000, 3)))) < 1e-9


def test_static_bound_is_reported_never_success(arm):
    """A mass bound that excludes exact balance: the constrained least squares, the bound in
    limited_by, not exact, and the reported residual is the balanced mechanism's."""
    q = random_poses(arm, 300, 11)
    res = static.balance(arm, [Slot("cw1", "shoulder", 0.0, 3.0, max_radius=0.2),
                               Slot("cw2", "elbow", 0.0, 5.0, max_radius=0.1, direction=MINUS_X)], q)
    assert not res.exact
    assert "bound: cw1.mass_max" in res.limited_by and "bound: cw1.max_radius" in res.limited_by
    # the lightest design within 1e-6 of the least residual (mechbal.balance.optimal) may sit
    # ~1e-6 inside the bound that limits it
    assert res.design["cw1"].mass == pytest.approx(3.0, rel=1e-5)
    G = res.balanced.gravity_torque(q)
    assert res.residual == pytest.approx(float(np.sqrt(np.mean(G ** 2))), rel=1e-12)
    assert 0 < res.residual < res.residual_before
    # the budget as well
    res = static.balance(arm, [Slot("cw1", "shoulder", max_radius=0.2, direction=MINUS_X),
                               Slot("cw2", "elbow", max_radius=0.1, direction=MINUS_X)], q, mass_budget=10.0)
    assert "bound: mass_budget" in res.limited_by
    assert res.metrics["added_mass"] == pytest.approx(10.0, rel=1e-5)


def test_static_impossible_reports_the_least_squares_residual(arm):
    """A counterweight on the shoulder link alone cannot hold joint 2: the least-squares
    residual is reported, equals the recomputed one, and says why."""
    q = random_poses(arm, 300, 5)
    res = static.balance(arm, [Slot("cw1", "shoulder", 0.0, 100.0, max_radius=1.0)], q)
    assert not res.exact and res.limited_by[0].startswith("impossible: rank")
    G = res.balanced.gravity_torque(q)
    assert res.residual == pytest.approx(float(np.sqrt(np.mean(G ** 2))), rel=1e-9)
    assert res.residual == pytest.approx(res.metrics["least_squares_residual"], rel=1e-6)
    assert 0.1 * res.residual_before < res.residual < res.residual_before


def test_static_closed_four_bar_equals_force_balance(four_bar):
    """In a vertical plane a closed linkage is statically balanced when its centre of mass does
    not move: C^T G = 0 gives the force-balancing masses (sampled over a full crank turn)."""
    slots = [Slot("cw_crank", "crank", max_radius=0.1), Slot("cw_rocker", "rocker", max_radius=0.1)]
    s = static.balance(four_bar, slots, 120, q_guess=FOUR_BAR_GUESS)
    f = force.balance(four_bar, slots, 120, q_guess=FOUR_BAR_GUESS)
    assert s.exact and f.exact
    for k in ("cw_crank", "cw_rocker"):
        assert s.design[k].mass == pytest.approx(f.design[k].mass, rel=1e-8)
    _, G = s.balanced.reduced_mass_matrix(np.linspace(0, 6, 40)[:, None], q_guess=FOUR_BAR_GUESS)
    assert np.max(np.abs(G)) < 1e-9


def test_slots_are_checked(arm):
    with pytest.raises(ValueError, match=r"design\[0\].link: no moving link named 'elbo'.*'elbow'"):
        static.balance(arm, [Slot("c", "elbo", max_radius=0.1)], 10)
    with pytest.raises(ValueError, match=r"design\[0\].link: the base does not move"):
        static.balance(arm, [Slot("c", "base", max_radius=0.1)], 10)
    with pytest.raises(ValueError, match=r"design\[0\]: give max_radius"):
        static.balance(arm, [Slot("c", "elbow")], 10)
    with pytest.raises(ValueError, match=r"design\[1\].name: 'c' is already"):
        static.balance(arm, [Slot("c", "elbow", max_radius=1), Slot("c", "shoulder", max_radius=1)], 10)
    with pytest.raises(ValueError, match=r"design\[0\].mass_max: must be >= mass_min"):
        static.balance(arm, [Slot("c", "elbow", 2.0, 1.0, max_radius=1)], 10)
    with pytest.raises(ValueError, match=r"design\[0\].direction"):
        static.balance(arm, [Slot("c", "elbow", max_radius=1, direction=(0, 0, 0))], 10)


def test_positions_are_in_the_users_dh_frame():
    """A standard-DH link is described in its DH frame: the counterweight position comes back in
    it, and putting the counterweight there (as a TOML body) balances the arm."""
    table = {"joints": [
        {"name": "j1", "dh": {"a": 0.3, "alpha": 0.0}, "axis": None,
         "link": {"mass": 2.0, "com": [-0.15, 0.0, 0.0], "inertia": [0.01, 0.02, 0.02]}},
        {"name": "j2", "dh": {"a": 0.25, "alpha": 0.0},
         "link": {"mass": 1.0, "com": [-0.1, 0.0, 0.0], "inertia": [0.01, 0.01, 0.01]}}],
        "gravity": [0.0, -9.81, 0.0]}
    for j in table["joints"]:
        j.pop("axis", None)
    mech = Mechanism.from_spec(mechanism_spec(table), name="dh")
    # within 0.1 m of each joint axis: x = -a in the DH frame (origin at the link's tip)
    slots = [Slot("cw1", "j1", 0.0, 50.0, max_radius=0.1, center=(-0.3, 0.0, 0.0)),
             Slot("cw2", "j2", 0.0, 50.0, max_radius=0.1, center=(-0.25, 0.0, 0.0))]
    res = static.balance(mech, slots, 200)
    assert res.exact
    assert np.allclose(res.design["cw2"].position, [-0.35, 0.0, 0.0], atol=1e-7)
    assert res.design["cw2"].mass == pytest.approx(1.0 * 0.15 / 0.1, rel=1e-7)
    bodies = [dict(name=k, kind="counterweight", link=v.link, mass=v.mass, com=list(v.position),
                   inertia=[0.0, 0.0, 0.0]) for k, v in res.design.items()]
    again = Mechanism.from_spec(mechanism_spec({**table, "bodies": bodies}))
    assert np.max(np.abs(again.gravity_torque(random_poses(again, 500, 2)))) < 1e-9


# ---- shaking force --------------------------------------------------------------------------------

def test_force_four_bar_closed_form(four_bar, tmp_path):
    """Berkof-Lowen conditions of a four-bar with crank a, coupler b, rocker c (complex link
    coordinates z = x + i z): crank mass moment = -m2 a (1 - z2/b), rocker's = -m2 z2 c / b.
    Then the shaking force of the balanced linkage is zero on a random motion: analytically to
    1e-9 of the unbalanced peak, and from the exported poses by finite differences."""
    res = force.balance(four_bar, [Slot("cw_crank", "crank", max_radius=0.1),
                                   Slot("cw_rocker", "rocker", max_radius=0.1)], 150, q_guess=FOUR_BAR_GUESS)
    a, b, c, m2, z2 = 0.2, 0.5, 0.4, 1.5, 0.25
    crank_own = 0.8 * 0.1 + 0.6 * -0.08
    rocker_own = 1.1 * 0.2
    h_crank = -m2 * a * (1 - z2 / b) - crank_own
    h_rocker = -m2 * z2 * c / b - rocker_own
    assert res.exact and res.rank == 4 and res.unknowns == 8
    assert res.design["cw_crank"].mass == pytest.approx(abs(h_crank) / 0.1, rel=1e-9)
    assert res.design["cw_rocker"].mass == pytest.approx(abs(h_rocker) / 0.1, rel=1e-9)
    # in the plane of motion to 1e-9; out of it (y) the mass moment is undetermined
    # (res.undetermined) and the lightest-mass program picks it on a polyhedral approximation of
    # the radius cone, to ~5e-7: 150 or 151 samples, or sampled poses that differ by 1e-12, give
    # 1e-11 or 4.8e-7
    for slot in ("cw_crank", "cw_rocker"):
        assert np.allclose(res.design[slot].position[[0, 2]], [-0.1, 0], atol=1e-9)
        assert abs(res.design[slot].position[1]) < 1e-6
    assert "cw_crank.mass_moment_y" in res.undetermined and "cw_rocker.mass_moment_y" in res.undetermined
    # a random smooth crank motion (sum of sines), solved by the loops
    t = np.linspace(0.0, 2.0, 4001)
    rng = np.random.default_rng(4)
    amp, freq, ph = rng.uniform(0.3, 1.0, 3), rng.uniform(0.5, 2.0, 3), rng.uniform(0, 6, 3)
    qa = 1.0 + np.sum(amp * np.sin(np.outer(t, freq) + ph), axis=1)[:, None]
    va = np.sum(amp * freq * np.cos(np.outer(t, freq) + ph), axis=1)[:, None]
    aa = np.sum(-amp * freq ** 2 * np.sin(np.outer(t, freq) + ph), axis=1)[:, None]
    peaks = {}
    for name, mech in (("unbalanced", four_bar), ("balanced", res.balanced)):
        m = mech.closed_motion(qa, va, aa, q_guess=FOUR_BAR_GUESS)
        assert np.all(m.status == 0)
        sw = mech.shaking_wrench(m.q, m.v, m.a)
        bm = mech.body_motion(m.q, m.v, m.a)
        bodies = mech.bodies
        path = write_bodies(tmp_path / f"bodies_{name}.npz", t=t, names=mech.body_names,
                            mass=np.array([x.mass for x in bodies]),
                            inertia_body=np.array([x.inertia for x in bodies]), com=bm.com,
                            rotation=bm.rotation, shaking_force=sw.shaking_force, shaking_moment=sw.shaking_moment)
        F_fd, _ = shaking_wrench_by_finite_differences(read_bodies(path))
        peaks[name] = (np.max(np.abs(sw.shaking_force)), np.max(np.abs(F_fd[5:-5])))
    unbalanced = peaks["unbalanced"][0]
    assert unbalanced > 1.0
    assert peaks["balanced"][0] < 1e-9 * unbalanced
    assert peaks["balanced"][1] < 1e-6 * unbalanced   # central differences of exported poses


def test_force_serial_arm_needs_masses_at_each_joint(arm):
    """A serial arm is force balanced when each subchain's centre of mass stays on its joint
    axis: with fixed masses on link extensions the radii are the static ones (in a vertical
    plane the two conditions coincide)."""
    res = force.balance(arm, [Slot("cw1", "shoulder", 7.4, 7.4, direction=MINUS_X),
                              Slot("cw2", "elbow", 2.0, 2.0, direction=MINUS_X)], 100)
    assert res.exact
    assert res.design["cw1"].signed_distance == pytest.approx(0.25, abs=1e-12)
    assert res.design["cw2"].signed_distance == pytest.approx(0.1, abs=1e-12)


def test_force_paminsa_counterweights_from_the_momentum_regressor():
    """PAMINSA (38 bodies, 9 loop closures, mechbal.papers.paminsa) unbalanced: the linear-momentum
    regressor of the general model over solved closed motions, with one unknown mass per
    counterweight type at the paper's points (identical legs), gives Briot & Arakelian's
    counterweights 2.7915 / 1.3865 / 0.436 kg per leg and the 9.615 kg vertical counter-mass.
    Without the identical-legs tie the system is rank-deficient: legs 1 and 2 share an actuator, so
    combinations of their counterweights move no momentum (the paper's design is one member of
    that family)."""
    from mechbal.papers.paminsa.runner import parameters_from_config
    from mechbal.config import case_path, read_toml
    from mechbal.papers.paminsa import paminsa_mechanism
    from mechbal.schema import validate_case

    params = parameters_from_config(validate_case(read_toml(case_path("paminsa")), warn=False))
    unb = paminsa_mechanism(params, False)
    traj = read_toml(case_path("paminsa-linkage"))["trajectory"]
    start, end = np.array(traj["start"]), np.array(traj["end"])
    rng = np.random.default_rng(3)
    qa = start + np.linspace(0, 1, 30)[:, None] * (end - start) + rng.uniform(-0.03, 0.03, (30, start.size))
    m = unb.closed_motion(qa, rng.standard_normal(qa.shape), q_guess=np.array(traj["initial_guess"]))
    assert np.all(m.status == 0)
    Y = unb.momentum_regressor(m.q, m.v)[:, :3, :]
    P = unb.momentum(m.q, m.v).linear_momentum
    cw = [(k, b) for k, b in enumerate(unb.bodies) if b.kind == "counterweight"]
    A = np.stack([Y[:, :, 10 * k:10 * k + 4] @ np.r_[1.0, b.com] for k, b in cw], axis=-1).reshape(-1, len(cw))
    assert np.linalg.matrix_rank(A) < len(cw)  # legs 1 and 2 share an actuator: not every mass is determined
    types = sorted({b.name.split(".", 1)[-1] for _, b in cw})
    tie = np.array([[b.name.split(".", 1)[-1] == t for t in types] for _, b in cw], float)
    x, _, rank, _ = np.linalg.lstsq(A @ tie, -P.reshape(-1), rcond=None)
    assert rank == len(types)
    masses = dict(zip(types, x))
    assert masses["CP1_atA"] == pytest.approx(2.7915, abs=1e-6)
    assert masses["CP2_atF"] == pytest.approx(1.3865, abs=1e-6)
    assert masses["CP3_atL"] == pytest.approx(0.436, abs=1e-6)
    assert masses["vertical_counter_mass"] == pytest.approx(9.615, abs=1e-6)
    assert np.abs(A @ tie @ x + P.reshape(-1)).max() < 1e-9 * np.abs(P).max()


# ---- RMS / peak torque ----------------------------------------------------------------------------

def arm2dof_motion(samples=1001):
    tr = _core.RestToRestTrajectory(np.array([0.0, 1.1526]), np.array([0.5236, 1.6762]), 1.0,
                                    _core.TimeLaw.cubic)
    return tr.evaluate_batch(np.linspace(0.0, 1.0, samples))


def test_rms_reproduces_the_2dof_radii_and_its_closed_form(arm):
    """0.2509 / 0.1913 m (the corrected eqs 39-59 of Arakelian et al. 2011; the paper prints
    0.25 / 0.147): the general method's closed form (Cardano on the torque regressor), its
    numerical path, and the paper's closed form on Arm2DofDynamics agree."""
    from mechbal.papers import arm2dof as paper

    motion = arm2dof_motion()
    design = [Slot("cw1", "shoulder", 7.4, 7.4, direction=MINUS_X),
              Slot("cw2", "elbow", 2.0, 2.0, direction=MINUS_X)]
    fast = rms.balance(arm, design, motion)
    slow = rms.balance(arm, design, motion, fast_path=False, starts=2)
    closed = paper.rms_optimal_radii(_core.Arm2DofParameters(**ARM, g=9.81), 7.4, 2.0, *motion)
    r = [fast.design[k].signed_distance for k in ("cw1", "cw2")]
    assert r == pytest.approx([0.2509, 0.1913], abs=5e-5)
    assert r == pytest.approx([closed.r_cw1, closed.r_cw2], abs=1e-10)
    assert [slow.design[k].signed_distance for k in ("cw1", "cw2")] == pytest.approx(r, abs=1e-6)
    assert "Cardano" in fast.design["cw1"].method and fast.exact
    # the reported torques are the balanced mechanism's
    tau = fast.balanced.inverse_dynamics(*motion)
    assert fast.metrics["rms_torque_after"] == pytest.approx(np.sqrt(np.mean(tau ** 2, axis=0)), rel=1e-12)


def test_rms_bounds_and_peak(arm):
    motion = arm2dof_motion(301)
    res = rms.balance(arm, [Slot("cw1", "shoulder", 7.4, 7.4, max_radius=0.2, direction=MINUS_X),
                            Slot("cw2", "elbow", 2.0, 2.0, direction=MINUS_X)], motion)
    assert res.design["cw1"].signed_distance == pytest.approx(0.2, abs=1e-12)
    assert res.limited_by == ["bound: cw1.max_radius"] and not res.exact
    peak = rms.balance(arm, [Slot("cw1", "shoulder", 7.4, 7.4, direction=MINUS_X),
                             Slot("cw2", "elbow", 2.0, 2.0, direction=MINUS_X)], motion, objective="peak", starts=2)
    best = rms.balance(arm, [Slot("cw1", "shoulder", 7.4, 7.4, direction=MINUS_X),
                             Slot("cw2", "elbow", 2.0, 2.0, direction=MINUS_X)], motion)
    # joint 2 is sized first, on its own torque (joint 1 then depends on that choice)
    assert peak.metrics["peak_torque_after"][1] <= best.metrics["peak_torque_after"][1] + 1e-9
    assert best.metrics["rms_torque_after"][1] <= peak.metrics["rms_torque_after"][1] + 1e-9
    assert peak.metrics["peak_torque_after"][1] < best.metrics["peak_torque_after"][1] - 1e-3


def test_rms_total_coupling_on_a_closed_linkage(four_bar):
    """Closed mechanisms: all slots together on the actuated force C^T tau."""
    t = np.linspace(0.0, 1.0, 201)
    tr = _core.RestToRestTrajectory(np.array([1.0]), np.array([2.2]), 1.0, _core.TimeLaw.quintic)
    qa, va, aa = tr.evaluate_batch(t)
    res = rms.balance(four_bar, [Slot("cw_crank", "crank", 0.0, 3.0, max_radius=0.15)], (qa, va, aa),
                      q_guess=FOUR_BAR_GUESS, starts=3)
    assert res.metrics["coupling"] == "total"
    assert res.residual < res.residual_before
    tau = res.balanced.actuated_forces(qa, va, aa, q_guess=FOUR_BAR_GUESS)
    assert res.residual == pytest.approx(float(np.sqrt(np.mean(tau ** 2))), rel=1e-9)


def test_method_lookup():
    assert method("static") is static and method("rms") is rms
    with pytest.raises(ValueError, match="unknown balancing method 'statik'.*did you mean 'static'"):
        method("statik")
