"""The trade-off front of a counterweight balance: what each added kilogram buys.

For a method whose condition is linear in the counterweights' mass moments (``static``: gravity
torque, ``force``: linear momentum), the least residual reachable with at most B kg of added mass
is a convex program (`mechbal.balance.optimal`); solving it for budgets B from the least
possible mass (zero, or the slots' ``mass_min``) to the mass of the lightest design with the best
residual gives the front (the epsilon-constraint method): residual non-increasing with mass, its
first point the unbalanced mechanism (no mass added), its last the lightest design of the best
residual. Each point also gets the quantities a designer trades against it, recomputed from that
point's balanced model along a motion: the peak and RMS shaking force and moment and actuator
torques, and the design's added inertia.

``front(mechanism, design, points)`` returns a `Front`; ``write(front, out, ...)`` writes
``front.csv``, ``front.json`` (schema: `json_schema`, shipped as
``mechbal/cases/front.schema.json``), ``front.png`` (residual and torque against added mass, the
knee marked) and ``front/<k>/balanced.toml``. ``mechbal balance CASE --front N --out DIR`` runs it
on a case.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
import numpy.typing as npt

from mechbal.balance import common
from mechbal.balance.result import BalanceResult, CounterweightSlot
from mechbal.mechanism import Mechanism

__all__ = ["Front", "FrontPoint", "front", "problem", "knee", "default_motion", "write", "mechanism_toml",
           "json_schema", "CSV_COLUMNS"]

#: the columns of front.csv, in order
CSV_COLUMNS = ("added_mass_kg", "residual", "shaking_force_peak", "shaking_moment_peak", "torque_peak",
               "torque_rms", "design")
#: the methods with a front (linear in the counterweights' mass moments)
FRONT_METHODS = ("static", "force")


@dataclass
class FrontPoint:
    """One design of the front: the budget it was solved for, its added mass [kg], its residual
    (the method's, recomputed from the balanced model), the peak (largest Euclidean norm) and RMS
    shaking force [N] and moment [N m] and the peak and RMS actuator torque [N m or N] along the
    motion, the added inertia (mean trace of the joint-space inertia added over the samples,
    kg m^2), and the `BalanceResult`."""

    budget: float
    added_mass: float
    residual: float
    shaking_force_peak: float
    shaking_force_rms: float
    shaking_moment_peak: float
    shaking_moment_rms: float
    torque_peak: float
    torque_rms: float
    result: BalanceResult
    #: the relative path of the point's balanced.toml once written
    design: str | None = None

    def row(self) -> dict[str, Any]:
        return {"added_mass_kg": self.added_mass, "residual": self.residual,
                "shaking_force_peak": self.shaking_force_peak, "shaking_moment_peak": self.shaking_moment_peak,
                "torque_peak": self.torque_peak, "torque_rms": self.torque_rms, "design": self.design or ""}

    def to_dict(self) -> dict[str, Any]:
        opt = self.result.metrics.get("optimality") or {}
        return {"budget_kg": self.budget, "added_mass_kg": self.added_mass, "residual": self.residual,
                "shaking_force_peak": self.shaking_force_peak, "shaking_force_rms": self.shaking_force_rms,
                "shaking_moment_peak": self.shaking_moment_peak,
                "shaking_moment_rms": self.shaking_moment_rms, "torque_peak": self.torque_peak,
                "torque_rms": self.torque_rms, "design": self.design,
                "masses": {k: float(d.mass) for k, d in self.result.design.items()},
                "duality_gap": opt.get("duality_gap"), "active_bounds": list(self.result.active_bounds)}


@dataclass
class Front:
    """The front of `front`: its points from the least to the most added mass, the method, the
    residual's units, the unbalanced residual, and the knee (`knee`: the point farthest from the
    chord between the ends, in coordinates scaled to the ends)."""

    method: str
    residual_units: str
    residual_before: float
    points: list[FrontPoint] = field(default_factory=list)
    knee: int = 0
    motion: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"method": self.method, "residual_units": self.residual_units,
                "residual_before": self.residual_before, "knee": self.knee, "motion": self.motion,
                "columns": list(CSV_COLUMNS), "points": [p.to_dict() for p in self.points]}


def knee(mass: Sequence[float], residual: Sequence[float]) -> int:
    """The index of the knee: the point farthest below the chord from the first to the last point,
    with mass and residual each scaled to [0, 1] over the front (0 when the front is flat)."""
    m = np.asarray(mass, float)
    r = np.asarray(residual, float)
    if len(m) < 3:
        return 0
    dm, dr = m[-1] - m[0], r[0] - r[-1]
    if dm <= 0 or dr <= 0:
        return 0
    x = (m - m[0]) / dm
    y = (r - r[-1]) / dr
    # the chord from (0, 1) to (1, 0): x + y = 1; below it means x + y < 1
    return int(np.argmax(1.0 - x - y))


def default_motion(mech: Mechanism, duration: float = 2.0, samples: int = 201,
                   lower=None, upper=None):
    """(t, q, v, a) of a smooth motion through the sample box of an open mechanism: each joint a
    sine about the box's middle over 80 % of its half-range, at 1/duration Hz with its own phase."""
    lo, hi = common.sample_box(mech, lower, upper, "independent")
    t = np.linspace(0.0, duration, samples)
    w = 2.0 * math.pi / duration
    phase = np.linspace(0.0, math.pi, mech.dof, endpoint=False)
    mid, half = 0.5 * (lo + hi), 0.4 * (hi - lo)
    s = np.sin(w * t[:, None] + phase)
    c = np.cos(w * t[:, None] + phase)
    return t, mid + half * s, half * w * c, -half * w * w * s


