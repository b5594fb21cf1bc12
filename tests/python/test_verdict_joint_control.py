"""A verdict for every controlled run kind (issue 37, point 1): the joint controllers
(``[control] kind = "computed_torque"`` and ``"decoupled"``) under every command that runs them
(``mechbal run``, ``run --engine mujoco``, ``verify``) and in Python (``simulate.closed_loop``,
``control.joint_controller``). For each kind and command: a run within its limits meets its goal
(exit 0, ``ok``); a saturating run (a declared torque limit below what the motion needs) and a
diverging one (a model far from the plant, so the loop leaves its command) are not ok and exit 6,
with DIR written and ``limited_by`` saying why; ``--allow-degraded`` exits 0 with a warning.

The reactionless kind's runs are tested in test_verdict.py.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import control, simulate
from mechbal.cli import EXIT_GOAL_NOT_MET, main
from mechbal.config import CASES_DIR

ARM = (CASES_DIR / "arm2link.toml").read_text()
def arm_case(tmp_path: Path, kind: str, extra: str = "", duration: float = 1.0, name: str = "arm.toml") -> Path:
    """The shipped two-link arm (without its [balance] table) with a ``[control]`` of ``kind``,
    Kp 400 / s^2, Kd 40 / s, and ``extra`` lines in the table."""
    text = ARM.split("[balance]")[0]
    text = text.replace("duration = 1.0", f"duration = {duration}").replace("samples = 1001", "samples = 101")
    text += f'\n[control]\nkind = "{kind}"\nkp = [400.0, 400.0]\nkd = [40.0, 40.0]\nrate_hz = 1000\n{extra}\n'
    p = tmp_path / name
    p.write_text(text)
    return p


def true_k() -> list[float]:
    mech = mechbal.Mechanism.from_toml(CASES_DIR / "arm2link.toml")
    M = np.asarray(control.MechanismDynamics(mech.model, np.zeros(2)).mass_matrix(np.zeros(2)), float)
    return list(map(float, np.diag(M)))


def run_cli(args, capsys):
    code = main(list(map(str, args)))
    out, err = capsys.readouterr()
    return code, out, err


def summary_of(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


#: the peak torque of the arm's motion is about 25 N m at the shoulder: 2 N m saturates
SATURATING = "torque_limit = [2.0, 2.0]"


def kinds():
    return ["computed_torque", "decoupled"]


def extra_of(kind: str, what: str) -> str:
    """The [control] lines of a run that meets its goal (``good``), saturates, or diverges."""
    k = true_k()
    base = f"k = {k}\n" if kind == "decoupled" else ""
    if what == "good":
        # decoupled control of an unbalanced arm is not exact: a tolerance the PD loop keeps
        return base + ("tolerance = { joint = 0.5 }" if kind == "decoupled" else "")
    if what == "saturating":
        return base + SATURATING
    assert what == "diverging"
    if kind == "decoupled":
        return f"k = {[0.02 * x for x in k]}\n"
    return ""   # computed torque: the plant's payload below makes the model wrong


def diverging_case(tmp_path: Path, kind: str) -> Path:
    """A run that leaves its command: decoupled control with a model 50 times too light (gravity
    wins); computed torque with gains its 100 Hz tick cannot hold (Kd dt = 20 > 2: the sampled
    loop is unstable)."""
    p = arm_case(tmp_path, kind, extra_of(kind, "diverging"), name=f"div-{kind}.toml")
    if kind == "computed_torque":
        text = p.read_text().replace("kp = [400.0, 400.0]", "kp = [1e6, 1e6]").replace(
            "kd = [40.0, 40.0]", "kd = [2000.0, 2000.0]").replace("rate_hz = 1000", "rate_hz = 100")
        p.write_text(text)
    return p


# ---- Python: closed_loop and joint_controller ----------------------------------------------------

@pytest.mark.parametrize("kind", kinds())
def test_joint_controller_of_a_table_and_its_closed_loop_verdict(kind):
    """control.joint_controller builds the table's controller (the declared limits in force);
    simulate.closed_loop judges it: saturating is not ok (status saturated), within limits ok."""
    from mechbal.trajectory import RestToRest

    mech = mechbal.Mechanism.from_toml(CASES_DIR / "arm2link.toml")
    traj = RestToRest([0.0, 0.0], [1.2, -0.9], 1.0)
    table = {"kind": kind, "kp": [400.0] * 2, "kd": [40.0] * 2, **({"k": true_k()} if kind == "decoupled" else {})}
    good = simulate.closed_loop(mech, control.joint_controller(mech, table), traj,
                                tolerance={"joint": 0.5} if kind == "decoupled" else None)
    assert good.ok, good.limited_by
    sat = simulate.closed_loop(mech, control.joint_controller(mech, {**table, "torque_limit": [2.0, 2.0]}), traj)
    assert not sat.ok and any(x.get("status") == "saturated" for x in sat.limited_by)
    assert np.max(np.abs(sat.joint_torque)) <= 2.0 + 1e-12


def test_decoupled_without_k_needs_a_balanced_design():
    """No k: the diagonal of M(0), which must be diagonal (as the C++ make_controller)."""
    mech = mechbal.Mechanism.from_toml(CASES_DIR / "arm2link.toml")
    with pytest.raises(ValueError, match=r"control\.k: the mass matrix at q = 0 is not diagonal"):
        control.joint_controller(mech, {"kind": "decoupled", "kp": [1.0] * 2, "kd": [1.0] * 2})


def test_decoupled_takes_the_declared_effort_limits():
    """No hidden limit, and every declared one: a joint's effort limit reaches the decoupled
    controller built from a table (its Python class alone has no model to read them from)."""
    text = ARM.split("[balance]")[0].replace('axis = [0.0, -1.0, 0.0]       # positive',
                                             'limits = { effort = 7.0 }\naxis = [0.0, -1.0, 0.0]       # positive')
    mech = mechbal.Mechanism.from_toml_string(text) if hasattr(mechbal.Mechanism, "from_toml_string") else None
    if mech is None:
        import tempfile

        with tempfile.TemporaryDirectory() as d:
            p = Path(d) / "a.toml"
            p.write_text(text)
            mech = mechbal.Mechanism.from_toml(p)
    ctrl = control.joint_controller(mech, {"kind": "decoupled", "kp": [1.0] * 2, "kd": [1.0] * 2, "k": [1.0, 1.0],
                                           "torque_limit": [9.0, 3.0]})
    assert np.allclose(ctrl.torque_limit, [7.0, 3.0])


# ---- mechbal run -----------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", kinds())
def test_run_of_a_joint_controller_gives_a_verdict(kind, tmp_path, capsys):
    """mechbal run simulates the case's joint controller in closed loop: within its limits exit 0,
    ok, the goal printed; saturating: exit 6 naming the status and DIR written; --allow-degraded:
    exit 0 with a warning; diverging: exit 6 on the tracking criterion."""
    good = arm_case(tmp_path, kind, extra_of(kind, "good"))
    code, text, err = run_cli(["run", good, "--out", tmp_path / "good"], capsys)
    assert code == 0, err
    s = summary_of(tmp_path / "good")
    assert s["ok"] is True and s["limited_by"] == [] and s["goal"]["kind"] == kind
    assert s["control"]["kind"] == kind and s["control"]["saturated_ticks"] == 0
    assert "goal met" in text and "closed loop" in text
    # the simulated motion is written, and follows the command within the tolerance
    b = np.load(tmp_path / "good" / "bodies_controlled.npz")
    d = np.load(tmp_path / "good" / "bodies_desired.npz")
    assert np.max(np.abs(b["q"] - d["q"])) <= s["goal"]["tolerance"]["joint"] + 1e-12

    sat = arm_case(tmp_path, kind, extra_of(kind, "saturating"), name="sat.toml")
    code, text, err = run_cli(["run", sat, "--out", tmp_path / "sat"], capsys)
    assert code == EXIT_GOAL_NOT_MET, err
    assert "control goal not met" in err and "saturated" in err
    s = summary_of(tmp_path / "sat")
    assert s["ok"] is False
    st = [x for x in s["limited_by"] if x.get("status") == "saturated"]
    assert st and st[0]["ticks"] > 0
    assert s["goal"]["limits"]["shoulder"]["effort"] == 2.0
    assert "NOT MET" in text and re.search(r"saturated ticks\s*\|?\s*[1-9]\d* of", text)
    code, _, err = run_cli(["run", sat, "--out", tmp_path / "sat2", "--allow-degraded"], capsys)
    assert code == 0 and "warning: control goal not met" in err

    div = diverging_case(tmp_path, kind)
    code, _, err = run_cli(["run", div, "--out", tmp_path / "div"], capsys)
    assert code == EXIT_GOAL_NOT_MET, err
    s = summary_of(tmp_path / "div")
    assert s["ok"] is False and any(x["criterion"] == "tracking" for x in s["limited_by"])
    assert s["control"]["saturated_ticks"] == 0   # not the limits: the loop itself


# ---- run --engine mujoco and verify: the case's controller, judged --------------------------------

@pytest.mark.parametrize("kind", kinds())
def test_mujoco_run_and_verify_of_a_joint_controller_give_the_simulations_verdict(kind, tmp_path, capsys):
    pytest.importorskip("mujoco")
    good = arm_case(tmp_path, kind, extra_of(kind, "good"), duration=0.5)
    sat = arm_case(tmp_path, kind, extra_of(kind, "saturating"), duration=0.5, name="sat.toml")
    div = diverging_case(tmp_path, kind)
    for cmd in (["run", "--engine", "mujoco"], ["verify"]):
        tag = cmd[0] + ("-mj" if len(cmd) > 1 else "")
        code, text, err = run_cli([cmd[0], good, *cmd[1:], "--out", tmp_path / f"{tag}-good"], capsys)
        assert code == 0, (cmd, err)
        s = summary_of(tmp_path / f"{tag}-good")
        assert s["ok"] is True and kind in s["controller"]
        code, text, err = run_cli([cmd[0], sat, *cmd[1:], "--out", tmp_path / f"{tag}-sat"], capsys)
        assert code == EXIT_GOAL_NOT_MET and "saturated" in err, (cmd, err)
        s = summary_of(tmp_path / f"{tag}-sat")
        assert s["ok"] is False and any(x.get("status") == "saturated" for x in s["limited_by"])
        assert "NOT MET" in text
        if cmd[0] == "verify":   # a failed loop is not printed as a realised wrench
            assert "mujoco_simulated_peak" not in s["variants"]["unbalanced"]["shaking_moment"]
        code, _, err = run_cli([cmd[0], sat, *cmd[1:], "--out", tmp_path / f"{tag}-sat2", "--allow-degraded"],
                               capsys)
        assert code == 0 and "warning: control goal not met" in err
        code, _, err = run_cli([cmd[0], div, *cmd[1:], "--out", tmp_path / f"{tag}-div"], capsys)
        assert code == EXIT_GOAL_NOT_MET, (cmd, err)
        s = summary_of(tmp_path / f"{tag}-div")
        assert s["ok"] is False and any(x["criterion"] in ("tracking", "steps") for x in s["limited_by"])
