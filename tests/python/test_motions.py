"""Motions of a case (issue 23): a linkage driven at constant crank speed (`law = "constant_speed"`)
against an independent closed-form position analysis of the four-bar (Freudenstein's equation, its
velocities and accelerations by differentiating it with sympy), both assembly branches (`branch =
"open" | "crossed"`, an `initial_guess` of the actuated joint only), the strict validation of the
new keys, and `mechbal balance` along a constant-speed motion."""
from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import mechbal
from mechbal.export.toml import toml_text
from mechbal.cases import run_case
from mechbal.cli import main
from mechbal.errors import ConfigError
from mechbal.export import read_bodies
from mechbal.schema import validate_case
from mechbal.trajectory import ConstantSpeed

from cli_checks import one_line_error, summary_of

PKG = Path(mechbal.__file__).resolve().parent
FOUR_BAR = tomllib.loads((PKG / "cases" / "four-bar.toml").read_text())

# the four-bar of cases/four-bar.toml, in its x-z plane (angles from +x towards +z)
CRANK, COUPLER, ROCKER, GROUND = 0.2, 0.5, 0.4, 0.45
#: (mass, distance of the centre of mass along the link) of every body, per link
BODIES = {"crank": [(0.8, 0.1), (0.6, -0.08)], "coupler": [(1.5, 0.25)], "rocker": [(1.1, 0.2)]}


def four_bar_case(trajectory: dict, **mechanism) -> dict:
    cfg = copy.deepcopy(FOUR_BAR)
    cfg["trajectory"] = trajectory
    cfg.pop("balance", None) if mechanism.pop("no_balance", False) else None
    cfg["mechanism"].update(mechanism)
    return cfg


