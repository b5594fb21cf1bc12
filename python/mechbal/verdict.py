"""The verdict of a controlled run: its goal, whether every criterion held, and what limited it.

A run that pursues a goal (cancel momentum components, follow a task, track a command in closed
loop) states the goal and its tolerances (`goal`), measures each criterion and says so
(`Verdict`): ``ok`` is true only if every criterion held, and ``limited_by`` lists each one that
did not, with numbers (the joint, the first tick, how many ticks, the peak demand against the
limit). ``summary.json`` of every controlled run carries ``goal``, ``ok`` and ``limited_by``; the
command line exits with `EXIT_GOAL_NOT_MET` (6) when ``ok`` is false, unless
``--allow-degraded``.

The criteria (each in force when it applies to the run):

* **statuses**: no tick of any controller stage saturated, was out of range, met non-finite
  input or a solver failure, or was damped near a singularity (`mechbal.Status`); every step of a
  closed loop completed;
* **limits**: the commanded (or simulated) motion keeps every declared velocity and effort limit
  (the model's joint limits, the ``[control]`` table's ``max_rate``, ``max_speed``,
  ``torque_limit``); only declared limits are in force (no hidden ones);
* **residual**: each cancelled momentum-rate component's peak (the shaking force / moment about O
  along the controlled motion) is at most ``residual`` times its uncontrolled peak plus ``floor``;
* **tracking**: the task frame's path error within ``position`` [m] and ``orientation`` [rad]
  (operational-space mode), and a closed loop's departure from its command within ``joint``
  [rad or m].

Defaults: `DEFAULT_TOLERANCE`, overridden by ``[control] tolerance = {...}``.

Layer: Python core (docs/architecture.md): numpy only, below `mechbal.control` and
`mechbal.simulate`, which use it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: exit code of a controlled run whose goal was not met (its DIR is written all the same)
EXIT_GOAL_NOT_MET = 6

#: the goal's tolerances when ``[control] tolerance`` does not set them
DEFAULT_TOLERANCE: dict[str, float] = {
    "residual": 1e-6,     # cancelled component's peak / its uncontrolled peak
    "floor": 1e-9,        # absolute floor of a cancelled component's residual [N or N m]
    "position": 1e-6,     # task frame's path error [m]
    "orientation": 1e-6,  # task frame's orientation error [rad]
    "joint": 1e-2,        # closed loop: plant's departure from the command [rad or m]
}

#: status bits (mechbal.Status) that fail a tick, with their names
STATUS_FLAGS: dict[int, str] = {1: "non_finite_input", 2: "singular", 4: "saturated", 8: "bad_size",
                                16: "solver_error", 32: "out_of_range"}

#: the cancel names and the rows of [F; M] they select
_COMPONENTS = {"force_x": 0, "force_y": 1, "force_z": 2, "moment_x": 3, "moment_y": 4, "moment_z": 5}


def cancelled_components(cancel) -> list[str]:
    """The single components (``force_x`` ... ``moment_z``) a ``cancel`` list names."""
    out: list[str] = []
    for c in ([cancel] if isinstance(cancel, str) else list(cancel)):
        names = {"force": ["force_x", "force_y", "force_z"], "moment": ["moment_x", "moment_y", "moment_z"],
                 "both": list(_COMPONENTS)}.get(c, [c])
        out += [n for n in names if n not in out]
    return sorted(out, key=_COMPONENTS.__getitem__)


def tolerance(ctl: Any = None) -> dict[str, float]:
    """`DEFAULT_TOLERANCE` with the ``[control] tolerance`` entries of ``ctl`` (a validated
    ``[control]`` table, a dict of tolerances, or None)."""
    out = dict(DEFAULT_TOLERANCE)
    given = ctl.get("tolerance") if isinstance(ctl, dict) and "tolerance" in ctl else getattr(ctl, "tolerance", ctl)
    if given is None:
        return out
    items = given.items() if isinstance(given, dict) else ((k, getattr(given, k, None)) for k in out)
    for k, v in items:
        if k not in out:
            raise ValueError(f"tolerance.{k}: not a tolerance (one of {', '.join(out)})")
        if v is not None:
            out[k] = float(v)
    return out


def limits_in_force(mech: Any, ctl: Any = None, balancing: list[str] | None = None) -> dict[str, dict[str, float]]:
    """Per actuated joint, the declared limits a controlled run keeps: ``velocity`` [rad/s or m/s]
    (the model's velocity limit; for a balancing joint also ``[control] max_rate``; for every
    joint ``max_speed``), ``effort`` [N m or N] (the model's effort limit and ``[control]
    torque_limit``). Only finite (declared) limits are listed."""
    model = getattr(mech, "model", mech)
    names = list(getattr(mech, "actuated_names", []))
    coords = list(model.actuated_coordinates)
    vel = np.asarray(model.velocity_limits, float)
    eff = np.asarray(model.effort_limits, float)
    get = ctl.get if isinstance(ctl, dict) else (lambda k: getattr(ctl, k, None))
    max_rate, max_speed, torque = get("max_rate"), get("max_speed"), get("torque_limit")
    if balancing is None:  # the operational-space mode moves every joint (balancing_joints optional there)
        balancing = get("balancing_joints") or (names if get("task_frame") is not None else [])
    balancing = list(balancing)
    out: dict[str, dict[str, float]] = {}
    for i, (name, c) in enumerate(zip(names, coords)):
        v = float(vel[c])
        if max_rate is not None and name in balancing:
            v = min(v, float(max_rate))
        if max_speed is not None:
            v = min(v, float(max_speed))
        e = float(eff[c])
        if torque is not None:
            e = min(e, float(torque[i]))
        entry = {k: x for k, x in (("velocity", v), ("effort", e)) if np.isfinite(x)}
        if entry:
            out[name] = entry
    return out


class ControlInfeasible(Exception):
    """A controlled run refused before it ran: the commanded motion needs more than a declared
    limit allows (`mechbal.control.feasibility`); ``report`` is the `mechbal.control.FeasibilityReport`. The
    command line exits with `EXIT_GOAL_NOT_MET` and writes nothing."""

    def __init__(self, report: Any):
        super().__init__(report.line())
        self.report = report


def fitted_duration(min_duration: float, dt: float) -> float:
    """The duration ``--fit-duration`` runs: the shortest feasible duration with a margin of
    1e-3 (time scaling is exact, the integration of the path to 1e-6), rounded up to whole
    ticks of ``dt``."""
    return float(np.ceil(min_duration * (1.0 + 1e-3) / dt - 1e-9) * dt)


@dataclass
class Verdict:
    """Whether a run met its goal: ``ok``, the ``goal`` (what was asked, with its tolerances and
    the limits in force) and ``limited_by`` (one entry per criterion that failed: ``criterion``,
    ``message`` and its numbers)."""

    goal: dict[str, Any]
    limited_by: list[dict[str, Any]] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when no criterion failed."""
        return not self.limited_by

    def summary(self) -> dict[str, Any]:
        """``{"goal", "ok", "limited_by"}`` for summary.json."""
        return {"goal": self.goal, "ok": self.ok, "limited_by": list(self.limited_by)}

    def line(self) -> str:
        """One line: the first reason (and how many more), or "goal met"."""
        if self.ok:
            return "goal met"
        more = len(self.limited_by) - 1
        return self.limited_by[0]["message"] + (f" (and {more} more: summary.json limited_by)" if more else "")

    # ---- the criteria -------------------------------------------------------------------------

    def add(self, criterion: str, message: str, **numbers: Any) -> None:
        """Record a failed ``criterion`` with its one-line ``message`` and its numbers."""
        self.limited_by.append({"criterion": criterion, "message": message, **numbers})

    def statuses(self, status: Any, t: Any, *, who: str = "controller",
                 joints: dict[str, str] | None = None) -> None:
        """One entry per failing flag of the per-tick ``status`` (ticks at times ``t`` [s]):
        the first tick, its time and how many ticks. ``joints``: flag name -> the joint it
        concerns, when known."""
        s = np.asarray(status, np.uint32).reshape(-1)
        t = np.asarray(t, float).reshape(-1)
        for bit, name in STATUS_FLAGS.items():
            hit = (s & np.uint32(bit)) != 0
            if not np.any(hit):
                continue
            k = int(np.argmax(hit))
            entry: dict[str, Any] = {"status": name, "first_tick": k, "first_time": float(t[min(k, len(t) - 1)]),
                                     "ticks": int(np.sum(hit)), "of_ticks": int(len(s))}
            joint = (joints or {}).get(name)
            where = f" ({joint})" if joint else ""
            if joint:
                entry["joint"] = joint
            self.add("status", f"{who}: {entry['ticks']} of {len(s)} ticks {name}{where}, the first at "
                               f"t = {entry['first_time']:.4g} s", **entry)

    def limit(self, series: Any, t: Any, names: list[str], kind: str, limits: dict[str, dict[str, float]],
              *, who: str = "motion", demand: dict[str, float] | None = None) -> None:
        """Each joint whose |``series``| (N, len(names)) exceeds its declared ``kind`` limit
        (``velocity`` or ``effort``), or reaches it within 1e-9 (a clipped command): first tick,
        tick count, peak (``demand``: the unclipped peak when known) against the limit."""
        x = np.abs(np.asarray(series, float).reshape(len(np.atleast_1d(t)), -1))
        t = np.asarray(t, float).reshape(-1)
        unit = "rad/s or m/s" if kind == "velocity" else "N m or N"
        for j, name in enumerate(names):
            lim = limits.get(name, {}).get(kind)
            if lim is None:
                continue
            hit = x[:, j] >= lim * (1.0 - 1e-9)
            if not np.any(hit):
                continue
            k = int(np.argmax(hit))
            peak = float((demand or {}).get(name, np.max(x[:, j])))
            self.add("limit", f"{name}: {kind} {peak:.4g} against its limit {lim:.4g} {unit} on {int(np.sum(hit))} "
                              f"ticks of the {who}, the first at t = {t[k]:.4g} s",
                     joint=name, limit_kind=kind, peak_demand=peak, limit=float(lim), first_tick=k,
                     first_time=float(t[k]), ticks=int(np.sum(hit)))

    def residual(self, controlled: Any, uncontrolled: Any, components: list[str], tol: dict[str, float],
                 *, what: str = "controlled motion") -> dict[str, dict[str, float]]:
        """Each cancelled component's peak along ``controlled`` [F M] (N, 6) against
        ``tol["residual"]`` times its peak along ``uncontrolled`` plus ``tol["floor"]``; returns
        the per-component figures (``reduction_pct`` included) for summary.json."""
        c = np.abs(np.asarray(controlled, float))
        u = np.abs(np.asarray(uncontrolled, float))
        out = {}
        for comp in components:
            row = _COMPONENTS[comp]
            pc, pu = float(np.max(c[:, row])), float(np.max(u[:, row]))
            allowed = tol["residual"] * pu + tol["floor"]
            out[comp] = {"uncontrolled_peak": pu, "controlled_peak": pc,
                         "fraction": pc / pu if pu > 0 else None,
                         "reduction_pct": 100.0 * (1.0 - pc / pu) if pu > 0 else None, "allowed": allowed}
            if not pc <= allowed:
                self.add("residual", f"{comp}: the {what} leaves {pc:.4g} of the uncontrolled {pu:.4g} "
                                     f"(allowed {allowed:.3g}: tolerance.residual {tol['residual']:g} of the "
                                     f"uncontrolled peak + floor {tol['floor']:g})",
                         component=comp, controlled_peak=pc, uncontrolled_peak=pu, allowed=allowed)
        return out

    def tracking(self, error: Any, t: Any, tol: float, *, what: str, unit: str, key: str) -> float:
        """The largest ``error`` (N,) against ``tol``; returns it."""
        e = np.asarray(error, float).reshape(-1)
        peak = float(np.max(e)) if e.size else 0.0
        if not np.all(np.isfinite(e)) or peak > tol:
            bad = ~(e <= tol)
            k = int(np.argmax(bad))
            self.add("tracking", f"{what}: error {peak:.4g} {unit} against the tolerance {tol:g} (tolerance.{key}), "
                                 f"beyond it on {int(np.sum(bad))} ticks from t = {float(np.asarray(t)[k]):.4g} s",
                     tracking=key, peak_error=peak, tolerance=tol, first_tick=k, ticks=int(np.sum(bad)))
        return peak

    def steps(self, completed: int, total: int, t: Any) -> None:
        """A closed loop that stopped before its last step (``completed`` of ``total``)."""
        if completed < total:
            tt = np.asarray(t, float).reshape(-1)
            self.add("steps", f"the simulation stopped at t = {tt[min(completed, len(tt) - 1)]:.4g} s "
                              f"({completed} of {total} steps)", steps_completed=int(completed), steps=int(total))


