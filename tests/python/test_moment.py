"""Shaking-moment balancing by counter-rotating discs (mechbal.balance.moment) on the general
model: the disc arms of Coutinho & Hess Coelho and the five-bar, built here from description
objects (statically balanced links + disc slots). The general method must give the closed forms'
gear ratios and inertia conditions (mechbal.papers.discs, corrected eqs 14, 25, 35; §5 for the
five-bar), say which columns cannot be cancelled and why, and -- with the discs it proposes --
cancel the angular momentum to 1e-9 over random motions (Mechanism.momentum of the balanced
mechanism: the C++ momentum, not the regressor the method solved with)."""
from __future__ import annotations

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.balance import DiscSlot, InertiaSlot
from mechbal.balance import moment
from mechbal.papers.discs.runner import parameters_from_config
from mechbal.config import read_case
from mechbal.papers import discs as dz

EX, EZ = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
CASES = {"planar3r": "discs-3r", "spatial3r": "discs-spatial", "scara": "scara"}


def _T(y):
    t = np.eye(4)
    t[1, 3] = y
    return t


def disc_arm(kind, inertia_from_design=True):
    """The case's arm with the closed form's static balancing (l_g), links only (no discs):
    (mechanism, parameters p, closed-form design d)."""
    p = parameters_from_config(kind, read_case(CASES[kind]))
    d = dz.design(kind, p, True)
    R, P = _core.JointType.revolute, _core.JointType.prismatic
    axes, types, coms = {"planar3r": ((EX, EX, EX), (R, R, R), (d["lg1"], d["lg2"], d["lg3"])),
                         "spatial3r": ((EZ, EX, EX), (R, R, R), (0.0, d["lg2"], d["lg3"])),
                         "scara": ((EX, EX, EX), (R, R, P), (d["lg1"], d["lg2"], 0.0))}[kind]
    src = d if inertia_from_design else p
    joints, bodies, parent = [], [], "base"
    for i, offset in enumerate((0.0, d["l1"], d["l2"])):
        n = f"joint{i + 1}"
        joints.append(_core.Joint(n, types[i], parent, _T(offset), axes[i]))
        inertia = np.diag([src[f"Jx{i + 1}"], src[f"Jy{i + 1}"], src[f"Jz{i + 1}"]])
        bodies.append(_core.Body(f"link{i + 1}", n, d[f"m{i + 1}"], np.array([0.0, coms[i], 0.0]), inertia))
        parent = n
    return mechbal.Mechanism.from_description(joints, bodies, name=kind), p, d


def paper_discs(kind, p, d):
    """The paper's disc slots: inertias given, the geared discs' ratios left to the method."""
    if kind == "planar3r":
        return [DiscSlot("disc4", "joint1", "joint2", position=(0, d["l1"], 0), ratio=1.0, inertia=p["Jx4"]),
                DiscSlot("disc5", "joint1", "joint2", position=(0, d["l1"], 0), inertia=p["Jx5"]),
                DiscSlot("disc6", "joint2", "joint3", position=(0, d["l2"], 0), ratio=1.0, inertia=p["Jx6"]),
                DiscSlot("disc7", "joint2", "joint3", position=(0, d["l2"], 0), inertia=p["Jx7"])]
    carrier, joint, at = ("joint2", "joint3", d["l2"]) if kind == "spatial3r" else ("joint1", "joint2", d["l1"])
    return [DiscSlot("disc4", carrier, joint, position=(0, at, 0), ratio=1.0, inertia=p["Jx4"]),
            DiscSlot("disc5", carrier, joint, position=(0, at, 0), inertia=p["Jx5"])]


def _samples(kind, n, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (n, 3))
    if kind == "scara":
        q[:, 2] = rng.uniform(-0.2, 0.2, n)
    return q


def _peak_H(mech, q, rng, vscale=1.0):
    v = rng.uniform(-vscale, vscale, q.shape)
    return float(np.max(np.linalg.norm(mech.momentum(q, v).angular_momentum, axis=1)))


