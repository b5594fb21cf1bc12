"""Passive simulation (issue 23): no controller, zero joint effort, gravity and springs only
(`mechbal.simulate.passive`, `mechbal.control.PassiveController`, `[control] kind = "passive"` in
`mechbal run`). Evidence: the energy (kinetic + gravity + springs) of a free pendulum, of a
spring-balanced arm (whose potential energy is constant, so it turns at constant speed) and of a
closed four-bar is conserved along the run, and the pendulum's motion agrees with MuJoCo
integrating mechbal's MJCF export."""
from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import simulate
from mechbal.export.toml import toml_text
from mechbal.cases import run_case
from mechbal.cli import main
from mechbal.control import PassiveController
from mechbal.errors import ConfigError
from mechbal.export import read_bodies
from mechbal.mechanism import Mechanism
from mechbal.schema import validate_case
from mechbal.trajectory import RestToRest

from cli_checks import one_line_error

PKG = Path(mechbal.__file__).resolve().parent
G = 9.81
# the spring-balanced arm: m g l_c = k h r makes gravity + spring energy constant (zero free length)
MASS, COM, HEIGHT, RADIUS = 2.0, 0.25, 0.3, 0.2
RATE = MASS * G * COM / (HEIGHT * RADIUS)


def pendulum() -> dict:
    return {"case": {"name": "pendulum", "kind": "mechanism"},
            "mechanism": {"gravity": [0.0, 0.0, -G],
                          "joints": [{"name": "hinge", "axis": [0.0, -1.0, 0.0],
                                      "link": {"mass": 1.3, "com": [0.4, 0.0, 0.0], "izz": 0.02}}]},
            "trajectory": {"law": "quintic", "start": [0.3], "end": [0.3], "duration": 2.0}}


def spring_arm() -> dict:
    return {"case": {"name": "spring-arm", "kind": "mechanism"},
            "mechanism": {"gravity": [0.0, 0.0, -G],
                          "joints": [{"name": "arm", "axis": [0.0, -1.0, 0.0],
                                      "link": {"mass": MASS, "com": [COM, 0.0, 0.0], "izz": 0.05}}],
                          "springs": [{"name": "balancer", "link_a": "base", "anchor_a": [0.0, 0.0, HEIGHT],
                                       "link_b": "arm", "anchor_b": [RADIUS, 0.0, 0.0], "rate": RATE}]},
            "trajectory": {"law": "constant_speed", "start": [-0.4], "speed": 2.5, "duration": 2.0, "samples": 11}}


def mech_of(cfg: dict) -> Mechanism:
    return Mechanism.from_spec(validate_case(cfg, warn=False).spec)


def test_the_controller_commands_nothing():
    c = PassiveController(3)
    cmd = c.step([1, 2, 3], [0, 0, 1], [0, 0, 0], [0, 0, 0], [0, 0, 0])
    assert np.all(cmd.joint_torque == 0) and cmd.status == 0
    assert c.step([np.nan, 0, 0], [0, 0, 0], [0] * 3, [0] * 3, [0] * 3).status == int(mechbal.Status.non_finite_input)
    run = c.run(np.ones((4, 3)), np.ones((4, 3)), np.zeros((4, 3)), np.zeros((4, 3)), np.zeros((4, 3)))
    assert np.all(run.joint_torque == 0) and np.all(run.status == 0)
    with pytest.raises(ValueError, match="dof"):
        PassiveController(0)


def test_free_pendulum_conserves_energy():
    mech = mech_of(pendulum())
    r = simulate.passive(mech, [0.3], dt=1e-3, duration=3.0)
    assert r.ok and r.steps_completed == 3000
    swing = np.ptp(r.kinetic_energy)
    assert swing > 1.0                                   # it swings: 1.3 kg falling 0.4 m (1 - sin)
    assert r.energy_drift < 1e-9 * swing
    # it swings through the bottom and back to the same height on the other side
    assert np.min(r.q) == pytest.approx(-math.pi - 0.3, abs=2e-3)
    # the energy is that of the model: m g z_com at rest at the start
    assert r.energy[0] == pytest.approx(1.3 * G * 0.4 * math.sin(0.3), rel=1e-12)


def test_spring_balanced_arm_turns_at_constant_speed():
    mech = mech_of(spring_arm())
    assert np.ptp(mech.potential_energy(np.linspace(-3, 3, 50)[:, None])) < 1e-12   # balanced
    r = simulate.passive(mech, [-0.4], [2.5], dt=1e-3, duration=2.0)
    assert r.ok
    assert np.max(np.abs(r.v - 2.5)) < 1e-10
    assert np.max(np.abs(r.q[:, 0] - (-0.4 + 2.5 * r.t))) < 1e-10
    assert r.energy_drift < 1e-12 * r.energy[0]
    # without the spring it falls, gaining the energy the spring was storing
    free = Mechanism.from_spec(validate_case({**spring_arm(), "mechanism": {
        **spring_arm()["mechanism"], "springs": []}}, warn=False).spec)
    f = simulate.passive(free, [-0.4], [2.5], dt=1e-3, duration=2.0)
    assert np.ptp(f.v) > 1.0 and f.energy_drift < 1e-9 * np.ptp(f.kinetic_energy)


