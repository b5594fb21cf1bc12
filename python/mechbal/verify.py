"""``mechbal verify CASE --out DIR``: a case's predictions checked in MuJoCo, unbalanced and balanced.

For the case's mechanism and its balanced variant (the case's ``[balance]`` method, or its default
design), along the case's trajectory:

* **prescribed motion**: MuJoCo's inverse dynamics of the MJCF export on mechbal's (q, v, a)
  (`mechbal.export.mujoco_engine.MujocoMechanism.inverse_dynamics`): the shaking force
  dP/dt and moment dH_O/dt (MuJoCo's base reaction on the moving bodies plus their weight), the
  actuator forces and the gravity (static) torque, projected on the actuated joints with mechbal's
  coupling matrix for a closed mechanism; the largest difference to mechbal's, relative to the
  unbalanced variant's scale (its peak; at least the moving weight m|g| for the force, m|g| times
  the reach for the moment, the actuator forces' peak for the gravity torque), so that a zero
  prediction is judged against what balancing removed.
* **simulated**: a 1 kHz computed-torque loop (mechbal's controller over mechbal's model, gains
  Kp = 400 / s^2, Kd = 40 / s) against MuJoCo integrating the export
  (`mechbal.export.mujoco_engine.co_simulate`): the peak shaking force and moment MuJoCo
  realises, and the largest loop-closure violation of its soft constraints.

DIR receives ``summary.json``, ``shaking_wrench.png`` (mechbal and MuJoCo, simulated) and the
MJCF files ``unbalanced.xml``, ``balanced.xml``; the table is printed. Needs ``mechbal[mujoco]``.

A case with a reactionless ``[control]`` table (the reaction-wheel arm and PAMINSA through the
general controller in the joint mode, the Panda in the operational-space mode:
`run_verify_reactionless`) is checked under its controller instead: uncontrolled and controlled
(`VARIANTS`), mechbal's predicted shaking wrench, actuator forces and gravity torque against
MuJoCo's by inverse dynamics on the same motion, and the controller ticked at 1 kHz against
MuJoCo (`cosimulate_reactionless`), with the residual's dependence on the tick measured.
``mechbal run CASE --engine mujoco`` of such a case (`run_cosimulation_reactionless`) writes
what ``mechbal run`` writes for it, of the motion MuJoCo realised.

Layer: methods (docs/architecture.md): uses the balance methods and the MuJoCo engine.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mechbal import progress, report
from mechbal.export import write_summary

#: computed-torque gains of the simulated check [1/s^2], [1/s]
KP, KD = 400.0, 40.0


def case_trajectory(bc, n: int):
    """The case's trajectory as a `mechbal.trajectory` object: its ``[trajectory]`` law, or
    the case's sampled motion (a paper's own law) through a cubic spline."""
    from mechbal.config import trajectory_from_config
    from mechbal.errors import ConfigError
    from mechbal.trajectory import Sampled

    table = {k: v for k, v in bc.trajectory_table.items() if k != "initial_guess"}
    try:
        return trajectory_from_config(table, n)[0]
    except (ConfigError, ValueError, KeyError, TypeError):
        return Sampled(bc.t, bc.motion[0], bc_type="not-a-knot")


def _peak(x) -> float:
    return float(np.max(np.abs(np.asarray(x)))) if np.size(x) else 0.0


def check_variant(bc, mech, *, simulate: bool = True, reference: dict | None = None, controller=None,
                  dt: float = 1e-3) -> dict:
    """The checks of one variant (module docstring) as a dict of plain values and arrays;
    ``controller``: ``mech -> joint controller`` of the simulated check (default: computed torque,
    `KP`, `KD`), ticked every ``dt`` [s]."""
    from mechbal.balance.run import evaluate
    from mechbal.control import ComputedTorque
    from mechbal.export.mujoco_engine import MujocoMechanism, co_simulate

    ev = evaluate(bc, mech)
    q, v, a = ev["q"], ev["v"], ev["a"]
    sim = MujocoMechanism(mech, q=q[0], q_guess=bc.q_guess)
    closed = mech.is_closed
    if closed:
        qa, va, aa = bc.motion
        P = np.asarray(mech.closed_motion(qa, va, aa, q_guess=bc.q_guess).projection)
    g = np.asarray(mech.gravity, float)
    mj, m, d = sim.mj, sim.model, sim.data
    N = len(q)
    F, M = np.zeros((N, 3)), np.zeros((N, 3))
    tau, G = np.zeros_like(np.asarray(ev["torque"])), np.zeros_like(np.asarray(ev["gravity_torque"]))
    for k in range(N):
        inv = sim.inverse_dynamics(q[k], v[k], a[k])
        mass = sum(m.body_mass[b] for b in sim.moving_bodies)
        mc = sum((m.body_mass[b] * d.xipos[b] for b in sim.moving_bodies), np.zeros(3))
        F[k] = inv.base_reaction_force + mass * g
        M[k] = inv.base_reaction_moment + np.cross(mc, g)
        Gk = sim.static_torque(q[k])
        tau[k] = P[k].T @ inv.joint_torque if closed else inv.joint_torque
        G[k] = P[k].T @ Gk if closed else Gk
    from mechbal.export.mjcf import mjcf_text

    # the file written is the export as `mechbal export` writes it (a closed mechanism's with the
    # minimum bodies that make its loops hold); the inverse dynamics above are of `mech` itself
    out: dict = {"q0": q[0], "mechanism": repr(mech), "mujoco": repr(sim), "light_bodies": sim.light_bodies,
                 "minimum_bodies": sim.names.minimum, "xml": mjcf_text(mech, q=q[0], q_guess=bc.q_guess), "t": bc.t,
                 "mechbal": {"shaking_force": ev["shaking_force"], "shaking_moment": ev["shaking_moment"],
                             "actuator_force": ev["torque"], "gravity_torque": ev["gravity_torque"]},
                 "mujoco_inverse": {"shaking_force": F, "shaking_moment": M, "actuator_force": tau,
                                    "gravity_torque": G}}
    if simulate:
        n = len(mech.actuated_names) if closed else mech.dof
        traj = case_trajectory(bc, n)
        ctrl = controller(mech) if controller is not None else ComputedTorque(mech, [KP] * n, [KD] * n,
                                                                               q_guess=bc.q_guess)
        cs = co_simulate(mech, ctrl, traj, q_guess=bc.q_guess, dt=dt)
        out["mujoco_simulated"] = {"t": cs.t, "status": cs.status, "v": cs.v, "shaking_force": cs.shaking_force,
                                   "shaking_moment": cs.shaking_moment,
                                   "predicted_shaking_force": cs.predicted_shaking_force,
                                   "predicted_shaking_moment": cs.predicted_shaking_moment,
                                   "constraint_violation": cs.constraint_violation,
                                   "tracking_error": cs.tracking_error, "ok": bool(np.all(cs.status == 0)),
                                   "steps_completed": cs.steps_completed, "options": cs.options}
    return out


def _scale(mech, res: dict) -> dict:
    """What a difference is relative to, from the unbalanced variant: the larger of the peaks
    and, for the shaking force, the moving weight m |g|; for the moment, m |g| times the largest
    distance of a body's centre of mass from O; for the gravity torque, the actuator forces' peak
    (a statically balanced mechanism's gravity torque is zero)."""
    from mechbal.export.mujoco_engine import _still_bodies

    still = _still_bodies(mech)
    m = sum(float(b.mass) for b in mech.bodies if b.name not in still)
    w = m * float(np.linalg.norm(mech.gravity))
    reach = max([float(np.linalg.norm(np.asarray(b.com, float))) for b in mech.bodies] + [0.0])
    motion = mech.body_motion(res["q0"]) if "q0" in res else None
    if motion is not None:
        reach = max(reach, float(np.max(np.linalg.norm(np.asarray(motion.com), axis=-1))))
    peak = {k: max(_peak(res["mechbal"][k]), _peak(res["mujoco_inverse"][k])) for k in res["mechbal"]}
    return {"shaking_force": max(peak["shaking_force"], w), "shaking_moment": max(peak["shaking_moment"], w * reach),
            "gravity_torque": max(peak["gravity_torque"], peak["actuator_force"]),
            "actuator_force": peak["actuator_force"]}


def _rows(label: str, res: dict, scale: dict, unbalanced: dict) -> tuple[list, dict]:
    rows, summary = [], {}
    for key, unit in (("shaking_force", "N"), ("shaking_moment", "N m"), ("gravity_torque", "N m or N"),
                      ("actuator_force", "N m or N")):
        mb, mi = res["mechbal"][key], res["mujoco_inverse"][key]
        ref = max(_peak(mb), _peak(mi), scale.get(key, 0.0), 1e-300)
        entry = {"unit": unit, "mechbal_peak": _peak(mb), "mujoco_inverse_peak": _peak(mi),
                 "max_difference": _peak(np.asarray(mb) - np.asarray(mi)),
                 "relative_difference": _peak(np.asarray(mb) - np.asarray(mi)) / ref}
        sim = res.get("mujoco_simulated")
        if sim is not None and res.get("simulation_failed"):
            sim = None   # a failed closed loop is judged (the verdict), not read as a realised wrench
        if sim is not None and key in ("shaking_force", "shaking_moment"):
            entry["mujoco_simulated_peak"] = _peak(sim[key])
            entry["simulated_minus_predicted"] = _peak(sim[key] - sim[f"predicted_{key}"])
            entry["simulated_peak_fraction_of_unbalanced"] = _peak(sim[key]) / max(unbalanced.get(key, 0.0) or _peak(mb), 1e-300)
        summary[key] = entry
        rows.append([label, key, unit, entry["mechbal_peak"], entry["mujoco_inverse_peak"],
                     entry["relative_difference"], entry.get("mujoco_simulated_peak", float("nan"))])
    return rows, summary


def run_verify(case: str, out: Path, *, simulate: bool = True, method: str | None = None,
               fit_duration: bool = False, allow_degraded: bool = False, view: bool = False) -> dict:
    """The whole check into ``out`` (module docstring); ``method``: the balancing method of the
    balanced variant (default: the case's ``balance.method``, or its default design's); returns
    the summary. ``view``: also ``out/view.html`` (`mechbal.view`), the variants side by side on
    the case's trajectory."""
    from mechbal.balance.run import balance_case, run_method

    out = Path(out)
    if reactionless_control(case) is not None:
        return run_verify_reactionless(case, out, simulate=simulate, fit_duration=fit_duration,
                                       allow_degraded=allow_degraded, view=view)
    progress.stage("reading the case")
    bc = balance_case(case)
    jc = joint_control(case)
    controller = None
    if jc is not None:   # the case's own controller drives the simulated check, and is judged
        from mechbal.control import joint_controller

        def controller(mech):
            return joint_controller(mech, jc.control, q_guess=bc.q_guess)
    variants = {"unbalanced": bc.mechanism}
    if method is None and bc.table is not None and getattr(bc.table, "method", None):
        method = bc.table.method
    if method is None and bc.default_design:
        method = next(iter(bc.default_design))
    notes = {}
    if method is not None:
        progress.stage(f"balancing ({method})")
        try:
            variants["balanced"] = run_method(bc, method).balanced
        except (ValueError, RuntimeError) as exc:
            notes["balanced"] = f"not balanced by {method}: {exc}"
    results, summary_variants, rows, scale, peaks, judged = {}, {}, [], {}, {}, {}
    for label, mech in variants.items():
        progress.stage(f"MuJoCo: {label}")
        res = check_variant(bc, mech, simulate=simulate, controller=controller,
                            dt=1.0 / jc.control.rate_hz if jc is not None else 1e-3)
        if jc is not None and simulate:
            judged[label] = judge_cosimulation(mech, res["mujoco_simulated"], jc.control,
                                               who=f"{label}: closed loop in MuJoCo")
            res["simulation_failed"] = not judged[label].ok
        (out / f"{label}.xml").parent.mkdir(parents=True, exist_ok=True)
        (out / f"{label}.xml").write_text(res["xml"])
        if label == "unbalanced":
            scale = _scale(mech, res)
        r, s = _rows(label, res, scale, peaks)
        if label == "unbalanced":
            peaks = {k: s[k]["mechbal_peak"] for k in s}
        rows += r
        sim = res.get("mujoco_simulated")
        summary_variants[label] = {"mechanism": res["mechanism"], "mujoco": res["mujoco"],
                                   "minimum_bodies": res["minimum_bodies"], "light_bodies": res["light_bodies"],
                                   **s}
        if sim is not None:
            summary_variants[label]["simulation"] = {
                "ok": sim["ok"], "steps_completed": sim["steps_completed"],
                "max_constraint_violation": _peak(sim["constraint_violation"]),
                "max_tracking_error": _peak(sim["tracking_error"])}
        results[label] = res
    if simulate:
        curves = {}
        for label, res in results.items():
            sim = res["mujoco_simulated"]
            curves[f"{label}, mechbal"] = (sim["predicted_shaking_force"], sim["predicted_shaking_moment"])
            curves[f"{label}, MuJoCo"] = (sim["shaking_force"], sim["shaking_moment"])
        report.plot_wrench(out / "shaking_wrench.png", results["unbalanced"]["mujoco_simulated"]["t"], curves,
                           title=f"{bc.title}: mechbal and MuJoCo",
                           caption="Shaking force and moment about O: mechbal's prediction along the desired "
                                   f"motion and MuJoCo's realised one (1 kHz computed torque, Kp {KP:g}, Kd {KD:g}).")
    summary = {"case": bc.name, "method": method, "variants": summary_variants,
               "checks": ("prescribed motion: MuJoCo inverse dynamics (constraints off) on mechbal's q, v, a; "
                          "relative_difference = max |mechbal - MuJoCo| / the unbalanced variant's scale (its "
                          "peak, at least the moving weight for the force, the weight times the reach for "
                          "the moment, the actuator forces' peak for the gravity torque); simulated: 1 kHz computed torque in MuJoCo"),
               "files": ["summary.json", "unbalanced.xml"] + (["balanced.xml"] if "balanced" in variants else [])
               + (["shaking_wrench.png"] if simulate else [])}
    if simulate:   # MuJoCo's integrator and time step of the simulated check
        summary["mujoco_options"] = results["unbalanced"]["mujoco_simulated"]["options"]
    if notes:
        summary["notes"] = notes
    if view:
        from mechbal.view import motion_variants, write_html

        write_html(out / "view.html", motion_variants(bc, variants), title=f"mechbal verify: {bc.name}")
        summary["files"].append("view.html")
    v = None
    if judged:   # the verdict of the simulations that ran: each variant's closed loop
        from mechbal import verdict as vd

        first = next(iter(judged.values()))
        v = vd.Verdict(first.goal)
        for label, j in judged.items():
            summary_variants[label]["simulation"]["ok"] = j.ok
            for x in j.limited_by:
                v.limited_by.append({**x, "variant": label})
        summary.update(v.summary())
        summary["controller"] = f"{jc.control.kind} ([control] of the case)"
    write_summary(out / "summary.json", summary, command="verify")
    print(report.table(rows, ["variant", "quantity", "unit", "mechbal peak", "MuJoCo peak (inverse)",
                              "relative difference", "MuJoCo peak (simulated)"]))
    if v is not None:
        print(report.table(vd.goal_rows(v, [[f"{label}: closed loop", "ok" if j.ok else "failed: " + j.line()]
                                            for label, j in judged.items()]),
                           [f"{jc.control.kind} in MuJoCo (verdict)", "value"]))
    return summary


def joint_control(case) -> "object | None":
    """The validated case of a case file whose ``[control]`` table asks for a joint controller
    (``computed_torque`` or ``decoupled``), else None (URDF files, cases without one, other kinds)."""
    from mechbal.config import read_case
    from mechbal.errors import ConfigError

    if str(case).lower().endswith(".urdf"):
        return None
    try:
        raw = read_case(case)
    except ConfigError:
        return None
    table = raw.get("control") if isinstance(raw, dict) else None
    if not isinstance(table, dict) or table.get("kind") not in ("computed_torque", "decoupled"):
        return None
    from mechbal.schema import validate_case

    return validate_case(raw, warn=False)


def judge_cosimulation(mech, cs, ctl=None, *, who: str = "closed loop in MuJoCo"):
    """The `mechbal.verdict.Verdict` of a joint controller's co-simulation ``cs`` (a
    `mechbal.export.mujoco_engine.CoSimulation` or the dict `check_variant` keeps): every tick ok,
    every step completed, MuJoCo's motion within ``tolerance.joint`` of the command, the declared
    velocity limits kept (``ctl``: the case's ``[control]``, or None: the defaults)."""
    from mechbal import verdict as vd

    get = cs.get if isinstance(cs, dict) else (lambda k: getattr(cs, k))
    t = np.asarray(get("t"), float)
    tol = vd.tolerance(ctl)
    limits = vd.limits_in_force(mech, ctl)
    kind = getattr(ctl, "kind", None) or "computed_torque"
    judged = vd.Verdict(vd.goal(kind=kind, tol=tol, limits=limits, closed_loop=True,
                                tracking={"joint": "largest |q_des - q| of MuJoCo's motion [rad or m]"}))
    judged.statuses(get("status"), t, who=who)
    judged.steps(int(get("steps_completed")), len(t) - 1, t)
    judged.tracking(np.max(np.abs(np.asarray(get("tracking_error"))), axis=1), t, tol["joint"], what=who,
                    unit="rad or m", key="joint")
    judged.limit(get("v"), t, list(mech.actuated_names), "velocity", limits, who=who)
    return judged


def run_cosimulation(case: str, out: Path, *, dt: float = 1e-3, duration: float | None = None,
                     fit_duration: bool = False, allow_degraded: bool = False) -> dict:
    """``mechbal run CASE --engine mujoco``: the case's mechanism driven along its trajectory by
    mechbal's computed-torque controller (Kp 400 / s^2, Kd 40 / s) ticked every ``dt`` against
    MuJoCo integrating its MJCF export. DIR receives ``summary.json``, ``base_reaction.png`` (MuJoCo's
    base reaction beside mechbal's prediction along the desired motion), ``tracking.png``,
    ``cosimulation.npz`` (every series) and ``mechanism.xml``; ``duration``: a horizon shorter
    than the trajectory [s]. A case with a reactionless ``[control]`` ticks its reactionless
    controller instead, both variants (`run_cosimulation_reactionless`)."""
    from mechbal.balance.run import balance_case
    from mechbal.control import ComputedTorque
    from mechbal.export.mujoco_engine import co_simulate

    out = Path(out)
    if reactionless_control(case) is not None:   # the case's own controller, not computed torque
        return run_cosimulation_reactionless(case, out, dt=dt, duration=duration, fit_duration=fit_duration,
                                             allow_degraded=allow_degraded)
    progress.stage("reading the case")
    bc = balance_case(case)
    mech = bc.mechanism
    n = len(mech.actuated_names) if mech.is_closed else mech.dof
    traj = case_trajectory(bc, n)
    jc = joint_control(case)
    ctl = jc.control if jc is not None else None
    progress.stage(f"co-simulation (MuJoCo, {ctl.rate_hz if ctl is not None else 1 / dt:g} Hz)")
    if ctl is not None:   # the case's own joint controller, at its own tick
        from mechbal.control import joint_controller

        dt = 1.0 / ctl.rate_hz
        ctrl = joint_controller(mech, ctl, q_guess=bc.q_guess)
        described = f"{ctl.kind}, Kp {list(ctl.kp)} 1/s^2, Kd {list(ctl.kd)} 1/s ([control] of the case)"
    else:
        ctrl = ComputedTorque(mech, [KP] * n, [KD] * n, q_guess=bc.q_guess)
        described = f"computed torque, Kp {KP:g} 1/s^2, Kd {KD:g} 1/s (mechbal's model)"
    cs = co_simulate(mech, ctrl, traj, q_guess=bc.q_guess, dt=dt, duration=duration)
    from mechbal.export.mjcf import mjcf_text

    out.mkdir(parents=True, exist_ok=True)
    q0 = (np.asarray(mech.closed_motion(bc.motion[0][0], q_guess=bc.q_guess).q) if mech.is_closed
          else np.asarray(bc.motion[0][0], float))
    (out / "mechanism.xml").write_text(mjcf_text(mech, q=q0, q_guess=bc.q_guess))
    np.savez_compressed(out / "cosimulation.npz", t=cs.t, q=cs.q, qd=cs.v, q_des=cs.q_des, qd_des=cs.v_des,
                        joint_torque=cs.joint_torque, status=cs.status,
                        base_reaction_force=cs.base_reaction_force, base_reaction_moment=cs.base_reaction_moment,
                        predicted_base_reaction_force=cs.predicted_base_reaction_force,
                        predicted_base_reaction_moment=cs.predicted_base_reaction_moment,
                        constraint_violation=cs.constraint_violation)
    report.plot_wrench(out / "base_reaction.png", cs.t,
                       {"mechbal (prediction)": (cs.predicted_base_reaction_force, cs.predicted_base_reaction_moment),
                        "MuJoCo (simulated)": (cs.base_reaction_force, cs.base_reaction_moment)},
                       title=f"{bc.title}: base reaction, mechbal and MuJoCo", force="base reaction force",
                       moment="base reaction moment",
                       caption="Wrench the base exerts on the moving mechanism, gravity included, moment about O: "
                               "mechbal's prediction along the desired motion and MuJoCo's along its simulated one "
                               f"(computed torque at {1 / dt:g} Hz).")
    names = mech.actuated_names if mech.is_closed else mech.joint_names
    report.plot_series(out / "tracking.png", cs.t, {"q_des - q": cs.tracking_error}, names, "tracking error [rad or m]",
                       title=f"{bc.title}: tracking in MuJoCo")
    diff_F = _peak(cs.base_reaction_force - cs.predicted_base_reaction_force)
    diff_M = _peak(cs.base_reaction_moment - cs.predicted_base_reaction_moment)
    from mechbal import verdict as vd

    judged = judge_cosimulation(mech, cs, ctl)
    summary = {"case": bc.name, "engine": "mujoco", "mechanism": repr(mech), "dt": dt, "mujoco_options": cs.options,
               "controller": described,
               **judged.summary(), "steps_completed": cs.steps_completed,
               "peak_tracking_error": _peak(cs.tracking_error),
               "max_constraint_violation": _peak(cs.constraint_violation),
               "base_reaction": {
                   "definition": "wrench the base exerts on the moving mechanism, gravity included, moment about O",
                   "peak_force_mujoco": _peak(cs.base_reaction_force),
                   "peak_force_mechbal": _peak(cs.predicted_base_reaction_force),
                   "max_force_difference": diff_F,
                   "peak_moment_mujoco": _peak(cs.base_reaction_moment),
                   "peak_moment_mechbal": _peak(cs.predicted_base_reaction_moment),
                   "max_moment_difference": diff_M},
               "shaking_wrench": {"peak_force_mujoco": _peak(cs.shaking_force),
                                  "peak_force_mechbal": _peak(cs.predicted_shaking_force),
                                  "peak_moment_mujoco": _peak(cs.shaking_moment),
                                  "peak_moment_mechbal": _peak(cs.predicted_shaking_moment)},
               "files": ["summary.json", "base_reaction.png", "tracking.png", "cosimulation.npz", "mechanism.xml"]}
    write_summary(out / "summary.json", summary)
    print(report.table([["force [N]", summary["base_reaction"]["peak_force_mechbal"],
                         summary["base_reaction"]["peak_force_mujoco"], diff_F],
                        ["moment [N m]", summary["base_reaction"]["peak_moment_mechbal"],
                         summary["base_reaction"]["peak_moment_mujoco"], diff_M]],
                       ["base reaction", "mechbal peak", "MuJoCo peak", "max difference"]))
    saturated = int(np.sum((np.asarray(cs.status) & np.uint32(4)) != 0))
    print(report.table(vd.goal_rows(judged, [["saturated ticks", f"{saturated} of {len(cs.t)}"],
                                             ["tracking error [rad or m]", f"{_peak(cs.tracking_error):.3g}"]]),
                       [f"{ctl.kind if ctl is not None else 'computed torque'} in MuJoCo (verdict)", "value"]))
    return summary


# ---- reactionless cases ------------------------------------------------------------------------

def reactionless_control(case) -> "object | None":
    """The validated ``[control]`` table of a case file or built-in case when it asks for the
    reactionless controller, else None (URDF files, cases without one, other kinds)."""
    from mechbal.case.load import load_case
    from mechbal.errors import ConfigError

    if str(case).lower().endswith(".urdf"):
        return None
    try:
        raw = load_case(case, validate=False).raw
    except ConfigError:
        return None
    table = raw.get("control") if isinstance(raw, dict) else None
    if not isinstance(table, dict) or table.get("kind") != "reactionless":
        return None
    from mechbal.schema import validate_case

    return validate_case(raw, warn=False)


@dataclass
class ReactionlessPlan:
    """A case with a reactionless ``[control]`` ready to run at tick ``dt`` [s] up to ``horizon``
    [s] (``t``: the ticks, ``th``: the half-step grid): the mechanism, the validated ``[control]``
    (``ctl``) and ``[trajectory]`` tables, the assembly guess ``q_guess`` and, by ``mode``:

    * ``"joint"`` (balancing joints): ``traj``, the trajectory of every actuated joint with the
      balancing joints held (`mechbal.case.control_plan.held_trajectory`), ``balancing`` and
      ``task`` (indices among the actuated joints);
    * ``"task"`` (operational space, ``task_frame``): ``start`` (every joint) and the frame's
      desired ``twist`` and ``twist_rate`` on ``th`` (`mechbal.case.motion.frame_path`).
    """

    name: str
    title: str
    kind: str
    mech: Any
    ctl: Any
    trajectory: Any
    q_guess: Any
    dt: float
    horizon: float
    t: np.ndarray
    th: np.ndarray
    mode: str
    traj: Any = None
    balancing: list = field(default_factory=list)
    task: list = field(default_factory=list)
    start: Any = None
    twist: Any = None
    twist_rate: Any = None

    @property
    def n(self) -> int:
        return len(self.mech.actuated_names)


def reactionless_plan(case, *, dt: float = 1e-3, duration: float | None = None, validated: Any = None) -> ReactionlessPlan:
    """The `ReactionlessPlan` of a case file or built-in case with a reactionless ``[control]``
    at tick ``dt`` [s] over ``duration`` [s] (default: the whole trajectory; a shorter horizon
    runs its beginning; ``validated``: the validated case, when already read, e.g. with a fitted
    duration). ConfigError naming the field for a case the controller cannot drive."""
    from mechbal.case.control_plan import check_task_space, held_trajectory
    from mechbal.case.motion import frame_path, start_assembly
    from mechbal.config import ConfigError
    from mechbal.mechanism import Mechanism

    cfg = validated if validated is not None else reactionless_control(case)
    if cfg is None:
        raise ConfigError("control.kind", "the case has no reactionless [control] table", has_value=False)
    ctl, tr = cfg.control, cfg.trajectory
    mech = Mechanism.from_spec(cfg.spec, name=cfg.case.name)
    total = float(tr.duration)
    horizon = total if duration is None else min(float(duration), total)
    if not (np.isfinite(dt) and dt > 0 and horizon >= dt):
        raise ValueError(f"dt must be > 0 and the horizon >= dt, got dt={dt}, duration={duration}")
    from mechbal.tables import check_run_ticks

    check_run_ticks(horizon, 1.0 / dt, "dt")  # bounded work before the run
    steps = int(round(horizon / dt))
    th = np.arange(2 * steps + 1) * (0.5 * dt)
    common = dict(name=cfg.case.name, title=cfg.case.title or cfg.case.name, kind=cfg.case.kind, mech=mech,
                  ctl=ctl, trajectory=tr, dt=float(dt), horizon=horizon, t=th[::2], th=th)
    if ctl.task_frame is not None:
        check_task_space(mech, cfg)
        from mechbal.case import task_end_pose

        _, _, twist, rate = frame_path(mech, ctl.task_frame, tr.start, tr.end, total, tr.law, th,
                                       end_pose=task_end_pose(mech, ctl.task_frame, tr))
        return ReactionlessPlan(**common, q_guess=None, mode="task", start=np.array(tr.start, float), twist=twist,
                                twist_rate=rate)
    traj, balancing, task = held_trajectory(mech, cfg)
    assembly = start_assembly(mech, tr, traj)
    guess = getattr(tr, "initial_guess", None)
    q_guess = assembly.q if assembly is not None else (None if guess is None else np.array(guess, float))
    return ReactionlessPlan(**common, q_guess=q_guess, mode="joint", traj=traj, balancing=balancing, task=task)


def _joint_options(plan: ReactionlessPlan) -> dict:
    ctl = plan.ctl
    from mechbal.control import declared_options

    return dict(cancel=list(ctl.cancel), integrator=ctl.integrator, rate_hz=1.0 / plan.dt, damping=ctl.damping,
                home_gain=ctl.home_gain, limit_gain=ctl.limit_gain, q_guess=plan.q_guess,
                **declared_options(ctl))


def _task_controller(plan: ReactionlessPlan, null_space: bool):
    from mechbal import control
    from mechbal.config import ConfigError

    ctl = plan.ctl
    rows = list(ctl.task_rows) if ctl.task_rows is not None else ["all"]
    try:
        return control.ReactionlessTaskController(plan.mech, ctl.task_frame, rows, list(ctl.cancel), ctl.integrator,
                                                  1.0 / plan.dt, ctl.damping, null_space=null_space, q0=plan.start,
                                                  max_rate=control.declared_options(ctl)["max_rate"])
    except ValueError as exc:
        raise ConfigError("control", str(exc), has_value=False) from None


#: what each variant of a reactionless case is, by mode
VARIANTS = {
    "joint": {"uncontrolled": "the balancing joints held at their start (computed torque tracks the task motion)",
              "controlled": "the reactionless controller computes the balancing joints"},
    "task": {"uncontrolled": "v = J^+ x' (the pseudo-inverse alone: no null-space term)",
             "controlled": "v = J^+ x' + N z, z minimising the cancelled momentum components"},
}


def reactionless_motions(plan: ReactionlessPlan) -> dict:
    """mechbal's two variants of a reactionless case at the plan's ticks (no simulation): per
    variant (``uncontrolled``, ``controlled``) the motion ``q``, ``v``, ``a`` (every coordinate)
    and its predicted ``shaking_force`` and ``shaking_moment`` (the controller's prediction for
    its command; the uncontrolled joint mode: the wrench of the held motion), and ``status``."""
    from mechbal import control
    from mechbal.case.motion import mechanism_motion

    mech = plan.mech
    out = {}
    if plan.mode == "task":
        for label, null_space in (("uncontrolled", False), ("controlled", True)):
            r = _task_controller(plan, null_space).run(plan.twist, plan.twist_rate)
            out[label] = dict(q=r.q, v=r.v, a=r.a, shaking_force=r.shaking_force, shaking_moment=r.shaking_moment,
                              status=r.status)
        return out
    qa, va, aa = plan.traj.evaluate_batch(plan.th)
    qu, vu, au, _, _ = mechanism_motion(mech, plan.traj, plan.t, plan.q_guess)
    sw = mech.shaking_wrench(qu, vu, au)
    out["uncontrolled"] = dict(q=qu, v=vu, a=au, shaking_force=np.asarray(sw.shaking_force),
                               shaking_moment=np.asarray(sw.shaking_moment), status=np.asarray(sw.status))
    ctrl = control.ReactionlessController(mech, plan.ctl.balancing_joints, q0=qa[0], v0=va[0], **_joint_options(plan))
    task = plan.task
    r = ctrl.run(np.ascontiguousarray(qa[:, task]), np.ascontiguousarray(va[:, task]),
                 np.ascontiguousarray(aa[:, task]))
    out["controlled"] = dict(q=r.q_full, v=r.v_full, a=r.a_full, shaking_force=r.shaking_force,
                             shaking_moment=r.shaking_moment, status=r.status)
    return out


class _Tracking:
    """A joint controller for `mechbal.export.mujoco_engine.co_simulate` that records, at every
    tick, the command it tracks: every coordinate ``q``, ``v``, ``a`` and the predicted shaking
    wrench of the command (N rows)."""

    def __init__(self, n_ticks: int, dof: int):
        self.k = 0
        self.q, self.v, self.a = (np.zeros((n_ticks, dof)) for _ in range(3))
        self.force, self.moment = np.zeros((n_ticks, 3)), np.zeros((n_ticks, 3))
        self.status = np.zeros(n_ticks, dtype=np.uint32)

    def _record(self, q, v, a, force, moment, status: int) -> None:
        k = min(self.k, len(self.q) - 1)
        self.q[k], self.v[k], self.a[k], self.force[k], self.moment[k] = q, v, a, force, moment
        self.status[k] = status
        self.k += 1


class _JointTracking(_Tracking):
    """The joint mode's reactionless controller with its computed-torque stage (C++
    ``ReactionlessJointController``): each tick its reactionless stage computes the balancing
    joints and the computed-torque stage tracks the command from MuJoCo's state."""

    def __init__(self, plan: ReactionlessPlan, kp, kd):
        from mechbal import control

        q0, v0, _ = plan.traj.evaluate(0.0)
        rl = control.ReactionlessController(plan.mech, plan.ctl.balancing_joints, q0=q0, v0=v0, kp=kp, kd=kd,
                                            **_joint_options(plan))
        self.controller = rl.joint_controller
        super().__init__(len(plan.t), plan.mech.dof)

    def step(self, q, v, q_des, v_des, a_des):
        tau, status = self.controller.step(q, v, q_des, v_des, a_des)
        c = self.controller.reactionless.command
        self._record(c.q_full, c.v_full, c.a_full, c.shaking_force, c.shaking_moment, int(c.status))
        return tau, int(status)


class _TaskTracking(_Tracking):
    """The operational-space reactionless controller (`mechbal.control.ReactionlessTaskController`)
    ticked with the frame's desired twist, followed by a computed-torque stage (mechbal's model)
    that tracks its command (q, v, a) from MuJoCo's state. ``null_space=False``: the
    pseudo-inverse path (the uncontrolled variant)."""

    def __init__(self, plan: ReactionlessPlan, kp, kd, null_space: bool):
        from mechbal import control

        self.task = _task_controller(plan, null_space)
        self.ct = control.ComputedTorque(plan.mech, kp, kd)
        self.twist, self.twist_rate = plan.twist, plan.twist_rate
        super().__init__(len(plan.t), plan.mech.dof)

    def step(self, q, v, q_des, v_des, a_des):
        rows = len(self.twist)   # the samples of tick k, as ReactionlessTaskController.run takes them
        j = min(2 * self.k, rows - 1)
        jh, jn = min(j + 1, rows - 1), min(j + 2, rows - 1)
        s = int(self.task.step(self.twist[j], self.twist_rate[j], self.twist[jh], self.twist[jn]))
        qc, vc, ac = np.asarray(self.task.q), np.asarray(self.task.v), np.asarray(self.task.a)
        self._record(qc, vc, ac, self.task.shaking_force, self.task.shaking_moment, s)
        cmd = self.ct.step(q, v, qc, vc, ac)
        return cmd.joint_torque, int(cmd.status) | s


@dataclass
class ReactionlessCoSimulation:
    """One variant of a reactionless case co-simulated in MuJoCo (`cosimulate_reactionless`):
    ``cosimulation`` (`mechbal.export.mujoco_engine.CoSimulation`: MuJoCo's realised motion
    ``q_full``, ``v_full``, ``a_full`` and wrench), the command the controller issued at each tick
    (``command_q``, ``command_v``, ``command_a``, every coordinate, and its predicted
    ``predicted_shaking_force`` / ``_moment``), mechbal's base reaction of that command
    (``predicted_base_reaction_force`` / ``_moment``, of the mechanism MuJoCo integrates), the
    ``tracking_error`` (largest |MuJoCo's q - command q| per tick) and the controller's ``status``."""

    cosimulation: Any
    command_q: np.ndarray
    command_v: np.ndarray
    command_a: np.ndarray
    predicted_shaking_force: np.ndarray
    predicted_shaking_moment: np.ndarray
    predicted_base_reaction_force: np.ndarray
    predicted_base_reaction_moment: np.ndarray
    tracking_error: np.ndarray
    status: np.ndarray

    @property
    def ok(self) -> bool:
        return bool(np.all((self.status & _HARD) == 0)) and self.cosimulation.steps_completed == len(self.status) - 1


def cosimulate_reactionless(plan: ReactionlessPlan, variant: str, motions: dict | None = None,
                            **options: Any) -> ReactionlessCoSimulation:
    """``variant`` (``"uncontrolled"`` or ``"controlled"``) of a reactionless case ticked every
    ``plan.dt`` against MuJoCo integrating the MJCF export (zero-order hold; `co_simulate`'s
    ``options``). The controlled variant ticks the reactionless controller itself: the joint
    mode's ``ReactionlessJointController`` (reactionless stage and computed torque), the task
    mode's `mechbal.control.ReactionlessTaskController` followed by computed torque; the
    uncontrolled variant is computed torque along the held motion (joint mode) or the
    pseudo-inverse path's controller (task mode). Gains: Kp `KP`, Kd `KD` on every actuated joint.
    ``motions``: `reactionless_motions` of the plan (the uncontrolled joint mode's command;
    computed when None)."""
    from mechbal import control
    from mechbal.export.mujoco_engine import co_simulate, cosimulated_mechanism
    from mechbal.trajectory import RestToRest

    mech, n = plan.mech, plan.n
    kp, kd = [KP] * n, [KD] * n
    command = None
    if plan.mode == "task":
        ctrl = _TaskTracking(plan, kp, kd, null_space=(variant == "controlled"))
        traj = RestToRest(plan.start, plan.start, plan.horizon)   # ignored by the controller: the start at rest
    elif variant == "controlled":
        ctrl = _JointTracking(plan, kp, kd)
        traj = plan.traj
    else:
        ctrl = control.ComputedTorque(mech, kp, kd, q_guess=plan.q_guess)
        traj = plan.traj
        m = (motions or reactionless_motions(plan))["uncontrolled"]
        command = (m["q"], m["v"], m["a"], m["shaking_force"], m["shaking_moment"], np.zeros(len(plan.t), np.uint32))
    cs = co_simulate(mech, ctrl, traj, dt=plan.dt, duration=plan.horizon, q_guess=plan.q_guess, **options)
    if command is None:
        command = (ctrl.q, ctrl.v, ctrl.a, ctrl.force, ctrl.moment, ctrl.status)
    q, v, a, force, moment, status = command
    exported = cosimulated_mechanism(mech, options.get("minimum_mass"))
    br = exported.base_reaction(q, v, a)
    act = [mech.joint_names.index(x) for x in mech.actuated_names]
    error = np.max(np.abs(cs.q_full[:, act] - q[:, act]), axis=1)
    return ReactionlessCoSimulation(cosimulation=cs, command_q=q, command_v=v, command_a=a,
                                    predicted_shaking_force=np.asarray(force),
                                    predicted_shaking_moment=np.asarray(moment),
                                    predicted_base_reaction_force=np.asarray(br.base_reaction_force),
                                    predicted_base_reaction_moment=np.asarray(br.base_reaction_moment),
                                    tracking_error=error, status=np.asarray(status, np.uint32) | cs.status)


def _mujoco_inverse(sim, mech, q, v, a, P=None) -> dict:
    """MuJoCo's inverse dynamics along (q, v, a) (every coordinate): the shaking force dP/dt and
    moment dH_O/dt of the moving bodies (its base reaction plus their weight), the actuator
    forces and the static (gravity and springs) torque, projected with P (N, dof, n_actuated) for
    a closed mechanism."""
    g = np.asarray(mech.gravity, float)
    m, d = sim.model, sim.data
    N = len(q)
    na = len(mech.actuated_names) if P is not None else mech.dof
    F, M = np.zeros((N, 3)), np.zeros((N, 3))
    tau, G = np.zeros((N, na)), np.zeros((N, na))
    mass = sum(m.body_mass[b] for b in sim.moving_bodies)
    for k in range(N):
        inv = sim.inverse_dynamics(q[k], v[k], a[k])
        mc = sum((m.body_mass[b] * d.xipos[b] for b in sim.moving_bodies), np.zeros(3))
        F[k] = inv.base_reaction_force + mass * g
        M[k] = inv.base_reaction_moment + np.cross(mc, g)
        Gk = sim.static_torque(q[k])
        tau[k] = inv.joint_torque if P is None else P[k].T @ inv.joint_torque
        G[k] = Gk if P is None else P[k].T @ Gk
    return {"shaking_force": F, "shaking_moment": M, "actuator_force": tau, "gravity_torque": G}


def _mechbal_torques(mech, q, v, a, q_guess) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(actuator forces, static torque (gravity and springs), projection P or None) along a full
    motion: inverse dynamics for an open mechanism, C^T of it for a closed one."""
    if not mech.is_closed:
        return np.asarray(mech.inverse_dynamics(q, v, a)), np.asarray(mech.static_torque(q)), None
    act = [mech.joint_names.index(x) for x in mech.actuated_names]
    m = mech.closed_motion(q[:, act], v[:, act], a[:, act], q_guess=q[0] if q_guess is None else q_guess,
                           with_forces=True)
    P = np.asarray(m.projection)
    return np.asarray(m.actuated_force), np.einsum("ndk,nd->nk", P, np.asarray(mech.static_torque(q))), P


def _largest_residual(plan: ReactionlessPlan, sim: ReactionlessCoSimulation, peak_u: dict) -> float:
    """The largest cancelled component of MuJoCo's realised wrench, each as a fraction of its
    uncontrolled peak."""
    worst = 0.0
    cs = sim.cosimulation
    for row in sorted({r for c in plan.ctl.cancel for r in _component_rows(c)}):
        key, axis = ("shaking_force", row) if row < 3 else ("shaking_moment", row - 3)
        x = cs.shaking_force if row < 3 else cs.shaking_moment
        worst = max(worst, _peak(x[:, axis]) / max(peak_u[key][axis], 1e-300))
    return worst


def feasible_case(case, *, fit_duration: bool = False, allow_degraded: bool = False):
    """(validated case, feasibility summary): a case with a reactionless ``[control]`` checked
    against its declared limits before anything runs
    (`mechbal.case.control_plan.check_feasibility`: `mechbal.verdict.ControlInfeasible`, or
    the fitted duration with ``fit_duration``)."""
    from mechbal.case.control_plan import check_feasibility
    from mechbal.case.motion import start_assembly
    from mechbal.config import trajectory_from_config
    from mechbal.mechanism import Mechanism

    cfg = reactionless_control(case)
    mech = Mechanism.from_spec(cfg.spec, name=cfg.case.name)
    q_guess = None
    if mech.is_closed:
        traj, _ = trajectory_from_config(cfg.trajectory, len(mech.actuated_names))
        q_guess = start_assembly(mech, cfg.trajectory, traj).q
    cfg, report, fitted = check_feasibility(mech, cfg, q_guess, fit_duration=fit_duration,
                                            allow_degraded=allow_degraded)
    return cfg, {**report.summary(), **({"fitted_duration": fitted} if fitted else {})}


def run_verify_reactionless(case, out: Path, *, simulate: bool = True, dt: float = 1e-3,
                            duration: float | None = None, time_step_study: bool = True,
                            fit_duration: bool = False, allow_degraded: bool = False, view: bool = False) -> dict:
    """``mechbal verify`` of a case with a reactionless ``[control]`` table, in the joint mode
    (balancing joints: the reaction-wheel arm, PAMINSA) or the operational-space mode
    (``task_frame``: the Panda). For each variant, **uncontrolled** and **controlled**
    (`VARIANTS`: the balancing joints held / the reactionless controller; in the operational
    space, the pseudo-inverse path / the reaction null space):

    * mechbal's predicted shaking force and moment (the wrench the controller predicts for its
      command, ticks with exact RK4 samples), actuator forces and gravity (static) torque;
    * MuJoCo's inverse dynamics on the same motion (q, v, a) (constraints off): the independent
      engine's values for mechbal's motion;
    * co-simulated: the controller ticked every ``dt`` (zero-order hold) against MuJoCo integrating
      the MJCF export (`cosimulate_reactionless`): the shaking wrench MuJoCo realises, the
      tracking error against the command and the loops' constraint violation.

    ``duration``: a horizon shorter than the trajectory (its beginning). The residual is MuJoCo's
    realised peak of each cancelled component under the controller as a fraction of the
    uncontrolled peak (mechbal's prediction). What limits it is measured (``time_step_study``):
    the controlled variant again at dt / 2, the residual and the tracking error at both ticks
    (the computed-torque stage's torque is held over each tick, so both scale with the tick)."""
    from mechbal.export.mujoco_engine import MujocoMechanism

    out = Path(out)
    progress.stage("reading the case")
    validated, feasible = feasible_case(case, fit_duration=fit_duration, allow_degraded=allow_degraded)
    plan = reactionless_plan(case, dt=dt, duration=duration, validated=validated)
    mech = plan.mech
    rows = sorted({r for c in plan.ctl.cancel for r in _component_rows(c)})

    progress.stage("mechbal: both variants")
    motions = reactionless_motions(plan)
    predicted = {k: {"shaking_force": m["shaking_force"], "shaking_moment": m["shaking_moment"]}
                 for k, m in motions.items()}
    projections = {}
    for label, m in motions.items():
        tau, G, P = _mechbal_torques(mech, m["q"], m["v"], m["a"], plan.q_guess)
        predicted[label].update(actuator_force=tau, gravity_torque=G)
        projections[label] = P

    progress.stage("MuJoCo: inverse dynamics of both motions")
    sim = MujocoMechanism(mech, q=motions["uncontrolled"]["q"][0], q_guess=plan.q_guess)
    inverse = {k: _mujoco_inverse(sim, mech, m["q"], m["v"], m["a"], projections[k]) for k, m in motions.items()}
    out.mkdir(parents=True, exist_ok=True)
    (out / "mechanism.xml").write_text(sim.xml)

    simulated: dict = {}
    time_step: dict = {}
    if simulate:
        progress.stage(f"MuJoCo: co-simulation at {1 / dt:g} Hz, uncontrolled and controlled")
        for label in ("uncontrolled", "controlled"):
            simulated[label] = cosimulate_reactionless(plan, label, motions)

    progress.stage("summary")
    peak_u = {key: _peak_axes(predicted["uncontrolled"][key]) for key in ("shaking_force", "shaking_moment")}
    judged = control_verdict(plan, motions, simulated.get("controlled"))
    loop_failed = simulate and not judged.ok
    if simulate and time_step_study and not loop_failed:
        progress.stage(f"MuJoCo: the controlled variant at {2 / dt:g} Hz (time step)")
        half = cosimulate_reactionless(reactionless_plan(case, dt=dt / 2, duration=duration, validated=validated),
                                       "controlled")
        r1, r2 = _largest_residual(plan, simulated["controlled"], peak_u), _largest_residual(plan, half, peak_u)
        e1, e2 = _peak(simulated["controlled"].tracking_error), _peak(half.tracking_error)
        time_step = {"dt": [dt, dt / 2], "residual": [r1, r2], "tracking_error": [e1, e2],
                     "residual_ratio": r2 / r1 if r1 > 0 else None,
                     "tracking_error_ratio": e2 / e1 if e1 > 0 else None,
                     "meaning": "the controlled variant co-simulated at dt and dt / 2: the largest cancelled "
                                "component's realised peak as a fraction of its uncontrolled peak, and the "
                                "largest |q - command| [rad or m]"}
    # what a difference is relative to: the uncontrolled peak; for the force at least the moving
    # weight (a force-balanced mechanism's peak is zero); for the torques the actuator forces' peak
    weight = sum(float(b.mass) for b in mech.bodies) * float(np.linalg.norm(mech.gravity))
    torque_scale = max(_peak(predicted["uncontrolled"]["actuator_force"]),
                       _peak(predicted["uncontrolled"]["gravity_torque"]), 1e-300)
    scales = {"shaking_force": max(max(peak_u["shaking_force"]), weight, 1e-300),
              "shaking_moment": max(max(peak_u["shaking_moment"]), 1e-300),
              "gravity_torque": torque_scale, "actuator_force": torque_scale}
    variants, table = {}, []
    for label in ("uncontrolled", "controlled"):
        entry = {}
        for key, unit in (("shaking_force", "N"), ("shaking_moment", "N m"), ("gravity_torque", "N m or N"),
                          ("actuator_force", "N m or N")):
            mb, mi = predicted[label][key], inverse[label][key]
            diff = _peak(mb - mi)
            e = {"unit": unit, "max_difference": diff, "relative_difference": diff / scales[key]}
            if key in ("shaking_force", "shaking_moment"):
                e.update(mechbal_peak=_peak_axes(mb), mujoco_inverse_peak=_peak_axes(mi))
                if label in simulated:
                    e["mujoco_simulated_peak"] = _peak_axes(getattr(simulated[label].cosimulation, key))
                for axis, name in enumerate("xyz"):
                    table.append([label, f"{key}_{name}", e["mechbal_peak"][axis], e["mujoco_inverse_peak"][axis],
                                  e["relative_difference"], e.get("mujoco_simulated_peak", [float("nan")] * 3)[axis]])
            else:
                e.update(mechbal_peak=_peak(mb), mujoco_inverse_peak=_peak(mi))
                table.append([label, key, e["mechbal_peak"], e["mujoco_inverse_peak"], e["relative_difference"],
                              float("nan")])
            entry[key] = e
        if label in simulated:
            s = simulated[label]
            entry["simulation"] = {"ok": s.ok, "steps_completed": int(s.cosimulation.steps_completed),
                                   "tracking_error": _peak(s.tracking_error),
                                   "constraint_violation": _peak(s.cosimulation.constraint_violation)}
        variants[label] = entry
    residual = {}
    for row in rows:
        key, axis = ("shaking_force", row) if row < 3 else ("shaking_moment", row - 3)
        comp = ("force_" if row < 3 else "moment_") + "xyz"[axis]
        ref = max(peak_u[key][axis], 1e-300)
        item = {"uncontrolled_peak": peak_u[key][axis],
                "mechbal_controlled_fraction": variants["controlled"][key]["mechbal_peak"][axis] / ref,
                "mujoco_inverse_controlled_fraction": variants["controlled"][key]["mujoco_inverse_peak"][axis] / ref}
        for label in simulated:
            if label == "controlled" and loop_failed:   # a failed loop is never printed as a residual
                continue
            item[f"mujoco_simulated_{label}_fraction"] = variants[label][key]["mujoco_simulated_peak"][axis] / ref
        residual[comp] = item
    closed = ""
    if mech.is_closed and simulated:
        violation = max(_peak(s.cosimulation.constraint_violation) for s in simulated.values())
        closed = f"; MuJoCo's soft loop constraints add their violation (at most {violation:.2g} m)"
    if loop_failed:
        limited_by = "the controlled loop failed its goal (limited_by): no residual is reported for it"
    elif time_step:
        limited_by = (f"the computed-torque stage's torque is held over each {dt * 1e3:g} ms tick (zero-order hold): "
                      "MuJoCo's motion leaves the command by the tracking error; halving the tick scales the "
                      f"residual by {time_step['residual_ratio']:.2f} ({time_step['residual'][0]:.2g} -> "
                      f"{time_step['residual'][1]:.2g} of the uncontrolled peak) and the tracking error by "
                      f"{time_step['tracking_error_ratio']:.2f} (time_step){closed}")
    else:
        limited_by = ("the computed-torque stage's torque is held over each tick (zero-order hold): MuJoCo's "
                      "motion leaves the command by the tracking error (simulation.tracking_error); the time "
                      f"step study (time_step) measures it{closed}")
    summary = {
        "case": plan.name, "kind": "reactionless", "mode": plan.mode, "mechanism": repr(mech), "mujoco": repr(sim),
        "dt": dt, "duration": plan.horizon, "cancel": list(plan.ctl.cancel),
        "variants": variants,
        "variant_meaning": VARIANTS[plan.mode],
        "residual": residual,
        "checks": ("mechbal_peak: the wrench the controller predicts for its command (uncontrolled joint mode: the "
                   "wrench of the motion with the balancing joints held), mechbal's actuator forces and static "
                   "torque of the same motion. mujoco_inverse_peak: MuJoCo's inverse dynamics of the MJCF export on "
                   "the same (q, v, a). mujoco_simulated_peak: the controller (computed-torque stage Kp "
                   f"{KP:g} 1/s^2, Kd {KD:g} 1/s, torque held over each {dt * 1e3:g} ms tick) against MuJoCo "
                   "integrating the export. residual: each cancelled component's peak as a fraction of its "
                   "uncontrolled peak (mechbal's). relative_difference: max |mechbal - MuJoCo inverse| over the "
                   "uncontrolled peak (the force: at least the weight; the torques: the actuator forces' peak)."),
        "residual_limited_by": limited_by,
        "feasibility": feasible,
        **judged.summary(),
        "files": ["summary.json", "mechanism.xml"] + (["shaking_wrench.png"] if simulate else []),
    }
    if plan.mode == "task":
        summary["task_frame"] = plan.ctl.task_frame
    else:
        summary["balancing_joints"] = list(plan.ctl.balancing_joints)
    if time_step:
        summary["time_step"] = time_step
    if simulate:   # MuJoCo's integrator and time step of the simulated check
        summary["mujoco_options"] = simulated["controlled"].cosimulation.options
    if simulate:
        curves = {}
        for label in ("uncontrolled", "controlled"):
            curves[f"{label}, mechbal"] = (predicted[label]["shaking_force"], predicted[label]["shaking_moment"])
            cs = simulated[label].cosimulation
            curves[f"{label}, MuJoCo"] = (cs.shaking_force, cs.shaking_moment)
        report.plot_wrench(out / "shaking_wrench.png", plan.t, curves, title=f"{plan.name}: reactionless control, "
                           "mechbal and MuJoCo",
                           caption="Shaking force and moment about O: mechbal's prediction and MuJoCo's realised "
                                   f"wrench under the controller at {1 / dt:g} Hz; uncontrolled: "
                                   f"{VARIANTS[plan.mode]['uncontrolled']}; controlled: "
                                   f"{VARIANTS[plan.mode]['controlled']}.")
    if view:  # mechbal's motions of both variants (MuJoCo's realised ones are in the bodies files)
        from mechbal.view import Variant, write_html

        write_html(out / "view.html", [Variant(label, mech, plan.t, m["q"], force=m["shaking_force"],
                                               moment=m["shaking_moment"]) for label, m in motions.items()],
                   title=f"mechbal verify: {plan.name}", samples=201)
        summary["files"].append("view.html")
    write_summary(out / "summary.json", summary, command="verify")
    if loop_failed:   # the failed loop's realised peaks are not a residual: not printed as one
        table = [row[:-1] + ["failed"] if row[0] == "controlled" else row for row in table]
    print(report.table(table, ["variant", "quantity", "mechbal peak", "MuJoCo peak (inverse)",
                               "relative difference", "MuJoCo peak (simulated)"]))
    print(report.table(_verdict_rows(judged, simulated.get("controlled"), plan.t),
                       ["reactionless control (verdict)", "value"]))
    return summary


def control_verdict(plan: ReactionlessPlan, motions: dict, sim: "ReactionlessCoSimulation | None" = None):
    """The `mechbal.verdict.Verdict` of a reactionless case's controlled variant: mechbal's
    command (its statuses, its predicted wrench's cancelled components against the uncontrolled
    ones, the declared velocity limits) and, when ``sim`` (the controlled variant co-simulated in
    MuJoCo) is given, the simulation that ran: every tick ok, every step completed, MuJoCo's motion
    within ``tolerance.joint`` of the command and within the declared velocity limits."""
    from mechbal import verdict as vd

    mech, ctl = plan.mech, plan.ctl
    names = list(mech.actuated_names)
    tol = vd.tolerance(ctl)
    limits = vd.limits_in_force(mech, ctl, balancing=names if plan.mode == "task" else None)
    tracking = {"joint": "largest |q - command| of MuJoCo's motion [rad or m]"} if sim is not None else None
    v = vd.Verdict(vd.goal(kind=f"reactionless ({plan.mode} mode)", tol=tol, limits=limits, cancel=list(ctl.cancel),
                           tracking=tracking, closed_loop=sim is not None))
    c = motions["controlled"]
    act = [mech.joint_names.index(x) for x in names]
    v.statuses(c["status"], plan.t, who="reactionless controller (mechbal's command)")
    v.limit(np.asarray(c["v"])[:, act], plan.t, names, "velocity", limits, who="commanded motion")
    u = motions["uncontrolled"]
    v.residual(np.hstack([c["shaking_force"], c["shaking_moment"]]), np.hstack([u["shaking_force"], u["shaking_moment"]]),
               vd.cancelled_components(list(ctl.cancel)), tol, what="controller's predicted wrench")
    if sim is not None:
        cs = sim.cosimulation
        v.statuses(sim.status, plan.t, who="closed loop in MuJoCo")
        v.steps(int(cs.steps_completed), len(plan.t) - 1, plan.t)
        v.tracking(sim.tracking_error, plan.t, tol["joint"], what="MuJoCo's motion against the command",
                   unit="rad or m", key="joint")
        v.limit(np.asarray(cs.v_full)[:, act], plan.t, names, "velocity", limits, who="motion in MuJoCo")
    return v


def _verdict_rows(v, sim, t) -> list:
    from mechbal import verdict as vd

    extra = []
    if sim is not None:
        s = np.asarray(sim.status, np.uint32)
        extra = [["saturated ticks", f"{int(np.sum((s & np.uint32(4)) != 0))} of {len(s)}"],
                 ["out-of-range ticks", f"{int(np.sum((s & np.uint32(32)) != 0))} of {len(s)}"],
                 ["tracking error [rad or m]", f"{_peak(sim.tracking_error):.3g}"]]
    return vd.goal_rows(v, extra)


def run_cosimulation_reactionless(case, out: Path, *, dt: float = 1e-3, duration: float | None = None,
                                  fit_duration: bool = False, allow_degraded: bool = False) -> dict:
    """``mechbal run CASE --engine mujoco`` of a case with a reactionless ``[control]`` (joint or
    operational-space mode): both variants (`VARIANTS`) co-simulated in MuJoCo, each ticking its
    controller every ``dt`` (`cosimulate_reactionless`: the controlled variant ticks the
    reactionless controller). DIR receives what ``mechbal run`` writes for the case, of the motion
    MuJoCo realised: ``bodies_uncontrolled.npz`` and ``bodies_controlled.npz`` (MuJoCo's states and
    accelerations, with mechbal's shaking wrench of those stored poses), ``shaking_wrench.png``
    (both variants), ``balancing_joints.png`` (command and MuJoCo), and ``summary.json`` (both
    variants' peaks, the controller); beside them MuJoCo's realised base reaction and mechbal's
    prediction for the controller's command: ``base_reaction.png`` (plotted together),
    ``cosimulation.npz`` (every series, keys prefixed by the variant) and ``mechanism.xml``."""
    from mechbal import control
    from mechbal.case.writer import write_variant
    from mechbal.export.mjcf import mjcf_text
    from mechbal.export.mujoco_engine import cosimulated_mechanism

    out = Path(out)
    progress.stage("reading the case")
    validated, feasible = feasible_case(case, fit_duration=fit_duration, allow_degraded=allow_degraded)
    plan = reactionless_plan(case, dt=dt, duration=duration, validated=validated)
    mech, ctl, t = plan.mech, plan.ctl, plan.t
    motions = reactionless_motions(plan)
    sims = {}
    for label in ("uncontrolled", "controlled"):
        progress.stage(f"co-simulation (MuJoCo, {1 / dt:g} Hz): {label}")
        sims[label] = cosimulate_reactionless(plan, label, motions)
    exported = cosimulated_mechanism(mech)

    progress.stage("bodies files and plots")
    out.mkdir(parents=True, exist_ok=True)
    stored, series = {}, {}
    for label, s in sims.items():
        cs = s.cosimulation
        stored[label] = write_variant(exported, out, label, t, cs.q_full, cs.v_full, cs.a_full)
        series.update({f"{label}_{k}": v for k, v in dict(
            t=t, q=cs.q_full, v=cs.v_full, a=cs.a_full, joint_torque=cs.joint_torque, status=s.status,
            command_q=s.command_q, command_v=s.command_v, command_a=s.command_a,
            base_reaction_force=cs.base_reaction_force, base_reaction_moment=cs.base_reaction_moment,
            predicted_base_reaction_force=s.predicted_base_reaction_force,
            predicted_base_reaction_moment=s.predicted_base_reaction_moment,
            shaking_force=cs.shaking_force, shaking_moment=cs.shaking_moment,
            predicted_shaking_force=s.predicted_shaking_force, predicted_shaking_moment=s.predicted_shaking_moment,
            tracking_error=s.tracking_error, constraint_violation=cs.constraint_violation).items()})
    np.savez_compressed(out / "cosimulation.npz", **series)
    q0 = sims["uncontrolled"].command_q[0]
    (out / "mechanism.xml").write_text(mjcf_text(mech, q=q0, q_guess=plan.q_guess))
    (Fu, Mu), (Fc, Mc) = stored["uncontrolled"], stored["controlled"]
    kind = VARIANTS[plan.mode]
    report.plot_wrench(out / "shaking_wrench.png", t, {"uncontrolled": (Fu, Mu), "controlled": (Fc, Mc)},
                       title=f"{plan.title}: reactionless control in MuJoCo",
                       caption="Shaking force dP/dt and moment dH_O/dt about O of the motion MuJoCo realised at "
                               f"{1 / dt:g} Hz; uncontrolled: {kind['uncontrolled']}; controlled: "
                               f"{kind['controlled']}.")
    curves = {}
    for label, s in sims.items():
        curves[f"{label}, mechbal"] = (s.predicted_base_reaction_force, s.predicted_base_reaction_moment)
        curves[f"{label}, MuJoCo"] = (s.cosimulation.base_reaction_force, s.cosimulation.base_reaction_moment)
    report.plot_wrench(out / "base_reaction.png", t, curves, title=f"{plan.name}: base reaction, mechbal and MuJoCo",
                       force="base reaction force", moment="base reaction moment",
                       caption="Wrench the base exerts on the moving mechanism, gravity included, moment about O: "
                               "mechbal's prediction for the controller's command and MuJoCo's along its "
                               f"simulated motion, both variants ({1 / dt:g} Hz).")
    names = mech.actuated_names
    shown = [names.index(b) for b in (names if ctl.balancing_joints is None else ctl.balancing_joints)]
    act = [mech.joint_names.index(names[i]) for i in shown]
    report.plot_series(out / "balancing_joints.png", t,
                       {f"{label}, {who}": (s.command_q if who == "command" else s.cosimulation.q_full)[:, act]
                        for label, s in sims.items() for who in ("command", "MuJoCo")},
                       [names[i] for i in shown], "rad or m", title=f"{plan.name}: balancing joints",
                       caption="Commanded and MuJoCo's positions of each balancing joint, both variants.")

    progress.stage("summary")
    by_variant = {}
    for label, s in sims.items():
        cs = s.cosimulation
        sw_F, sw_M = stored[label]
        by_variant[label] = {
            "ok": s.ok, "steps_completed": int(cs.steps_completed), "peak_tracking_error": _peak(s.tracking_error),
            "max_constraint_violation": _peak(cs.constraint_violation),
            "base_reaction": {
                "definition": "wrench the base exerts on the moving mechanism, gravity included, moment about O",
                "peak_force_mujoco": _peak(cs.base_reaction_force),
                "peak_force_mechbal": _peak(s.predicted_base_reaction_force),
                "max_force_difference": _peak(cs.base_reaction_force - s.predicted_base_reaction_force),
                "peak_moment_mujoco": _peak(cs.base_reaction_moment),
                "peak_moment_mechbal": _peak(s.predicted_base_reaction_moment),
                "max_moment_difference": _peak(cs.base_reaction_moment - s.predicted_base_reaction_moment)},
            "shaking_wrench": {
                "peak_force_mujoco": _peak(cs.shaking_force), "peak_force_mechbal": _peak(s.predicted_shaking_force),
                "max_force_difference": _peak(cs.shaking_force - s.predicted_shaking_force),
                "peak_moment_mujoco": _peak(cs.shaking_moment),
                "peak_moment_mechbal": _peak(s.predicted_shaking_moment),
                "max_moment_difference": _peak(cs.shaking_moment - s.predicted_shaking_moment)},
            "stored_poses_wrench_difference": {
                "force": _peak(sw_F - cs.shaking_force), "moment": _peak(sw_M - cs.shaking_moment),
                "meaning": "mechbal's shaking wrench of the stored poses (MuJoCo's states and accelerations) "
                           "against MuJoCo's realised one [N, N m]"}}
    from mechbal import verdict as verdict_

    judged = control_verdict(plan, motions, sims["controlled"])
    rc = sims["controlled"]
    singular = (rc.status & np.uint32(int(control.Status.singular))) != 0
    saturated = (rc.status & np.uint32(int(control.Status.saturated))) != 0
    ctl_summary = {"kind": ctl.kind, "cancel": list(ctl.cancel), "integrator": ctl.integrator,
                   "rate_hz": 1.0 / dt, "damping": float(ctl.damping), "ticks": int(len(t)),
                   "singular_ticks": int(np.sum(singular)), "saturated_ticks": int(np.sum(saturated)),
                   "variants": dict(kind)}
    if plan.mode == "task":
        ctl_summary.update(mode="operational space (reaction null space)", task_frame=ctl.task_frame,
                           task_rows=list(ctl.task_rows) if ctl.task_rows is not None else ["all"])
    else:
        ctl_summary.update(balancing_joints=list(ctl.balancing_joints),
                           peak_balancing_rate=report.peak_abs(rc.command_v[:, act]))
    summary = {
        "case": plan.name, "engine": "mujoco", "kind": plan.kind, "mechanism": repr(mech), "dt": dt,
        "dof": mech.dof, "actuated": names, "closed": mech.is_closed, "duration": plan.horizon,
        "samples": int(len(t)), "law": plan.trajectory.law,
        "controller": (f"the reactionless controller ({plan.mode} mode) followed by computed torque, Kp {KP:g} "
                       f"1/s^2, Kd {KD:g} 1/s (mechbal's model), torque held over each {dt * 1e3:g} ms tick"),
        "variants": ["uncontrolled", "controlled"],
        "peak_shaking_force": {"uncontrolled": report.peak_abs(Fu), "controlled": report.peak_abs(Fc)},
        "peak_shaking_moment": {"uncontrolled": report.peak_abs(Mu), "controlled": report.peak_abs(Mc)},
        "shaking_moment_reduction": verdict_.moment_reduction(Mu, Mc, list(ctl.cancel)),
        "control": ctl_summary,
        "feasibility": feasible,
        **judged.summary(),
        "cosimulation": by_variant,
        "mujoco_options": sims["controlled"].cosimulation.options,
        "total_mass": mech.total_mass,
        "files": ["bodies_uncontrolled.npz", "bodies_controlled.npz", "shaking_wrench.png", "balancing_joints.png",
                  "base_reaction.png", "cosimulation.npz", "mechanism.xml"],
    }
    write_summary(out / "summary.json", summary)
    print(report.table(
        [[f"{label} ({who})", *report.peak_abs(M)] for label, s in sims.items()
         for who, M in (("mechbal prediction", s.predicted_shaking_moment),
                        ("MuJoCo", s.cosimulation.shaking_moment))],
        ["peak shaking moment about O [N m]", "x", "y", "z"]))
    print(report.table(_verdict_rows(judged, rc, t), ["reactionless control in MuJoCo (verdict)", "value"]))
    return summary


_HARD = 1 | 16 | 32  # non_finite_input | solver_error | out_of_range (mechbal.Status)


def _peak_axes(x) -> list:
    x = np.asarray(x, float)
    return [float(v) for v in np.max(np.abs(x), axis=0)] if x.size else [0.0, 0.0, 0.0]


def _component_rows(name: str) -> list[int]:
    """Rows of [F; M] (0..5) of a ``cancel`` name."""
    table = {"force": [0, 1, 2], "moment": [3, 4, 5], "both": list(range(6))}
    if name in table:
        return table[name]
    kind, axis = name.split("_")
    return [(0 if kind == "force" else 3) + "xyz".index(axis)]