def goal(*, kind: str, tol: dict[str, float], limits: dict[str, dict[str, float]],
         cancel: list[str] | None = None, tracking: dict[str, str] | None = None,
         closed_loop: bool = False) -> dict[str, Any]:
    """The ``goal`` of summary.json: the controller ``kind``, the cancelled ``components`` with
    their tolerance, the ``tracking`` criteria (name -> what), the ``limits`` in force and the
    ``tolerance`` table in force."""
    out: dict[str, Any] = {"kind": kind, "statuses": "every tick ok: none saturated, out of range, singular, "
                                                     "non-finite or failed" + (", every step completed" if closed_loop else "")}
    if cancel:
        comps = cancelled_components(cancel)
        out["cancelled"] = {"components": comps, "residual": tol["residual"], "floor": tol["floor"],
                            "meaning": "each component's peak <= residual x its uncontrolled peak + floor"}
    if tracking:
        out["tracking"] = {k: {"tolerance": tol[k], "meaning": v} for k, v in tracking.items()}
    out["limits"] = limits or {}
    out["limits_meaning"] = ("declared limits only (the model's joint limits, [control] max_rate, max_speed, "
                             "torque_limit): velocity [rad/s or m/s], effort [N m or N]; undeclared: no limit")
    out["tolerance"] = dict(tol)
    return out


