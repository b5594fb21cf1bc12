"""Simulation through the C++ core: a whole run per call, numpy in, numpy out.

* `closed_loop`: any joint controller (`mechbal.control`) driving any mechanism
  (a `mechbal.Mechanism`, closed loops included, or any forward-dynamics plant such as
  ``Arm2DofDynamics``) along any trajectory (`mechbal.trajectory`), integrated by RK4 at the
  controller period.
* `passive`: no controller; the mechanism moves under gravity and its springs with zero
  joint effort from an initial state (RK4, the same C++ loop with
  `mechbal.control.PassiveController`), with its energy along the run.
* open-loop evaluation along a trajectory: `mechbal.Mechanism` (``shaking_wrench``,
  ``base_reaction``, ``inverse_dynamics`` over ``(N, n)`` samples of a trajectory).

Units: SI (s, rad or m, rad/s or m/s, N m or N).

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from mechbal import _core
from mechbal._deprecation import DeprecatedAttributes, renamed_kwargs
from mechbal.control import MechanismDynamics

#: the C++ RK4 closed loop (any ForwardDynamics plant, any JointController): dict of arrays
simulate_closed_loop = _core.simulate_closed_loop
simulate_computed_torque = _core.simulate_computed_torque

__all__ = ["closed_loop", "ClosedLoopResult", "judge_closed_loop", "passive", "PassiveResult", "ForwardDynamics", "MechanismDynamics",
           "simulate_closed_loop", "simulate_computed_torque"]

ForwardDynamics = _core.ForwardDynamics
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ClosedLoopResult(DeprecatedAttributes):
    """One closed-loop run, one row per controller tick k = 0 .. steps (t_k = k dt):

    * ``t`` (N,) [s];
    * ``q``, ``v`` (N, n): the plant's state [rad or m, rad/s or m/s];
    * ``q_des``, ``v_des`` (N, n): the desired motion at the ticks;
    * ``joint_torque`` (N, n) [N m or N]: the command applied from t_k on;
    * ``status`` (N,): per tick, the controller's and the plant's flags (0 = ok,
      `mechbal.Status`);
    * ``saturated_ticks``: ticks on which the controller clipped the torque;
    * ``steps_completed``: ``steps`` unless the plant failed (later rows repeat the last state);
    * ``mujoco``: with ``engine="mujoco"``, the co-simulation's record (MuJoCo's base reaction
      beside mechbal's prediction), else None;
    * ``verdict``: the run's goal and whether it was met (`mechbal.verdict.Verdict`: every tick
      ok, every step completed, the plant within ``tolerance["joint"]`` of the desired motion,
      the declared velocity limits kept); None for a passive run (no goal). ``ok`` is its ``ok``.

    ``qd`` and ``qd_des``, the names of earlier releases, still read ``v`` and ``v_des`` for one
    release (with a DeprecationWarning).
    """

    t: FloatArray
    q: FloatArray
    v: FloatArray
    q_des: FloatArray
    v_des: FloatArray
    joint_torque: FloatArray
    status: npt.NDArray[np.uint32]
    saturated_ticks: int
    steps_completed: int
    #: ``engine="mujoco"``: the `mechbal.export.mujoco_engine.CoSimulation` (MuJoCo's base
    #: reaction at every tick beside mechbal's prediction, the loops' constraint violation)
    mujoco: Any = None
    verdict: Any = None

    _renamed: ClassVar[dict[str, str]] = {"qd": "v", "qd_des": "v_des"}

    @property
    def tracking_error(self) -> FloatArray:
        """``q_des - q`` (N, n) [rad or m]."""
        return self.q_des - self.q

    @property
    def ok(self) -> bool:
        """True when the run met its goal (`verdict`); without one (a passive run), when every
        tick's status is 0 (ok)."""
        if self.verdict is not None:
            return bool(self.verdict.ok)
        return bool(np.all(self.status == 0))

    @property
    def limited_by(self) -> list:
        """What kept the run from its goal (empty when ``ok``): `mechbal.verdict.Verdict`'s."""
        return list(self.verdict.limited_by) if self.verdict is not None else []