def problem(mechanism: Mechanism, design, method: str = "static", samples=None, **options) -> common.LinearProblem:
    """The method's `mechbal.balance.common.LinearProblem` (static or force)."""
    if method not in FRONT_METHODS:
        raise ValueError(f"method: a front needs a method linear in the counterweights ({', '.join(FRONT_METHODS)}); "
                         f"got {method!r}")
    from mechbal.balance import force, static

    mod = static if method == "static" else force
    if samples is None:
        samples = 1000 if method == "static" else 200
    return mod.problem(mechanism, design, samples, **options)


def front(mechanism: Mechanism, design: Sequence[CounterweightSlot] | CounterweightSlot, points: int = 20, *,
          method: str = "static", samples: int | npt.ArrayLike | None = None, mass_budget: float | None = None,
          seed: int = 0, lower: npt.ArrayLike | None = None, upper: npt.ArrayLike | None = None,
          q_guess: npt.ArrayLike | None = None, motion: tuple | None = None,
          evaluate: Callable[[Mechanism], dict] | None = None) -> Front:
    """``points`` designs from the least added mass to the lightest design of the best residual
    (see the module docstring). ``method``: "static" or "force"; ``samples``, ``seed``,
    ``lower``, ``upper``, ``q_guess``: the method's; ``mass_budget``: the case's cap on the total
    (the front ends there if the best residual needs more). The shaking and torque columns are
    along ``motion`` (q, v, a) arrays of an open mechanism (default: `default_motion`), or
    computed by ``evaluate(balanced) -> {"torque", "shaking_force", "shaking_moment"}`` (a closed
    mechanism needs one of the two: its motions come from the loop solve)."""
    if int(points) != points or points < 2:
        raise ValueError(f"points: must be an integer >= 2 (got {points})")
    prob = problem(mechanism, design, method, samples, seed=seed, lower=lower, upper=upper, q_guess=q_guess)
    if evaluate is None:
        evaluate = _evaluator(mechanism, motion, lower, upper, q_guess)
    lightest = prob.solve(mass_budget=mass_budget, certified=True)
    dsg_min = sum(s.mass_min for s in prob.slots)      # a tied slot takes its group's mass_min
    m_hi = float(sum(x for x in lightest.x[0::4]))
    m_lo = float(dsg_min)
    out = Front(method, "", 0.0, motion="the given motion" if motion is not None or evaluate is not None
                else "default_motion: a sine per joint through the sample box")
    budgets = np.linspace(m_lo, m_hi, int(points))
    for k, B in enumerate(budgets):
        if k == len(budgets) - 1:
            sol = lightest
        else:
            sol = prob.solve(mass_budget=float(B) if mass_budget is None else min(float(B), mass_budget),
                             certified=True)
        res = prob.result(sol)
        ev = evaluate(res.balanced)
        F = np.linalg.norm(np.asarray(ev["shaking_force"], float), axis=-1)
        M = np.linalg.norm(np.asarray(ev["shaking_moment"], float), axis=-1)
        tau = np.asarray(ev["torque"], float)
        out.points.append(FrontPoint(
            budget=float(B), added_mass=float(res.metrics["added_mass"]), residual=float(res.residual),
            shaking_force_peak=float(np.max(F)), shaking_force_rms=float(np.sqrt(np.mean(F ** 2))),
            shaking_moment_peak=float(np.max(M)), shaking_moment_rms=float(np.sqrt(np.mean(M ** 2))),
            torque_peak=float(np.max(np.abs(tau))), torque_rms=float(np.sqrt(np.mean(tau ** 2))), result=res))
        out.residual_units, out.residual_before = res.residual_units, float(res.residual_before)
    out.knee = knee([p.added_mass for p in out.points], [p.residual for p in out.points])
    return out


