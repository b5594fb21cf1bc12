"""The reactionless controllers against MuJoCo through the MJCF export (issue 22):

* ``mechbal verify panda-reactionless``: the operational-space mode (the reaction null space of
  the Panda's tool frame) checked like the joint-mode cases: mechbal's predicted shaking wrench,
  actuator forces and gravity torque against MuJoCo's inverse dynamics of the same motion, and
  the controller ticked at 1 kHz against MuJoCo, the residual as a fraction of the uncontrolled
  peak and its dependence on the tick measured (halving the tick);
* ``mechbal run CASE --engine mujoco`` of a reactionless case ticks the case's reactionless
  controller (not computed torque alone), writes what ``mechbal run`` writes for the case, of the
  motion MuJoCo realised (bodies files holding the wrench of their poses), and MuJoCo's base
  reaction beside mechbal's prediction;
* the operational-space controller ticked one step at a time is its whole-motion ``run``.

Short horizons keep the Panda's runs to a few seconds: its 2 s path's acceleration peaks
near 0.42 s, inside the 0.6 s horizon.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import mechbal
from mechbal import control
from mechbal.config import CASES_DIR, read_case
from mechbal.export import read_bodies

pytest.importorskip("mujoco")

#: the documented bounds on MuJoCo's realised residual under the controller (each cancelled
#: component's peak as a fraction of its uncontrolled peak), computed torque Kp 400 / s^2,
#: Kd 40 / s with each tick's torque held over 1 ms. Measured: the wheel arm 7.4e-6 (moment_z);
#: the Panda over 0.6 s 3.3e-3 / 9.6e-3 / 5e-7 (moment x / y / z; the norm's peak 3.2e-3 of the
#: uncontrolled one). Halving the tick halves them (summary.json's time_step): the zero-order hold.
WHEEL_RESIDUAL = 1e-4
PANDA_RESIDUAL = 2e-2
PANDA_HORIZON = 0.6


# ---- the operational-space controller, tick by tick --------------------------------------------

def test_task_controller_step_is_run():
    """``step`` (one tick, the binding's) gives the commands of ``run`` over the same samples,
    RK4 and Euler: what the co-simulation ticks is the controller the mechbal engine runs."""
    from mechbal.cases.panda import START, TOOL_FRAME
    from mechbal.case.motion import frame_path

    mech = mechbal.Mechanism.from_toml(CASES_DIR / "panda-reactionless.toml")
    end = read_case("panda-reactionless")["trajectory"]["end"]
    th = np.arange(401) * 0.5e-3
    _, _, twist, rate = frame_path(mech, TOOL_FRAME, START, end, 2.0, "quintic", th + 0.3)
    for integrator in ("rk4", "euler"):
        make = lambda: control.ReactionlessTaskController(mech, TOOL_FRAME, "linear", "moment",  # noqa: E731
                                                          integrator, 1000.0, q0=np.array(START))
        r = make().run(twist, rate)
        c = make()
        rows = len(twist)
        for k in range(len(r.t)):
            j = min(2 * k, rows - 1)
            s = c.step(twist[j], rate[j], twist[min(j + 1, rows - 1)], twist[min(j + 2, rows - 1)])
            assert s == r.status[k] == c.status
            for name in ("q", "v", "a", "shaking_force", "shaking_moment", "momentum", "frame_twist"):
                assert np.array_equal(np.asarray(getattr(c, name)), getattr(r, name)[k]), (integrator, k, name)
        # the twist's rate estimated from the three samples when not given
        c = make()
        c.step(twist[0], None, twist[1], twist[2])
        assert np.all(np.isfinite(c.a))
    with pytest.raises(ValueError, match="twist"):
        make().step(np.zeros(5))


# ---- mechbal verify panda-reactionless --------------------------------------------------------------

@pytest.fixture(scope="module")
def panda_verify(tmp_path_factory):
    from mechbal.verify import run_verify_reactionless

    out = tmp_path_factory.mktemp("panda-verify") / "out"
    return out, run_verify_reactionless("panda-reactionless", out, duration=PANDA_HORIZON)


def test_verify_panda_prescribed_motion_matches_mujoco(panda_verify):
    out, s = panda_verify
    assert s["mode"] == "task" and s["task_frame"] == "panda_hand_tcp" and s["duration"] == PANDA_HORIZON
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["command"] == "verify" and on_disk["variants"].keys() == {"uncontrolled", "controlled"}
    for label in ("uncontrolled", "controlled"):
        for key in ("shaking_force", "shaking_moment", "gravity_torque", "actuator_force"):
            v = s["variants"][label][key]
            assert v["relative_difference"] < 1e-9, (label, key, v)
        # the Panda holds itself up: the gravity torque is not a zero compared with a zero
        assert s["variants"][label]["gravity_torque"]["mechbal_peak"] > 10.0
    # mechbal's and MuJoCo's inverse dynamics agree that the null space cancels the moment
    for comp, r in s["residual"].items():
        assert comp.startswith("moment_")
        assert r["uncontrolled_peak"] > 1e-2, (comp, r)
        assert r["mechbal_controlled_fraction"] < 1e-8, (comp, r)
        assert r["mujoco_inverse_controlled_fraction"] < 1e-8, (comp, r)
    assert (out / "mechanism.xml").is_file() and (out / "shaking_wrench.png").stat().st_size > 10_000


def test_verify_panda_cosimulated_residual_and_what_limits_it(panda_verify):
    """MuJoCo's realised moment under the controller is below the documented fraction of the
    uncontrolled peak; the uncontrolled path does shake MuJoCo's base (the check can fail); the
    residual is the zero-order hold of the computed-torque stage: halving the tick halves it and
    the tracking error (first order)."""
    _, s = panda_verify
    for label in ("uncontrolled", "controlled"):
        sim = s["variants"][label]["simulation"]
        assert sim["ok"] and sim["steps_completed"] == round(PANDA_HORIZON / s["dt"])
        assert sim["tracking_error"] < 1e-4
    for comp, r in s["residual"].items():
        assert r["mujoco_simulated_controlled_fraction"] < PANDA_RESIDUAL, (comp, r)
        assert r["mujoco_simulated_uncontrolled_fraction"] > 0.9, (comp, r)
    ts = s["time_step"]
    assert ts["dt"] == [1e-3, 5e-4]
    assert max(r["mujoco_simulated_controlled_fraction"] for r in s["residual"].values()) == \
        pytest.approx(ts["residual"][0], rel=1e-12)
    assert 0.3 < ts["residual_ratio"] < 0.7, ts
    assert 0.3 < ts["tracking_error_ratio"] < 0.7, ts
    assert "halving the tick" in s["residual_limited_by"]
    assert s["ok"] is True and s["limited_by"] == []


# ---- mechbal run CASE --engine mujoco -----------------------------------------------------------------

@pytest.fixture(scope="module")
def wheel_run(tmp_path_factory):
    from mechbal.cli import main

    out = tmp_path_factory.mktemp("wheel-mujoco") / "out"
    assert main(["run", "reaction-wheel-arm", "--engine", "mujoco", "--out", str(out), "-q"]) == 0
    return out, json.loads((out / "summary.json").read_text())


def test_run_mujoco_ticks_the_reactionless_controller_on_the_wheel_arm(wheel_run):
    """MuJoCo's realised shaking moment about z under the case's controller is below
    WHEEL_RESIDUAL of the uncontrolled peak; the uncontrolled variant (computed torque with the
    wheel held: what the run did before it ticked the reactionless controller) realises the whole
    uncontrolled peak, so the bound fails for computed torque."""
    out, s = wheel_run
    assert s["engine"] == "mujoco" and s["ok"] and s["variants"] == ["uncontrolled", "controlled"]
    assert {"bodies_uncontrolled.npz", "bodies_controlled.npz", "shaking_wrench.png", "base_reaction.png",
            "cosimulation.npz", "mechanism.xml"} <= set(s["files"])
    for f in s["files"]:
        assert (out / f).is_file(), f
    peak_u = s["peak_shaking_moment"]["uncontrolled"][2]   # MuJoCo's motion, wheel held
    peak_c = s["peak_shaking_moment"]["controlled"][2]
    predicted_u = s["cosimulation"]["uncontrolled"]["shaking_wrench"]["peak_moment_mechbal"]
    assert peak_u > 1.0
    assert peak_u == pytest.approx(predicted_u, rel=1e-2)
    assert peak_c < WHEEL_RESIDUAL * peak_u, (peak_c, peak_u)
    c = s["control"]
    assert c["balancing_joints"] == ["wheel"] and c["peak_balancing_rate"][0] > 1.0
    assert c["singular_ticks"] == 0 and c["saturated_ticks"] == 0
    # the wheel moved in MuJoCo (the controller drove it) and stood still uncontrolled
    du, dc = read_bodies(out / "bodies_uncontrolled.npz"), read_bodies(out / "bodies_controlled.npz")
    wheel = 2
    assert np.max(np.abs(du["q"][:, wheel])) < 1e-3 and np.max(np.abs(dc["q"][:, wheel])) > 0.5


def test_run_mujoco_bodies_hold_the_wrench_of_their_poses(wheel_run):
    """The bodies files hold MuJoCo's states and accelerations with mechbal's shaking wrench of
    them, which is MuJoCo's realised wrench (the engines agree on the simulated motion); the base
    reaction MuJoCo realises is mechbal's prediction for the command up to the tracking."""
    out, s = wheel_run
    mech = mechbal.Mechanism.from_toml(CASES_DIR / "reaction-wheel-arm.toml")
    cs = np.load(out / "cosimulation.npz")
    peak = np.max(np.abs(read_bodies(out / "bodies_uncontrolled.npz")["shaking_moment"]))
    for label in ("uncontrolled", "controlled"):
        d = read_bodies(out / f"bodies_{label}.npz")
        sw = mech.shaking_wrench(d["q"], d["qd"], d["qdd"])
        assert np.max(np.abs(sw.shaking_moment - d["shaking_moment"])) <= 1e-12 * peak
        assert np.max(np.abs(d["shaking_moment"] - cs[f"{label}_shaking_moment"])) <= 1e-9 * peak
        assert np.max(np.abs(d["shaking_force"] - cs[f"{label}_shaking_force"])) <= 1e-9 * max(peak, 1.0)
        assert np.array_equal(d["q"], cs[f"{label}_q"])
        v = s["cosimulation"][label]
        assert v["stored_poses_wrench_difference"]["moment"] <= 1e-9 * peak
        br = v["base_reaction"]
        # measured: 2.5e-3 (uncontrolled), 6.6e-5 (controlled) of the peak: the tracking
        assert br["max_moment_difference"] < 1e-2 * peak
        assert br["max_force_difference"] < 1e-3 * br["peak_force_mechbal"]
        assert v["peak_tracking_error"] < 1e-3   # measured 1.0e-5 (wheel held), 7.7e-5 rad
    assert (out / "base_reaction.png").stat().st_size > 10_000


def test_run_mujoco_panda_operational_space(tmp_path):
    """``--engine mujoco`` of the operational-space case: the controller MuJoCo is driven by
    issues, tick by tick, the commands of the mechbal engine's run (the same controller), and its
    realised moment is cancelled against the pseudo-inverse path's."""
    from mechbal.cases.panda import TOOL_FRAME
    from mechbal.verify import reactionless_plan, run_cosimulation

    out = tmp_path / "out"
    s = run_cosimulation("panda-reactionless", out, duration=PANDA_HORIZON)
    assert s["engine"] == "mujoco" and s["ok"] and s["control"]["task_frame"] == TOOL_FRAME
    cs = np.load(out / "cosimulation.npz")
    plan = reactionless_plan("panda-reactionless", duration=PANDA_HORIZON)
    for label, null_space in (("uncontrolled", False), ("controlled", True)):
        r = control.ReactionlessTaskController(plan.mech, TOOL_FRAME, "linear", "moment", "rk4", 1000.0, 1e-2,
                                               null_space=null_space, q0=plan.start).run(plan.twist, plan.twist_rate)
        assert np.array_equal(cs[f"{label}_command_q"], r.q), label
        assert np.array_equal(cs[f"{label}_predicted_shaking_moment"], r.shaking_moment), label
    red = s["shaking_moment_reduction"]["whole_moment"]
    assert red["peak_norm_uncontrolled"] > 0.1
    assert red["ratio"] < 1e-2
    assert s["cosimulation"]["controlled"]["peak_tracking_error"] < 1e-4


def test_verify_cli_without_simulation(tmp_path):
    """``mechbal verify CASE --no-simulation`` on a reactionless case: the prescribed-motion checks
    alone (no co-simulation, no time step study, no plot)."""
    from mechbal.cli import main

    out = tmp_path / "out"
    assert main(["verify", "reaction-wheel-arm", "--no-simulation", "--out", str(out), "-q"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["mode"] == "joint" and "time_step" not in s and "shaking_wrench.png" not in s["files"]
    assert not (out / "shaking_wrench.png").exists()
    for label in ("uncontrolled", "controlled"):
        assert "simulation" not in s["variants"][label]
        assert s["variants"][label]["shaking_moment"]["relative_difference"] < 1e-9
    assert s["residual"]["moment_z"]["mujoco_inverse_controlled_fraction"] < 1e-9
