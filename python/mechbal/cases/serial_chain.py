"""Runner for ``kind = "mechanism"`` (alias ``kind = "serial_chain"``): any mechanism of the
general model (`mechbal.spec`: chains, trees, extra bodies, gear couplings, loop closures)
moving along a rest-to-rest trajectory of its actuated joints; shaking force and moment, base
reaction with gravity, actuator torques and, for closed mechanisms, the loop solve's conditioning.

Layer: methods (docs/architecture.md)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal import control
from mechbal.mechanism import JointType
from mechbal import progress, report, verdict
from mechbal.case.control_plan import check_feasibility, check_task_space, held_trajectory
from mechbal.case.motion import frame_path, mechanism_motion, motion_summary, start_assembly, task_end_pose
from mechbal.case.writer import drawing, write_variant
from mechbal.cases.runners import register
from mechbal.config import ConfigError, law_name, trajectory_from_config
from mechbal.export import write_bodies, write_summary
from mechbal.mechanism import Mechanism
from mechbal.schema import validate_case


@register("mechanism", stages=3)
@register("serial_chain", stages=3)
def run(config, out: Path) -> dict:
    case = validate_case(config, warn=False)
    mech = Mechanism.from_spec(case.spec, name=case.case.name)
    if case.trajectory.law == "min_shaking":
        return run_min_shaking(mech, case, out)
    if case.trajectory.law == "line":   # the task frame's path: the controller finds the joints' motion
        if case.control is None or case.control.task_frame is None:
            raise ConfigError("trajectory.law", "'line' moves the [control] task_frame along a line (the "
                              "reactionless controller's operational-space mode): give [control] task_frame, "
                              "or a joint-space law (quintic, cubic) with end", "line")
        return run_controlled(mech, case, out)
    traj, t = trajectory_from_config(case.trajectory, len(mech.actuated_names))
    assembly = start_assembly(mech, case.trajectory, traj)
    q_guess = None if assembly is None else assembly.q
    if case.control is not None and case.control.kind == "passive":
        return run_passive(mech, case, traj, out, q_guess=q_guess, assembly=assembly)
    if case.control is not None:
        return run_controlled(mech, case, out, q_guess=q_guess, assembly=assembly)
    return run_mechanism(mech, traj, t, out, name=case.case.name, kind=case.case.kind,
                         title=case.case.title or case.case.name, q_guess=q_guess,
                         summary_extra=motion_summary(case.trajectory, traj), assembly=assembly)


def run_min_shaking(mech: Mechanism, case, out: Path) -> dict:
    """``law = "min_shaking"`` (`mechbal.plan`): plan the motion, then the run every mechanism
    gets along it, with motion.npz, the plot of the quintic against the planned motion and
    summary.json's ``plan`` (objective, value of both, reduction, active limits, the
    centre-of-mass law)."""
    from mechbal.plan.case import com_law_of_table, plan_from_table, write_plan_outputs

    tr = case.trajectory
    if case.control is not None:
        raise ConfigError("control", "is not run along a planned motion (law = 'min_shaking'): plan "
                                     "first, then control the motion.npz it writes", has_value=False)
    q_guess = None
    assembly = None
    if mech.is_closed:
        from mechbal.assembly import assemble

        assembly = assemble(mech, np.asarray(tr.start, float), branch=tr.branch, initial_guess=tr.initial_guess)
        q_guess = assembly.q
    result = plan_from_table(mech, tr, q_guess)
    t = np.linspace(0.0, float(tr.duration), tr.samples)
    com, why_not = com_law_of_table(mech, tr, t, q_guess)
    summary = run_mechanism(mech, result.trajectory, t, out, name=case.case.name, kind=case.case.kind,
                            title=case.case.title or case.case.name, q_guess=q_guess, assembly=assembly)
    q, v, a, _, _ = mechanism_motion(mech, result.trajectory, t, q_guess)
    summary["plan"] = write_plan_outputs(mech, result, com, why_not, t, q, v, a, out,
                                         title=case.case.title or case.case.name, q_guess=q_guess)
    summary["files"] += ["motion.npz", "plan_shaking_wrench.png"]
    write_summary(out / "summary.json", summary)
    print(report.table([[result.objective, result.quintic_value, result.value, f"{100 * result.reduction:.1f} %"]],
                       ["objective", "quintic", "min_shaking", "reduction"]))
    if not result.ok:
        print(f"plan: not converged ({result.message})")
    return summary


def run_mechanism(mech: Mechanism, traj, t, out: Path, *, name: str, kind: str, title: str,
                  q_guess=None, summary_extra: dict | None = None, assembly=None) -> dict:
    """The run every mechanism gets (TOML case or URDF file): motion along ``traj`` at ``t``
    (loops solved for closed mechanisms), shaking wrench, base reaction, actuator torques;
    writes bodies_nominal.npz, the plots and summary.json into ``out``; returns the summary."""
    names = mech.actuated_names
    progress.stage("kinematics, loop solve, shaking wrench, inverse dynamics")
    q, v, a, torque, extra = mechanism_motion(mech, traj, t, q_guess)
    sw = mech.shaking_wrench(q, v, a)
    br = mech.base_reaction(q, v, a)
    motion = mech.body_motion(q, v, a)
    for what, status in (("kinematics", motion.status), ("shaking wrench", sw.status),
                         ("base reaction", br.status)):
        if np.any(status != 0):
            raise ConfigError("trajectory", f"{what} failed at {int(np.sum(status != 0))} instants "
                                            "(non-finite results)", has_value=False)
    F, M = sw.shaking_force, sw.shaking_moment
    R_F, R_M = br.base_reaction_force, br.base_reaction_moment

    progress.stage("bodies file and plots")
    bodies = mech.bodies
    write_bodies(out / "bodies_nominal.npz", t=t, names=mech.body_names,
                 mass=np.array([b.mass for b in bodies], float),
                 inertia_body=np.array([b.inertia for b in bodies], float).reshape(-1, 3, 3),
                 com=motion.com, rotation=motion.rotation, shaking_force=F, shaking_moment=M,
                 q=q, qd=v, qdd=a, torque=torque, base_reaction_force=R_F, base_reaction_moment=R_M,
                 **drawing(mech, motion))
    report.plot_wrench(out / "shaking_wrench.png", t, {"nominal": (F, M)}, title=title,
                       caption="Shaking force dP/dt and shaking moment dH_O/dt (about the base origin "
                               "O, inertial part only: no gravity) of all bodies along the trajectory.")
    report.plot_wrench(out / "base_reaction.png", t, {"with gravity": (R_F, R_M),
                                                      "shaking wrench (no gravity)": (F, M)},
                       title=f"{name}: base reaction", force="base reaction force",
                       moment="base reaction moment",
                       caption="Wrench the base exerts on the mechanism (gravity included, moment "
                               "about O) against the shaking wrench (inertial only): they differ "
                               "by the weight, -m g and -(m c) x g.")
    types = {j.name: j.type for j in mech.model.description.joints}
    kinds = ["prismatic" if types[n] == JointType.prismatic else "revolute" for n in names]
    report.plot_series(out / "joint_torques.png", t, {"general model": torque},
                       [f"{n} ({k})" for n, k in zip(names, kinds)],
                       ["torque [N m]" if k == "revolute" else "force [N]" for k in kinds],
                       title=f"{name}: actuator torques",
                       caption="Actuator torque (revolute) or force (prismatic) of each actuated "
                               "joint along the trajectory, gravity included"
                               + (" (C^T tau of the closed mechanism)." if mech.is_closed else "."))
    progress.stage("summary")
    rms = np.sqrt(np.mean(torque ** 2, axis=0))
    summary = {
        "case": name,
        "kind": kind,
        "dof": mech.dof,
        "actuated": names,
        "closed": mech.is_closed,
        "duration": float(traj.duration),
        "samples": int(len(t)),
        "law": law_name(traj),
        "variants": ["nominal"],
        "peak_shaking_force": {"nominal": report.peak_abs(F)},
        "peak_shaking_moment": {"nominal": report.peak_abs(M)},
        "peak_joint_torque": {"nominal": report.peak_abs(torque)},
        "rms_joint_torque": {"nominal": rms},
        "peak_base_reaction_force": {"nominal": report.peak_abs(R_F)},
        "peak_base_reaction_moment": {"nominal": report.peak_abs(R_M)},
        "base_reaction": "wrench the base exerts on the mechanism, gravity included, moment about O",
        "total_mass": mech.total_mass,
        "files": ["bodies_nominal.npz", "shaking_wrench.png", "base_reaction.png", "joint_torques.png"],
    }
    if extra:
        summary["loops"] = extra
        if assembly is not None:   # the branch picked at the start, and where the motion ends
            from mechbal.assembly import loop_branches

            extra["assembly"] = {**assembly.summary(), "branch_at_end": loop_branches(mech, q[-1])}
    if mech.springs:  # springs are part of the model: the torques above include them
        static = mech.static_torque(q)
        if mech.is_closed:
            qa = q[:, list(mech.model.actuated_coordinates)]
            static = np.einsum("ndk,nd->nk", mech.closed_motion(qa, q_guess=q_guess).projection, static)
        summary["springs"] = mech.spring_names
        summary["peak_static_torque"] = {"nominal": report.peak_abs(static)}
        summary["static_torque"] = ("actuator torque that holds each pose still, gravity plus springs; "
                                    "the joint torques include the springs' forces")
    summary.update(summary_extra or {})
    write_summary(out / "summary.json", summary)
    print(report.table(
        [["peak shaking force [N]", *report.peak_abs(F)],
         ["peak shaking moment about O [N m]", *report.peak_abs(M)]],
        ["quantity", "x", "y", "z"]))
    print(report.table([["peak torque", *report.peak_abs(torque)], ["RMS torque", *rms]],
                       ["actuator torque [N m or N]", *names]))
    return summary


def run_controlled(mech: Mechanism, case, out: Path, q_guess=None, assembly=None) -> dict:
    """A case with ``[control]`` (kinds computed_torque and decoupled: `run_joint_controller`;
    kind reactionless below): the motion with the balancing joints held
    at their start (``uncontrolled``) and under the reactionless controller (``controlled``), at
    the controller's ticks; bodies_uncontrolled.npz, bodies_controlled.npz (each with the shaking
    wrench of its stored poses), the plots and both variants' peaks in summary.json."""
    ctl = case.control
    if ctl.kind in ("computed_torque", "decoupled"):
        return run_joint_controller(mech, case, out, q_guess=q_guess, assembly=assembly)
    from mechbal.cases.runners import RUN_OPTIONS

    options = RUN_OPTIONS.get()
    case, report, fitted = check_feasibility(mech, case, q_guess, fit_duration=options.get("fit_duration", False),
                                             allow_degraded=options.get("allow_degraded", False))
    extra = {"feasibility": {**report.summary(), **({"fitted_duration": fitted} if fitted else {})}}
    if ctl.task_frame is not None:
        return run_task_space(mech, case, out, summary_extra=extra)
    return _run_joint_mode(mech, case, out, q_guess, extra)


