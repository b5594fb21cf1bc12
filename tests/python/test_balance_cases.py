"""`mechbal balance` on the papers' built-in cases (issue 11): PAMINSA by shaking-force balancing
with tied, fixed-position counterweight slots (Briot & Arakelian's 2.7915 / 1.3865 / 0.436 kg per
leg and 9.615 kg), the disc cases by shaking-moment balancing from [[balance.discs]] tables (the
closed forms' gear ratios and inertia conditions, mechbal.papers.discs), the five-bar's
impossibility and its reason, the written-back cases run by `mechbal run`, and the new keys'
refusals naming the field. Everything through the CLI into tmp folders."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mechbal import _core
from mechbal.balance import CounterweightSlot as Slot
from mechbal.balance import force, rms, static
from mechbal.cli import main
from mechbal.config import case_path, read_case
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences
from mechbal.mechanism import Mechanism
from mechbal.papers import discs as dz

from cli_checks import one_line_error, summary_of

#: Briot & Arakelian 2009, the counterweights they print (per leg) and the vertical counter-mass
PAMINSA_PRINTED = {"CP1_atA": 2.7915, "CP2_atF": 1.3865, "CP3_atL": 0.436}
PAMINSA_VERTICAL = 9.615




def balance_table(case: str) -> str:
    """The [balance] part of a built-in case file (to edit into a --design file)."""
    text = case_path(case).read_text()
    return text[text.index("\n[balance]") + 1:]


# ---- PAMINSA: force -----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def paminsa_force(tmp_path_factory):
    out = tmp_path_factory.mktemp("balance") / "paminsa"
    assert main(["balance", "paminsa", "--method", "force", "--out", str(out), "-q"]) == 0
    return out


def test_paminsa_force_reproduces_the_papers_counterweights(paminsa_force):
    s = summary_of(paminsa_force)
    b = s["balance"]
    d = b["design"]
    for leg in (1, 2, 3):
        for kind, mass in PAMINSA_PRINTED.items():
            assert d[f"leg{leg}.{kind}"]["mass"] == pytest.approx(mass, abs=1e-6)
            assert d[f"leg{leg}.{kind}"]["fixed_position"]
    assert d["vertical_counter_mass"]["mass"] == pytest.approx(PAMINSA_VERTICAL, abs=1e-6)
    # one unknown per group: 3 tied groups + the vertical counter-mass, all determined
    assert b["unknowns"] == 4 and b["rank"] == 4 and b["exact"] and not b["undetermined"]
    assert b["tied"] == {f"leg1.{k}": [f"leg{i}.{k}" for i in (1, 2, 3)] for k in PAMINSA_PRINTED}
    assert d["leg2.CP1_atA"]["tied_to"] == "leg1.CP1_atA" and "tied_to" not in d["leg1.CP1_atA"]
    # the positions are the paper's points, exactly (A on link 3, F on link 2, L on the guide)
    assert d["leg3.CP1_atA"]["position"] == [-0.42, 0.0, 0.0]
    assert d["leg1.CP3_atL"]["position"] == [-0.15, 0.0, 0.0]
    assert b["residual"] < 1e-9 * b["residual_before"]
    assert s["closed"] and s["kind"] == "paminsa"


def test_paminsa_force_balanced_poses_have_no_shaking_force(paminsa_force):
    """Issue 11's evidence: the shaking force of the balanced mechanism recomputed from the
    exported poses (the exported joint states through the written-back balanced.toml, and the
    bodies' centres of mass) is below 1e-9 of the unbalanced peak; finite differences of the
    exported poses agree to round-off amplified by 1/dt^2."""
    unb = read_bodies(paminsa_force / "bodies_unbalanced.npz")
    bal = read_bodies(paminsa_force / "bodies_balanced.npz")
    peak = float(np.max(np.abs(unb["shaking_force"])))
    assert peak > 10.0
    assert np.max(np.abs(bal["shaking_force"])) < 1e-9 * peak
    # the written-back mechanism, at the exported joint states
    mech = Mechanism.from_toml(paminsa_force / "balanced.toml")
    assert sorted(mech.body_names) == sorted(bal["names"].tolist())
    sw = mech.shaking_wrench(bal["q"], bal["qd"], bal["qdd"])
    assert np.max(np.abs(sw.shaking_force)) < 1e-9 * peak
    # the total centre of mass of the exported bodies does not move
    excursion = {k: np.ptp(np.einsum("b,nbk->nk", d["mass"], d["com"]), axis=0).max() for k, d in
                 (("unbalanced", unb), ("balanced", bal))}
    assert excursion["balanced"] < 1e-9 * excursion["unbalanced"]
    F_fd, _ = shaking_wrench_by_finite_differences(bal)
    assert np.max(np.abs(F_fd[5:-5])) < 1e-6 * peak
    F_unb, _ = shaking_wrench_by_finite_differences(unb)
    assert np.max(np.abs(F_unb[5:-5] - unb["shaking_force"][5:-5])) < 1e-3 * peak


def test_paminsa_balanced_toml_runs(paminsa_force, tmp_path):
    data = tomllib.loads((paminsa_force / "balanced.toml").read_text())
    assert data["case"]["kind"] == "mechanism" and data["mechanism"]["loops"]
    assert len(data["trajectory"]["initial_guess"]) == 28
    assert main(["run", str(paminsa_force / "balanced.toml"), "--out", str(tmp_path / "run"), "-q"]) == 0
    s = summary_of(tmp_path / "run")
    unbalanced = np.max(np.abs(read_bodies(paminsa_force / "bodies_unbalanced.npz")["shaking_force"]))
    assert s["closed"] and max(s["peak_shaking_force"]["nominal"]) < 1e-9 * unbalanced


def test_paminsa_untied_legs_leave_masses_undetermined(tmp_path):
    """Without the ties (each leg's slots their own unknowns) legs 1 and 2, driven by one
    actuator, leave combinations of their masses undetermined: the design file overrides the
    built-in table, and the summary says so."""
    table = "\n".join(line for line in balance_table("paminsa").splitlines() if not line.startswith("tie ="))
    for leg in (2, 3):
        for kind, x in (("CP1_atA", "-0.42"), ("CP2_atF", "0.14"), ("CP3_atL", "-0.15")):
            table = table.replace(f'name = "leg{leg}.{kind}"\n', f'name = "leg{leg}.{kind}"\nposition = [{x}, 0.0, 0.0]\n')
    (tmp_path / "design.toml").write_text(table)
    out = tmp_path / "untied"
    assert main(["balance", "paminsa", "--design", str(tmp_path / "design.toml"), "--out", str(out), "-q"]) == 0
    b = summary_of(out)["balance"]
    assert b["unknowns"] == 10 and b["rank"] < 10 and b["undetermined"] and not b["tied"]
    assert b["residual"] < 1e-9 * b["residual_before"]    # still balanced: one member of the family


# ---- fixed positions and ties, generally -------------------------------------------------------------

def two_pendulums():
    """Two identical pendulums on the base (about y, at x = -0.5 and 0.5, link x along the arm)."""
    R = _core.JointType.revolute
    joints, bodies = [], []
    for i, x in enumerate((-0.5, 0.5)):
        T = np.eye(4)
        T[0, 3] = x
        joints.append(_core.Joint(f"arm{i + 1}", R, "base", T, np.array([0.0, 1.0, 0.0])))
        bodies.append(_core.Body(f"link{i + 1}", f"arm{i + 1}", 2.0, np.array([0.3, 0.0, 0.0]),
                                 np.diag([0.0, 0.02, 0.02]), "link"))
    return Mechanism.from_description(joints, bodies, name="two-pendulums")


def test_fixed_position_is_exact_and_equals_max_radius_zero():
    mech = two_pendulums()
    slots = [Slot("cw1", "arm1", position=(-0.2, 0.0, 0.0)), Slot("cw2", "arm2", position=(-0.25, 0.0, 0.0))]
    r = static.balance(mech, slots, 50)
    assert r.exact and r.unknowns == 2 and r.rank == 2
    assert r.design["cw1"].mass == pytest.approx(2.0 * 0.3 / 0.2, rel=1e-12)
    assert r.design["cw2"].mass == pytest.approx(2.0 * 0.3 / 0.25, rel=1e-12)
    assert r.design["cw1"].position.tolist() == [-0.2, 0.0, 0.0]
    r0 = static.balance(mech, [Slot("cw1", "arm1", center=(-0.2, 0, 0), max_radius=0.0),
                               Slot("cw2", "arm2", center=(-0.25, 0, 0), max_radius=0.0)], 50)
    assert r0.unknowns == 2 and r0.design["cw1"].mass == pytest.approx(3.0, rel=1e-12)


def test_tied_slots_share_mass_and_position_in_static_force_and_rms():
    mech = two_pendulums()
    tied = [Slot("cw1", "arm1", max_radius=0.2), Slot("cw2", "arm2", tie="cw1")]
    r = static.balance(mech, tied, 50)
    assert r.exact and r.tied == {"cw1": ["cw1", "cw2"]}
    assert r.unknowns == 4   # one group: its mass and its 3 mass moments
    for k in ("cw1", "cw2"):
        assert r.design[k].mass == pytest.approx(3.0, rel=1e-9)       # lightest: at the full radius
        assert np.allclose(r.design[k].position, [-0.2, 0, 0], atol=1e-9)
    rf = force.balance(mech, tied, 50)
    assert rf.exact and rf.design["cw2"].mass == pytest.approx(rf.design["cw1"].mass, rel=1e-12)
    # rms (total coupling): one set of variables for the group
    t = np.linspace(0, 1, 201)
    q = np.stack([np.sin(3 * t), 0.5 * np.cos(2 * t)], 1)
    v = np.stack([3 * np.cos(3 * t), -np.sin(2 * t)], 1)
    a = np.stack([-9 * np.sin(3 * t), -2 * np.cos(2 * t)], 1)
    rr = rms.balance(mech, [Slot("cw1", "arm1", 1.0, 1.0, direction=(-1, 0, 0), max_radius=1.0),
                            Slot("cw2", "arm2", tie="cw1")], (q, v, a), coupling="total")
    assert rr.unknowns == 1 and rr.tied == {"cw1": ["cw1", "cw2"]}
    assert rr.design["cw2"].signed_distance == pytest.approx(rr.design["cw1"].signed_distance, abs=1e-15)
    with pytest.raises(ValueError, match=r"design\[1\].tie: .*per_joint"):
        rms.balance(mech, [Slot("cw1", "arm1", 1.0, 1.0, direction=(-1, 0, 0), max_radius=1.0),
                           Slot("cw2", "arm2", tie="cw1")], (q, v, a), coupling="per_joint")


def test_bad_ties_and_fixed_positions_are_named():
    mech = two_pendulums()
    with pytest.raises(ValueError, match=r"design\[1\].tie: no counterweight slot named 'cw3' .*did you mean 'cw1'"):
        static.balance(mech, [Slot("cw1", "arm1", max_radius=0.2), Slot("cw2", "arm2", tie="cw3")], 5)
    with pytest.raises(ValueError, match=r"design\[1\].mass_max: 'cw2' is tied to 'cw1'"):
        static.balance(mech, [Slot("cw1", "arm1", max_radius=0.2), Slot("cw2", "arm2", mass_max=1.0, tie="cw1")], 5)
    with pytest.raises(ValueError, match=r"design\[0\].tie: the ties form a cycle"):
        static.balance(mech, [Slot("cw1", "arm1", tie="cw2"), Slot("cw2", "arm2", tie="cw1")], 5)
    with pytest.raises(ValueError, match=r"design\[0\].max_radius: the position is given"):
        static.balance(mech, [Slot("cw1", "arm1", position=(0.1, 0, 0), max_radius=0.2)], 5)
    with pytest.raises(ValueError, match=r"design\[0\].direction: the position is given"):
        static.balance(mech, [Slot("cw1", "arm1", position=(0.1, 0, 0), direction=(1, 0, 0))], 5)


# ---- discs: moment --------------------------------------------------------------------------------

DISC_CASES = {"planar3r": "discs-3r", "spatial3r": "discs-spatial", "scara": "scara"}


def params(kind):
    from mechbal.papers.discs.runner import parameters_from_config

    return parameters_from_config(kind, read_case(DISC_CASES.get(kind, "five-bar")))


@pytest.fixture(scope="module")
def disc_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("moment")
    out = {}
    for kind, case in list(DISC_CASES.items()) + [("fivebar", "five-bar")]:
        assert main(["balance", case, "--method", "moment", "--out", str(root / case), "-q",
                     "--allow-partial"]) == 0      # scara and the five-bar: partial, said why
        out[kind] = root / case
    return out


def test_discs_3r_reproduces_eq14(disc_runs):
    cf = dz.balance_planar3r(params("planar3r"))
    b = summary_of(disc_runs["planar3r"])["balance"]
    assert b["design"]["disc5"]["ratio"] == pytest.approx(cf["beta"], rel=1e-10)
    assert b["design"]["disc7"]["ratio"] == pytest.approx(cf["gamma"], rel=1e-10)
    mm = b["metrics"]["mass_matrix"]
    assert mm["offdiag_ratio"] < 1e-12 and mm["diag_variation"] < 1e-12
    assert np.allclose(mm["diag_mean"], cf["k"], rtol=1e-10)
    cols = b["metrics"]["columns"]
    assert cols["joint2"]["cancelled"] and cols["joint3"]["cancelled"] and not cols["joint1"]["cancelled"]
    assert np.allclose(cols["joint1"]["constant_remainder"]["vector"], [cf["k"][0], 0, 0], rtol=1e-10)
    assert not b["exact"] and "disc on 'base'" in b["limited_by"][0]


def test_discs_spatial_reproduces_corrected_eq25(disc_runs):
    p = params("spatial3r")
    cf = dz.balance_spatial3r(p)
    b = summary_of(disc_runs["spatial3r"])["balance"]
    assert b["design"]["disc5"]["ratio"] == pytest.approx(cf["beta"], rel=1e-10)
    assert b["design"]["link2_cross_bar"]["Iyy"] == pytest.approx(cf["inertia_conditions"]["Jy2"], rel=1e-10)
    assert b["design"]["link3_shape"]["Iyy"] == pytest.approx(cf["inertia_conditions"]["Jy3"], rel=1e-10)
    assert abs(b["design"]["link2_cross_bar"]["Iyy"] - p["Jz2"]) > 0.1     # not the printed eq 25
    mm = b["metrics"]["mass_matrix"]
    assert mm["offdiag_ratio"] < 1e-12 and np.allclose(mm["diag_mean"], cf["k"], rtol=1e-10)


def test_scara_reproduces_eq35_and_says_why_the_rest_is_impossible(disc_runs):
    cf = dz.balance_scara(params("scara"))
    b = summary_of(disc_runs["scara"])["balance"]
    assert b["design"]["disc5"]["ratio"] == pytest.approx(cf["beta"], rel=1e-10)
    assert np.allclose(b["metrics"]["mass_matrix"]["diag_mean"], cf["k"], rtol=1e-10)
    assert "not force-balanced" in b["metrics"]["columns"]["joint3"]["why"]
    assert any("not force-balanced" in x for x in b["limited_by"])


def test_five_bar_leg_discs_cannot_balance_the_moment_and_say_why(disc_runs):
    """The parallelogram five-bar with discs on its legs (the built-in table): one actuated rate's
    angular momentum is cancelled, the other keeps k1 + k2 + J1 + J2 (the leg discs act on the
    two rates only together), constant in the base frame: a base disc would cancel it."""
    p = params("fivebar")
    cf = dz.balance_fivebar(p)
    s = summary_of(disc_runs["fivebar"])
    b = s["balance"]
    assert not b["exact"] and b["limited_by"][0].startswith("impossible:")
    cols = b["metrics"]["columns"]
    left = [k for k, c in cols.items() if not c["cancelled"]]
    assert len(left) == 1 and "act on both only together" in cols[left[0]]["why"]
    assert "disc on 'base'" in cols[left[0]]["add"]
    # what remains is k1 + k2 + J1 + J2 of the leg-wise balanced parallelogram (k from the
    # closed form of the decoupled inertias, docs/discs_derivation.md section 5)
    H = moment_columns_of_case()
    assert cols[left[0]]["peak_remaining"] == pytest.approx(H.sum() + 0.01 + 0.01, rel=1e-9)
    assert s["closed"] and b["residual_before"] > 0.1
    assert cf["k"][0] > 0 and cf["k"][1] > 0


def moment_columns_of_case():
    """The angular momentum of a unit rate of theta1 and of theta2 (constant: the leg-wise
    balanced parallelogram) of the five-bar case's balance mechanism."""
    from mechbal.balance import moment
    from mechbal.balance.run import balance_case as load_balance_case

    bc = load_balance_case("five-bar")
    _, H = moment.angular_momentum_columns(bc.mechanism, np.array([[0.5, 2.0], [1.0, 2.4]]), q_guess=bc.q_guess)
    assert np.allclose(H[0], H[1], atol=1e-12)
    return H[0, :, 0]


def test_five_bar_base_discs_balance_it_with_the_decoupled_inertias(tmp_path):
    """With base discs geared to the actuators (a --design file) the five-bar is moment-balanced
    exactly: ratio x inertia = -(angular momentum of a unit rate)."""
    table = balance_table("five-bar")
    table = table[:table.index("[[balance.discs]]")] + """
[[balance.discs]]
name = "disc1"
carrier = "base"
joint = "theta1"
inertia = 0.05
[[balance.discs]]
name = "disc2"
carrier = "base"
joint = "theta2"
inertia = 0.05
"""
    (tmp_path / "base.toml").write_text(table)
    out = tmp_path / "fb"
    assert main(["balance", "five-bar", "--design", str(tmp_path / "base.toml"), "--out", str(out), "-q"]) == 0
    b = summary_of(out)["balance"]
    H = moment_columns_of_case()
    assert b["exact"], b["limited_by"]
    assert b["design"]["disc1"]["geared_inertia"] == pytest.approx(-H[0], rel=1e-9)
    assert b["design"]["disc2"]["geared_inertia"] == pytest.approx(-H[1], rel=1e-9)
    assert b["residual"] < 1e-9 * b["residual_before"]
    bal = read_bodies(out / "bodies_balanced.npz")
    unb = read_bodies(out / "bodies_unbalanced.npz")
    assert np.max(np.abs(bal["shaking_moment"])) < 1e-9 * np.max(np.abs(unb["shaking_moment"]))
    assert main(["run", str(out / "balanced.toml"), "--out", str(tmp_path / "run"), "-q"]) == 0


def test_disc_balanced_toml_has_the_geared_discs_and_runs(disc_runs, tmp_path):
    path = disc_runs["planar3r"] / "balanced.toml"
    data = tomllib.loads(path.read_text())
    joints = {j["name"]: j for j in data["mechanism"]["joints"]}
    cf = dz.balance_planar3r(params("planar3r"))
    assert joints["disc5"]["mimic"]["joint"] == "joint2"
    assert joints["disc5"]["mimic"]["ratio"] == pytest.approx(cf["beta"], rel=1e-10)
    assert {b["name"]: b["kind"] for b in data["mechanism"]["bodies"]}["disc7"] == "disc"
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "-q"]) == 0
    mech = Mechanism.from_toml(path)
    M = mech.mass_matrix(np.random.default_rng(0).uniform(-3, 3, (20, 3)))
    assert np.allclose(M, np.diag(cf["k"]), atol=1e-12)


