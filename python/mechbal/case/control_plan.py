"""The control plan of a case with a reactionless ``[control]``: what the controller is asked
to follow, checked against the mechanism and the declared limits before anything runs.

* joint mode: `held_trajectory` (the ``[trajectory]`` with the balancing joints held at their
  start, and the balancing and task joints);
* operational-space mode (``task_frame``): `check_task_space` (the case fits the mode);
* both: `feasibility_of` (`mechbal.control.feasibility` of the commanded motion) and
  `check_feasibility` (infeasible: fit the duration, run degraded, or
  `mechbal.verdict.ControlInfeasible`).

Layer: the case (docs/architecture.md)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from mechbal import control, verdict
from mechbal.case.motion import frame_path, task_end_pose
from mechbal.config import trajectory_from_config
from mechbal.errors import ConfigError

if TYPE_CHECKING:
    from mechbal.mechanism import Mechanism


def held_trajectory(mech: Mechanism, case):
    """(trajectory, balancing, task) of a validated case with a reactionless ``[control]`` in the
    joint mode: the ``[trajectory]`` of every actuated joint with the balancing joints held at
    their start (their end or speed is ignored: the controller computes them; the uncontrolled
    motion), and the indices of the balancing and task joints among the actuated ones.
    ConfigError naming a balancing joint that is not actuated."""
    from mechbal.schema import did_you_mean

    ctl = case.control
    names = mech.actuated_names
    for i, b in enumerate(ctl.balancing_joints):
        if b not in names:
            raise ConfigError(f"control.balancing_joints[{i}]",
                              f"is not an actuated joint{did_you_mean(b, names)}", b)
    balancing = [names.index(b) for b in ctl.balancing_joints]
    task = [i for i in range(len(names)) if i not in balancing]
    if case.trajectory.law == "constant_speed":   # a balancing joint's speed is ignored: held at its start
        speed = case.trajectory.speeds(len(names))
        for i in balancing:
            speed[i] = 0.0
        held = {"speed": speed, "rpm": None}
    else:                                        # a balancing joint's end is ignored: held at its start
        end = list(case.trajectory.end)
        if len(end) == len(names):
            for i in balancing:
                end[i] = case.trajectory.start[i]
        held = {"end": end}
    traj, _ = trajectory_from_config(case.trajectory.model_copy(update=held), len(names))
    return traj, balancing, task



def check_task_space(mech: Mechanism, case) -> None:
    """ConfigError naming the field unless the validated ``case``'s operational-space mode
    (``[control] task_frame``) fits ``mech``: an open mechanism with every joint actuated and
    listed as balancing, a named task frame, a quintic or cubic ``[trajectory]`` whose ``start``
    and ``end`` are joint positions."""
    from mechbal.schema import did_you_mean

    ctl = case.control
    names = mech.actuated_names
    if mech.is_closed or len(names) != mech.dof:
        raise ConfigError("control.task_frame", "the operational-space mode drives open mechanisms with "
                          "every joint actuated", ctl.task_frame)
    if ctl.task_frame not in mech.frame_names:
        raise ConfigError("control.task_frame", "is not a frame of the mechanism"
                          + did_you_mean(ctl.task_frame, list(mech.frame_names)), ctl.task_frame)
    listed = list(names if ctl.balancing_joints is None else ctl.balancing_joints)  # absent: every joint
    missing = [n for n in names if n not in listed]
    for i, b in enumerate(listed):
        if b not in names:
            raise ConfigError(f"control.balancing_joints[{i}]",
                              f"is not an actuated joint{did_you_mean(b, names)}", b)
    if missing:
        raise ConfigError("control.balancing_joints", "in the operational-space mode (task_frame) the "
                          "controller moves every joint: list them all (missing: " + ", ".join(missing) + ")",
                          listed)
    tr = case.trajectory
    if tr.law not in ("quintic", "cubic", "line"):
        raise ConfigError("trajectory.law", "the operational-space mode's path is rest-to-rest between the "
                          "frame's poses at start and end (quintic or cubic), or a line from start "
                          "(line, with displacement and / or rotation)", tr.law)
    for key in ("start",) if tr.law == "line" else ("start", "end"):
        if getattr(tr, key) is None or len(getattr(tr, key)) != len(names):
            raise ConfigError(f"trajectory.{key}", f"must have {len(names)} values (joint positions: the "
                              "task frame's path runs from its pose at start to its pose at end)",
                              getattr(tr, key))



def feasibility_of(mech: Mechanism, case, q_guess=None):
    """`mechbal.control.feasibility` of a validated case with a reactionless ``[control]``: its
    commanded motion (joint mode: the held trajectory; operational-space mode: the frame's path)."""
    ctl = case.control
    if ctl.task_frame is not None:
        check_task_space(mech, case)
        tr = case.trajectory
        dt = 1.0 / ctl.rate_hz
        th = np.arange(2 * int(round(tr.duration / dt)) + 1) * (0.5 * dt)
        _, _, twist, twist_rate = frame_path(mech, ctl.task_frame, tr.start, tr.end, tr.duration, tr.law, th,
                                             end_pose=task_end_pose(mech, ctl.task_frame, tr))
        motion = control.FrameMotion(np.array(tr.start, float), twist, twist_rate, float(tr.duration))
        return control.feasibility(mech, ctl, motion)
    traj, _, _ = held_trajectory(mech, case)
    return control.feasibility(mech, ctl, traj, q_guess=q_guess)



def check_feasibility(mech: Mechanism, case, q_guess=None, *, fit_duration: bool = False,
                      allow_degraded: bool = False):
    """(case, report, fitted duration or None): the case's motion checked against the declared
    limits before the run (`feasibility_of`). Infeasible: with ``fit_duration`` the case with its
    ``[trajectory] duration`` set to the shortest feasible one (`mechbal.verdict.fitted_duration`;
    rest-to-rest laws); with ``allow_degraded`` the case as it is (the run's verdict will say why
    it failed); otherwise `mechbal.verdict.ControlInfeasible`."""
    report = feasibility_of(mech, case, q_guess)
    if report.feasible:
        return case, report, None
    if fit_duration and np.isfinite(report.min_duration) and case.trajectory.law != "constant_speed":
        fitted = verdict.fitted_duration(report.min_duration, 1.0 / case.control.rate_hz)
        refit = case.model_copy(update={"trajectory": case.trajectory.model_copy(update={"duration": fitted})})
        again = feasibility_of(mech, refit, q_guess)
        if again.feasible:
            return refit, again, fitted
        report = again
    if allow_degraded:
        return case, report, None
    raise verdict.ControlInfeasible(report)