def _evaluator(mech: Mechanism, motion, lower, upper, q_guess):
    if motion is None:
        if mech.is_closed:
            raise ValueError("motion: a closed mechanism's front needs a motion (q#, v#, a#) of its actuated "
                             "joints, or evaluate=")
        _, q, v, a = default_motion(mech, lower=lower, upper=upper)
    else:
        q, v, a = (np.atleast_2d(np.asarray(x, float)) for x in motion)

    def ev(m: Mechanism) -> dict:
        if m.is_closed:
            cm = m.closed_motion(q, v, a, q_guess=q_guess, with_forces=True)
            qq, vv, aa, tau = cm.q, cm.v, cm.a, cm.actuated_force
        else:
            qq, vv, aa = q, v, a
            tau = m.inverse_dynamics(q, v, a)
        sw = m.shaking_wrench(qq, vv, aa)
        return {"torque": tau, "shaking_force": sw.shaking_force, "shaking_moment": sw.shaking_moment}

    return ev


# ---- files -------------------------------------------------------------------------------------------

def json_schema() -> dict[str, Any]:
    """The JSON Schema of front.json (shipped as mechbal/cases/front.schema.json)."""
    from mechbal.export.bodies import SUMMARY_SCHEMA_VERSION

    num = {"type": "number"}
    opt_num = {"type": ["number", "null"]}
    point = {"type": "object", "additionalProperties": False,
             "required": ["budget_kg", "added_mass_kg", "residual", "design"],
             "properties": {
                 "budget_kg": {**num, "description": "The added-mass budget this point was solved for [kg]."},
                 "added_mass_kg": {**num, "description": "Total counterweight mass of the design [kg]."},
                 "residual": {**num, "description": "The method's residual, recomputed from the balanced model "
                              "(units: residual_units)."},
                 "shaking_force_peak": {**num, "description": "Largest |shaking force| along the motion [N]."},
                 "shaking_force_rms": {**num, "description": "RMS |shaking force| along the motion [N]."},
                 "shaking_moment_peak": {**num, "description": "Largest |shaking moment| along the motion [N m]."},
                 "shaking_moment_rms": {**num, "description": "RMS |shaking moment| along the motion [N m]."},
                 "torque_peak": {**num, "description": "Largest |actuator torque| along the motion [N m or N]."},
                 "torque_rms": {**num, "description": "RMS actuator torque along the motion [N m or N]."},
                 "design": {"type": ["string", "null"], "description": "Relative path of the point's balanced.toml."},
                 "masses": {"type": "object", "additionalProperties": num, "description": "Mass per slot [kg]."},
                 "duality_gap": {**opt_num, "description": "The conic solver's duality gap of the last stage."},
                 "active_bounds": {"type": "array", "items": {"type": "string"}}}}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://mechbal.invalid/front.schema.json",
        "title": "mechbal front.json",
        "description": "The trade-off front of `mechbal balance --front N` (mechbal.balance.fronts): per added-mass "
                       "budget, the design with the least residual.",
        "type": "object", "additionalProperties": False,
        "required": ["schema_version", "command", "method", "residual_units", "points"],
        "properties": {
            "schema_version": {"const": SUMMARY_SCHEMA_VERSION}, "command": {"const": "balance --front"},
            "case": {"type": "string"},
            "method": {"enum": list(FRONT_METHODS)},
            "residual_units": {"type": "string"}, "residual_before": num,
            "knee": {"type": "integer", "description": "Index of the knee point (farthest below the chord)."},
            "motion": {"type": "string", "description": "The motion of the shaking and torque columns."},
            "columns": {"type": "array", "items": {"type": "string"}},
            "points": {"type": "array", "items": point},
        },
    }