def run_joint_controller(mech: Mechanism, case, out: Path, q_guess=None, assembly=None) -> dict:
    """A case with ``[control] kind = "computed_torque"`` or ``"decoupled"``: the controller of the
    table (`mechbal.control.joint_controller`: gains, the declared effort limits and
    ``torque_limit``, ``max_speed``) drives the mechanism along ``[trajectory]`` in closed loop
    (`mechbal.simulate.closed_loop`, RK4 at ``rate_hz``, zero-order hold), from the trajectory's
    start. Writes bodies_desired.npz (the commanded motion) and bodies_controlled.npz (the
    simulated one, every coordinate; accelerations from the spline of the simulated rates), the
    wrench and tracking plots, and summary.json with the run's verdict (`mechbal.simulate.judge_closed_loop`:
    every tick ok, no saturation, the tracking within ``tolerance.joint``, the declared velocity
    limits kept). A run that misses its goal is written all the same; the command line exits 6."""
    from mechbal import simulate

    ctl = case.control
    name, title = case.case.name, case.case.title or case.case.name
    names = mech.actuated_names
    traj, _ = trajectory_from_config(case.trajectory, len(names))
    try:
        ctrl = control.joint_controller(mech, ctl, q_guess=q_guess)
    except ValueError as exc:
        msg = str(exc)
        field, _, why = msg.partition(": ") if msg.startswith("control.") else ("control", "", msg)
        raise ConfigError(field, why, has_value=False) from None
    dt = 1.0 / ctl.rate_hz
    progress.stage(f"closed loop ({ctl.kind}, {ctl.rate_hz:g} Hz)")
    r = simulate.closed_loop(mech, ctrl, traj, dt=dt, duration=float(traj.duration), q_guess=q_guess,
                             tolerance=ctl.tolerance.model_dump() if ctl.tolerance is not None else None)
    t = r.t
    progress.stage("bodies files and plots")
    qd, vd, ad, _, _ = mechanism_motion(mech, traj, t, q_guess)
    ok_steps = r.steps_completed + 1   # rows of the simulated motion that the plant reached
    a_sim = _motion_acceleration(t[:ok_steps], r.v[:ok_steps]) if ok_steps > 5 else np.zeros_like(r.v[:ok_steps])
    if mech.is_closed:
        m = mech.closed_motion(r.q[:ok_steps], r.v[:ok_steps], a_sim, q_guess=q_guess)
        qs, vs, as_ = m.q, m.v, m.a
    else:
        qs, vs, as_ = r.q[:ok_steps], r.v[:ok_steps], a_sim
    Fd, Md = write_variant(mech, out, "desired", t, qd, vd, ad)
    finite = bool(np.all(np.isfinite(qs)) and np.all(np.isfinite(vs)) and np.all(np.isfinite(as_)))
    files = ["bodies_desired.npz", "shaking_wrench.png", "tracking.png"]
    curves = {"desired motion": (Fd, Md)}
    if finite:   # a diverged loop's motion may overflow in its wrench: then it is not written
        try:
            Fc, Mc = write_variant(mech, out, "controlled", t[:ok_steps], qs, vs, as_)
        except ConfigError:
            finite = False
    if finite:
        curves["closed loop (simulated)"] = (np.pad(Fc, ((0, len(t) - ok_steps), (0, 0)), mode="edge"),
                                             np.pad(Mc, ((0, len(t) - ok_steps), (0, 0)), mode="edge"))
        files.insert(1, "bodies_controlled.npz")
    report.plot_wrench(out / "shaking_wrench.png", t, curves, title=f"{title}: {ctl.kind} control",
                       caption="Shaking force dP/dt and moment dH_O/dt about O along the commanded motion and "
                               f"along the motion the {ctl.kind} controller realised in closed loop.")
    report.plot_series(out / "tracking.png", t, {"q_des - q": r.tracking_error}, names, "tracking error [rad or m]",
                       title=f"{name}: {ctl.kind} tracking")

    progress.stage("summary")
    v = r.verdict
    v.goal["kind"] = ctl.kind
    v.goal["limits"] = verdict.limits_in_force(mech, ctl)   # the [control] table's limits too
    torque = r.joint_torque
    saturated = int(np.sum((r.status & np.uint32(int(control.Status.saturated))) != 0))
    out_of_range = int(np.sum((r.status & np.uint32(int(control.Status.out_of_range))) != 0))
    err = np.abs(r.tracking_error)
    summary = {
        "case": name,
        "kind": case.case.kind,
        "dof": mech.dof,
        "actuated": names,
        "closed": mech.is_closed,
        "duration": float(traj.duration),
        "samples": int(len(t)),
        "law": law_name(traj),
        "variants": ["desired", "controlled"] if finite else ["desired"],
        "peak_shaking_force": {"desired": report.peak_abs(Fd), **({"controlled": report.peak_abs(Fc)} if finite else {})},
        "peak_shaking_moment": {"desired": report.peak_abs(Md), **({"controlled": report.peak_abs(Mc)} if finite else {})},
        "control": {
            "kind": ctl.kind, "rate_hz": float(ctl.rate_hz), "sampling": "zero_order_hold", "integrator": "rk4",
            "kp": list(ctl.kp), "kd": list(ctl.kd),
            **({"k": list(np.asarray(ctrl.k, float))} if ctl.kind == "decoupled" else {}),
            "torque_limit_in_force": [float(x) if np.isfinite(x) else None for x in np.asarray(ctrl.torque_limit, float)]
            if np.any(np.isfinite(np.asarray(ctrl.torque_limit, float))) else None,
            "ticks": int(len(t)), "steps_completed": int(r.steps_completed),
            "saturated_ticks": saturated, "out_of_range_ticks": out_of_range,
            "peak_tracking_error": report.peak_abs(err),
            "peak_joint_torque": report.peak_abs(torque),
        },
        **v.summary(),
        "total_mass": mech.total_mass,
        "files": files,
    }
    if assembly is not None:
        summary["loops"] = {"assembly": assembly.summary()}
    write_summary(out / "summary.json", summary)
    print(report.table([["peak |q_des - q| [rad or m]", *report.peak_abs(err)],
                        ["peak torque [N m or N]", *report.peak_abs(torque)]], [f"{ctl.kind} control", *names]))
    print(report.table(verdict.goal_rows(v, [["saturated ticks", f"{saturated} of {len(t)}"],
                                             ["out-of-range ticks", f"{out_of_range} of {len(t)}"],
                                             ["steps completed", f"{r.steps_completed} of {len(t) - 1}"],
                                             ["tracking error [rad or m]", f"{float(np.max(err)):.3g}"]]),
                       [f"{ctl.kind} control (closed loop)", "value"]))
    return summary