def judge_closed_loop(result: ClosedLoopResult, controller: Any, mechanism_or_plant: Any = None,
                      tolerance: Any = None) -> Any:
    """The `mechbal.verdict.Verdict` of a closed-loop run: every tick's status ok, every step
    completed, the largest |q_des - q| of the tracked joints (a reactionless controller's task
    joints: its balancing joints follow the reactionless command, not q_des) within
    ``tolerance["joint"]`` beyond the error the run started with (default `mechbal.verdict.DEFAULT_TOLERANCE`), and, for a
    `mechbal.Mechanism` plant, its declared velocity limits kept by the simulated motion. None
    for a passive run (no goal)."""
    from mechbal import verdict as vd
    from mechbal.control import PassiveController
    from mechbal.mechanism import Mechanism

    if isinstance(controller, PassiveController):
        return None
    tol = vd.tolerance(tolerance)
    n = result.q.shape[1]
    tracked = list(range(n))
    if isinstance(controller, _core.ReactionlessJointController):
        tracked = list(controller.reactionless.task_indices)
    mech = mechanism_or_plant if isinstance(mechanism_or_plant, Mechanism) else None
    limits = vd.limits_in_force(mech) if mech is not None else {}
    v = vd.Verdict(vd.goal(kind=type(controller).__name__, tol=tol, limits=limits, closed_loop=True,
                           tracking={"joint": "largest |q_des - q| of the tracked joints [rad or m] beyond "
                                              "the error the run started with"}))
    v.statuses(result.status, result.t, joints=_saturated_joint(result, controller, mech))
    v.steps(result.steps_completed, len(result.t) - 1, result.t)
    if tracked:
        err = np.max(np.abs(result.q_des[:, tracked] - result.q[:, tracked]), axis=1)
        # a start off the desired motion is the caller's: the loop must not depart from it by
        # more than the tolerance beyond the error it started with
        v.tracking(np.maximum(err - err[0], 0.0), result.t, tol["joint"],
                   what="closed-loop tracking (beyond the initial error)", unit="rad or m", key="joint")
    if mech is not None:
        v.limit(result.v, result.t, list(mech.actuated_names), "velocity", limits, who="simulated motion")
    return v


def _saturated_joint(result: ClosedLoopResult, controller: Any, mech: Any) -> dict[str, str] | None:
    """``{"saturated": joint}`` for the verdict: the joint whose torque sat at the controller's
    |tau| limit first (then on the most ticks), when the controller has one."""
    limit = np.asarray(getattr(controller, "torque_limit", []), float).reshape(-1)
    tau = np.abs(np.asarray(result.joint_torque, float))
    if limit.size != tau.shape[1] or not np.any(np.isfinite(limit)):
        return None
    hit = tau >= limit[None, :] * (1.0 - 1e-9)
    if not np.any(hit):
        return None
    first = np.where(np.any(hit, axis=0), np.argmax(hit, axis=0), len(tau))
    j = min(range(len(limit)), key=lambda i: (first[i], -int(np.sum(hit[:, i]))))
    names = list(mech.actuated_names) if mech is not None else [f"joint {i}" for i in range(len(limit))]
    return {"saturated": f"{names[j]} at its |tau| limit {limit[j]:.4g} N m or N"}


def _plant(mechanism_or_plant: Any, q_guess: npt.ArrayLike | None) -> Any:
    from mechbal.mechanism import Mechanism

    if isinstance(mechanism_or_plant, Mechanism):
        model = mechanism_or_plant.model
        guess = np.zeros(model.dof) if q_guess is None else np.asarray(q_guess, dtype=float)
        return MechanismDynamics(model, guess)
    if isinstance(mechanism_or_plant, _core.MechanismModel):
        return _plant(Mechanism(mechanism_or_plant), q_guess)
    if not isinstance(mechanism_or_plant, _core.ForwardDynamics):
        raise TypeError("plant must be a mechbal.Mechanism, a MechanismModel or a forward-dynamics "
                        "plant (MechanismDynamics, Arm2DofDynamics), got "
                        f"{type(mechanism_or_plant).__name__}")
    return mechanism_or_plant


#: most RK4 steps of one closed_loop call (the log holds 5 arrays of steps x dof values)
MAX_STEPS = 10_000_000