# ---- refusals ----------------------------------------------------------------------------------------

def test_bad_balance_tables_are_refused_naming_the_field(capsys, tmp_path):
    out = str(tmp_path / "o")
    design = tmp_path / "d.toml"

    def refused(case, text, *needles):
        design.write_text(text)
        assert main(["balance", case, "--design", str(design), "--out", out]) == 2
        one_line_error(capsys, *needles)

    discs = balance_table("discs-3r")
    refused("discs-3r", discs.replace("ratio = 1.0", "ratoi = 1.0", 1),
            "balance.discs[0].ratoi: unknown key (did you mean 'ratio'?)")
    refused("discs-3r", discs.replace('carrier = "joint1"', 'carrier = "joint11"', 1),
            "balance.discs[0].carrier", "did you mean 'joint1'")
    refused("discs-3r", discs.replace('joint = "joint2"', 'joint = "joint9"', 1), "balance.discs[0].joint")
    refused("discs-3r", discs.replace("inertia = 0.002", "inertia = 0.002\ninertia_max = 1.0", 1),
            "balance.discs[0].inertia_max", "the inertia is given")
    refused("discs-spatial", balance_table("discs-spatial").replace('body = "link2"', 'body = "lnk2"'),
            "balance.inertias[0].body", "did you mean 'link2'")
    refused("discs-spatial", balance_table("discs-spatial").replace('components = ["Iyy"]', 'components = ["Iyz"]', 1),
            "balance.inertias[0].components")
    five = balance_table("five-bar")
    refused("five-bar", five.replace("lower = [0.3, 1.9]", "").replace("upper = [1.2, 2.6]", ""), "balance.lower")
    refused("five-bar", five.replace("lower = [0.3, 1.9]", "lower = [0.3]"), "balance.lower", "2 values")
    pam = balance_table("paminsa")
    refused("paminsa", pam.replace('tie = "leg1.CP2_atF"', 'tie = "leg1.CP2_atG"', 1),
            "balance.counterweights[4].tie", "did you mean 'leg1.CP2_atF'")
    refused("paminsa", pam.replace("position = [-0.42, 0.0, 0.0]", "position = [-0.42, 0.0, 0.0]\nmax_radius = 0.1"),
            "balance.counterweights[0].max_radius", "the position is given")
    refused("paminsa", pam.replace('tie = "leg1.CP1_atA"', 'tie = "leg1.CP1_atA"\nmass = 1.0', 1),
            "balance.counterweights[1].mass", "tied to 'leg1.CP1_atA'")
    refused("paminsa", pam.replace('link = "leg1_link3"', 'link = "leg1_lnk3"'),
            "balance.counterweights[0].link", "did you mean 'leg1_link3'")
    assert not (tmp_path / "o").exists()


