"""Controlled runs say whether the controller met its goal (issue 37, points 1-3):

* no hidden limits: every limit a controller stage enforces is declared (the model's joint
  limits, ``[control]``); the control sources hold no literal limit;
* a verdict for every controlled run: ``goal``, ``ok``, ``limited_by`` in summary.json, exit
  code 6 unless ``--allow-degraded``; reductions per cancelled axis;
* feasibility before the run: the commanded motion's demand against the declared limits, the
  shortest feasible duration, ``--fit-duration``.

The iiwa 14 URDF is not shipped with mechbal nor installed by the test extra: the infeasible tool
line runs on the shipped Franka Panda (its declared velocity limits 2.175-2.61 rad/s), 0.41 m in
1 s, and on the iiwa 14 itself when a URDF of it is given (``MECHBAL_IIWA14_URDF``:
`test_iiwa14_tool_line_acceptance`). The joint controllers' verdicts (computed_torque,
decoupled) under every command: test_verdict_joint_control.py.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import control, simulate, verdict
from mechbal.cli import EXIT_GOAL_NOT_MET, main
from mechbal.config import CASES_DIR
from mechbal.export import read_bodies

ROOT = Path(__file__).resolve().parents[2]
WHEEL = (CASES_DIR / "reaction-wheel-arm.toml").read_text()
WHEEL_JOINT = 'name = "wheel"                # the reaction wheel: a disc spinning about its own axis\n'


def wheel_case(tmp_path: Path, limits: str | None = None, control_extra: str = "", name: str = "wheel.toml",
               duration: float | None = None) -> Path:
    """The shipped wheel arm, with ``limits`` on the wheel and, for a declared limit, its motion in
    ``duration`` (default 0.2 s: the wheel then needs 119 rad/s; in the shipped 2 s, 11.9)."""
    text = WHEEL
    if duration is None and limits is not None:
        duration = 0.2
    if duration is not None:
        assert "duration = 2.0" in text
        text = text.replace("duration = 2.0", f"duration = {duration}").replace("samples = 2001", "samples = 201")
    if limits is not None:
        assert WHEEL_JOINT in text
        text = text.replace(WHEEL_JOINT, WHEEL_JOINT + f"limits = {limits}\n")
    text += control_extra
    p = tmp_path / name
    p.write_text(text)
    return p


def run_cli(args, capsys):
    code = main(list(map(str, args)))
    out, err = capsys.readouterr()
    return code, out, err


def summary_of(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


# ---- 1. no hidden limits ------------------------------------------------------------------------

#: literal limits that remain in the control sources, each with its origin (not a limit a user
#: meets: numerical thresholds and validation ranges of settings)
REVIEWED = {
    "max_condition": "the condition number above which a solve is damped (a numerical threshold, Status.singular)",
    "max_dof": "the decoupled controller's fixed-size vectors (a construction-time size check)",
    "max_minor_side": "the size up to which a closed-form eigenvalue path is used (numerics)",
    "limit_gain": "a gain of the null-space objective (default 0: off), not a limit",
}


def test_no_literal_limits_in_the_control_sources():
    """Every limit field of the general controllers (C++ headers and sources of control/, the
    bindings of the reactionless controllers, the Python control module's general classes) defaults
    to no limit: no numeric literal is assigned to a ``max_*`` or ``*limit*`` name, except the
    reviewed numerical thresholds above."""
    files = sorted((ROOT / "cpp/include/mechbal/control").glob("*.hpp")) + sorted(
        (ROOT / "cpp/src/control").glob("*.cpp")) + [ROOT / "bindings/bind_reactionless.cpp",
                                                    ROOT / "bindings/controller_step.hpp"]
    literal = re.compile(r"\b((?:max_|min_)\w*|\w*limit\w*)\s*(?:=|\{)\s*[-+]?(\d[\d.]*(?:e[-+]?\d+)?)\b",
                         re.IGNORECASE)
    found = []
    for f in files:
        for i, line in enumerate(f.read_text().splitlines(), 1):
            code = line.split("//")[0]
            for m in literal.finditer(code):
                name = m.group(1)
                if name in REVIEWED or name.startswith("max_iter") or "rate_hz" in name:
                    continue
                found.append(f"{f.relative_to(ROOT)}:{i}: {line.strip()}")
    assert not found, "literal limits (declare them, or review them in REVIEWED):\n" + "\n".join(found)
    # the Python general classes: no numeric default for a limit keyword
    src = (ROOT / "python/mechbal/control.py").read_text()
    # (PAMINSA's own controllers live in mechbal.papers.paminsa, with the paper's limits)
    general = src
    assert not re.findall(r"\b(max_\w+|\w*limit\w*)\s*:\s*float\s*=\s*\d", general)


def test_no_hidden_limit_on_the_wheel_and_every_limit_reaches_closed_loop():
    """Issue 37: the wheel used to stop at 100 rad/s (JointInputRange.max_speed = 100, which no
    setting reached, and max_rate = 100). Undeclared, nothing stops it; a declared ``max_rate``
    is met in closed loop, and a declared ``max_speed`` reaches the computed-torque stage."""
    mech = mechbal.Mechanism.from_toml(CASES_DIR / "reaction-wheel-arm.toml")
    from mechbal.trajectory import RestToRest

    traj = RestToRest([0.0, 0.0, 0.0], [3.0, -3.0, 0.0], 0.5)   # fast: the wheel needs > 100 rad/s
    kw = dict(cancel="moment_z", integrator="rk4", kp=[400.0] * 3, kd=[40.0] * 3)
    free = control.ReactionlessController(mech, "wheel", **kw)
    r = simulate.closed_loop(mech, free, traj)
    assert r.ok, r.limited_by
    assert np.max(np.abs(r.v[:, 2])) > 120.0
    limited = control.ReactionlessController(mech, "wheel", max_rate=100.0, **kw)
    r = simulate.closed_loop(mech, limited, traj)
    assert not r.ok and any(x.get("status") == "saturated" for x in r.limited_by)
    assert np.max(np.abs(r.v[:, 2])) < 102.0          # met (the stage tracks it), and said
    speed = control.ReactionlessController(mech, "wheel", max_speed=50.0, **kw)
    r = simulate.closed_loop(mech, speed, traj)
    assert any(x.get("status") == "out_of_range" for x in r.limited_by)
    assert control.ReactionlessController(mech, "wheel").joint_controller is None


def test_declared_effort_limits_reach_the_computed_torque_stage():
    mech = mechbal.Mechanism.from_toml(CASES_DIR / "panda-reactionless.toml")
    ct = control.ComputedTorque(mech, [100.0] * 7, [20.0] * 7)
    assert np.allclose(ct.torque_limit, [87, 87, 87, 87, 12, 12, 12])
    ct = control.ComputedTorque(mech, [100.0] * 7, [20.0] * 7, [50.0] * 7)
    assert np.allclose(ct.torque_limit, [50, 50, 50, 50, 12, 12, 12])


# ---- 2. verdicts ---------------------------------------------------------------------------------

def _moment_by_finite_differences(path: Path) -> np.ndarray:
    """dH_O/dt of the stored poses by finite differences (positions and orientations only)."""
    b = read_bodies(path)
    t, c, R = b["t"], b["com"], b["rotation"]
    m, I = b["mass"], b["inertia_body"]
    cd = np.gradient(c, t, axis=0, edge_order=2)
    Rd = np.gradient(R, t, axis=0, edge_order=2)
    W = np.einsum("nbij,nbkj->nbik", Rd, R)               # [w]x = dR/dt R^T
    w = np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)
    Iw = np.einsum("nbij,bjk,nblk,nbl->nbi", R, I, R, w)
    H = np.sum(m[None, :, None] * np.cross(c, cd) + Iw, axis=1)
    return np.gradient(H, t, axis=0, edge_order=2)


def test_wheel_without_declared_limits_cancels_moment_z(tmp_path, capsys):
    """No declared limit: the run meets its goal (exit 0, ok), M_z <= 1e-3 of the uncontrolled
    peak by finite differences of the exported controlled poses; the reduction is per axis."""
    out = tmp_path / "out"
    code, text, err = run_cli(["run", CASES_DIR / "reaction-wheel-arm.toml", "--out", out], capsys)
    assert code == 0, err
    s = summary_of(out)
    assert s["ok"] is True and s["limited_by"] == []
    assert s["goal"]["cancelled"]["components"] == ["moment_z"] and s["goal"]["limits"] == {}
    assert s["feasibility"]["feasible"] is True
    Mc = _moment_by_finite_differences(out / "bodies_controlled.npz")
    Mu = _moment_by_finite_differences(out / "bodies_uncontrolled.npz")
    inner = slice(5, -5)
    assert np.max(np.abs(Mc[inner, 2])) <= 1e-3 * np.max(np.abs(Mu[inner, 2]))
    z = s["shaking_moment_reduction"]["per_axis"]["z"]
    assert z["cancelled"] and z["reduction_pct"] > 99.9
    assert not s["shaking_moment_reduction"]["per_axis"]["x"]["cancelled"]
    assert "whole" in s["shaking_moment_reduction"]["whole_moment"]["meaning"] or \
        "all three axes" in s["shaking_moment_reduction"]["whole_moment"]["meaning"]
    assert "goal met" in text and "goal: cancel" in text


def test_wheel_with_a_declared_velocity_limit_is_refused_before_the_run(tmp_path, capsys):
    """The wheel declared ``limits = { velocity = 100.0 }``: mechbal run refuses before simulating
    (exit 6, nothing written) with one line naming the joint, its demand, the limit and the
    shortest feasible duration; --allow-degraded runs it (exit 0, a warning, ok false, limited_by
    naming the wheel); --fit-duration runs it at that duration and meets the goal."""
    case = wheel_case(tmp_path, "{ velocity = 100.0 }")
    from mechbal.config import read_case
    from mechbal.schema import validate_case
    from mechbal.trajectory import RestToRest

    report = control.feasibility(mechbal.Mechanism.from_toml(case), validate_case(read_case(case), warn=False).control,
                                 RestToRest([0.0, 0.0, 0.0], [1.0, -1.2, 0.0], 0.2))
    out = tmp_path / "out"
    code, _, err = run_cli(["run", case, "--out", out], capsys)
    demand = report.exceeded[0]
    if demand.peak_demand <= 100.0:   # the shipped motion is feasible: make it infeasible
        pytest.fail(f"the wheel needs only {demand.peak_demand} rad/s")
    assert code == EXIT_GOAL_NOT_MET
    assert not out.exists()
    line = err.strip().splitlines()[-1]
    assert "wheel" in line and "velocity" in line and "100" in line and "--fit-duration" in line
    assert f"{report.min_duration:.4g} s" in line
    code, text, err = run_cli(["run", case, "--out", out, "--allow-degraded"], capsys)
    assert code == 0 and "warning: control goal not met" in err and "wheel" in err
    s = summary_of(out)
    assert s["ok"] is False
    sat = [x for x in s["limited_by"] if x.get("status") == "saturated"]
    assert sat and sat[0]["joint"] == "wheel" and sat[0]["ticks"] > 0
    lim = [x for x in s["limited_by"] if x["criterion"] == "limit"]
    assert lim and lim[0]["joint"] == "wheel" and lim[0]["limit"] == 100.0
    assert "NOT MET" in text and "saturated ticks" in text
    out2 = tmp_path / "fit"
    code, _, err = run_cli(["run", case, "--out", out2, "--fit-duration"], capsys)
    assert code == 0, err
    s = summary_of(out2)
    assert s["ok"] is True and s["feasibility"]["fitted_duration"] >= report.min_duration
    assert s["duration"] == pytest.approx(s["feasibility"]["fitted_duration"])
    assert max(s["control"]["peak_balancing_rate"]) <= 100.0


def test_a_cancelled_component_beyond_its_tolerance_is_not_ok(tmp_path, capsys):
    """A goal the balancing joints cannot reach: the wheel cannot cancel force_x (its column of the
    momentum matrix has no linear part). The run is not ok (exit 6), limited_by names force_x and
    its residual; moment_z alone is met. The verdict judges the wrench of the stored poses."""
    case = wheel_case(tmp_path)
    case.write_text(case.read_text().replace('cancel = ["moment_z"]', 'cancel = ["moment_z", "force_x"]'))
    code, _, err = run_cli(["run", case, "--out", tmp_path / "o"], capsys)
    # the one line names the first reason: the ticks flagged singular (more cancelled components
    # than the wheel can cancel) or the residual; limited_by holds both
    assert code == EXIT_GOAL_NOT_MET and ("force_x" in err or "singular" in err)
    s = summary_of(tmp_path / "o")
    res = [x for x in s["limited_by"] if x["criterion"] == "residual"]
    assert [x["component"] for x in res] == ["force_x"]
    assert res[0]["controlled_peak"] > 0.5 * res[0]["uncontrolled_peak"] > 0
    assert s["cancelled_residual"]["moment_z"]["controlled_peak"] <= 1e-6 * s["cancelled_residual"]["moment_z"][
        "uncontrolled_peak"]
    # a tolerance the user loosens is the goal: force_x within 100 % of its uncontrolled peak
    case.write_text(case.read_text().replace("damping = 1e-3", "damping = 1e-3\ntolerance = { residual = 1.01 }"))
    code, _, err = run_cli(["run", case, "--out", tmp_path / "p"], capsys)
    s = summary_of(tmp_path / "p")
    assert s["goal"]["tolerance"]["residual"] == 1.01
    assert not [x for x in s["limited_by"] if x["criterion"] == "residual"]


# ---- the Panda's tool line (the iiwa's stands in: see the module docstring) ---------------------

def panda_line(tmp_path: Path, displacement, duration: float, rows: str = '["all"]', cancel='["moment_z"]') -> Path:
    from mechbal.cases.panda import START, end_pose

    mech = mechbal.Mechanism.from_toml(CASES_DIR / "panda-reactionless.toml")
    end = end_pose(mech, START, displacement)
    text = (CASES_DIR / "panda-reactionless.toml").read_text()
    text = re.sub(r"(?ms)^\[trajectory\].*?(?=^\[control\])",
                  f"[trajectory]\nlaw = \"quintic\"\nstart = {list(START)}\nend = {list(map(float, end))}\n"
                  f"duration = {duration}\n\n", text)
    text = re.sub(r"(?m)^cancel = .*$", f"cancel = {cancel}", text)
    text = re.sub(r"(?m)^task_rows = .*$", f"task_rows = {rows}", text)
    p = tmp_path / "line.toml"
    p.write_text(text)
    return p


def test_infeasible_tool_line_is_refused_and_a_feasible_one_cancels_moment_z(tmp_path, capsys):
    d = 0.41 / np.sqrt(3.0)
    case = panda_line(tmp_path, (d, d, d), 1.0)
    code, _, err = run_cli(["run", case, "--out", tmp_path / "a"], capsys)
    assert code == EXIT_GOAL_NOT_MET, err
    assert re.search(r"panda_joint\d needs (velocity|effort|position) [\d.]+ \(at t = [\d.]+ s\) against its "
                     r"declared limit", err), err
    code, _, err = run_cli(["run", case, "--out", tmp_path / "b", "--allow-degraded"], capsys)
    assert code == 0 and "control goal not met" in err
    s = summary_of(tmp_path / "b")
    assert s["ok"] is False and s["limited_by"]
    feasible = panda_line(tmp_path, (0.03, 0.0, 0.0), 2.0)
    code, _, err = run_cli(["run", feasible, "--out", tmp_path / "c"], capsys)
    assert code == 0, err
    s = summary_of(tmp_path / "c")
    assert s["ok"] is True
    z = s["cancelled_residual"]["moment_z"]
    assert z["controlled_peak"] <= 1e-9 * z["uncontrolled_peak"] + 1e-12   # round-off


# ---- closed loop: every controller kind ----------------------------------------------------------

def test_closed_loop_verdict_per_controller_kind():
    """simulate.closed_loop says ok only when its goal held: computed torque and decoupled
    control saturating at a declared torque limit, or diverging (a wrong model), are not ok;
    within their limits they are."""
    from mechbal.papers import Arm2DofDynamics, Arm2DofParameters
    from mechbal.trajectory import RestToRest

    plant = Arm2DofDynamics(Arm2DofParameters())
    traj = RestToRest([0.0, 0.0], [1.0, -0.5], 1.0)
    good = simulate.closed_loop(plant, control.ComputedTorque(plant, [400.0] * 2, [40.0] * 2), traj)
    assert good.ok and good.verdict.goal["tracking"]["joint"]["tolerance"] == 1e-2
    sat = simulate.closed_loop(plant, control.ComputedTorque(plant, [400.0] * 2, [40.0] * 2, [0.5, 0.5]), traj)
    assert not sat.ok and sat.limited_by[0]["status"] == "saturated"
    wrong = Arm2DofDynamics(Arm2DofParameters(m2=0.01))
    diverging = simulate.closed_loop(plant, control.ComputedTorque(wrong, [4.0] * 2, [0.5] * 2), traj)
    assert not diverging.ok and any(x["criterion"] == "tracking" for x in diverging.limited_by)
    M = plant.mass_matrix(np.zeros(2))
    dec = control.DecoupledJointController(np.diag(M), [400.0] * 2, [40.0] * 2, [0.01, 0.01])
    r = simulate.closed_loop(plant, dec, traj)
    assert not r.ok and any(x.get("status") == "saturated" for x in r.limited_by)
    passive = simulate.closed_loop(plant, control.PassiveController(2), traj)
    assert passive.verdict is None   # no goal


# ---- 3. feasibility --------------------------------------------------------------------------------

def test_feasibility_time_scaling_is_exact_on_the_wheel():
    """The demand at duration T' is the demand at T scaled (rates by T / T'): the shortest
    duration for a velocity limit is T * peak / limit, and at it the controller just keeps it."""
    mech = mechbal.Mechanism.from_toml(CASES_DIR / "reaction-wheel-arm.toml")
    from mechbal.trajectory import RestToRest

    ctl = dict(balancing_joints=["wheel"], cancel=["moment_z"], integrator="rk4", rate_hz=1000.0, max_rate=10.0)
    r2 = control.feasibility(mech, ctl, RestToRest([0.0, 0.0, 0.0], [1.0, -1.2, 0.0], 2.0))
    r4 = control.feasibility(mech, ctl, RestToRest([0.0, 0.0, 0.0], [1.0, -1.2, 0.0], 4.0))
    w2, w4 = r2.peak_velocity["wheel"], r4.peak_velocity["wheel"]
    assert w4 == pytest.approx(w2 / 2.0, rel=1e-6)
    item = [x for x in r2.limits if x.joint == "wheel" and x.quantity == "velocity"][0]
    assert item.min_duration == pytest.approx(2.0 * w2 / 10.0, rel=1e-12)
    assert r2.feasible == (w2 <= 10.0)


def _random_limited_case(rng):
    """A random open tree (random_trees) with one balancing joint and random declared velocity
    limits on it, and a rest-to-rest motion of the others."""
    from random_trees import random_tree

    for _ in range(50):
        tree = random_tree(rng, int(rng.integers(3, 6)), types="RRRR")
        mech = tree.mechanism()
        names = list(mech.actuated_names)
        if len(names) >= 2:
            break
    b = names[-1]
    end = rng.uniform(-1.0, 1.0, len(names))
    end[-1] = 0.0
    return mech, names, b, end


def test_property_feasibility_predicts_saturation_on_random_trees():
    """Random trees, random declared rate limits: the closed loop (the reactionless controller
    with the limit) saturates exactly when feasibility says infeasible; near the boundary
    (limits within 2 % of the demand) at most 5 % false "infeasible", never a false "feasible"."""
    from mechbal.trajectory import RestToRest

    rng = np.random.default_rng(37)
    false_feasible = false_infeasible = near = 0
    outcomes = set()
    for trial in range(24):
        mech, names, b, end = _random_limited_case(rng)
        traj = RestToRest(np.zeros(len(names)), end, 0.5)
        base = dict(balancing_joints=[b], cancel=["moment_z"], integrator="rk4", rate_hz=500.0)
        demand = control.feasibility(mech, base, traj).peak_velocity[b]
        if not np.isfinite(demand) or demand == 0.0:
            continue
        scale = rng.uniform(0.98, 1.02) if trial % 2 else rng.uniform(0.3, 3.0)
        near += trial % 2
        limit = float(demand * scale)
        ctl = dict(base, max_rate=limit)
        report = control.feasibility(mech, ctl, traj)
        task = [i for i, n in enumerate(names) if n != b]
        ctrl = control.ReactionlessController(mech, [b], "moment_z", "rk4", 500.0, max_rate=limit)
        th = np.arange(2 * 250 + 1) * 1e-3
        q, v, a = traj.evaluate(th)
        run = ctrl.run(np.ascontiguousarray(q[:, task]), np.ascontiguousarray(v[:, task]),
                       np.ascontiguousarray(a[:, task]))
        saturated = bool(np.any(run.status & np.uint32(4)))
        false_feasible += report.feasible and saturated
        false_infeasible += (not report.feasible) and not saturated
        outcomes.add((report.feasible, saturated))
    assert {(True, False), (False, True)} <= outcomes   # both sides met
    assert false_feasible == 0
    assert false_infeasible <= max(1, 0.05 * near)


# ---- verify and run --engine mujoco: the verdict of the simulation that ran ----------------------

def test_verify_and_mujoco_run_of_the_limited_wheel(tmp_path, capsys):
    """``mechbal verify`` and ``run --engine mujoco`` of the wheel with a declared 100 rad/s:
    refused before the run (exit 6, naming the wheel); with --allow-degraded the closed loop runs,
    its verdict is the simulation's (ok false, the wheel saturated), and no residual is printed or
    written for the failed loop (it used to print 1.3e-5 of the uncontrolled peak and exit 0)."""
    pytest.importorskip("mujoco")
    case = wheel_case(tmp_path, "{ velocity = 100.0 }")
    for cmd in (["verify", case], ["run", case, "--engine", "mujoco"]):
        code, _, err = run_cli([*cmd, "--out", tmp_path / "x"], capsys)
        assert code == EXIT_GOAL_NOT_MET and "wheel needs velocity" in err, err
        assert not (tmp_path / "x").exists()
    out = tmp_path / "v"
    code, text, err = run_cli(["verify", case, "--out", out, "--allow-degraded"], capsys)
    assert code == 0 and "control goal not met" in err
    s = summary_of(out)
    assert s["ok"] is False and any(x.get("joint") == "wheel" for x in s["limited_by"])
    assert "mujoco_simulated_controlled_fraction" not in s["residual"]["moment_z"]
    assert "time_step" not in s and "NOT MET" in text and "failed" in text
    out = tmp_path / "m"
    code, text, err = run_cli(["run", case, "--engine", "mujoco", "--out", out, "--allow-degraded"], capsys)
    assert code == 0 and "control goal not met" in err
    s = summary_of(out)
    assert s["ok"] is False and s["shaking_moment_reduction"]["per_axis"]["z"]["cancelled"]


def test_a_closed_loop_beyond_its_tracking_tolerance_exits_6_with_dir_written(tmp_path, capsys):
    """run --engine mujoco of the (feasible) wheel arm with a joint tolerance no zero-order-hold
    loop meets: the loop runs, DIR is written, the verdict is the simulation's (tracking), exit 6."""
    pytest.importorskip("mujoco")
    case = wheel_case(tmp_path, None, "", duration=0.3)
    case.write_text(case.read_text().replace("damping = 1e-3", "damping = 1e-3\ntolerance = { joint = 1e-12 }"))
    out = tmp_path / "m"
    code, text, err = run_cli(["run", case, "--engine", "mujoco", "--out", out], capsys)
    assert code == EXIT_GOAL_NOT_MET and "(tolerance.joint)" in err
    s = summary_of(out)
    assert s["ok"] is False and [x["criterion"] for x in s["limited_by"]] == ["tracking"]
    assert s["limited_by"][0]["tolerance"] == 1e-12 and "NOT MET" in text