def moment_reduction(uncontrolled: Any, controlled: Any, cancel: list[str] | None = None,
                     labels: tuple[str, str] = ("uncontrolled", "controlled")) -> dict[str, Any]:
    """``shaking_moment_reduction`` of summary.json: per axis (x, y, z) the peak |M_i| of both
    motions, their ratio and the reduction [%] (``cancelled``: whether the controller cancels
    that axis), and the whole-moment figure, labelled as such (peak |M| over all three axes,
    cancelled or not)."""
    Mu, Mc = np.asarray(uncontrolled, float), np.asarray(controlled, float)
    comps = cancelled_components(cancel or [])
    out: dict[str, Any] = {"per_axis": {}}
    for i, axis in enumerate("xyz"):
        pu, pc = float(np.max(np.abs(Mu[:, i]))), float(np.max(np.abs(Mc[:, i])))
        out["per_axis"][axis] = {f"peak_{labels[0]}": pu, f"peak_{labels[1]}": pc,
                                 "ratio": pc / pu if pu > 0 else None,
                                 "reduction_pct": 100.0 * (1.0 - pc / pu) if pu > 0 else None,
                                 "cancelled": f"moment_{axis}" in comps}
    nu, nc = float(np.max(np.linalg.norm(Mu, axis=1))), float(np.max(np.linalg.norm(Mc, axis=1)))
    out["whole_moment"] = {f"peak_norm_{labels[0]}": nu, f"peak_norm_{labels[1]}": nc,
                           "ratio": nc / nu if nu > 0 else None,
                           "reduction_pct": 100.0 * (1.0 - nc / nu) if nu > 0 else None,
                           "meaning": "peak |M| over all three axes, cancelled or not"}
    return out