def write(tmp_path: Path, cfg: dict, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(toml_text(cfg))
    return path


# ---- the closed form ------------------------------------------------------------------------------

def closed_form(branch: str):
    """Functions of t (numpy) of the four-bar driven at theta2 = theta0 + w t, derived here from
    Freudenstein's equation in Norton's form (*Design of Machinery*, eqs 4.8-4.10: the minus root
    is the open circuit, angles counterclockwise from O2 -> O4 seen with the crank turning
    counterclockwise: from +x towards +z here): (crank, coupler, rocker) joint angles, their rates
    and accelerations (sympy derivatives), the pin B and the shaking force (x, z) = sum m a_com."""
    t, theta0, w = sp.symbols("t theta0 w", real=True)
    a, b, c, d = CRANK, COUPLER, ROCKER, GROUND
    th2 = theta0 + w * t
    k1, k2, k3 = d / a, d / c, (a**2 - b**2 + c**2 + d**2) / (2 * a * c)
    A = sp.cos(th2) - k1 - k2 * sp.cos(th2) + k3
    B = -2 * sp.sin(th2)
    C = k1 - (k2 + 1) * sp.cos(th2) + k3
    root = sp.sqrt(B**2 - 4 * A * C)
    th4 = 2 * sp.atan2(-B - root if branch == "open" else -B + root, 2 * A)
    ax, az = a * sp.cos(th2), a * sp.sin(th2)
    bx, bz = d + c * sp.cos(th4), c * sp.sin(th4)
    th3 = sp.atan2(bz - az, bx - ax)
    q = [th2, th3 - th2, th4]                      # the joints: crank, coupler (relative), rocker
    com = []
    for link, angle, (px, pz) in (("crank", th2, (0, 0)), ("coupler", th3, (ax, az)), ("rocker", th4, (d, 0))):
        for m, r in BODIES[link]:
            com.append((m, px + r * sp.cos(angle), pz + r * sp.sin(angle)))
    force = [sum(m * sp.diff(x if k == 0 else z, t, 2) for m, x, z in com) for k in (0, 1)]
    args = (t, theta0, w)
    f = lambda e: sp.lambdify(args, e, "numpy")  # noqa: E731
    return {"q": [f(e) for e in q], "v": [f(sp.diff(e, t)) for e in q], "a": [f(sp.diff(e, t, 2)) for e in q],
            "pin": [f(bx), f(bz)], "force": [f(e) for e in force]}


@pytest.fixture(scope="module")
def forms():
    return {branch: closed_form(branch) for branch in ("open", "crossed")}


def evaluate(form: dict, key: str, t, theta0, w) -> np.ndarray:
    return np.stack([np.broadcast_to(np.asarray(fn(t, theta0, w), float), t.shape) for fn in form[key]], axis=1)


# ---- constant speed against the closed form -------------------------------------------------------

@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_four_bar_at_constant_speed_matches_the_closed_form(tmp_path, forms, branch):
    rpm, theta0 = 90.0, 1.0
    w = rpm * 2 * math.pi / 60
    path = write(tmp_path, four_bar_case({"law": "constant_speed", "start": [theta0], "rpm": rpm,
                                          "revolutions": 1.0, "samples": 361, "branch": branch}, no_balance=True))
    out = tmp_path / "run"
    s = run_case(path, out)
    assert s["law"] == "constant_speed"
    assert s["duration"] == pytest.approx(60.0 / rpm, rel=1e-15)
    assert s["rpm"] == pytest.approx([rpm], rel=1e-14) and s["revolutions"] == pytest.approx(1.0, rel=1e-14)
    assert s["loops"]["assembly"]["branch"] == {"coupler_rocker": branch}
    assert s["loops"]["assembly"]["branch_at_end"] == {"coupler_rocker": branch}   # a crank-rocker keeps its circuit
    b = read_bodies(out / "bodies_nominal.npz")
    t = np.asarray(b["t"])
    form = forms[branch]
    names = mechbal.Mechanism.from_toml(path).model.coordinate_names
    order = [names.index(n) for n in ("crank", "coupler", "rocker")]
    q, v, a = (np.asarray(b[k])[:, order] for k in ("q", "qd", "qdd"))
    wrap = lambda x: (x + np.pi) % (2 * np.pi) - np.pi  # noqa: E731
    q_cf = evaluate(form, "q", t, theta0, w)
    assert np.max(np.abs(wrap(q - q_cf))) < 1e-10
    assert np.max(np.abs(v - evaluate(form, "v", t, theta0, w))) < 1e-9 * w
    assert np.max(np.abs(a - evaluate(form, "a", t, theta0, w))) < 1e-8 * w**2
    assert np.allclose(v[:, 0], w, rtol=0, atol=1e-12) and np.allclose(a[:, 0], 0.0, atol=1e-12)
    F = np.asarray(b["shaking_force"])
    F_cf = evaluate(form, "force", t, theta0, w)
    scale = np.max(np.abs(F_cf))
    assert scale > 1.0                                             # a four-bar shakes
    assert np.max(np.abs(F[:, [0, 2]] - F_cf)) < 1e-8 * scale
    assert np.max(np.abs(F[:, 1])) < 1e-12 * scale                 # planar: nothing along y
    assert s["peak_shaking_force"]["nominal"][0] == pytest.approx(np.max(np.abs(F_cf[:, 0])), rel=1e-8)
    # the branch is a circuit: the same label over the whole turn (a crank-rocker has no toggle)
    from mechbal.assembly import loop_branches

    mech = mechbal.Mechanism.from_toml(path)
    assert {loop_branches(mech, qk)["coupler_rocker"] for qk in np.asarray(b["q"])[::12]} == {branch}


def test_the_two_branches_differ_and_the_guess_of_the_crank_alone_is_enough(tmp_path, forms):
    pins = {}
    for branch in ("open", "crossed"):
        path = write(tmp_path, four_bar_case({"law": "constant_speed", "start": [0.3], "speed": 4.0,
                                              "duration": 0.5, "samples": 11, "branch": branch,
                                              "initial_guess": [0.3]}, no_balance=True), f"{branch}.toml")
        s = run_case(path, tmp_path / branch)
        assert s["loops"]["assembly"] == {"branch": {"coupler_rocker": branch}, "chosen_by": "branch",
                                          "branch_at_end": {"coupler_rocker": branch}}
        pose = read_bodies(tmp_path / branch / "bodies_nominal.npz")
        pins[branch] = np.asarray(pose["frame_position"])[:, 0, [0, 2]]    # coupler_tip in x-z
        assert np.max(np.abs(pins[branch] - evaluate(forms[branch], "pin", np.asarray(pose["t"]), 0.3, 4.0))) < 1e-12
    assert np.min(np.linalg.norm(pins["open"] - pins["crossed"], axis=1)) > 0.05


def test_default_branch_is_open_and_a_full_guess_reports_its_branch(tmp_path):
    base = {"law": "quintic", "start": [1.0], "end": [2.2], "duration": 1.0, "samples": 21}
    s = run_case(write(tmp_path, four_bar_case(base, no_balance=True), "d.toml"), tmp_path / "d")
    assert s["loops"]["assembly"]["branch"] == {"coupler_rocker": "open"}
    assert s["loops"]["assembly"]["chosen_by"] == "default"
    # the shipped case's full initial_guess: the branch it lands on is reported, never silent
    s = run_case(PKG / "cases" / "four-bar.toml", tmp_path / "shipped")
    assert s["loops"]["assembly"]["chosen_by"] == "initial_guess"
    assert s["loops"]["assembly"]["branch"]["coupler_rocker"] in ("open", "crossed")


def test_constant_speed_of_an_open_chain(tmp_path):
    """Tree joints at their own speeds: q = start + speed t exactly, zero acceleration."""
    cfg = tomllib.loads((PKG / "cases" / "arm2link.toml").read_text())
    cfg["trajectory"] = {"law": "constant_speed", "start": [0.1, -0.2], "speed": [1.5, -3.0], "revolutions": 2.0,
                         "samples": 101}
    cfg.pop("balance", None)
    s = run_case(write(tmp_path, cfg), tmp_path / "arm")
    assert s["duration"] == pytest.approx(2 * 2 * math.pi / 3.0, rel=1e-15)   # turns of the fastest joint
    b = read_bodies(tmp_path / "arm" / "bodies_nominal.npz")
    t = np.asarray(b["t"])
    assert np.allclose(b["q"], np.array([0.1, -0.2]) + np.outer(t, [1.5, -3.0]), rtol=0, atol=1e-14)
    assert np.all(b["qd"] == np.array([1.5, -3.0])) and np.all(b["qdd"] == 0.0)
    assert "loops" not in s


def test_constant_speed_trajectory_object():
    tr = ConstantSpeed.from_rpm([0.0, 1.0], [60.0, -30.0], revolutions=2.0)
    assert tr.duration == pytest.approx(2.0) and tr.law == "constant_speed"
    q, v, a = tr.evaluate([-1.0, 0.5, 2.0, 3.0])
    assert np.allclose(q, [[0, 1], [math.pi, 1 - math.pi / 2], [4 * math.pi, 1 - 2 * math.pi], [4 * math.pi, 1 - 2 * math.pi]])
    assert np.allclose(v, [[0, 0], [2 * math.pi, -math.pi], [2 * math.pi, -math.pi], [0, 0]])
    assert np.all(a == 0)
    with pytest.raises(ValueError, match="duration or revolutions"):
        ConstantSpeed.from_rpm([0.0], [60.0])
    with pytest.raises(ValueError, match="speed must have 2 values"):
        ConstantSpeed([0.0, 1.0], [1.0, 2.0, 3.0], 1.0)


# ---- mechbal balance along a constant-speed motion -----------------------------------------------

def test_balance_at_constant_speed_cancels_the_shaking_force(tmp_path, capsys):
    cfg = four_bar_case({"law": "constant_speed", "start": [0.0], "rpm": 120.0, "revolutions": 1.0,
                         "samples": 241, "branch": "crossed"})
    out = tmp_path / "bal"
    assert main(["balance", str(write(tmp_path, cfg)), "--method", "force", "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    assert s["trajectory"]["law"] == "constant_speed" and s["trajectory"]["branch"] == "crossed"
    assert s["assembly"]["branch"] == {"coupler_rocker": "crossed"}
    force = s["before_after"]["shaking_force"]
    assert max(force["unbalanced"]["peak"]) > 10.0
    assert max(force["balanced"]["peak"]) < 1e-9 * max(force["unbalanced"]["peak"])
    # the balanced case written back runs at the same constant speed
    back = tomllib.loads((out / "balanced.toml").read_text())
    assert back["trajectory"]["rpm"] == 120.0 and back["trajectory"]["branch"] == "crossed"
    s2 = run_case(out / "balanced.toml", tmp_path / "again")
    assert max(s2["peak_shaking_force"]["nominal"]) < 1e-9 * max(force["unbalanced"]["peak"])


# ---- strict validation ----------------------------------------------------------------------------

BAD_TRAJECTORIES = {
    "constant speed with end": ({"law": "constant_speed", "start": [0.0], "end": [1.0], "rpm": 60, "duration": 1.0},
                                "trajectory.end", "rest-to-rest"),
    "speed and rpm": ({"law": "constant_speed", "start": [0.0], "speed": 1.0, "rpm": 60, "duration": 1.0},
                      "trajectory.rpm", "not both"),
    "no speed": ({"law": "constant_speed", "start": [0.0], "duration": 1.0}, "trajectory.speed", "needs speed"),
    "no duration": ({"law": "constant_speed", "start": [0.0], "rpm": 60}, "trajectory.duration", "revolutions"),
    "duration and revolutions": ({"law": "constant_speed", "start": [0.0], "rpm": 60, "duration": 1.0, "revolutions": 2},
                                 "trajectory.revolutions", "not both"),
    "revolutions at rest": ({"law": "constant_speed", "start": [0.0], "rpm": 0, "revolutions": 2},
                            "trajectory.revolutions", "non-zero speed"),
    "revolutions negative": ({"law": "constant_speed", "start": [0.0], "rpm": 60, "revolutions": -1.0},
                             "trajectory.revolutions", "-1.0"),
    "rpm a string": ({"law": "constant_speed", "start": [0.0], "rpm": "60", "duration": 1.0}, "trajectory.rpm", "'60'"),
    "speed too many": ({"law": "constant_speed", "start": [0.0], "speed": [1.0, 2.0], "duration": 1.0},
                       "trajectory.speed", "1 values"),
    "rpm on quintic": ({"law": "quintic", "start": [0.0], "end": [1.0], "duration": 1.0, "rpm": 60},
                       "trajectory.rpm", "constant_speed"),
    "quintic without end": ({"start": [0.0], "duration": 1.0}, "trajectory.end", "needs end"),
    "law unknown": ({"law": "constant-speed", "start": [0.0], "rpm": 60, "duration": 1.0}, "trajectory.law", "constant_speed"),
    "unknown key": ({"law": "constant_speed", "start": [0.0], "rpms": 60, "duration": 1.0}, "trajectory.rpms", "rpm"),
    "branch unknown": ({"law": "quintic", "start": [0.0], "end": [1.0], "duration": 1.0, "branch": "closed"},
                       "trajectory.branch", "'closed'"),
}


@pytest.mark.parametrize("name", list(BAD_TRAJECTORIES))
def test_bad_trajectories_are_refused_by_both_readers(tmp_path, name):
    table, field, needle = BAD_TRAJECTORIES[name]
    cfg = four_bar_case(table, no_balance=True)
    with pytest.raises(ConfigError) as exc:
        validate_case(cfg, warn=False)
    assert exc.value.field == field, str(exc.value)
    assert needle in str(exc.value), str(exc.value)
    with pytest.raises(ValueError) as cpp:
        mechbal._core.load_case_file(str(write(tmp_path, cfg)))
    assert str(cpp.value).startswith(field + ": "), str(cpp.value)


def test_branch_and_guess_on_an_open_chain_are_refused(tmp_path):
    cfg = tomllib.loads((PKG / "cases" / "arm2link.toml").read_text())
    cfg["trajectory"]["branch"] = "open"
    with pytest.raises(ConfigError, match=r"trajectory\.branch.*no loop"):
        validate_case(cfg, warn=False)
    with pytest.raises(ValueError, match=r"^trajectory\.branch: .*no loop"):
        mechbal._core.load_case_file(str(write(tmp_path, cfg)))


def test_branch_where_it_does_not_apply(tmp_path):
    """A loop that is not four-bar-like (the crank's joint is not on the ground link once the rocker
    is actuated too... here: both ground joints actuated) has no branch name."""
    cfg = four_bar_case({"law": "quintic", "start": [1.0, 1.3], "end": [1.1, 1.35], "duration": 1.0,
                         "samples": 5, "branch": "open"}, actuated=["crank", "rocker"], no_balance=True)
    with pytest.raises(ConfigError, match=r"trajectory\.branch.*four-bar-like"):
        run_case(write(tmp_path, cfg), tmp_path / "x")


def test_cli_reads_constant_speed(tmp_path, capsys):
    cfg = four_bar_case({"law": "constant_speed", "start": [0.0], "rpm": 60, "duration": 0.5, "samples": 11},
                        no_balance=True)
    assert main(["run", str(write(tmp_path, cfg)), "--out", str(tmp_path / "ok"), "-q"]) == 0
    bad = four_bar_case({"law": "constant_speed", "start": [0.0], "rpm": 60, "speed": 1.0, "duration": 0.5},
                        no_balance=True)
    assert main(["run", str(write(tmp_path, bad, "bad.toml")), "--out", str(tmp_path / "no"), "-q"]) == 2
    one_line_error(capsys, "trajectory.rpm", "not both")


def test_init_linkage_template_turns_at_constant_speed(tmp_path, capsys):
    assert main(["init", "linkage"]) == 0
    path = tmp_path / "my.toml"
    path.write_text(capsys.readouterr().out)
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "-q"]) == 0
    s = summary_of(tmp_path / "o")
    assert s["law"] == "constant_speed" and s["rpm"] == pytest.approx([60.0], rel=1e-14) and s["duration"] == pytest.approx(1.0)
    assert s["loops"]["assembly"]["branch"] == {"coupler_rocker": "open"}
