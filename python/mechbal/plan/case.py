"""``law = "min_shaking"`` in a case's ``[trajectory]``: the plan from the validated table, and
what ``mechbal run`` writes about it beside the usual run (motion.npz, the plot of the shaking
wrench of the quintic against the planned motion, summary.json's ``plan``).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from mechbal.errors import ConfigError
from mechbal.mechanism import Mechanism
from mechbal.plan.com import ComLawNotApplicable, com_law
from mechbal.plan.min_shaking import PlanInfeasible, PlanResult, min_shaking
from mechbal.plan.model import ActuatedModel, LoopFailure


def plan_from_table(mech: Mechanism, tr: Any, q_guess=None, field: str = "trajectory") -> PlanResult:
    """The `PlanResult` of a validated ``[trajectory]`` table (`mechbal.schema.ChainTrajectory`)
    with ``law = "min_shaking"``; ConfigError naming the field where the request is wrong or
    infeasible (with the shortest feasible duration)."""
    na = len(mech.actuated_names)
    for key in ("start", "end", "start_velocity", "end_velocity", "acceleration_limit", "torque_limit"):
        v = getattr(tr, key)
        if isinstance(v, list) and len(v) != na:
            raise ConfigError(f"{field}.{key}", f"must have {na} values (one per actuated joint)", v)
    kw: dict[str, Any] = dict(
        objective=tr.objective or "force_rms",
        weights=None if tr.weights is None else tr.weights.model_dump(),
        moment_point=tr.moment_point or (0.0, 0.0, 0.0),
        start_velocity=tr.start_velocity, end_velocity=tr.end_velocity,
        acceleration_limit=tr.acceleration_limit, torque_limit=tr.torque_limit,
        smooth_ends=bool(tr.smooth_ends), control_points=tr.control_points or 14, samples=tr.samples,
        q_guess=q_guess)
    try:
        return min_shaking(mech, tr.start, tr.end, float(tr.duration), **kw)
    except PlanInfeasible as exc:
        raise ConfigError(f"{field}.{exc.field}", str(exc), getattr(tr, exc.field, None)) from exc
    except LoopFailure as exc:
        raise ConfigError(field, f"the planned motion leaves the mechanism's workspace: {exc}",
                          has_value=False) from exc


def com_law_of_table(mech: Mechanism, tr: Any, t: np.ndarray, q_guess=None):
    """(ComLawResult, None) of the table's centre-of-mass law at the times ``t``, or (None, why
    not) where it does not apply (profile ``none``, boundary velocities, the centre of mass not
    invertible)."""
    profile = tr.com_profile or "bang_bang"
    if profile == "none":
        return None, "not asked (com_profile = none)"
    if any(np.any(np.asarray(getattr(tr, k) or 0.0) != 0.0) for k in ("start_velocity", "end_velocity")):
        return None, "the centre-of-mass law is rest to rest; this motion has boundary velocities"
    try:
        return com_law(mech, tr.start, tr.end, float(tr.duration), profile=profile, samples=len(t),
                       q_guess=q_guess), None
    except (ComLawNotApplicable, LoopFailure) as exc:
        return None, str(exc)


def write_plan_outputs(mech: Mechanism, result: PlanResult, com, com_reason: str | None, t: np.ndarray,
                       q: np.ndarray, v: np.ndarray, a: np.ndarray, out: Path, *, title: str,
                       q_guess=None) -> dict[str, Any]:
    """motion.npz (t, q, v, a of every joint of the planned motion), plan_shaking_wrench.png
    (quintic against planned, and the centre-of-mass law where it applies); returns summary.json's
    ``plan``."""
    from mechbal import report
    np.savez_compressed(out / "motion.npz", t=t, q=q, v=v, a=a, joint_names=np.array(mech.joint_names),
                 actuated=np.array(mech.actuated_names), law=np.array("min_shaking"))
    am = ActuatedModel(mech, q_guess=q_guess, moment_point=result.moment_point)
    variants = {}
    for name, traj in (("quintic", result.quintic), ("min_shaking", result.trajectory)):
        qa, va, aa = traj.evaluate(t)
        W = am.evaluate(qa, va, aa).wrench
        variants[name] = (W[:, :3], W[:, 3:])
    summary = result.summary(mech.actuated_names)
    if com is not None:
        qa, va, aa = com.trajectory.evaluate(t)
        W = am.evaluate(qa, va, aa).wrench
        variants[f"centre-of-mass law ({com.profile})"] = (W[:, :3], W[:, 3:])
        w = np.zeros_like(t)
        d = np.diff(t)
        w[:-1] += 0.5 * d
        w[1:] += 0.5 * d
        w /= t[-1] - t[0]
        F2, M2 = np.sum(W[:, :3] ** 2, axis=1), np.sum(W[:, 3:] ** 2, axis=1)
        summary["com_law"] = {"profile": com.profile, "joints": [mech.actuated_names[j] for j in com.joints],
                              "rms_shaking_force": float(np.sqrt(w @ F2)),
                              "peak_shaking_force": float(np.sqrt(F2.max())),
                              "rms_shaking_moment": float(np.sqrt(w @ M2)),
                              "peak_shaking_moment": float(np.sqrt(M2.max())),
                              "max_com_error": com.max_com_error}
    else:
        summary["com_law"] = {"not_applicable": com_reason}
    p = result.moment_point
    report.plot_wrench(out / "plan_shaking_wrench.png", t, variants, title=f"{title}: planned motion",
                       caption=f"Shaking force and shaking moment (about ({p[0]:g}, {p[1]:g}, {p[2]:g}) m) "
                               f"of the quintic and of the motion that minimises {result.objective}"
                               + (", and of the centre-of-mass law." if com is not None else "."))
    return summary
