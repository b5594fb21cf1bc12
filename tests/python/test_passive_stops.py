"""Joint limits in passive simulation (issue 37, point 4): a declared position limit is an
inelastic end stop in `mechbal.simulate.passive` (C++ ClosedLoopOptions::lower_limit /
upper_limit) and in the MJCF export (a stiff, overdamped MuJoCo limit), and the two agree
on a pendulum and on a double pendulum falling onto their limits (MuJoCo integrating mechbal's own
export). Evidence beside MuJoCo: the energy is conserved up to the impact and is then the
potential energy at the stop (all the kinetic energy of a one-joint pendulum goes into the stop);
the joint never passes its limit, where it did before (the free dynamics: 1.4 rad beyond)."""
from __future__ import annotations

import numpy as np
import pytest

from mechbal import simulate
from mechbal.control import PassiveController
from mechbal.mechanism import Mechanism
from mechbal.schema import validate_case
from mechbal.trajectory import RestToRest

G = 9.81
LOWER = -0.8   # rad: the pendulum falls from 0.3 rad onto this stop (it would hang at -pi/2)


def pendulum(links: int = 1, lower: float = LOWER) -> Mechanism:
    """Links along x, hinges about -y (q > 0 lifts the link); the last joint has the stop."""
    joints = []
    for i in range(links):
        j = {"name": f"j{i + 1}", "axis": [0.0, -1.0, 0.0],
             "link": {"mass": 1.3 - 0.4 * i, "com": [0.4, 0.0, 0.0],
                      "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.02, "ixy": 0.0, "ixz": 0.0, "iyz": 0.0}}}
        if i > 0:
            j["parent"] = f"j{i}"
            j["origin"] = {"xyz": [0.6, 0.0, 0.0]}
        if i == links - 1:
            j["limits"] = {"lower": lower, "upper": 2.0}
        joints.append(j)
    start = [0.3] * links
    cfg = {"case": {"name": "stop", "kind": "mechanism"},
           "mechanism": {"gravity": [0.0, 0.0, -G], "joints": joints},
           "trajectory": {"law": "quintic", "start": start, "end": start, "duration": 1.0}}
    return Mechanism.from_spec(validate_case(cfg, warn=False).spec, name="stop")


def _mujoco(mech, q0, v0, duration):
    return simulate.closed_loop(mech, PassiveController(mech.dof), RestToRest(q0, q0, duration), q0, v0,
                                dt=1e-3, duration=duration, engine="mujoco", integrator="RK4", substeps=4)


def test_a_pendulum_rests_on_its_stop_and_loses_its_kinetic_energy():
    mech = pendulum()
    r = simulate.passive(mech, [0.3], dt=1e-3, duration=1.5)
    assert r.ok and r.stop_steps > 100
    assert r.q.min() >= LOWER                      # never beyond the stop
    assert r.q[-1, 0] == LOWER and r.v[-1, 0] == 0.0
    hit = int(np.argmax(r.q[:, 0] <= LOWER))
    assert 0 < hit < len(r.t) - 100
    before = r.energy[:hit]
    assert np.max(np.abs(before - before[0])) < 1e-8           # conserved up to the impact
    assert r.kinetic_energy[hit - 1] > 1.0                      # it arrives fast ...
    np.testing.assert_allclose(r.energy[hit:], r.potential_energy[hit], atol=1e-12)   # ... and stops dead
    assert np.max(np.abs(r.a_full[hit + 1:])) < 1e-9            # resting: the stop holds it
    # without the stop (the dynamics before issue 37) it swings 1.4 rad past the limit
    free = simulate.passive(mech, [0.3], dt=1e-3, duration=1.5, joint_limits=False)
    assert free.stop_steps == 0 and free.q.min() < LOWER - 1.0


def test_the_pendulum_agrees_with_mujoco_through_the_export():
    pytest.importorskip("mujoco")
    mech = pendulum()
    ours = simulate.passive(mech, [0.3], [0.0], dt=1e-3, duration=1.0)
    theirs = _mujoco(mech, [0.3], [0.0], 1.0)
    assert theirs.steps_completed == ours.steps_completed
    hit = int(np.argmax(ours.q[:, 0] <= LOWER))
    assert np.max(np.abs(theirs.q[:hit - 2] - ours.q[:hit - 2])) < 1e-6   # the fall, to the integrators
    assert np.max(np.abs(theirs.q - ours.q)) < 1e-2                      # the impact: MuJoCo's soft stop
    assert theirs.q.min() > LOWER - 1e-2                                 # sinks < 1e-2 rad into it
    assert np.max(theirs.q[hit + 50:]) < LOWER + 1e-4                    # no bounce off it
    assert abs(theirs.q[-1, 0] - LOWER) < 1e-4 and abs(theirs.v[-1, 0]) < 1e-3   # at rest on it


def test_a_double_pendulum_falling_onto_joint_2s_stop_agrees_with_mujoco():
    """Joint 2's stop takes the impact through the inverse mass matrix: joint 1's motion after it
    is MuJoCo's (a stop that only zeroed joint 2's rate would leave joint 1 too fast)."""
    pytest.importorskip("mujoco")
    mech = pendulum(2, lower=-0.4)
    q0, v0 = [0.2, 0.3], [0.0, -2.0]
    ours = simulate.passive(mech, q0, v0, dt=1e-3, duration=0.6)
    theirs = _mujoco(mech, q0, v0, 0.6)
    assert ours.stop_steps > 0 and ours.q[:, 1].min() >= -0.4
    assert theirs.q[:, 1].min() > -0.4 - 1e-2
    # joint 1 swings on and pulls joint 2 off its stop: MuJoCo's soft stop lets it go a few ms
    # later, which stays as a small offset of both joints
    err = np.max(np.abs(theirs.q - ours.q), axis=0)
    assert np.all(err < 2e-2), err
    free = simulate.passive(mech, q0, v0, dt=1e-3, duration=0.6, joint_limits=False)
    assert np.max(np.abs(theirs.q - free.q)) > 0.08   # what the comparison would catch (4 x its tolerance)
    assert free.q[:, 1].min() < -0.4 - 0.02            # the free joint 2 passes its limit


def test_q0_beyond_a_limit_is_refused_naming_the_joint():
    with pytest.raises(ValueError, match=r"q0\[0\].*j1.*limits"):
        simulate.passive(pendulum(), [-1.0])
    simulate.passive(pendulum(), [-1.0], duration=0.01, joint_limits=False)   # the free dynamics may


def test_a_passive_case_reports_its_stops(tmp_path):
    """``[control] kind = "passive"`` through ``mechbal run``: the stop in summary.json, the energy
    drift measured before the impact (the integrator's error, not the impact's loss), the stored
    poses on the stop."""
    from mechbal.cli import main
    from mechbal.export import read_bodies
    from mechbal.export.toml import toml_text

    from cli_checks import summary_of

    mech = pendulum()
    case = tmp_path / "stop.toml"
    text = mech.to_toml(name="stop", trajectory={"law": "quintic", "start": [0.3], "end": [0.3], "duration": 1.0})
    case.write_text(text + toml_text({"control": {"kind": "passive"}}))
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q"]) == 0
    p = summary_of(out)["passive"]
    assert p["stop_steps"] > 100 and p["final_q"] == [LOWER] and p["final_v"] == [0.0]
    assert p["max_energy_drift"] < 1e-8
    assert read_bodies(out / "bodies_passive.npz")["q"].min() >= LOWER