def goal_rows(v: Verdict, extra: list[list[Any]] | None = None) -> list[list[Any]]:
    """Rows (criterion, value) of the printed verdict table: the goal, the statuses, each
    failing criterion."""
    g = v.goal
    rows: list[list[Any]] = []
    if "cancelled" in g:
        c = g["cancelled"]
        rows.append(["goal: cancel", f"{', '.join(c['components'])} to {c['residual']:g} of the uncontrolled "
                                     f"peak + {c['floor']:g}"])
    for k, x in (g.get("tracking") or {}).items():
        rows.append([f"goal: {k} tracking", f"<= {x['tolerance']:g} ({x['meaning']})"])
    lim = g.get("limits") or {}
    rows.append(["limits in force", "; ".join(f"{j}: " + ", ".join(f"{k} {x:g}" for k, x in d.items())
                                              for j, d in lim.items()) or "none declared"])
    rows += extra or []
    rows.append(["verdict", "goal met" if v.ok else "NOT MET: " + v.line()])
    return rows


__all__ = ["ControlInfeasible", "fitted_duration", "DEFAULT_TOLERANCE", "EXIT_GOAL_NOT_MET", "STATUS_FLAGS", "Verdict", "cancelled_components", "goal", "goal_rows", "moment_reduction",
           "limits_in_force", "tolerance"]
