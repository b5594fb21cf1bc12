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

A case with a reactionless ``[control]`` table (the reaction-wheel arm, PAMINSA through the
general controller: `run_verify_reactionless`) is checked under its controller instead:
uncontrolled (balancing joints held) and controlled, mechbal's predicted shaking wrench against
MuJoCo's, by inverse dynamics on the same motion and co-simulated at 1 kHz.

Layer: methods (docs/architecture.md): uses the balance methods and the MuJoCo engine.
"""
from __future__ import annotations

from pathlib import Path

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


def check_variant(bc, mech, *, simulate: bool = True, reference: dict | None = None) -> dict:
    """The checks of one variant (module docstring) as a dict of plain values and arrays."""
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
    out: dict = {"q0": q[0], "mechanism": repr(mech), "mujoco": repr(sim), "light_bodies": sim.light_bodies,
                 "minimum_bodies": sim.names.minimum, "xml": sim.xml, "t": bc.t,
                 "mechbal": {"shaking_force": ev["shaking_force"], "shaking_moment": ev["shaking_moment"],
                             "actuator_force": ev["torque"], "gravity_torque": ev["gravity_torque"]},
                 "mujoco_inverse": {"shaking_force": F, "shaking_moment": M, "actuator_force": tau,
                                    "gravity_torque": G}}
    if simulate:
        n = len(mech.actuated_names) if closed else mech.dof
        traj = case_trajectory(bc, n)
        ctrl = ComputedTorque(mech, [KP] * n, [KD] * n, q_guess=bc.q_guess)
        cs = co_simulate(mech, ctrl, traj, q_guess=bc.q_guess)
        out["mujoco_simulated"] = {"t": cs.t, "shaking_force": cs.shaking_force,
                                   "shaking_moment": cs.shaking_moment,
                                   "predicted_shaking_force": cs.predicted_shaking_force,
                                   "predicted_shaking_moment": cs.predicted_shaking_moment,
                                   "constraint_violation": cs.constraint_violation,
                                   "tracking_error": cs.tracking_error, "ok": bool(np.all(cs.status == 0)),
                                   "steps_completed": cs.steps_completed}
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
        if sim is not None and key in ("shaking_force", "shaking_moment"):
            entry["mujoco_simulated_peak"] = _peak(sim[key])
            entry["simulated_minus_predicted"] = _peak(sim[key] - sim[f"predicted_{key}"])
            entry["simulated_peak_fraction_of_unbalanced"] = _peak(sim[key]) / max(unbalanced.get(key, 0.0) or _peak(mb), 1e-300)
        summary[key] = entry
        rows.append([label, key, unit, entry["mechbal_peak"], entry["mujoco_inverse_peak"],
                     entry["relative_difference"], entry.get("mujoco_simulated_peak", float("nan"))])
    return rows, summary


def run_verify(case: str, out: Path, *, simulate: bool = True, method: str | None = None) -> dict:
    """The whole check into ``out`` (module docstring); ``method``: the balancing method of the
    balanced variant (default: the case's ``balance.method``, or its default design's); returns
    the summary."""
    from mechbal.balance.run import load_case, run_method

    out = Path(out)
    if reactionless_control(case) is not None:
        return run_verify_reactionless(case, out, simulate=simulate)
    progress.stage("reading the case")
    bc = load_case(case)
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
    results, summary_variants, rows, scale, peaks = {}, {}, [], {}, {}
    for label, mech in variants.items():
        progress.stage(f"MuJoCo: {label}")
        res = check_variant(bc, mech, simulate=simulate)
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
    if notes:
        summary["notes"] = notes
    write_summary(out / "summary.json", summary, command="verify")
    print(report.table(rows, ["variant", "quantity", "unit", "mechbal peak", "MuJoCo peak (inverse)",
                              "relative difference", "MuJoCo peak (simulated)"]))
    return summary


def run_cosimulation(case: str, out: Path, *, dt: float = 1e-3) -> dict:
    """``mechbal run CASE --engine mujoco``: the case's mechanism driven along its trajectory by
    mechbal's computed-torque controller (Kp 400 / s^2, Kd 40 / s) ticked every ``dt`` against
    MuJoCo integrating its MJCF export. DIR receives ``summary.json``, ``base_reaction.png`` (MuJoCo's
    base reaction beside mechbal's prediction along the desired motion), ``tracking.png``,
    ``cosimulation.npz`` (every series) and ``mechanism.xml``."""
    from mechbal.balance.run import load_case
    from mechbal.control import ComputedTorque
    from mechbal.export.mujoco_engine import co_simulate

    out = Path(out)
    progress.stage("reading the case")
    bc = load_case(case)
    mech = bc.mechanism
    n = len(mech.actuated_names) if mech.is_closed else mech.dof
    traj = case_trajectory(bc, n)
    progress.stage("co-simulation (MuJoCo, 1 kHz)")
    ctrl = ComputedTorque(mech, [KP] * n, [KD] * n, q_guess=bc.q_guess)
    cs = co_simulate(mech, ctrl, traj, q_guess=bc.q_guess, dt=dt)
    from mechbal.export.mjcf import mjcf_text

    out.mkdir(parents=True, exist_ok=True)
    q0 = (np.asarray(mech.closed_motion(bc.motion[0][0], q_guess=bc.q_guess).q) if mech.is_closed
          else np.asarray(bc.motion[0][0], float))
    (out / "mechanism.xml").write_text(mjcf_text(mech, q=q0, q_guess=bc.q_guess))
    np.savez_compressed(out / "cosimulation.npz", t=cs.t, q=cs.q, qd=cs.qd, q_des=cs.q_des, qd_des=cs.qd_des,
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
    summary = {"case": bc.name, "engine": "mujoco", "mechanism": repr(mech), "dt": dt,
               "controller": f"computed torque, Kp {KP:g} 1/s^2, Kd {KD:g} 1/s (mechbal's model)",
               "ok": bool(np.all(cs.status == 0)), "steps_completed": cs.steps_completed,
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
    return summary


# ---- reactionless cases ------------------------------------------------------------------------

def reactionless_control(case) -> "object | None":
    """The validated ``[control]`` table of a case file or built-in case when it asks for the
    reactionless controller, else None (URDF files, cases without one, other kinds)."""
    from mechbal.config import load_case as read_case
    from mechbal.errors import ConfigError

    if str(case).lower().endswith(".urdf"):
        return None
    try:
        raw = read_case(case)
    except ConfigError:
        return None
    table = raw.get("control") if isinstance(raw, dict) else None
    if not isinstance(table, dict) or table.get("kind") != "reactionless":
        return None
    from mechbal.schema import validate_case

    return validate_case(raw, warn=False)


def _mujoco_inverse_wrench(sim, mech, q, v, a):
    """MuJoCo's shaking force dP/dt and moment dH_O/dt of the moving bodies along (q, v, a) (every
    coordinate): its inverse dynamics' base reaction plus their weight."""
    g = np.asarray(mech.gravity, float)
    m, d = sim.model, sim.data
    N = len(q)
    F, M = np.zeros((N, 3)), np.zeros((N, 3))
    for k in range(N):
        inv = sim.inverse_dynamics(q[k], v[k], a[k])
        mass = sum(m.body_mass[b] for b in sim.moving_bodies)
        mc = sum((m.body_mass[b] * d.xipos[b] for b in sim.moving_bodies), np.zeros(3))
        F[k] = inv.base_reaction_force + mass * g
        M[k] = inv.base_reaction_moment + np.cross(mc, g)
    return F, M