def test_planar3r_reproduces_eq14_and_the_base_disc_completes_moment_balance():
    m, p, d = disc_arm("planar3r")
    cf = dz.balance_planar3r(p)
    r = moment.balance(m, paper_discs("planar3r", p, d), _samples("planar3r", 200, 1))
    assert r.design["disc5"].ratio == pytest.approx(cf["beta"], rel=1e-10)
    assert r.design["disc7"].ratio == pytest.approx(cf["gamma"], rel=1e-10)
    cols = r.metrics["columns"]
    assert cols["joint2"]["cancelled"] and cols["joint3"]["cancelled"]
    # joint 1 turns the whole arm: what remains is k1 theta1' about x (eq 16), and the method
    # says which disc would cancel it
    assert not cols["joint1"]["cancelled"] and not r.exact
    rem = cols["joint1"]["constant_remainder"]
    assert rem["link"] == "base" and np.allclose(rem["vector"], [cf["k"][0], 0, 0], rtol=1e-10, atol=1e-12)
    assert "disc on 'base'" in cols["joint1"]["add"]
    # and the paper's own criterion: M diagonal and constant, M_ii = k_i (eq 16)
    mm = r.metrics["mass_matrix"]
    assert mm["offdiag_ratio"] < 1e-12 and mm["diag_variation"] < 1e-12
    assert np.allclose(mm["diag_mean"], cf["k"], rtol=1e-10)

    slots = paper_discs("planar3r", p, d) + [DiscSlot("disc0", "base", "joint1", inertia=0.05)]
    r2 = moment.balance(m, slots, _samples("planar3r", 200, 1))
    assert r2.exact, r2.limited_by
    assert r2.design["disc0"].ratio == pytest.approx(-cf["k"][0] / 0.05, rel=1e-10)
    rng = np.random.default_rng(7)
    q = _samples("planar3r", 1000, 8)
    assert _peak_H(r2.balanced, q, rng) < 1e-9
    assert _peak_H(m, q, rng) > 0.1
    assert r2.residual < 1e-9 < r2.residual_before


def test_planar3r_disc_inertias_for_given_ratios():
    """The other way round: ratios fixed at the closed form's, inertias chosen: the case's."""
    m, p, d = disc_arm("planar3r")
    cf = dz.balance_planar3r(p)
    slots = paper_discs("planar3r", p, d)
    slots[1] = DiscSlot("disc5", "joint1", "joint2", position=(0, d["l1"], 0), ratio=cf["beta"])
    slots[3] = DiscSlot("disc7", "joint2", "joint3", position=(0, d["l2"], 0), ratio=cf["gamma"])
    r = moment.balance(m, slots, _samples("planar3r", 200, 2))
    assert r.design["disc5"].inertia == pytest.approx(p["Jx5"], rel=1e-10)
    assert r.design["disc7"].inertia == pytest.approx(p["Jx7"], rel=1e-10)


def test_spatial3r_reproduces_corrected_eq25_and_full_balance_with_two_more_discs():
    m, p, d = disc_arm("spatial3r", inertia_from_design=False)    # Jy2, Jy3 as in the case file
    cf = dz.balance_spatial3r(p)
    slots = paper_discs("spatial3r", p, d) + [InertiaSlot("link2_cross_bar", "link2", ("Iyy",)),
                                              InertiaSlot("link3_shape", "link3", ("Iyy",))]
    q = _samples("spatial3r", 200, 3)
    r = moment.balance(m, slots, q)
    assert r.design["disc5"].ratio == pytest.approx(cf["beta"], rel=1e-10)
    assert r.design["link2_cross_bar"].components["Iyy"] == pytest.approx(cf["inertia_conditions"]["Jy2"], rel=1e-10)
    assert r.design["link3_shape"].components["Iyy"] == pytest.approx(cf["inertia_conditions"]["Jy3"], rel=1e-10)
    # the printed eq 25 (J_y2 = J_z2, J_y3 = J_z3 + mu) is not what the method finds (C2)
    assert abs(r.design["link2_cross_bar"].components["Iyy"] - p["Jz2"]) > 0.1
    mm = r.metrics["mass_matrix"]
    assert mm["offdiag_ratio"] < 1e-12 and mm["diag_variation"] < 1e-12
    assert np.allclose(mm["diag_mean"], cf["k"], rtol=1e-10)
    assert {k for k, c in r.metrics["columns"].items() if not c["cancelled"]} == {"joint1", "joint2"}
    assert r.metrics["columns"]["joint2"]["constant_remainder"]["link"] == "joint1"

    full = slots + [DiscSlot("disc0", "base", "joint1", axis=(0, 0, 1), inertia=0.1),
                    DiscSlot("disc1", "joint1", "joint2", position=(0, d["l1"], 0), inertia=0.1)]
    r2 = moment.balance(m, full, q)
    assert r2.exact, r2.limited_by
    rng = np.random.default_rng(9)
    qc = _samples("spatial3r", 1000, 10)
    assert _peak_H(r2.balanced, qc, rng) < 1e-9 < _peak_H(m, qc, rng)


def test_scara_reproduces_eq35_generalised_and_says_why_the_rest_is_impossible():
    m, p, d = disc_arm("scara")
    cf = dz.balance_scara(p)
    r = moment.balance(m, paper_discs("scara", p, d), _samples("scara", 200, 4))
    assert r.design["disc5"].ratio == pytest.approx(cf["beta"], rel=1e-10)
    assert np.allclose(r.metrics["mass_matrix"]["diag_mean"], cf["k"], rtol=1e-10)
    cols = r.metrics["columns"]
    assert cols["joint3"].get("force_balanced") is False        # F_x = m3 d3'' (docs §6b)
    assert "not force-balanced" in cols["joint3"]["why"]
    assert not cols["joint2"]["cancelled"] and "about y, z" in cols["joint2"]["why"]