# ---- RPSP (Heydari & Enferadi): mechbal balance rpsp --method force ----------------------------

def test_rpsp_force_reproduces_eqs_29_31_and_its_toml_runs(tmp_path):
    """`mechbal balance rpsp --method force`: the [balancing] counterweight bodies as fixed-position
    slots give the paper's eqs 29-31 masses (the platform counterweight zero); the balanced
    robot's shaking force along the paper's motion, recomputed through the written-back case at
    the exported joint states, is below 1e-9 of the unbalanced peak; balanced.toml runs."""
    from mechbal.papers import rpsp as paper
    from mechbal.schema import validate_case

    out = tmp_path / "rpsp"
    assert main(["balance", "rpsp", "--method", "force", "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    b = s["balance"]
    assert s["kind"] == "rpsp" and s["closed"] and b["exact"] and b["rank"] == b["unknowns"] == 10
    c = validate_case(read_case("rpsp"), warn=False)
    p = c.paper
    eqs = paper.counterweights_eqs_29_31(p.m_E, p.m_Q, p.m_H, p.m_K, p.r_H, p.r_K, p.r_P, p.r_N, p.r_Q, p.r_F)
    for key in ("m_P", "m_N", "m_F"):
        for name in getattr(c.balancing, key):
            assert b["design"][name]["mass"] == pytest.approx(eqs[key], rel=1e-7), name
    assert 0.0 <= b["design"]["platform_counterweight"]["mass"] < 1e-7
    unb = read_bodies(out / "bodies_unbalanced.npz")
    bal = read_bodies(out / "bodies_balanced.npz")
    peak = float(np.max(np.abs(unb["shaking_force"])))
    assert peak > 10.0 and np.max(np.abs(bal["shaking_force"])) < 1e-9 * peak
    data = tomllib.loads((out / "balanced.toml").read_text())
    assert data["case"]["kind"] == "rpsp" and "balance" not in data
    assert sum(x["name"] == "P_1" for x in data["mechanism"]["bodies"]) == 1   # replaced, not added
    from mechbal.papers.rpsp import runner as runner

    written = validate_case(data, warn=False)
    mech = Mechanism.from_spec(runner.driven_by_platform(written.spec, written.motion.platform))
    assert sorted(mech.body_names) == sorted(bal["names"].tolist())
    sw = mech.shaking_wrench(bal["q"], bal["qd"], bal["qdd"])
    assert np.max(np.abs(sw.shaking_force)) < 1e-9 * peak
    assert main(["run", str(out / "balanced.toml"), "--out", str(tmp_path / "run"), "-q"]) == 0


def test_rpsp_design_file_gives_only_balance(capsys, tmp_path):
    design = tmp_path / "design.toml"
    design.write_text('[balance]\n[[balance.counterweights]]\nname = "cw"\nlink = "AD_1"\nmass_max = 5.0\n'
                      '[trajectory]\nstart = [0.0, 0.0, 0.0]\nend = [0.1, 0.0, 0.0]\nduration = 1.0\n')
    assert main(["balance", "rpsp", "--method", "force", "--design", str(design), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, "trajectory", "[motion]")


# ---- Orthoglide (Martini et al.): mechbal balance orthoglide --method springs --------------------

def test_orthoglide_springs_reproduce_eqs_18_19_and_its_toml_runs(tmp_path):
    """`mechbal balance orthoglide --method springs`: the case's [[springs]] sized over the
    sliders' positions of its workspace grid (as its runner sizes them) give the runner's
    published rates 2.510052 / 11.130577 N/mm (eqs 18-19); the static slider forces (gravity +
    springs) along the rest-to-rest move are below 1e-9 of the unbalanced peak; balanced.toml is
    the case with the sized rates and runs (its paths shortened here for speed)."""
    import copy

    out = tmp_path / "orthoglide"
    assert main(["balance", "orthoglide", "--method", "springs", "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    b = s["balance"]
    assert s["kind"] == "orthoglide" and s["closed"] and b["exact"] and b["rank"] == b["unknowns"] == 2
    published = {"distal": 2.510052, "proximal": 11.130576923}   # tests/python/test_orthoglide.py
    for name, rate in published.items():
        assert b["design"][name]["rate"] / 1e3 == pytest.approx(rate, rel=1e-9), name
    assert s["case_notes"]["paper_spring_rates_N_per_mm"] == {"K_D": 2.510, "K_P": 11.131}
    assert "11^3 workspace grid" in s["case_notes"]["sizing_samples"]
    unb = read_bodies(out / "bodies_unbalanced.npz")
    bal = read_bodies(out / "bodies_balanced.npz")
    peak = float(np.max(np.abs(unb["gravity_torque"])))
    assert peak > 100.0 and np.max(np.abs(bal["gravity_torque"])) < 1e-9 * peak
    assert s["before_after"]["gravity_torque"]["balanced"]["peak"] == pytest.approx(
        np.max(np.abs(bal["gravity_torque"]), axis=0).tolist(), abs=1e-12)
    data = tomllib.loads((out / "balanced.toml").read_text())
    assert data["case"]["kind"] == "orthoglide" and "balance" not in data
    assert {x["name"]: x["rate"] for x in data["springs"]} == {n: b["design"][n]["rate"] for n in published}
    small = copy.deepcopy(data)   # as test_orthoglide's run test: a coarse grid, few short paths
    small["workspace"]["grid"] = 3
    small["paths"].update(sample_period=0.05, helix_speeds=[0.8], cube_speeds=[1.0])
    small["machining"]["tasks"] = small["machining"]["tasks"][-1:]
    small["machining"]["holes"] = small["machining"]["holes"][:1]
    from mechbal.export.toml import toml_text

    (tmp_path / "small.toml").write_text(toml_text(small))
    assert main(["run", str(tmp_path / "small.toml"), "--out", str(tmp_path / "run"), "-q"]) == 0
    ran = summary_of(tmp_path / "run")
    for key, name in (("K_D", "distal"), ("K_P", "proximal")):
        assert ran["spring_rates_N_per_mm"][key] == pytest.approx(b["design"][name]["rate"] / 1e3, rel=1e-14)
    assert ran["acceptance"]["static_motor_force_balanced_max"] < 1e-9


def test_orthoglide_design_springs_the_kind_cannot_carry_are_written_as_a_mechanism(tmp_path):
    """A --design spring the orthoglide kind cannot carry (two springs in parallel): balanced.toml
    is a kind `mechanism` case (the mechanism, its springs, the trajectory) and runs."""
    design = tmp_path / "design.toml"
    design.write_text('[balance]\nsamples = 60\nlower = [0.45, 0.45, 0.45]\nupper = [0.95, 0.95, 0.95]\n'
                      '[[balance.springs]]\nname = "distal"\nlink_a = "slider2"\nanchor_a = [0.06, 0.10, 0.0]\n'
                      'link_b = "platform_phi1"\nanchor_b = [0.06, -0.05, 0.0]\ncount = 2\n'
                      '[[balance.springs]]\nname = "proximal"\nlink_a = "slider2"\nanchor_a = [0.20, -0.08, -0.15]\n'
                      'link_b = "support"\nanchor_b = [0.05, 0.05, 0.0]\n')
    out = tmp_path / "o"
    assert main(["balance", "orthoglide", "--method", "springs", "--design", str(design), "--out", str(out),
                 "-q"]) == 0
    b = summary_of(out)["balance"]
    assert b["exact"] and b["design"]["distal"]["count"] == 2
    assert b["design"]["distal"]["rate"] == pytest.approx(2510.052 / 2, rel=1e-9)
    data = tomllib.loads((out / "balanced.toml").read_text())
    assert data["case"]["kind"] == "mechanism" and len(data["mechanism"]["springs"]) == 2
    assert main(["run", str(out / "balanced.toml"), "--out", str(tmp_path / "run"), "-q"]) == 0