# ---- the KUKA iiwa 14 of the issue, when its URDF is at hand ---------------------------------------

#: a KUKA iiwa 14 URDF (e.g. Drake's iiwa14_no_collision.urdf, whose tool flange link is named
#: by MECHBAL_IIWA14_TOOL, default "tool0"); not shipped with mechbal nor installed by the test
#: extra, so this acceptance run of issue 37 runs only where one is given
IIWA14 = __import__("os").environ.get("MECHBAL_IIWA14_URDF")
IIWA14_TOOL = __import__("os").environ.get("MECHBAL_IIWA14_TOOL", "tool0")


def iiwa_design(tmp_path: Path, displacement, duration: float, name: str) -> Path:
    joints = [f"iiwa_joint_{i}" for i in range(1, 8)]
    p = tmp_path / name
    p.write_text(f'[trajectory]\nlaw = "line"\nstart = [0.0, 0.6, 0.0, -1.2, 0.0, 0.9, 0.0]\n'
                 f"displacement = {list(map(float, displacement))}\nduration = {duration}\n\n"
                 f'[control]\nkind = "reactionless"\ntask_frame = "{IIWA14_TOOL}"\ntask_rows = ["all"]\n'
                 f"balancing_joints = {json.dumps(joints)}\ncancel = [\"moment_z\"]\n")
    return p