def five_bar(parallelogram=True):
    """The five-bar case's leg-wise statically balanced 5R (y-z plane, axes x) with a point loop
    closure at the end effector; a general (non-parallelogram) variant otherwise."""
    p = parameters_from_config("fivebar", read_case("five-bar"))
    if not parallelogram:
        p = dict(p, d=0.12, b1=0.32, b2=0.36)
    d = dz.design("fivebar", p, True)
    R = _core.JointType.revolute
    joints = [_core.Joint("p1", R, "base", np.eye(4), EX), _core.Joint("d1", R, "p1", _T(d["a1"]), EX),
              _core.Joint("p2", R, "base", _T(d["d"]), EX), _core.Joint("d2", R, "p2", _T(d["a2"]), EX)]
    bodies = [_core.Body(n, n, d[f"m{n}"], np.array([0, d[f"c{n}"], 0.0]), np.diag(d[f"inertia_{n}"]))
              for n in ("p1", "d1", "p2", "d2")]
    bodies.append(_core.Body("end_effector", "d1", d["mP"], np.array([0, d["b1"], 0.0]), np.zeros((3, 3))))
    frames = [_core.Frame("tip1", "d1", _T(d["b1"])), _core.Frame("tip2", "d2", _T(d["b2"]))]
    loops = [_core.LoopConstraint("tip", _core.LoopType.point, "tip1", "tip2")]
    m = mechbal.Mechanism.from_description(joints, bodies, frames, loops=loops, actuated=["p1", "p2"])
    t = np.linspace(0, 2 * np.pi, 150)
    th1 = 0.3 + 0.6 * np.sin(t)
    samples = np.stack([th1, th1 + 1.5 + 0.7 * np.sin(2 * t + 0.3)], 1)   # |th2 - th1| in [0.8, 2.2]
    B1, B2, P = dz.fivebar_positions(d, *samples[0])
    phi1, phi2 = np.arctan2(*(P - B1)[[2, 1]]), np.arctan2(*(P - B2)[[2, 1]])
    guess = np.array([samples[0, 0], phi1 - samples[0, 0], samples[0, 1], phi2 - samples[0, 1]])
    return m, p, d, samples, guess


def test_parallelogram_five_bar_base_discs_reproduce_the_decoupled_inertias():
    """A closed loop: base discs geared to the actuated joints need ratio x inertia = -k_i, the
    closed form's decoupled inertias (docs/discs_derivation.md §5); then H = 0."""
    m, p, d, samples, guess = five_bar(True)
    cf = dz.balance_fivebar(p)
    slots = [DiscSlot("disc1", "base", "p1", inertia=0.05), DiscSlot("disc2", "base", "p2", inertia=0.05)]
    r = moment.balance(m, slots, samples, q_guess=guess)
    assert r.exact, r.limited_by
    assert r.design["disc1"].geared_inertia == pytest.approx(-cf["k"][0], rel=1e-9)
    assert r.design["disc2"].geared_inertia == pytest.approx(-cf["k"][1], rel=1e-9)
    motion = r.balanced.closed_motion(samples, np.random.default_rng(3).uniform(-1, 1, samples.shape), q_guess=guess)
    H = r.balanced.momentum(motion.q, motion.v).angular_momentum
    assert np.max(np.abs(H)) < 1e-9
    assert r.residual_before > 0.1


def test_general_five_bar_moment_balance_is_impossible_and_says_why():
    """A general 5R: J_phi varies, so constant-ratio discs cannot follow (the five-bar proof)."""
    m, p, d, samples, guess = five_bar(False)
    slots = [DiscSlot("disc1", "base", "p1", inertia=0.05), DiscSlot("disc2", "base", "p2", inertia=0.05)]
    r = moment.balance(m, slots, samples, q_guess=guess)
    assert not r.exact
    for name in ("p1", "p2"):
        assert "varies over the workspace" in r.metrics["columns"][name]["why"]
    assert 1e-3 < r.residual < r.residual_before


def test_bad_slots_are_named():
    m, p, d = disc_arm("planar3r")
    q = _samples("planar3r", 5, 0)
    with pytest.raises(ValueError, match=r"discs.dx.joint: 'joint9' is not a coordinate"):
        moment.balance(m, [DiscSlot("dx", "joint1", "joint9")], q)
    with pytest.raises(ValueError, match=r"discs.dx.carrier: no link named 'joint11' \(did you mean 'joint1'\?\)"):
        moment.balance(m, [DiscSlot("dx", "joint11", "joint2")], q)
    with pytest.raises(ValueError, match=r"inertias.ix.body: no body named"):
        moment.balance(m, [InertiaSlot("ix", "nobody")], q)