def _check_timing(dt: Any, duration: Any) -> tuple[float, float]:
    """(dt, duration) as floats, or ValueError / TypeError naming the argument: real numbers,
    finite, dt > 0, duration >= dt, at most `MAX_STEPS` steps."""
    values = {}
    for name, x in (("dt", dt), ("duration", duration)):
        if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise TypeError(f"{name} must be a number of seconds, got {type(x).__name__}")
        x = float(x)
        if not np.isfinite(x) or x <= 0.0:
            raise ValueError(f"{name} must be a finite number of seconds > 0, got {x!r}")
        values[name] = x
    dt, duration = values["dt"], values["duration"]
    if duration < dt:
        raise ValueError(f"duration must be >= dt, got duration={duration!r}, dt={dt!r}")
    steps = duration / dt
    if steps > MAX_STEPS:
        raise ValueError(f"duration / dt = {steps:.4g} steps, more than the {MAX_STEPS} one "
                         f"simulation may take (dt={dt!r}, duration={duration!r}): raise dt or "
                         "shorten duration")
    return dt, duration


@renamed_kwargs(qd0="v0")
def closed_loop(mechanism_or_plant: Any, controller: Any, trajectory: Any,
                q0: npt.ArrayLike | None = None, v0: npt.ArrayLike | None = None, *,
                dt: float = 1e-3, duration: float | None = None,
                sampling: str = "zero_order_hold",
                q_guess: npt.ArrayLike | None = None, engine: str = "mechbal",
                tolerance: dict | None = None, **engine_options: Any) -> ClosedLoopResult:
    """Simulate ``controller`` driving ``mechanism_or_plant`` along ``trajectory`` (one C++ call).

    Args:
        mechanism_or_plant: a `mechbal.Mechanism` (its forward dynamics in the actuated
            coordinates; loops solved at every stage, warm-started from ``q_guess``, the full
            coordinates near the assembly) or any forward-dynamics plant (``MechanismDynamics``,
            ``Arm2DofDynamics``).
        controller: any joint controller (`mechbal.control.ComputedTorque`, whose model
            may differ from the plant, `mechbal.control.DecoupledJointController`, or a
            `mechbal.control.ReactionlessController` built with ``kp`` and ``kd``).
            Its state carries over from previous ticks; call ``reset()`` to start afresh.
        trajectory: any `mechbal.trajectory` object, evaluated at the simulation time
            t = 0 .. duration [s]. A rest-to-rest trajectory runs on the C++ path; any other is
            sampled every dt/2 first.
        q0: initial positions [rad or m]; default: the trajectory at t = 0.
        v0: initial velocities [rad/s or m/s]; default: the trajectory at t = 0 (``qd0``, the
            name of earlier releases, works for one release and warns).
        dt: controller period = RK4 step [s].
        duration: simulated time [s]; default the trajectory's ``end_time`` (or ``duration``).
        sampling: ``"zero_order_hold"`` (a digital controller: the torque of tick k is held over
            the step) or ``"every_rk4_stage"`` (the continuous control law at each RK4 stage).
        q_guess: full coordinates near the assembly, for a closed-loop Mechanism.
        engine: ``"mechbal"`` (the C++ RK4 above) or ``"mujoco"``: the controller ticked every
            ``dt`` from Python against MuJoCo integrating the mechanism's MJCF export (a
            `mechbal.Mechanism` only; zero-order hold; needs ``mechbal[mujoco]``). The
            result's ``mujoco`` holds MuJoCo's base reaction at every tick beside mechbal's
            prediction.
        tolerance: the goal's tolerances (`mechbal.verdict.DEFAULT_TOLERANCE`; ``joint``: the
            largest |q_des - q| that counts as tracking [rad or m]).
        **engine_options: with ``engine="mujoco"``, the options of
            `mechbal.export.mujoco_engine.co_simulate` (``substeps``, ``integrator``,
            ``solref``, ``solimp``, ``minimum_mass``, ``constraint_weight``).

    Returns:
        `ClosedLoopResult`, with its ``verdict`` (`judge_closed_loop`). A plant failure (an
        unassemblable pose, a non-finite state) stops the integration and shows in ``status``,
        ``steps_completed`` and ``ok``; it does not raise.
    """
    import dataclasses

    result = _closed_loop(mechanism_or_plant, controller, trajectory, q0, v0, dt=dt, duration=duration,
                          sampling=sampling, q_guess=q_guess, engine=engine, **engine_options)
    inner = getattr(controller, "joint_controller", None) or controller
    return dataclasses.replace(result, verdict=judge_closed_loop(result, inner, mechanism_or_plant, tolerance))