def mechanism_toml(result: BalanceResult) -> str:
    """A case file of the balanced mechanism alone (``[case]`` and ``[mechanism]``: readable by
    `mechbal.Mechanism.from_toml`): what `write` writes per point when no case is given."""
    from mechbal.export.toml import mechanism_table, toml_text

    m = result.balanced
    added = ", ".join(f"{k} {d.mass:.6g} kg" for k, d in result.design.items())
    return toml_text({"case": {"name": m.name, "kind": "mechanism"}, "mechanism": mechanism_table(m)},
                     f"A point of a front ({result.method}): {added or 'nothing added'}.\n"
                     f"Residual {result.residual:.6g} {result.residual_units}.")


def write(fr: Front, out: Path, balanced_toml: Callable[[BalanceResult], str] | None = None, *,
          case: str = "", title: str = "") -> list[str]:
    """front.csv, front.json, front.png and front/<k>/balanced.toml into ``out`` (an existing
    folder); the names. ``balanced_toml(result)``: the text of a point's file (default
    `mechanism_toml`)."""
    out = Path(out)
    balanced_toml = balanced_toml or mechanism_toml
    for k, p in enumerate(fr.points):
        d = out / "front" / str(k)
        d.mkdir(parents=True, exist_ok=True)
        (d / "balanced.toml").write_text(balanced_toml(p.result))
        p.design = f"front/{k}/balanced.toml"
    with open(out / "front.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(CSV_COLUMNS))
        w.writeheader()
        for p in fr.points:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in p.row().items()})
    from mechbal.export.bodies import SUMMARY_SCHEMA_VERSION

    data = {"schema_version": SUMMARY_SCHEMA_VERSION, "command": "balance --front",
            **({"case": case} if case else {}), **fr.to_dict()}
    (out / "front.json").write_text(json.dumps(data, indent=1, default=_plain) + "\n")
    _plot(fr, out / "front.png", title)
    return ["front.csv", "front.json", "front.png", "front/"]


def _plain(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(type(x).__name__)


def _plot(fr: Front, path: Path, title: str) -> None:
    from mechbal.report import _pyplot

    plt = _pyplot()

    m = [p.added_mass for p in fr.points]
    r = [p.residual for p in fr.points]
    t = [p.torque_peak for p in fr.points]
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(m, r, "o-", color="C0", label=f"residual [{fr.residual_units.split(' (')[0]}]")
    ax.plot([m[fr.knee]], [r[fr.knee]], "s", ms=12, mfc="none", mec="C3", mew=2, label="knee")
    ax.set_xlabel("added mass [kg]")
    ax.set_ylabel(f"residual [{fr.residual_units.split(' (')[0]}]", color="C0")
    ax2 = ax.twinx()
    ax2.plot(m, t, "^--", color="C1", label="peak actuator torque")
    ax2.set_ylabel("peak actuator torque [N m or N]", color="C1")
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], loc="upper right", fontsize=8)
    import textwrap

    ax.set_title(textwrap.fill(title or f"{fr.method} balance: least residual per added-mass budget", 80),
                 fontsize=9)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