def run_verify_reactionless(case, out: Path, *, simulate: bool = True, dt: float = 1e-3) -> dict:
    """``mechbal verify`` of a case with a reactionless ``[control]`` table (joint mode: balancing
    joints; not the operational-space mode). For each variant, **uncontrolled** (the balancing
    joints held at their start, tracked by computed torque) and **controlled** (the reactionless
    controller with its computed-torque stage, `mechbal.control.ReactionlessController`):

    * mechbal's predicted shaking force and moment (the motion's wrench; controlled: the wrench
      the controller predicts for its command, ticks with exact RK4 samples);
    * MuJoCo's inverse dynamics on the same motion (q, v, a) (constraints off): the independent
      engine's wrench of mechbal's motion;
    * co-simulated: the controller ticked at 1 kHz (zero-order hold) against MuJoCo integrating
      the MJCF export (``simulate.closed_loop(engine="mujoco")``): the shaking wrench MuJoCo
      realises, the tracking error against the command and the loops' constraint violation.

    The residual is MuJoCo's realised peak of each cancelled component under the controller as a
    fraction of the uncontrolled peak (mechbal's prediction). What limits it is the tracking of
    the command by the computed-torque stage (Kp = 400 / s^2, Kd = 40 / s), whose torque is held
    over each 1 ms tick (halving the tick halves the residual), and, for closed mechanisms,
    MuJoCo's soft loop constraints; both are measured and reported beside it."""
    from mechbal import control
    from mechbal.cases.serial_chain import mechanism_motion
    from mechbal.config import ConfigError, trajectory_from_config
    from mechbal.export.mujoco_engine import MujocoMechanism, co_simulate
    from mechbal.mechanism import Mechanism
    from mechbal.simulate import closed_loop

    progress.stage("reading the case")
    cfg = reactionless_control(case)
    ctl = cfg.control
    if ctl.task_frame is not None:
        raise ConfigError("control.task_frame", "mechbal verify checks the joint mode of the reactionless "
                          "controller (balancing joints); the operational-space mode is checked by mechbal run",
                          ctl.task_frame)
    mech = Mechanism.from_spec(cfg.spec, name=cfg.case.name)
    guess = getattr(cfg.trajectory, "initial_guess", None)
    q_guess = None if guess is None else np.array(guess, float)
    names = mech.actuated_names
    balancing = [names.index(b) for b in ctl.balancing_joints]
    task = [i for i in range(len(names)) if i not in balancing]
    if cfg.trajectory.law == "constant_speed":  # the balancing joints' speed is ignored: held
        speed = cfg.trajectory.speeds(len(names))
        for i in balancing:
            speed[i] = 0.0
        held = {"speed": speed, "rpm": None}
    else:                                         # their end is ignored: held at their start
        end = list(cfg.trajectory.end)
        for i in balancing:
            end[i] = cfg.trajectory.start[i]
        held = {"end": end}
    traj, _ = trajectory_from_config(cfg.trajectory.model_copy(update=held), len(names))
    steps = int(round(traj.duration / dt))
    th = np.arange(2 * steps + 1) * (0.5 * dt)
    t = th[::2]
    qa, va, aa = traj.evaluate_batch(th)
    rows = sorted({r for c in ctl.cancel for r in _component_rows(c)})

    progress.stage("mechbal: uncontrolled motion and the reactionless controller")
    qu, vu, au, _, _ = mechanism_motion(mech, traj, t, q_guess)
    sw = mech.shaking_wrench(qu, vu, au)
    options = dict(cancel=list(ctl.cancel), integrator=ctl.integrator, rate_hz=1.0 / dt, damping=ctl.damping,
                   max_rate=ctl.max_rate, home_gain=ctl.home_gain, limit_gain=ctl.limit_gain, q_guess=q_guess)
    ctrl = control.ReactionlessController(mech, ctl.balancing_joints, q0=qa[0], v0=va[0], **options)
    r = ctrl.run(np.ascontiguousarray(qa[:, task]), np.ascontiguousarray(va[:, task]),
                 np.ascontiguousarray(aa[:, task]))
    motion = {"uncontrolled": (qu, vu, au), "controlled": (r.q_full, r.v_full, r.a_full)}
    predicted = {"uncontrolled": (np.asarray(sw.shaking_force), np.asarray(sw.shaking_moment)),
                 "controlled": (r.shaking_force, r.shaking_moment)}

    progress.stage("MuJoCo: inverse dynamics of both motions")
    sim = MujocoMechanism(mech, q=qu[0], q_guess=q_guess)
    inverse = {k: _mujoco_inverse_wrench(sim, mech, *m) for k, m in motion.items()}
    (out / "mechanism.xml").parent.mkdir(parents=True, exist_ok=True)
    (out / "mechanism.xml").write_text(sim.xml)

    simulated = {}
    if simulate:
        progress.stage("MuJoCo: co-simulation at 1 kHz, uncontrolled and controlled")
        n = len(names)
        ct = control.ComputedTorque(mech, [KP] * n, [KD] * n, q_guess=q_guess)
        rl = control.ReactionlessController(mech, ctl.balancing_joints, q0=qa[0], kp=[KP] * n, kd=[KD] * n,
                                            **options)
        for label, c in (("uncontrolled", ct), ("controlled", rl)):
            res = closed_loop(mech, c, traj, dt=dt, duration=traj.duration, q_guess=q_guess, engine="mujoco")
            cs = res.mujoco
            command = qu[:, [mech.joint_names.index(x) for x in names]] if mech.is_closed else qu
            if label == "controlled":
                command = r.q
            simulated[label] = {"shaking_force": cs.shaking_force, "shaking_moment": cs.shaking_moment,
                                "tracking_error": float(np.max(np.abs(cs.q - command))),
                                "constraint_violation": float(np.max(np.abs(cs.constraint_violation))),
                                "ok": bool(np.all((cs.status & _HARD) == 0)),
                                "steps_completed": int(cs.steps_completed)}

    progress.stage("summary")
    peak_u = {"shaking_force": _peak_axes(predicted["uncontrolled"][0]),
              "shaking_moment": _peak_axes(predicted["uncontrolled"][1])}
    # what a difference is relative to: the uncontrolled peak; for the force at least the moving
    # weight (a force-balanced mechanism's peak is zero)
    weight = sum(float(b.mass) for b in mech.bodies) * float(np.linalg.norm(mech.gravity))
    scales = {"shaking_force": max(max(peak_u["shaking_force"]), weight, 1e-300),
              "shaking_moment": max(max(peak_u["shaking_moment"]), 1e-300)}
    variants, table = {}, []
    for label in ("uncontrolled", "controlled"):
        entry = {}
        for j, key in enumerate(("shaking_force", "shaking_moment")):
            mb, mi = predicted[label][j], inverse[label][j]
            scale = scales[key]
            e = {"unit": "N" if j == 0 else "N m", "mechbal_peak": _peak_axes(mb), "mujoco_inverse_peak": _peak_axes(mi),
                 "max_difference": _peak(mb - mi), "relative_difference": _peak(mb - mi) / scale}
            if label in simulated:
                e["mujoco_simulated_peak"] = _peak_axes(simulated[label][key])
            entry[key] = e
            for axis, name in enumerate("xyz"):
                table.append([label, f"{key}_{name}", e["mechbal_peak"][axis], e["mujoco_inverse_peak"][axis],
                              e.get("mujoco_simulated_peak", [float("nan")] * 3)[axis]])
        if label in simulated:
            entry["simulation"] = {k: v for k, v in simulated[label].items() if k not in ("shaking_force", "shaking_moment")}
        variants[label] = entry
    residual = {}
    for row in rows:
        key, axis = ("shaking_force", row) if row < 3 else ("shaking_moment", row - 3)
        comp = ("force_" if row < 3 else "moment_") + "xyz"[axis]
        ref = peak_u[key][axis]
        item = {"uncontrolled_peak": ref,
                "mechbal_controlled_fraction": variants["controlled"][key]["mechbal_peak"][axis] / max(ref, 1e-300),
                "mujoco_inverse_controlled_fraction": variants["controlled"][key]["mujoco_inverse_peak"][axis] / max(ref, 1e-300)}
        if simulated:
            item["mujoco_simulated_controlled_fraction"] = (variants["controlled"][key]["mujoco_simulated_peak"][axis]
                                                            / max(ref, 1e-300))
        residual[comp] = item
    summary = {
        "case": cfg.case.name, "kind": "reactionless", "mechanism": repr(mech), "mujoco": repr(sim),
        "dt": dt, "balancing_joints": list(ctl.balancing_joints), "cancel": list(ctl.cancel),
        "variants": variants,
        "residual": residual,
        "checks": ("mechbal_peak: controlled, the wrench the reactionless controller predicts for its command; "
                   "uncontrolled, the wrench of the motion with the balancing joints held. mujoco_inverse_peak: "
                   "MuJoCo's inverse dynamics of the MJCF export on the same (q, v, a). mujoco_simulated_peak: "
                   f"the controller (computed-torque stage Kp {KP:g} 1/s^2, Kd {KD:g} 1/s, torque held over each "
                   f"{dt * 1e3:g} ms tick) against MuJoCo integrating the export. residual: each cancelled "
                   "component's controlled peak as a fraction of its uncontrolled peak. relative_difference: "
                   "max |mechbal - MuJoCo inverse| over the uncontrolled peak (the force: at least the weight)."),
        "limited_by": ("the simulated residual is the shaking of the tracking error: MuJoCo integrates the "
                       "torques of the computed-torque stage, each held over its tick (zero-order hold), so "
                       "the simulated motion leaves the reactionless command by the tracking error reported "
                       "under simulation; halving the tick period halves both (the wheel arm: 7.4e-6 of the "
                       "uncontrolled peak at 1 kHz, 3.8e-6 at 2 kHz), and, for closed mechanisms, MuJoCo's "
                       "soft loop constraints add their violation"),
        "files": ["summary.json", "mechanism.xml"] + (["shaking_wrench.png"] if simulate else []),
    }
    if simulate:
        curves = {"uncontrolled, mechbal": predicted["uncontrolled"], "controlled, mechbal": predicted["controlled"],
                  "uncontrolled, MuJoCo": (simulated["uncontrolled"]["shaking_force"],
                                           simulated["uncontrolled"]["shaking_moment"]),
                  "controlled, MuJoCo": (simulated["controlled"]["shaking_force"],
                                         simulated["controlled"]["shaking_moment"])}
        report.plot_wrench(out / "shaking_wrench.png", t, curves, title=f"{cfg.case.name}: reactionless control, "
                           "mechbal and MuJoCo",
                           caption="Shaking force and moment about O: mechbal's prediction and MuJoCo's realised "
                                   f"wrench under the controller at {1 / dt:g} Hz, balancing joints held "
                                   "(uncontrolled) and reactionless (controlled).")
    write_summary(out / "summary.json", summary, command="verify")
    print(report.table(table, ["variant", "component", "mechbal peak", "MuJoCo peak (inverse)",
                               "MuJoCo peak (simulated)"]))
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
