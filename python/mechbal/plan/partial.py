"""The combined design: counterweights under a mass budget plus a minimum-shaking motion on the
partially balanced mechanism (``mechbal balance CASE --method force --partial``).

The counterweights are the convex force balance of `mechbal.balance.force` solved with the
case's ``balance.mass_budget`` (``problem(...).solve(mass_budget=B)``: the least RMS linear
momentum that the budget allows); the motion is `mechbal.plan.min_shaking` between the ends of
the case's ``[trajectory]`` in its duration, planned once on the mechanism as it is and once on
the balanced one. Four variants are compared along the same time grid:

(a) the quintic on the unbalanced mechanism, (b) the planned motion on the unbalanced mechanism,
(c) the quintic on the balanced mechanism, (d) the planned motion on the balanced mechanism.

The verdict (``ok``) is a claim: both plans converged within their limits, the added mass is
within the budget, and the combined design (d) has the least RMS shaking force of the four; with
a ``shaking_target`` [N], (d)'s RMS shaking force is at most the target. Where it is not met,
``limited_by`` names why (the budget, where it is active: ``balance.mass_budget``).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechbal.errors import ConfigError
from mechbal.mechanism import Mechanism
from mechbal.plan.min_shaking import PlanInfeasible, PlanResult, min_shaking
from mechbal.plan.model import ActuatedModel, LoopFailure

#: the four variants, in the order of the report
VARIANTS = ("quintic_unbalanced", "min_shaking_unbalanced", "quintic_balanced", "min_shaking_balanced")
#: what the report calls them
LABELS = {"quintic_unbalanced": "(a) quintic, unbalanced", "min_shaking_unbalanced": "(b) min-shaking, unbalanced",
          "quintic_balanced": "(c) quintic, counterweights", "min_shaking_balanced": "(d) min-shaking, counterweights"}
#: slack of the comparisons of the verdict, relative to the unbalanced quintic's RMS shaking force
SLACK = 1e-9
#: an RMS shaking force below this fraction of the unbalanced quintic's is round-off (the complete
#: force balance: no motion to plan for the force)
ROUND_OFF = 1e-9


@dataclass
class CombinedDesign:
    """Counterweights plus motion (module docstring). ``metrics``: per variant of `VARIANTS`,
    RMS and peak shaking force [N], shaking moment about O [N m] and actuator torque (all
    actuated joints together, [N m or N]); ``added_mass`` [kg] and ``mass_budget`` [kg];
    ``plans``: the `PlanResult` on the unbalanced and on the balanced mechanism; ``ok``,
    ``limited_by``: the verdict and why not."""

    added_mass: float
    mass_budget: float
    shaking_target: float | None
    metrics: dict[str, dict[str, float]]
    plans: dict[str, PlanResult]
    ok: bool
    limited_by: list[str] = field(default_factory=list)
    series: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict, repr=False)
    #: per mechanism (unbalanced, balanced) without a plan: why
    notes: dict[str, str] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        """What summary.json says of it (``partial``)."""
        return {"ok": self.ok, "limited_by": self.limited_by, "added_mass": self.added_mass,
                "mass_budget": self.mass_budget, "shaking_target": self.shaking_target,
                "variants": {k: {"label": LABELS[k], **self.metrics[k]} for k in VARIANTS},
                "plans": {k: {"ok": p.ok, "message": p.message, "objective": p.objective,
                              "value": p.value, "quintic_value": p.quintic_value, "reduction": p.reduction,
                              "active_limits": p.active_limits}
                          for k, p in self.plans.items()},
                "notes": self.notes}

    def table_rows(self) -> list[list[Any]]:
        m = self.metrics
        return [[LABELS[k], m[k]["added_mass"], m[k]["rms_shaking_force"], m[k]["peak_shaking_force"],
                 m[k]["rms_shaking_moment"], m[k]["peak_shaking_moment"], m[k]["rms_joint_torque"],
                 m[k]["peak_joint_torque"]] for k in VARIANTS]

    TABLE_HEADER = ["variant", "added mass [kg]", "RMS force [N]", "peak force [N]", "RMS moment [N m]",
                    "peak moment [N m]", "RMS torque", "peak torque"]


def _metrics(am: ActuatedModel, traj, t: np.ndarray) -> tuple[dict[str, float], tuple]:
    qa, va, aa = traj.evaluate(t)
    ev = am.evaluate(qa, va, aa, torque=True)
    w = np.zeros_like(t)
    d = np.diff(t)
    w[:-1] += 0.5 * d
    w[1:] += 0.5 * d
    w /= t[-1] - t[0]
    F, M, T = ev.wrench[:, :3], ev.wrench[:, 3:], np.asarray(ev.torque)
    F2, M2, T2 = (np.sum(x ** 2, axis=1) for x in (F, M, T))
    return ({"rms_shaking_force": float(np.sqrt(w @ F2)), "peak_shaking_force": float(np.sqrt(F2.max())),
             "rms_shaking_moment": float(np.sqrt(w @ M2)), "peak_shaking_moment": float(np.sqrt(M2.max())),
             "rms_joint_torque": float(np.sqrt(w @ T2)), "peak_joint_torque": float(np.max(np.abs(T)))},
            (F, M))


def combined_design(mech: Mechanism, balanced: Mechanism, start, end, duration: float, *,
                    added_mass: float, mass_budget: float, shaking_target: float | None = None,
                    budget_active: bool = False, samples: int = 501, q_guess=None,
                    plan_options: dict[str, Any] | None = None, field_prefix: str = "trajectory") -> CombinedDesign:
    """Plan the least-shaking motion from ``start`` to ``end`` in ``duration`` on ``mech`` and on
    its partially balanced variant ``balanced`` (``added_mass`` kg of counterweights within
    ``mass_budget``; ``budget_active``: the budget limited the balance), compare the four variants
    of the module docstring on ``samples`` instants and give the verdict. ``plan_options``: the
    keywords of `min_shaking` (objective, limits, ...). ConfigError naming the trajectory's field
    where a plan is infeasible."""
    if shaking_target is not None and not (np.isfinite(shaking_target) and shaking_target > 0):
        raise ValueError(f"shaking_target must be a finite force > 0 N, got {shaking_target!r}")
    opts = dict(plan_options or {})
    opts.setdefault("samples", samples)
    t = np.linspace(0.0, float(duration), int(samples))
    plans: dict[str, PlanResult] = {}
    metrics: dict[str, dict[str, float]] = {}
    series = {}
    force_objective = "weights" not in opts and opts.get("objective", "force_rms") in ("force_rms", "force_peak")
    notes: dict[str, str] = {}
    for which, m in (("unbalanced", mech), ("balanced", balanced)):
        am = ActuatedModel(m, q_guess=q_guess)
        if which == "balanced" and force_objective:
            quintic = plans["unbalanced"].quintic      # the same ends: the same quintic
            metrics["quintic_balanced"], series["quintic_balanced"] = _metrics(am, quintic, t)
            if (metrics["quintic_balanced"]["rms_shaking_force"]
                    <= ROUND_OFF * metrics["quintic_unbalanced"]["rms_shaking_force"]):
                # the budget reaches the complete force balance: every motion has no shaking force
                notes["balanced"] = ("no plan: the counterweights cancel the shaking force for every motion "
                                     "(the quintic's RMS force is round-off), so the quintic is kept")
                metrics["min_shaking_balanced"] = dict(metrics["quintic_balanced"])
                series["min_shaking_balanced"] = series["quintic_balanced"]
                for key in ("quintic_balanced", "min_shaking_balanced"):
                    metrics[key]["added_mass"] = added_mass
                continue
        try:
            plans[which] = p = min_shaking(m, start, end, duration, q_guess=q_guess, **opts)
        except PlanInfeasible as exc:
            raise ConfigError(f"{field_prefix}.{exc.field}", f"({which} mechanism) {exc}", has_value=False) from exc
        except LoopFailure as exc:
            raise ConfigError(field_prefix, f"({which} mechanism) the motion leaves the workspace: {exc}",
                              has_value=False) from exc
        for law, traj in (("quintic", p.quintic), ("min_shaking", p.trajectory)):
            key = f"{law}_{which}"
            metrics[key], series[key] = _metrics(am, traj, t)
            metrics[key]["added_mass"] = added_mass if which == "balanced" else 0.0
    limited_by = []
    for which, p in plans.items():
        if not p.ok:
            limited_by.append(f"{field_prefix}: the plan on the {which} mechanism did not converge: {p.message}")
    if added_mass > mass_budget * (1 + SLACK):
        limited_by.append(f"balance.mass_budget: the counterweights weigh {added_mass:.6g} kg > {mass_budget:g} kg")
    d = metrics["min_shaking_balanced"]["rms_shaking_force"]
    best_other = min(metrics[k]["rms_shaking_force"] for k in VARIANTS[:3])
    floor = SLACK * metrics["quintic_unbalanced"]["rms_shaking_force"]   # round-off of the comparison
    budget_note = (f"balance.mass_budget = {mass_budget:g} kg is too small (the budget limits the counterweights)"
                   if budget_active else "the counterweight slots' bounds (not the budget) limit the balance")
    if shaking_target is not None and d > shaking_target:
        limited_by.append(f"--shaking-target: the combined design leaves an RMS shaking force of {d:.6g} N > "
                          f"{shaking_target:g} N; {budget_note}")
    if d > best_other + floor:
        worse = min(VARIANTS[:3], key=lambda k: metrics[k]["rms_shaking_force"])
        limited_by.append(f"the combined design's RMS shaking force {d:.6g} N is above {LABELS[worse]}'s "
                          f"{best_other:.6g} N")
    return CombinedDesign(added_mass=float(added_mass), mass_budget=float(mass_budget),
                          shaking_target=shaking_target, metrics=metrics, plans=plans, ok=not limited_by,
                          limited_by=limited_by, series=series, notes=notes)


def plan_options_of(raw_trajectory: dict | None) -> dict[str, Any]:
    """The `min_shaking` keywords of a case's ``[trajectory]`` table (its plan keys where the law
    is ``min_shaking``; none otherwise: the RMS shaking force, rest to rest)."""
    if not raw_trajectory or raw_trajectory.get("law") != "min_shaking":
        return {}
    from mechbal.tables import PLAN_KEYS

    out = {k: raw_trajectory[k] for k in PLAN_KEYS if k in raw_trajectory and k != "com_profile"}
    if "smooth_ends" in out:
        out["smooth_ends"] = bool(out["smooth_ends"])
    return out