def _closed_loop(mechanism_or_plant: Any, controller: Any, trajectory: Any, q0: Any, v0: Any, *, dt: float,
                 duration: float | None, sampling: str, q_guess: Any, engine: str,
                 **engine_options: Any) -> ClosedLoopResult:
    from mechbal.trajectory import RestToRest, as_trajectory

    if hasattr(controller, "joint_controller"):  # a ReactionlessController with its CT stage
        if controller.joint_controller is None:
            raise TypeError("a ReactionlessController drives a plant through its computed-torque "
                            "stage: construct it with kp and kd")
        controller = controller.joint_controller
    if engine == "mujoco":
        return _closed_loop_mujoco(mechanism_or_plant, controller, trajectory, q0, v0, dt=dt,
                                   duration=duration, sampling=sampling, q_guess=q_guess, **engine_options)
    if engine != "mechbal":
        raise ValueError(f"engine must be 'mechbal' or 'mujoco', got {engine!r}")
    if engine_options:
        raise TypeError(f"unexpected options for the mechbal engine: {', '.join(engine_options)}")
    plant = _plant(mechanism_or_plant, q_guess)
    if not isinstance(controller, _core.JointController):
        raise TypeError("controller must be a joint controller (mechbal.control.ComputedTorque, "
                        f"DecoupledJointController), got {type(controller).__name__}")
    traj = as_trajectory(trajectory)
    if duration is None:  # until the motion ends (a trajectory may start after t = 0)
        duration = float(getattr(traj, "end_time", traj.duration))
    dt, duration = _check_timing(dt, duration)
    q_start, v_start, _ = traj.evaluate(0.0)
    q0 = q_start if q0 is None else q0
    v0 = v_start if v0 is None else v0
    if isinstance(traj, RestToRest):
        log = _core.simulate_closed_loop(plant, controller, traj.core, q0, v0, dt, duration,
                                         sampling)
    else:
        steps = int(round(duration / dt))
        q_des, v_des, a_des = traj.evaluate(np.arange(2 * steps + 1) * (0.5 * dt))
        log = _core.simulate_closed_loop_sampled(plant, controller, q_des, v_des, a_des, q0,
                                                 v0, dt, duration, sampling)
    return ClosedLoopResult(t=np.asarray(log["t"]), q=np.asarray(log["q"]),
                            v=np.asarray(log["v"]), q_des=np.asarray(log["q_des"]),
                            v_des=np.asarray(log["v_des"]), joint_torque=np.asarray(log["tau"]),
                            status=np.asarray(log["tick_status"]),
                            saturated_ticks=int(log["saturated_ticks"]),
                            steps_completed=int(log["steps_completed"]))


def _closed_loop_mujoco(mech: Any, controller: Any, trajectory: Any, q0: npt.ArrayLike | None,
                        v0: npt.ArrayLike | None, *, dt: float, duration: float | None,
                        sampling: str, q_guess: npt.ArrayLike | None,
                        **options: Any) -> ClosedLoopResult:
    from mechbal.mechanism import Mechanism

    if not isinstance(mech, Mechanism):
        raise TypeError("engine='mujoco' simulates a mechbal.Mechanism (exported to MJCF), got "
                        f"{type(mech).__name__}")
    if sampling != "zero_order_hold":
        raise ValueError("engine='mujoco' ticks the controller once per dt (sampling='zero_order_hold')")
    if not isinstance(controller, _core.JointController):
        raise TypeError("controller must be a joint controller (mechbal.control.ComputedTorque, "
                        f"DecoupledJointController), got {type(controller).__name__}")
    from mechbal.export.mujoco_engine import co_simulate  # the optional engine (mechbal[mujoco])

    r = co_simulate(mech, controller, trajectory, q0, v0, dt=dt, duration=duration, q_guess=q_guess,
                    **options)
    return ClosedLoopResult(t=r.t, q=r.q, v=r.v, q_des=r.q_des, v_des=r.v_des,
                            joint_torque=r.joint_torque, status=r.status,
                            saturated_ticks=r.saturated_ticks, steps_completed=r.steps_completed,
                            mujoco=r)


