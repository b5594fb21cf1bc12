"""Runner for a URDF file (``mechbal run robot.urdf --out DIR``): the robot read by the C++ URDF
reader as a general `mechbal.Mechanism`, moved along a default rest-to-rest trajectory;
shaking force and moment about O, base reaction and joint torques (inverse dynamics), written as
every case writes them (summary.json, PNG plots, bodies_nominal.npz).

Default trajectory (the case of a URDF file: `mechbal.case.load.urdf_run_case`): a quintic
rest-to-rest motion over ``duration`` seconds (2 s) sampled at ``samples`` instants (501). Every
joint starts at 0 (clipped into its limits) and moves towards its upper limit by half the room left, at most 0.5 rad (revolute) or 0.1 m (prismatic); a joint with
no room above moves towards its lower limit the same way; an unlimited (continuous) joint moves
by 0.5 rad. The duration is lengthened where the URDF's velocity limits (15/8 |step| / limit, the
quintic's peak) or effort limits (doubled while the inverse-dynamics torque exceeds one) need it:
`mechbal.trajectory.quintic_within_limits`; summary.json's ``default_motion`` echoes the
limits, the peaks reached and whether they are respected.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal import trajectory
from mechbal.case.load import URDF_KIND as KIND
from mechbal.cases.runners import register
from mechbal.config import ConfigError, integer, number, require
from mechbal.mechanism import Mechanism


@register(KIND, stages=3)
def run(config: dict, out: Path) -> dict:
    from mechbal.cases.serial_chain import run_mechanism

    path = Path(require(require(config, "urdf", ""), "path", "urdf"))
    table = require(config, "trajectory", "")
    duration = number(require(table, "duration", "trajectory"), "trajectory.duration (--duration)",
                      positive=True)
    samples = integer(require(table, "samples", "trajectory"), "trajectory.samples (--samples)",
                      minimum=3)
    mech = Mechanism.from_urdf(path)
    if mech.dof == 0:
        raise ConfigError(f"URDF file '{path}'", "has no moving joint to run", has_value=False)
    start, end = trajectory.default_motion(mech)
    # at least as long as asked, longer where the URDF's velocity or effort limits need it
    duration, limits = trajectory.quintic_within_limits(mech, start, end, duration)
    traj = trajectory.RestToRestTrajectory(start, end, duration, trajectory.TimeLaw.quintic)
    t = np.linspace(0.0, duration, samples)
    return run_mechanism(mech, traj, t, out, name=config["case"]["name"], kind=KIND,
                         title=config["case"].get("title", config["case"]["name"]),
                         summary_extra={"urdf": str(path), "joint_names": mech.joint_names,
                                        "body_names": mech.body_names, "start": start, "end": end,
                                        "default_motion": limits})