def _run_joint_mode(mech: Mechanism, case, out: Path, q_guess, summary_extra: dict) -> dict:
    ctl = case.control
    name, title = case.case.name, case.case.title or case.case.name
    names = mech.actuated_names
    traj, balancing, task = held_trajectory(mech, case)
    dt = 1.0 / ctl.rate_hz
    steps = int(round(traj.duration / dt))
    th = np.arange(2 * steps + 1) * (0.5 * dt)
    t = th[::2]
    qa, va, aa = traj.evaluate_batch(th)

    progress.stage("uncontrolled motion (balancing joints held) and the reactionless controller")
    qu, vu, au, _, _ = mechanism_motion(mech, traj, t, q_guess)
    ctrl = control.ReactionlessController(
        mech, ctl.balancing_joints, cancel=list(ctl.cancel), integrator=ctl.integrator,
        rate_hz=ctl.rate_hz, damping=ctl.damping, home_gain=ctl.home_gain,
        limit_gain=ctl.limit_gain, q0=qa[0], v0=va[0], q_guess=q_guess, **control.declared_options(ctl))
    r = ctrl.run(np.ascontiguousarray(qa[:, task]), np.ascontiguousarray(va[:, task]),
                 np.ascontiguousarray(aa[:, task]))

    progress.stage("bodies files and plots")
    Fu, Mu = write_variant(mech, out, "uncontrolled", t, qu, vu, au)
    Fc, Mc = write_variant(mech, out, "controlled", t, r.q_full, r.v_full, r.a_full)
    report.plot_wrench(out / "shaking_wrench.png", t, {"uncontrolled": (Fu, Mu), "controlled": (Fc, Mc)},
                       title=f"{title}: reactionless control",
                       caption="Shaking force dP/dt and moment dH_O/dt about O with the balancing joints "
                               f"({', '.join(ctl.balancing_joints)}) held still (uncontrolled) and "
                               f"under the reactionless controller cancelling {', '.join(ctl.cancel)} "
                               "(controlled).")
    bnames = list(ctl.balancing_joints)
    report.plot_series(out / "balancing_joints.png", t, {"position": r.q[:, balancing],
                                                         "rate": r.v[:, balancing]},
                       bnames, "rad or m, rad/s or m/s", title=f"{name}: balancing joints",
                       caption="Commanded position and rate of each balancing joint.")

    progress.stage("summary")
    singular = (r.status & np.uint32(int(control.Status.singular))) != 0
    saturated = (r.status & np.uint32(int(control.Status.saturated))) != 0
    tol = verdict.tolerance(ctl)
    limits = verdict.limits_in_force(mech, ctl)
    v = verdict.Verdict(verdict.goal(kind="reactionless (joint mode)", tol=tol, limits=limits, cancel=list(ctl.cancel)))
    at_limit = _joint_at_limit(r.v[:, balancing], bnames, limits)
    v.statuses(r.status, t, who="reactionless controller", joints={"saturated": at_limit} if at_limit else None)
    demand = summary_extra.get("feasibility", {}).get("peak_velocity")   # unclipped, before the run
    v.limit(r.v, t, names, "velocity", limits, who="commanded motion", demand=demand)
    components = verdict.cancelled_components(list(ctl.cancel))
    residual = v.residual(np.hstack([Fc, Mc]), np.hstack([Fu, Mu]), components, tol,
                          what="controlled motion (the wrench of the stored poses)")
    summary = {
        "case": name,
        "kind": case.case.kind,
        "dof": mech.dof,
        "actuated": names,
        "closed": mech.is_closed,
        "duration": float(traj.duration),
        "samples": int(len(t)),
        "law": law_name(traj),
        "variants": ["uncontrolled", "controlled"],
        "peak_shaking_force": {"uncontrolled": report.peak_abs(Fu), "controlled": report.peak_abs(Fc)},
        "peak_shaking_moment": {"uncontrolled": report.peak_abs(Mu), "controlled": report.peak_abs(Mc)},
        "control": {
            "kind": ctl.kind, "balancing_joints": bnames, "cancel": list(ctl.cancel),
            "integrator": ctl.integrator, "rate_hz": float(ctl.rate_hz), "damping": float(ctl.damping),
            "ticks": int(len(t)), "singular_ticks": int(np.sum(singular)),
            "saturated_ticks": int(np.sum(saturated)), "max_condition": float(np.max(r.condition)),
            "peak_balancing_rate": report.peak_abs(r.v[:, balancing]),
        },
        "cancelled_residual": residual,
        "shaking_moment_reduction": verdict.moment_reduction(Mu, Mc, list(ctl.cancel)),
        **summary_extra,
        **v.summary(),
        "total_mass": mech.total_mass,
        "files": ["bodies_uncontrolled.npz", "bodies_controlled.npz", "shaking_wrench.png",
                  "balancing_joints.png"],
    }
    write_summary(out / "summary.json", summary)
    print(report.table(
        [["uncontrolled", *report.peak_abs(Mu)], ["controlled", *report.peak_abs(Mc)]],
        ["peak shaking moment about O [N m]", "x", "y", "z"]))
    out_of_range = int(np.sum((r.status & np.uint32(int(control.Status.out_of_range))) != 0))
    print(report.table(verdict.goal_rows(v, [["saturated ticks", f"{int(np.sum(saturated))} of {len(t)}"],
                                             ["out-of-range ticks", f"{out_of_range} of {len(t)}"],
                                             ["singular ticks", f"{int(np.sum(singular))} of {len(t)}"]]),
                       ["reactionless control", "value"]))
    return summary