def _on_stops(plant: Any, q: FloatArray, v: FloatArray, a: FloatArray, lower: FloatArray,
              upper: FloatArray) -> None:
    """The accelerations ``a`` (rows of the free motion, changed in place) where a joint rests on
    a stop: the stops' efforts hold those joints (their acceleration 0) where the free motion
    would push them through, through the inverse mass matrix (an active set: a stop only pushes)."""
    n = q.shape[1]
    zero = np.zeros(n)
    for k in range(q.shape[0]):
        side = np.where(q[k] >= upper, 1.0, np.where(q[k] <= lower, -1.0, 0.0))
        active = [i for i in range(n) if side[i] != 0.0 and side[i] * a[k, i] > 0.0 and side[i] * v[k, i] >= 0.0]
        if not active:
            continue
        a0 = np.asarray(plant.forward_dynamics(q[k], v[k], zero), float)
        W = np.empty((n, n))
        for i in range(n):
            e = np.zeros(n)
            e[i] = 1.0
            W[:, i] = np.asarray(plant.forward_dynamics(q[k], v[k], e), float) - a0
        for _ in range(n):
            lam = np.linalg.solve(W[np.ix_(active, active)], -a0[active])
            keep = [i for i, x in zip(active, lam) if side[i] * x <= 0.0]   # a stop pushes back
            if keep == active:
                a[k] = a0 + W[:, active] @ lam
                break
            active = keep
            if not active:
                break


@dataclass(frozen=True)
class PassiveResult:
    """A passive run (`passive`), one row per step k = 0 .. steps (t_k = k dt):

    * ``t`` (N,) [s];
    * ``q``, ``v`` (N, na): the actuated coordinates and their rates (every coordinate of an open
      mechanism) [rad or m, rad/s or m/s];
    * ``q_full``, ``v_full``, ``a_full`` (N, dof): every coordinate (the loops solved), its rate
      and acceleration (forward dynamics at zero effort);
    * ``kinetic_energy``, ``potential_energy`` (N,) [J]: 1/2 v^T M v, and gravity (zero at O) plus
      springs; their sum ``energy`` is conserved by the exact motion (no effort, no friction);
    * ``status`` (N,): per step (0 = ok); ``steps_completed`` as `ClosedLoopResult`;
    * ``stop_steps``: steps that ended with a joint on one of its limits (an inelastic end stop;
      `passive`'s ``joint_limits``); ``on_stop`` (N, na): which joint is on a stop at each step.
      The energy is conserved only up to the first impact.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    q_full: np.ndarray
    v_full: np.ndarray
    a_full: np.ndarray
    kinetic_energy: np.ndarray
    potential_energy: np.ndarray
    status: np.ndarray
    steps_completed: int
    stop_steps: int = 0
    on_stop: np.ndarray | None = None

    @property
    def energy(self) -> np.ndarray:
        """Kinetic plus potential energy (N,) [J]."""
        return self.kinetic_energy + self.potential_energy

    @property
    def energy_drift(self) -> float:
        """Largest |energy - energy at t = 0| [J] over the run, or up to the first step on a stop
        (an impact dissipates energy): the integrator's error."""
        e = self.energy
        if self.on_stop is not None and np.any(self.on_stop):
            e = e[:max(1, int(np.argmax(np.any(self.on_stop, axis=1))))]
        return float(np.max(np.abs(e - e[0])))

    @property
    def ok(self) -> bool:
        """True when every step's status is 0 (ok)."""
        return bool(np.all(self.status == 0))