@pytest.mark.skipif(not IIWA14, reason="no KUKA iiwa 14 URDF given (MECHBAL_IIWA14_URDF)")
def test_iiwa14_tool_line_acceptance(tmp_path, capsys):
    """Issue 37's acceptance on the iiwa 14: its tool on a 0.41 m line in 1 s is refused (exit 6,
    naming the joint whose declared limit the motion needs more than), and with --allow-degraded
    its verdict names it too; 3 cm in 2 s meets the goal (exit 0) with M_z cancelled to round-off."""
    d = 0.41 / np.sqrt(3.0)
    fast = iiwa_design(tmp_path, (d, d, d), 1.0, "fast.toml")
    code, _, err = run_cli(["run", IIWA14, "--design", fast, "--out", tmp_path / "a"], capsys)
    assert code == EXIT_GOAL_NOT_MET, err
    assert re.search(r"iiwa_joint_\d needs (velocity|effort|position) [\d.]+ \(at t = [\d.]+ s\) against its "
                     r"declared limit", err), err
    assert not (tmp_path / "a").exists()
    code, _, err = run_cli(["run", IIWA14, "--design", fast, "--out", tmp_path / "b", "--allow-degraded"], capsys)
    assert code == 0 and "control goal not met" in err
    s = summary_of(tmp_path / "b")
    assert s["ok"] is False and any(str(x.get("joint", "")).startswith("iiwa_joint_") for x in s["limited_by"])
    slow = iiwa_design(tmp_path, (0.03, 0.0, 0.0), 2.0, "slow.toml")
    code, _, err = run_cli(["run", IIWA14, "--design", slow, "--out", tmp_path / "c"], capsys)
    assert code == 0, err
    s = summary_of(tmp_path / "c")
    assert s["ok"] is True
    z = s["cancelled_residual"]["moment_z"]
    assert z["controlled_peak"] <= 1e-9 * z["uncontrolled_peak"] + 1e-12   # round-off