def _joint_at_limit(rates, names: list[str], limits: dict) -> str | None:
    """The joint whose |rate| comes closest to (or reaches) its declared velocity limit."""
    best, name = -1.0, None
    for j, n in enumerate(names):
        lim = limits.get(n, {}).get("velocity")
        if lim:
            x = float(np.max(np.abs(rates[:, j]))) / lim
            if x > best:
                best, name = x, n
    return name


def _motion_acceleration(t, v):
    """dv/dt of the integrated motion at the ticks: the derivative of the quintic spline through
    the commanded rates (the stored poses' own acceleration, whatever the feed-forward)."""
    from scipy.interpolate import make_interp_spline

    t, v = np.asarray(t, float), np.asarray(v, float)
    if len(t) < 2:
        return np.zeros_like(v)
    # quintic where there are ticks enough (6); a run of few ticks (a low rate_hz) the highest odd
    # degree they carry (cubic: 4, linear: 2), never scipy's refusal
    k = 5 if len(t) >= 6 else 3 if len(t) >= 4 else 1
    return make_interp_spline(t, v, k=k)(t, 1)


def run_task_space(mech: Mechanism, case, out: Path, summary_extra: dict | None = None) -> dict:
    """A case whose ``[control]`` names a ``task_frame`` (the operational-space mode,
    `mechbal.control.ReactionlessTaskController`): ``[trajectory]`` is the frame's path,
    from its pose at ``start`` to its pose at ``end`` (joint positions; `frame_path`), and
    the arm starts at ``start``. The path is run twice at the controller's ticks: with the
    pseudo-inverse alone, v = J^+ x' (``uncontrolled``: no null-space term), and in the reaction
    null space, v = J^+ x' + N z (``controlled``); bodies_uncontrolled.npz and
    bodies_controlled.npz hold each motion (rates integrated, the accelerations those of the
    stored motion) with the wrench of its poses; summary.json reports the shaking-moment
    reduction that the redundancy buys."""
    ctl = case.control
    name, title = case.case.name, case.case.title or case.case.name
    names = mech.actuated_names
    check_task_space(mech, case)
    tr = case.trajectory
    start = np.array(tr.start, float)
    dt = 1.0 / ctl.rate_hz
    steps = int(round(tr.duration / dt))
    th = np.arange(2 * steps + 1) * (0.5 * dt)
    t = th[::2]
    position, rotation, twist, twist_rate = frame_path(mech, ctl.task_frame, tr.start, tr.end, tr.duration,
                                                       tr.law, th, end_pose=task_end_pose(mech, ctl.task_frame, tr))
    rows = list(ctl.task_rows) if ctl.task_rows is not None else ["all"]

    progress.stage("operational space: pseudo-inverse alone and in the reaction null space")
    runs = {}
    for variant, null_space in (("uncontrolled", False), ("controlled", True)):
        try:
            ctrl = control.ReactionlessTaskController(
                mech, ctl.task_frame, rows, list(ctl.cancel), ctl.integrator, ctl.rate_hz, ctl.damping,
                null_space=null_space, q0=start, max_rate=control.declared_options(ctl)["max_rate"])
        except ValueError as exc:
            raise ConfigError("control", str(exc), has_value=False) from None
        runs[variant] = ctrl.run(twist, twist_rate)

    progress.stage("bodies files and plots")
    wrench, frame_error, frame_errors = {}, {}, {}
    for variant, r in runs.items():
        a = _motion_acceleration(t, r.v)
        wrench[variant] = write_variant(mech, out, variant, t, r.q, r.v, a)
        T = np.asarray(mech.frame_placement(r.q, ctl.task_frame))
        dR = np.einsum("nij,nkj->nik", T[:, :3, :3], rotation[::2])
        angle = np.arccos(np.clip((np.trace(dR, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0))
        axes = [i for i, a_ in enumerate("xyz") if any(r_ in ("all", "linear", f"v_{a_}") for r_ in rows)]
        position_error = np.linalg.norm((T[:, :3, 3] - position[::2])[:, axes], axis=1)
        frame_errors[variant] = {"position": position_error, "orientation": angle}
        frame_error[variant] = {"position": float(np.max(position_error)) if axes else 0.0}
        if any(r_ in ("all", "angular") or r_.startswith("w_") for r_ in rows):
            frame_error[variant]["orientation"] = float(np.max(angle))
    (Fu, Mu), (Fc, Mc) = wrench["uncontrolled"], wrench["controlled"]
    report.plot_wrench(out / "shaking_wrench.png", t, {"uncontrolled (J^+ x')": (Fu, Mu),
                                                      "controlled (J^+ x' + N z)": (Fc, Mc)},
                       title=f"{title}: reaction null space",
                       caption=f"Shaking force and moment about O while the frame {ctl.task_frame} follows the "
                               "same path: by the pseudo-inverse alone (uncontrolled) and with the null-space "
                               f"term minimising {', '.join(ctl.cancel)} (controlled).")
    report.plot_series(out / "balancing_joints.png", t, {"pseudo-inverse": runs["uncontrolled"].q,
                                                         "reaction null space": runs["controlled"].q},
                       names, "rad or m", title=f"{name}: joint positions",
                       caption="Joint positions along the path, without and with the null-space term.")

    progress.stage("summary")
    rc = runs["controlled"]
    singular = (rc.status & np.uint32(int(control.Status.singular))) != 0
    saturated = (rc.status & np.uint32(int(control.Status.saturated))) != 0
    peak_u = float(np.max(np.linalg.norm(Mu, axis=1)))
    peak_c = float(np.max(np.linalg.norm(Mc, axis=1)))
    # the feed-forward against the stored motion's own acceleration, on the tracked rows and the
    # predicted moment
    a_motion = _motion_acceleration(t, rc.v)
    inner = slice(3, -3)
    tol = verdict.tolerance(ctl)
    limits = verdict.limits_in_force(mech, ctl, balancing=names)
    tracked = {"position": f"largest distance of {ctl.task_frame} from its path [m], tracked axes"}
    if "orientation" in frame_error["controlled"]:
        tracked["orientation"] = f"largest angle of {ctl.task_frame} from its path [rad]"
    v = verdict.Verdict(verdict.goal(kind="reactionless (operational-space mode)", tol=tol, limits=limits,
                                     cancel=list(ctl.cancel), tracking=tracked))
    at_limit = _joint_at_limit(rc.v, names, limits)
    v.statuses(rc.status, t, who="operational-space controller",
               joints={"saturated": at_limit} if at_limit else None)
    v.limit(rc.v, t, names, "velocity", limits, who="commanded motion",
            demand=(summary_extra or {}).get("feasibility", {}).get("peak_velocity"))
    for key, unit in (("position", "m"), ("orientation", "rad")):
        if key in tracked:
            v.tracking(frame_errors["controlled"][key], t, tol[key], what=f"{ctl.task_frame} {key}", unit=unit,
                       key=key)
    residual = v.residual(np.hstack([Fc, Mc]), np.hstack([Fu, Mu]), verdict.cancelled_components(list(ctl.cancel)),
                          tol, what="controlled motion (the wrench of the stored poses)")
    summary = {
        "case": name,
        "kind": case.case.kind,
        "dof": mech.dof,
        "actuated": names,
        "closed": False,
        "duration": float(tr.duration),
        "samples": int(len(t)),
        "law": tr.law,
        "variants": ["uncontrolled", "controlled"],
        "peak_shaking_force": {"uncontrolled": report.peak_abs(Fu), "controlled": report.peak_abs(Fc)},
        "peak_shaking_moment": {"uncontrolled": report.peak_abs(Mu), "controlled": report.peak_abs(Mc)},
        "shaking_moment_reduction": verdict.moment_reduction(Mu, Mc, list(ctl.cancel),
                                                             ("without_null_space", "with_null_space")),
        "cancelled_residual": residual,
        **(summary_extra or {}),
        "control": {
            "kind": ctl.kind, "mode": "operational space (reaction null space)", "task_frame": ctl.task_frame,
            "task_rows": rows, "cancel": list(ctl.cancel), "integrator": ctl.integrator,
            "rate_hz": float(ctl.rate_hz), "damping": float(ctl.damping),
            "variants": {"uncontrolled": "v = J^+ x' (the pseudo-inverse alone: no null-space term)",
                         "controlled": "v = J^+ x' + N z, z minimising the cancelled momentum components"},
            "ticks": int(len(t)), "singular_ticks": int(np.sum(singular)),
            "saturated_ticks": int(np.sum(saturated)),
            "frame_path_error": frame_error,
            "peak_joint_rate": {k: report.peak_abs(r.v) for k, r in runs.items()},
            "feed_forward": {
                # away from the ends (0 for a run of 7 ticks or fewer: no tick away from them)
                "max_acceleration_difference": float(np.max(np.abs(rc.a - a_motion)[inner], initial=0.0)),
                "max_predicted_moment_difference": float(np.max(np.abs(rc.shaking_moment - Mc)[inner], initial=0.0)),
                "meaning": "commanded acceleration feed-forward and its predicted shaking moment against "
                           "the stored motion's (derivative of the integrated rates), away from the ends"},
        },
        **v.summary(),
        "total_mass": mech.total_mass,
        "files": ["bodies_uncontrolled.npz", "bodies_controlled.npz", "shaking_wrench.png",
                  "balancing_joints.png"],
    }
    write_summary(out / "summary.json", summary)
    print(report.table(
        [["uncontrolled (J^+ x')", *report.peak_abs(Mu), peak_u],
         ["controlled (J^+ x' + N z)", *report.peak_abs(Mc), peak_c]],
        ["peak shaking moment about O [N m]", "x", "y", "z", "|M| (whole moment)"]))
    print(report.table(verdict.goal_rows(v, [
        ["saturated ticks", f"{int(np.sum(saturated))} of {len(t)}"],
        ["out-of-range ticks", f"{int(np.sum((rc.status & np.uint32(int(control.Status.out_of_range))) != 0))} of {len(t)}"],
        ["singular ticks", f"{int(np.sum(singular))} of {len(t)}"],
        *[[f"task error: {k}", f"{x:.3g} {'m' if k == 'position' else 'rad'}"]
          for k, x in frame_error["controlled"].items()]]), ["reactionless control (operational space)", "value"]))
    return summary


def run_passive(mech: Mechanism, case, traj, out: Path, q_guess=None, assembly=None) -> dict:
    """A case with ``[control] kind = "passive"``: no controller; the mechanism starts from the
    trajectory's start with its initial rates (zero for the rest-to-rest laws, ``speed`` for
    constant_speed) and moves under gravity and its springs with zero effort for the trajectory's
    duration, RK4 at ``rate_hz`` (`mechbal.simulate.passive`). Writes bodies_passive.npz (the
    shaking wrench of its stored poses), the wrench and energy plots, and summary.json with the
    energy balance (kinetic + gravity + springs, conserved by the exact motion)."""
    from mechbal import simulate

    ctl = case.control
    name, title = case.case.name, case.case.title or case.case.name
    q0, v0, _ = (np.atleast_2d(x)[0] for x in traj.evaluate_batch(np.zeros(1)))
    progress.stage("passive simulation (zero effort: gravity and springs)")
    r = simulate.passive(mech, q0, v0, dt=1.0 / ctl.rate_hz, duration=float(traj.duration), q_guess=q_guess)
    if r.steps_completed < len(r.t) - 1:
        k = r.steps_completed
        raise ConfigError("control", f"the passive simulation stopped at t = {r.t[k]:.4g} s (status "
                          f"{control.status_text(int(r.status[k + 1]))}): the mechanism cannot be "
                          "assembled or its state is not finite there", has_value=False)
    progress.stage("bodies file and plots")
    t = r.t
    F, M = write_variant(mech, out, "passive", t, r.q_full, r.v_full, r.a_full)
    report.plot_wrench(out / "shaking_wrench.png", t, {"passive": (F, M)}, title=f"{title}: passive motion",
                       caption="Shaking force dP/dt and moment dH_O/dt about O of the mechanism moving "
                               "with zero joint effort under gravity and its springs.")
    report.plot_series(out / "energy.png", t, {"kinetic": r.kinetic_energy[:, None],
                                                "potential (gravity + springs)": r.potential_energy[:, None],
                                                "total": r.energy[:, None]},
                       ["energy"], ["energy [J]"], title=f"{name}: energy of the passive motion",
                       caption="Kinetic energy 1/2 v^T M v, potential energy (gravity, zero at O, plus "
                               "springs) and their sum, which the exact unforced motion conserves: its "
                               "drift is the integrator's error.")
    progress.stage("summary")
    e0 = float(r.energy[0])
    swing = float(np.max(r.kinetic_energy) - np.min(r.kinetic_energy))
    summary = {
        "case": name,
        "kind": case.case.kind,
        "dof": mech.dof,
        "actuated": mech.actuated_names,
        "closed": mech.is_closed,
        "duration": float(traj.duration),
        "samples": int(len(t)),
        "law": law_name(traj),
        "variants": ["passive"],
        "peak_shaking_force": {"passive": report.peak_abs(F)},
        "peak_shaking_moment": {"passive": report.peak_abs(M)},
        "passive": {
            "rate_hz": float(ctl.rate_hz), "integrator": "rk4", "q0": q0, "v0": v0,
            "initial_energy": e0, "max_energy_drift": r.energy_drift,
            "kinetic_energy_swing": swing,
            "relative_energy_drift": r.energy_drift / swing if swing > 0 else 0.0,
            "energy": "kinetic 1/2 v^T M v + gravity (zero at O) + springs; conserved by the exact motion "
                      "until a joint hits a limit (an inelastic end stop: the drift is measured before it)",
            "stop_steps": r.stop_steps,
            "final_q": r.q[-1], "final_v": r.v[-1],
        },
        "total_mass": mech.total_mass,
        "files": ["bodies_passive.npz", "shaking_wrench.png", "energy.png"],
    }
    if assembly is not None:
        from mechbal.assembly import loop_branches

        summary["loops"] = {"assembly": {**assembly.summary(), "branch_at_end": loop_branches(mech, r.q_full[-1])}}
    write_summary(out / "summary.json", summary)
    print(report.table([["energy at t = 0 [J]", e0], ["largest energy drift [J]", r.energy_drift],
                        ["kinetic energy swing [J]", swing]], ["passive motion", "value"]))
    return summary