def test_closed_four_bar_released_from_rest_conserves_energy():
    mech = Mechanism.from_toml(PKG / "cases" / "four-bar.toml")
    from mechbal.assembly import assemble

    asm = assemble(mech, [1.0], branch="open")
    r = simulate.passive(mech, [1.0], dt=5e-4, duration=1.5, q_guess=asm.q)
    assert r.ok
    swing = np.ptp(r.kinetic_energy)
    assert swing > 0.5
    assert r.energy_drift < 1e-7 * swing
    # every instant is assembled: the loop closes along the run
    pin = mech.body_motion(r.q_full).frame_placement[:, :, :3, 3]
    names = mech.frame_names
    assert np.max(np.linalg.norm(pin[:, names.index("coupler_tip")] - pin[:, names.index("rocker_tip")], axis=1)) < 1e-11


def test_pendulum_agrees_with_mujoco():
    pytest.importorskip("mujoco")
    mech = mech_of(pendulum())
    ours = simulate.passive(mech, [0.3], [1.0], dt=1e-3, duration=1.5)
    theirs = simulate.closed_loop(mech, PassiveController(1), RestToRest([0.3], [0.3], 1.5), [0.3], [1.0],
                                  dt=1e-3, duration=1.5, engine="mujoco", integrator="RK4", substeps=4)
    assert theirs.steps_completed == ours.steps_completed
    err = np.max(np.abs(theirs.q - ours.q))
    assert err < 1e-6, err
    assert np.ptp(ours.q) > 1.0


def test_spring_arm_agrees_with_mujoco():
    pytest.importorskip("mujoco")
    mech = mech_of(spring_arm())
    ours = simulate.passive(mech, [-0.4], [0.5], dt=1e-3, duration=1.0)
    theirs = simulate.closed_loop(mech, PassiveController(1), RestToRest([-0.4], [-0.4], 1.0), [-0.4], [0.5],
                                  dt=1e-3, duration=1.0, engine="mujoco", integrator="RK4", substeps=4)
    assert np.max(np.abs(theirs.qd - 0.5)) < 1e-6                     # MuJoCo keeps it at constant speed too
    assert np.max(np.abs(theirs.q - ours.q)) < 1e-6


# ---- the case way: [control] kind = "passive" -------------------------------------------------------

def test_mechbal_run_passive_case(tmp_path):
    cfg = spring_arm()
    cfg["control"] = {"kind": "passive", "rate_hz": 500.0}
    path = tmp_path / "arm.toml"
    path.write_text(toml_text(cfg))
    s = run_case(path, tmp_path / "out")
    p = s["passive"]
    assert s["variants"] == ["passive"] and s["samples"] == 1001
    assert p["v0"] == [2.5] and p["q0"] == [-0.4]
    assert p["max_energy_drift"] < 1e-10 and abs(p["final_v"][0] - 2.5) < 1e-10
    b = read_bodies(tmp_path / "out" / "bodies_passive.npz")
    assert np.max(np.abs(np.asarray(b["q"])[:, 0] - (-0.4 + 2.5 * np.asarray(b["t"])))) < 1e-10
    assert (tmp_path / "out" / "energy.png").is_file()


def test_passive_four_bar_case_from_the_cli(tmp_path):
    cfg = tomllib.loads((PKG / "cases" / "four-bar.toml").read_text())
    cfg.pop("balance")
    cfg["trajectory"] = {"law": "quintic", "start": [1.0], "end": [1.0], "duration": 1.0, "branch": "crossed"}
    cfg["control"] = {"kind": "passive"}
    path = tmp_path / "fb.toml"
    path.write_text(toml_text(cfg))
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "-q"]) == 0
    s = __import__("json").loads((tmp_path / "o" / "summary.json").read_text())
    assert s["loops"]["assembly"]["branch"] == {"coupler_rocker": "crossed"}
    assert s["passive"]["relative_energy_drift"] < 1e-6


@pytest.mark.parametrize("extra, field", [({"kp": [1.0]}, "control.kp"),
                                          ({"balancing_joints": ["crank"]}, "control.balancing_joints"),
                                          ({"rate_hz": 0.5}, "control.rate_hz")])
def test_passive_control_table_is_strict(tmp_path, extra, field):
    cfg = copy.deepcopy(tomllib.loads((PKG / "cases" / "four-bar.toml").read_text()))
    cfg.pop("balance")
    cfg["control"] = {"kind": "passive", **extra}
    with pytest.raises(ConfigError) as exc:
        validate_case(cfg, warn=False)
    assert exc.value.field == field, str(exc.value)
    path = tmp_path / "c.toml"
    path.write_text(toml_text(cfg))
    with pytest.raises(ValueError) as cpp:
        mechbal._core.load_case_file(str(path))
    assert str(cpp.value).startswith(field + ": "), str(cpp.value)


def test_cpp_reader_reads_passive(tmp_path):
    cfg = spring_arm()
    cfg["control"] = {"kind": "passive", "rate_hz": 250.0}
    path = tmp_path / "arm.toml"
    path.write_text(toml_text(cfg))
    model, control, name = mechbal._core.load_case_file(str(path))
    assert (control.kind, control.rate_hz, name) == ("passive", 250.0, "spring-arm")


def test_passive_arguments_are_checked():
    mech = mech_of(pendulum())
    with pytest.raises(ValueError, match="q0 must have 1 values"):
        simulate.passive(mech, [0.1, 0.2])
    with pytest.raises(ValueError, match="v0 must be finite"):
        simulate.passive(mech, [0.1], [np.nan])
    with pytest.raises(ValueError, match="dt"):
        simulate.passive(mech, [0.1], dt=-1.0)
    with pytest.raises(TypeError, match="mechbal.Mechanism"):
        simulate.passive(mech.model, [0.1])