def passive(mech: Any, q0: npt.ArrayLike, v0: npt.ArrayLike | None = None, *, dt: float = 1e-3,
            duration: float = 1.0, q_guess: npt.ArrayLike | None = None,
            joint_limits: bool = True) -> PassiveResult:
    """Passive simulation: no controller, zero joint effort; ``mech`` (a `mechbal.Mechanism`,
    closed loops included) moves under gravity and its springs from ``q0`` (actuated coordinates,
    every coordinate of an open mechanism) [rad or m] with rates ``v0`` (default at rest), RK4 with
    step ``dt`` [s] for ``duration`` [s] (the closed loop of `closed_loop` with
    `mechbal.control.PassiveController`). ``q_guess``: the full coordinates near the
    assembly of a closed mechanism (its branch). The result carries the energy along the run, the
    invariant of an unforced motion while no joint is on a stop.

    ``joint_limits`` (default True): the declared position limits of the actuated joints (URDF
    ``<limit lower upper>``, case ``limits``) are inelastic end stops (C++
    ``ClosedLoopOptions::lower_limit / upper_limit``): a joint that reaches one is put back on it
    and its rate towards it removed by an impulse through the inverse mass matrix (the other joints
    take the reaction); it rests there while the load pushes it in, and leaves when the load pulls
    it away. An impact loses energy (no bounce): the result's ``stop_steps`` counts the steps that
    ended on a stop. False: the joints pass their limits (the unconstrained dynamics). ``q0``
    must lie within the limits (ValueError naming the joint otherwise)."""
    from mechbal.mechanism import Mechanism

    if not isinstance(mech, Mechanism):
        raise TypeError(f"passive simulates a mechbal.Mechanism, got {type(mech).__name__}")
    na = len(mech.model.actuated_coordinates)
    q0 = np.asarray(q0, dtype=float).reshape(-1)
    v0 = np.zeros(na) if v0 is None else np.asarray(v0, dtype=float).reshape(-1)
    for name, x in (("q0", q0), ("v0", v0)):
        if x.shape != (na,):
            raise ValueError(f"{name} must have {na} values (the actuated coordinates: "
                             f"{', '.join(mech.actuated_names)}), got {x.size}")
        if not np.all(np.isfinite(x)):
            raise ValueError(f"{name} must be finite")
    dt, duration = _check_timing(dt, duration)
    coords = list(mech.model.actuated_coordinates)
    lower = np.asarray(mech.model.lower_limits, float)[coords]
    upper = np.asarray(mech.model.upper_limits, float)[coords]
    if not joint_limits:
        lower, upper = np.full(na, -np.inf), np.full(na, np.inf)
    names = mech.actuated_names
    for i in range(na):
        if not lower[i] <= q0[i] <= upper[i]:
            raise ValueError(f"q0[{i}] = {q0[i]!r} ({names[i]}) is outside the joint's limits "
                             f"[{lower[i]!r}, {upper[i]!r}] (joint_limits=False lets it pass them)")
    guess = np.zeros(mech.dof) if q_guess is None else np.asarray(q_guess, float)
    plant = _core.MechanismDynamics(mech.model, guess)
    log = _core.simulate_passive(plant, q0, v0, dt, duration, lower, upper)
    q, v = np.asarray(log["q"]), np.asarray(log["v"])
    plant = _core.MechanismDynamics(mech.model, guess)   # accelerations at zero effort
    zero = np.zeros(na)
    aa = np.array([plant.forward_dynamics(qk, vk, zero) for qk, vk in zip(q, v)]).reshape(q.shape)
    if int(log["stop_ticks"]):
        _on_stops(plant, q, v, aa, lower, upper)
    if mech.is_closed:
        m = mech.closed_motion(q, v, aa, q_guess=guess)
        qf, vf, af = m.q, m.v, m.a
    else:
        qf, vf, af = q, v, aa
    M = mech.mass_matrix(qf)
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", vf, M, vf)
    potential = np.asarray(mech.potential_energy(qf), float)
    return PassiveResult(t=np.asarray(log["t"]), q=q, v=v, q_full=qf, v_full=vf, a_full=af,
                         kinetic_energy=kinetic, potential_energy=potential,
                         status=np.asarray(log["tick_status"]),
                         steps_completed=int(log["steps_completed"]), stop_steps=int(log["stop_ticks"]),
                         on_stop=(q <= lower) | (q >= upper))
