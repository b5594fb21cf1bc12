"""Real-time controllers of balanced robots, from Python: tick by tick and in batch.

The classes here are the C++ controllers themselves (Python subclasses that add named results):
a tick from Python runs the same ``noexcept``, allocation-free ``step()`` an embedded 1 kHz loop
calls.

* `ComputedTorque`: `tau = M(q) (a_des + Kp e + Kd e') + C(q, v) v + G(q)` over any
  dynamics back end (Arakelian, Le Baron & Mottu 2011, eqs 2-6);
* `DecoupledJointController`: `tau_i = k_i (a_des + Kp e + Kd e')` for a dynamically balanced
  arm whose mass matrix is diagonal and constant (Coutinho & Hess Coelho, eqs 15, 26, 36);
* `PassiveController`: no controller, zero effort every tick (a passive simulation: gravity and
  springs move the mechanism; `mechbal.simulate.passive`);
* `ReactionlessController`: reactionless control of any mechanism: balancing joints keep chosen
  momentum components at their target, ``A_b v_b = h* - A_t v_t`` (the PAMINSA wrist is a special
  case); with gains it also drives a computed-torque stage usable in
  `mechbal.simulate.closed_loop`.

Three ways to tick a joint controller (``n`` joints; positions in rad or m, velocities in rad/s
or m/s, accelerations in rad/s^2 or m/s^2, torques in N m or forces in N):

* ``step(q, v, q_des, v_des, a_des) -> JointCommand(joint_torque, status)``: any real
  array-like input;
* ``step_into(q, v, q_des, v_des, a_des, out) -> int``: the fast tick (about a microsecond;
  ``bench/bench_python.py``): C-contiguous float64 arrays only, the torque written into the
  preallocated ``out``, the status returned;
* ``run(q, v, q_des, v_des, a_des) -> ControlRun``: N consecutive ticks over (N, n) arrays
  in one C++ call.

The keyword names of earlier releases (``qd``, ``qd_des``, ``qdd_des``) still work for one
release and raise a `DeprecationWarning`.

Statuses are bit flags of `mechbal.Status` (0 = ok), one per tick (``status`` arrays in
batch results, as in every batch result of mechbal). Non-finite or out-of-range input never
raises in a tick: it returns the held (last safe) command and a non-ok status.

The dynamics back ends a `ComputedTorque` computes over are here too:
`MechanismDynamics` (the general model, any mechanism, closed loops included),
`KdlChainDynamics` (Orocos KDL on a serial MechanismModel, the independent engine), and the
papers' closed forms in `mechbal.papers`. Their ``inverse_dynamics(q, v, a)`` returns an
`InverseDynamicsResult` (``joint_torque``, ``support_force``, ``support_moment``, ``status``).

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, ClassVar, NamedTuple

import numpy as np
import numpy.typing as npt

import mechbal._core as _core
from mechbal._deprecation import DeprecatedAttributes, renamed_kwargs, renamed_method_kwargs

__all__ = [
    "ComputedTorque", "DecoupledJointController", "PassiveController", "JointController", "JointCommand",
    "ControlRun", "InverseDynamics", "ForwardDynamics",
    "MechanismDynamics", "KdlChainDynamics", "InverseDynamicsResult", "Status", "status_text",
    "ReactionlessController", "ReactionlessCommand", "ReactionlessRun", "ReactionlessJointController",
    "ReactionlessTaskController", "TaskSpaceRun", "declared_options", "declared_torque_limit",
    "joint_controller", "feasibility", "FeasibilityReport", "LimitDemand", "FrameMotion",
]

Status = _core.Status
JointController = _core.JointController
InverseDynamics = _core.InverseDynamics
ForwardDynamics = _core.ForwardDynamics


def status_text(status: int) -> str:
    """The names of the flags set in a status (``"ok"`` for 0), e.g. ``"saturated"``."""
    return str(_core.status_name(int(status)))


FloatArray = npt.NDArray[np.float64]
StatusArray = npt.NDArray[np.uint32]


@dataclass(frozen=True)
class InverseDynamicsResult(DeprecatedAttributes):
    """Inverse dynamics of a dynamics back end (`MechanismDynamics`, `KdlChainDynamics`):
    ``joint_torque`` (N, dof) [N m or N], the wrench the base exerts on the chain
    ``support_force`` [N] and ``support_moment`` about the base origin [N m] (N, 3), and
    ``status`` (N,) per instant (instants with non-finite input give zeros and their flag). A
    single sample (1-D q, v, a) gives (dof,), (3,), (3,) and a 0-d ``status``.

    The dict of earlier releases is read for one release with a DeprecationWarning:
    ``result["tau"]``, ``["support_force"]``, ``["support_moment"]``, ``["status"]`` (the OR of
    every instant's flags) and ``["status_per_instant"]``."""

    joint_torque: FloatArray
    support_force: FloatArray
    support_moment: FloatArray
    status: StatusArray

    _renamed: ClassVar[dict[str, str]] = {"tau": "joint_torque"}
    _dict_keys: ClassVar[dict[str, str]] = {
        "tau": "joint_torque", "support_force": "support_force",
        "support_moment": "support_moment", "status": "status", "status_per_instant": "status"}

    def _dict_value(self, key: str, attribute: str) -> Any:
        if key == "status":
            return int(np.bitwise_or.reduce(np.atleast_1d(self.status)))
        if key == "status_per_instant":
            return np.atleast_1d(self.status)
        return getattr(self, attribute)

    @property
    def ok(self) -> bool:
        """True when every instant's status is 0 (ok)."""
        return bool(np.all(self.status == 0))


def _states(where: str, dof: int, **arrays: npt.ArrayLike) -> tuple[bool, list[FloatArray]]:
    """(single, [(N, dof) float64 C-contiguous arrays]) from (dof,) or (N, dof) array-likes; a
    ValueError / TypeError naming the argument otherwise."""
    out: list[FloatArray] = []
    single: bool | None = None
    first = ""
    for name, value in arrays.items():
        a = np.asarray(value)
        if a.dtype.kind not in "iuf":
            raise TypeError(f"{where}: {name} must be real numbers (int or float), got dtype "
                            f"{a.dtype}")
        if a.ndim not in (1, 2) or a.shape[-1] != dof:
            raise ValueError(f"{where}: {name} must have shape ({dof},) or (N, {dof}), got "
                             f"{a.shape}")
        is_single = a.ndim == 1
        a2 = a.reshape(1, -1) if is_single else a
        if a2.dtype.char != "d" or not a2.flags.c_contiguous:  # not float64 C-contiguous
            a2 = np.ascontiguousarray(a2, dtype=np.float64)
        if single is None:
            single, first = is_single, name
        elif is_single != single or a2.shape[0] != out[0].shape[0]:
            raise ValueError(f"{where}: {name} has shape {a.shape}, which does not match {first} "
                             f"{np.shape(arrays[first])}")
        out.append(a2)
    return bool(single), out


def _inverse_dynamics(backend: Any, base: Any, q: npt.ArrayLike, v: npt.ArrayLike,
                      a: npt.ArrayLike) -> InverseDynamicsResult:
    where = f"{type(backend).__name__}.inverse_dynamics"
    single, (q2, v2, a2) = _states(where, int(backend.dof), q=q, v=v, a=a)
    r = base.inverse_dynamics(backend, q2, v2, a2)
    tau = np.asarray(r["tau"])
    force = np.asarray(r["support_force"])
    moment = np.asarray(r["support_moment"])
    status = np.asarray(r["status_per_instant"], dtype=np.uint32)
    if single:
        if status[0] != 0:
            raise ValueError(f"{where}: input rejected ({status_text(int(status[0]))}); q, v, a "
                             "must be finite and give finite results")
        return InverseDynamicsResult(tau[0], force[0], moment[0], status[0, ...])
    return InverseDynamicsResult(tau, force, moment, status)


class MechanismDynamics(_core.MechanismDynamics):
    """Joint-space dynamics of a ``MechanismModel`` in its actuated coordinates (recursive
    Newton-Euler inverse dynamics with the base support wrench, composite rigid body mass matrix,
    loops solved each call, warm-started from ``q_guess``): the dynamics back end of the general
    model for `ComputedTorque` and the simulators.

    Args:
        model: the ``MechanismModel`` (``Mechanism.model``).
        q_guess: every coordinate near the assembly [rad or m] (closed loops; default: none).

    ``inverse_dynamics(q, v, a)`` -> `InverseDynamicsResult`; ``forward_dynamics(q, v, tau)``,
    ``bias(q, v)``, ``coriolis(q, v)``, ``mass_matrix(q)``, ``gravity(q)``,
    ``static_torque(q)`` -> arrays (one sample).
    """

    @renamed_kwargs(qd="v", qdd="a")
    def inverse_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
                         a: npt.ArrayLike) -> InverseDynamicsResult:
        """Joint torques and the base support wrench at one sample ((dof,) each) or N samples
        ((N, dof) each): `InverseDynamicsResult`."""
        return _inverse_dynamics(self, _core.MechanismDynamics, q, v, a)

    @renamed_kwargs(qd="v")
    def forward_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
                         tau: npt.ArrayLike) -> FloatArray:
        """Accelerations a = M^-1 (tau - b) (dof,) [rad/s^2 or m/s^2] at one sample."""
        return np.asarray(super().forward_dynamics(q, v, tau))

    @renamed_kwargs(qd="v")
    def bias(self, q: npt.ArrayLike, v: npt.ArrayLike) -> FloatArray:  # type: ignore[override]
        """Bias torques C(q, v) v + G(q) + K(q) (springs included) (dof,) [N m or N]."""
        return np.asarray(super().bias(q, v))

    @renamed_kwargs(qd="v")
    def coriolis(self, q: npt.ArrayLike, v: npt.ArrayLike) -> FloatArray:  # type: ignore[override]
        """Coriolis and centrifugal torques C(q, v) v (dof,) [N m or N]."""
        return np.asarray(super().coriolis(q, v))


class KdlChainDynamics(_core.KdlChainDynamics):
    """Joint-space dynamics of a serial ``MechanismModel`` through Orocos KDL (the independent
    engine; bodies lumped per link); ValueError naming the link or joint when the model is not a
    serial chain.

    Args:
        model: the ``MechanismModel`` (``Mechanism.model``).

    ``inverse_dynamics(q, v, a)`` -> `InverseDynamicsResult` (KDL's ``ChainIdSolver_RNE``);
    ``coriolis(q, v)``, ``mass_matrix(q)``, ``gravity(q)`` -> arrays (one sample).
    """

    @renamed_kwargs(qd="v", qdd="a")
    def inverse_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
                         a: npt.ArrayLike) -> InverseDynamicsResult:
        """Joint torques and the base support wrench at one sample ((dof,) each) or N samples
        ((N, dof) each): `InverseDynamicsResult`."""
        return _inverse_dynamics(self, _core.KdlChainDynamics, q, v, a)

    @renamed_kwargs(qd="v")
    def coriolis(self, q: npt.ArrayLike, v: npt.ArrayLike) -> FloatArray:  # type: ignore[override]
        """Coriolis and centrifugal torques C(q, v) v (dof,) [N m or N]."""
        return np.asarray(super().coriolis(q, v))


class JointCommand(NamedTuple):
    """One tick's result: ``joint_torque`` (n,) [N m or N] and its ``status`` (int, 0 = ok).
    A tuple, so ``tau, status = controller.step(...)`` works."""

    joint_torque: np.ndarray
    status: int


@dataclass(frozen=True)
class ControlRun(DeprecatedAttributes):
    """N ticks of a joint controller: ``joint_torque`` (N, n) [N m or N], ``status`` (N,).
    ``result["joint_torque"]`` and ``["status"]`` (the dict of earlier releases of
    `ReactionlessJointController.run`) still work for one release, with a DeprecationWarning."""

    joint_torque: np.ndarray
    status: np.ndarray

    _dict_keys: ClassVar[dict[str, str]] = {"joint_torque": "joint_torque", "status": "status"}


#: JointCommand from the binding's (tau, int status) tuple without a Python-level __new__
_joint_command = tuple.__new__


def _control_run(result: dict[str, Any]) -> ControlRun:
    return ControlRun(joint_torque=np.asarray(result["joint_torque"]),
                      status=np.asarray(result["status"]))


def _dynamics(model: Any, q_guess: npt.ArrayLike | None) -> Any:
    from mechbal.mechanism import Mechanism

    if isinstance(model, Mechanism):
        guess = np.zeros(model.dof) if q_guess is None else np.asarray(q_guess, dtype=float)
        return MechanismDynamics(model.model, guess)
    if q_guess is not None:
        raise ValueError("q_guess is for a Mechanism model (closed loops); a dynamics back end "
                         "was given")
    return model


class _JointTicks:
    """``step`` and ``run`` of the joint controllers (`ComputedTorque`,
    `DecoupledJointController`, `PassiveController`), mixed in before their C++ class: a tick is
    the binding's single call ``_tick`` (the status as an int) wrapped in a `JointCommand`
    without a Python-level ``__new__``; ``run`` is the binding's batch in a `ControlRun`. The
    keyword names of earlier releases (``qd``, ``qd_des``, ``qdd_des``) are renamed with a
    DeprecationWarning."""

    if TYPE_CHECKING:
        def _tick(self, q: npt.ArrayLike, v: npt.ArrayLike, q_des: npt.ArrayLike, v_des: npt.ArrayLike,
                  a_des: npt.ArrayLike) -> tuple[FloatArray, int]: ...

    @renamed_method_kwargs(qd="v", qd_des="v_des", qdd_des="a_des")
    def step(self, q: npt.ArrayLike, v: npt.ArrayLike, q_des: npt.ArrayLike,
             v_des: npt.ArrayLike, a_des: npt.ArrayLike) -> JointCommand:
        """One tick: `JointCommand` (joint_torque (n,) [N m or N], status)."""
        return _joint_command(JointCommand, self._tick(q, v, q_des, v_des, a_des))

    @renamed_method_kwargs(qd="v", qd_des="v_des", qdd_des="a_des")
    def run(self, q: npt.ArrayLike, v: npt.ArrayLike, q_des: npt.ArrayLike,
            v_des: npt.ArrayLike, a_des: npt.ArrayLike) -> ControlRun:
        """N consecutive ticks over (N, n) arrays in one C++ call: `ControlRun`."""
        return _control_run(super().run(q, v, q_des, v_des, a_des))  # type: ignore[misc]


def declared_torque_limit(model: Any, torque_limit: npt.ArrayLike | None = None) -> FloatArray | None:
    """The |tau| limit in force per actuated joint [N m or N]: the smaller of ``torque_limit``
    (when given) and the model's declared effort limits (a `mechbal.Mechanism` or a
    ``MechanismModel``; +inf where neither declares one). Another dynamics back end: the
    ``torque_limit`` given (None: no limit). No hidden limit is added."""
    m = getattr(model, "model", model)
    if not isinstance(m, _core.MechanismModel):
        return None if torque_limit is None else np.asarray(torque_limit, float)
    declared = np.asarray(m.effort_limits, float)[list(m.actuated_coordinates)]
    if torque_limit is None:
        return declared if np.any(np.isfinite(declared)) else None
    given = np.asarray(torque_limit, float).reshape(-1)
    if given.shape != declared.shape:
        return given  # the controller names the size mistake
    return np.minimum(given, declared)


def declared_options(ctl: Any) -> dict[str, float]:
    """The reactionless controllers' limits of a validated ``[control]`` table: ``max_rate``
    (balancing joints) and ``max_speed`` (the task joints' input range), +inf where the table
    declares none (the model's declared velocity limits apply in the controller either way)."""
    out = {"max_rate": float(getattr(ctl, "max_rate", None) or np.inf)}
    if getattr(ctl, "max_speed", None) is not None:
        out["max_speed"] = float(ctl.max_speed)
    return out


class ComputedTorque(_JointTicks, _core.ComputedTorque):  # type: ignore[misc]
    """Computed-torque control (Arakelian, Le Baron & Mottu 2011, eqs 2-6):
    ``tau = M(q) (a_des + Kp (q_des - q) + Kd (v_des - v)) + C(q, v) v + G(q)``, clipped
    to ``torque_limit``; with an exact model the error obeys ``e'' + Kd e' + Kp e = 0`` (eq 6).

    Args:
        model: a `mechbal.Mechanism` (its `MechanismDynamics` is built and kept) or
            any dynamics back end: `MechanismDynamics`,
            `KdlChainDynamics`, ``Arm2DofDynamics``,
            ``FiveBarDynamics`` (`mechbal.papers`). The model may differ from the plant.
        kp: proportional gains [1/s^2], one per joint.
        kd: derivative gains [1/s], one per joint.
        torque_limit: |tau| limit per joint [N m or N]; with a `mechbal.Mechanism` the joints'
            declared effort limits when smaller; default and +inf: no limit beyond the declared
            ones.
        **input_range: ``max_position``, ``max_speed``, ``max_acceleration``: the input range of a
            tick (|q| [rad or m], |v|, |a_des|; default +inf: no limit); beyond it the tick holds
            the last command with ``Status.out_of_range``.
        q_guess: with a closed-loop Mechanism, every joint coordinate near the assembly [rad or
            m] (picks the assembly mode the loop solve follows; default zeros).

    Ticks: ``step`` / ``step_into`` / ``run`` (see `mechbal.control`); ``reset()`` forgets
    the held command.
    """

    def __init__(self, model: Any, kp: npt.ArrayLike, kd: npt.ArrayLike,
                 torque_limit: npt.ArrayLike | None = None, *, q_guess: npt.ArrayLike | None = None,
                 **input_range: float):
        super().__init__(_dynamics(model, q_guess), kp, kd, declared_torque_limit(model, torque_limit),
                         **input_range)


class DecoupledJointController(_JointTicks, _core.DecoupledJointController):  # type: ignore[misc]
    """Decoupled joint control of a dynamically balanced arm (Coutinho & Hess Coelho, eqs 15,
    26, 36): ``tau_i = k_i (a_des_i + Kp_i e_i + Kd_i e'_i)``, exact when counter-rotating
    discs make the mass matrix diagonal and constant and gravity is balanced.

    Args:
        k: the constant diagonal of the mass matrix [kg m^2 or kg], one per joint.
        kp: proportional gains [1/s^2].
        kd: derivative gains [1/s].
        torque_limit: as `ComputedTorque`.

    The keywords ``max_position``, ``max_speed`` and ``max_acceleration`` bound the input of a
    tick as for `ComputedTorque`.
    """


def joint_controller(mechanism: Any, ctl: Any, *, q_guess: npt.ArrayLike | None = None) -> Any:
    """The joint controller of a validated ``[control]`` table of kind ``computed_torque`` or
    ``decoupled`` over ``mechanism`` (a `mechbal.Mechanism`), as the C++ ``make_controller``
    builds it: `ComputedTorque` over the mechanism's model, or `DecoupledJointController` with
    ``k`` (default: the diagonal of the mass matrix at q = 0, which must be diagonal: a
    dynamically balanced design); gains ``kp``, ``kd``; the |tau| limit in force
    (`declared_torque_limit`: ``torque_limit`` and the declared effort limits) and ``max_speed``
    (the input range). ValueError naming the ``control.`` field otherwise."""
    get: Callable[[str], Any] = ctl.get if isinstance(ctl, dict) else (lambda k: getattr(ctl, k, None))
    kind = get("kind")
    speed = {} if get("max_speed") is None else {"max_speed": float(get("max_speed"))}
    if kind == "computed_torque":
        return ComputedTorque(mechanism, get("kp"), get("kd"), get("torque_limit"), q_guess=q_guess, **speed)
    if kind != "decoupled":
        raise ValueError(f"control.kind: a joint controller is computed_torque or decoupled, got {kind!r}")
    k = get("k")
    if k is None:
        n = len(mechanism.actuated_names)
        dyn = _dynamics(mechanism, q_guess)
        M = np.asarray(dyn.mass_matrix(np.zeros(n)), float)
        off = M - np.diag(np.diag(M))
        scale = float(np.max(np.abs(np.diag(M))))
        if not np.all(np.isfinite(M)) or np.max(np.abs(off)) > 1e-9 * scale:
            i, j = np.unravel_index(int(np.argmax(np.abs(off))), off.shape)
            raise ValueError(f"control.k: the mass matrix at q = 0 is not diagonal (M[{i}][{j}] = {M[i, j]:.6g}): "
                             "the decoupled controller needs a dynamically balanced design, or give k")
        k = np.diag(M)
    limit = declared_torque_limit(mechanism, get("torque_limit"))
    return DecoupledJointController(k, get("kp"), get("kd"), limit, **speed)


class PassiveController(_JointTicks, _core.PassiveController):  # type: ignore[misc]
    """No controller: ``tau = 0`` every tick, so the plant moves under gravity, its springs and its
    inertia only (a free pendulum, a spring-balanced arm let go). Driving a plant with it in
    `mechbal.simulate.closed_loop` is a passive simulation (`mechbal.simulate.passive`
    does exactly that).

    Args:
        dof: number of actuated coordinates (>= 1).

    ``step`` returns a zero ``joint_torque`` (n,) and the status of the input check.
    """


@dataclass(frozen=True)
class ReactionlessCommand:
    """One reactionless tick: the actuated command ``q`` [rad or m], ``v``, ``a`` (n_actuated,)
    (task joints as given, balancing joints computed), every coordinate ``q_full``, ``v_full``,
    ``a_full`` (dof,), the momentum ``momentum`` = [P; H_O] (6,) [kg m/s, kg m^2/s] of the
    command, the predicted ``shaking_force`` [N] and ``shaking_moment`` [N m] about O (3,),
    ``condition`` (cond of the balancing block) and ``status`` (int, 0 = ok)."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    q_full: np.ndarray
    v_full: np.ndarray
    a_full: np.ndarray
    momentum: np.ndarray
    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    condition: float
    status: int


@dataclass(frozen=True)
class ReactionlessRun:
    """Ticks t_n = n dt of a reactionless run: ``t`` (N,) [s], the actuated command ``q``, ``v``,
    ``a`` (N, n_actuated), every coordinate ``q_full``, ``v_full``, ``a_full`` (N, dof),
    ``momentum`` (N, 6), predicted ``shaking_force`` [N] and ``shaking_moment`` [N m] (N, 3),
    ``condition`` (N,), ``status`` (N,)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    q_full: np.ndarray
    v_full: np.ndarray
    a_full: np.ndarray
    momentum: np.ndarray
    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    condition: np.ndarray
    status: np.ndarray


def _cancel_list(cancel: Any) -> list[str]:
    return [cancel] if isinstance(cancel, str) else [str(c) for c in cancel]


class ReactionlessController(_core.ReactionlessController):
    """Reactionless control of any mechanism (C++ ``mechbal::ReactionlessController``).

    The actuated joints are split into task joints (motion given) and ``balancing_joints``
    (motion computed each tick) so that the ``cancel``-ed components of the momentum about O,
    h = [P; H_O] = A(q) v, keep their target (the momentum at the start): with loops v = C v#,
    K = A C, and each tick solves ``S K_b v_b = S h* - S K_t v_t`` (exact, least squares or minimum
    norm with a null-space objective), damped least squares near singularity
    (``Status.singular``). The balancing accelerations ``S K_b a_b = S dh*/dt - S K_t a_t - S W(q,
    v, c)`` are the feed-forward; the shaking wrench of the command is predicted. Derivation:
    ``cpp/include/mechbal/control/reactionless.hpp``.

    Args:
        mechanism: a `mechbal.Mechanism` (or a ``MechanismModel``).
        balancing_joints: names of actuated joints.
        cancel: ``"moment"`` (default), ``"force"``, ``"both"`` or single axes ``"moment_z"``,
            ``"force_x"``, ... (a name or a list).
        integrator: ``"euler"`` or ``"rk4"`` (needs the task motion at t + dt/2 and t + dt).
        rate_hz: tick rate [Hz].
        damping: damped least squares factor relative to the largest singular value.
        q0: actuated coordinates at the start [rad or m] (default zeros).
        v0: their rates at the start [rad/s or m/s] (default rest); the target momentum is the
            momentum there.
        q_guess: every coordinate near the assembly (closed loops).
        kp: proportional gains [1/s^2] of an optional computed-torque stage; with ``kd``,
            `joint_controller` is a joint controller for `mechbal.simulate.closed_loop`
            (which accepts this object directly).
        kd: derivative gains [1/s] of the computed-torque stage.
        torque_limit: |tau| limit per joint of the computed-torque stage [N m or N] (the joints'
            declared effort limits when smaller; default: only those).
        **options: ``max_condition``, ``max_rate`` [rad/s] (the balancing joints' declared
            velocity limits when smaller), ``max_acceleration``, ``position_limits`` (bool),
            ``home_gain``, ``limit_gain``, ``home``, ``max_position``, ``max_speed``,
            ``max_task_acceleration`` (the task input range; ``max_speed`` also the
            computed-torque stage's). Every limit defaults to +inf: no limit beyond the declared
            ones.

    Ticks: ``step(q_task, v_task, a_task[, q_half, v_half, q_next, v_next])`` ->
    `ReactionlessCommand`; ``step_into(now (3, nt), half (2, nt), next (2, nt), out (3,
    na)) -> int`` (fast, float64 arrays); `run` over a task motion sampled every dt/2;
    `follow` along a `mechbal.trajectory` of every actuated joint.
    """

    def __init__(self, mechanism: Any, balancing_joints: Any, cancel: Any = "moment",
                 integrator: str = "euler", rate_hz: float = 1000.0, damping: float = 1e-2, *,
                 q0: npt.ArrayLike | None = None, v0: npt.ArrayLike | None = None,
                 q_guess: npt.ArrayLike | None = None, kp: npt.ArrayLike | None = None,
                 kd: npt.ArrayLike | None = None, torque_limit: npt.ArrayLike | None = None,
                 **options: Any):
        model = getattr(mechanism, "model", mechanism)
        if isinstance(balancing_joints, str):
            balancing_joints = [balancing_joints]
        na = len(model.actuated_coordinates)
        q0 = np.zeros(na) if q0 is None else q0
        kwargs = dict(balancing_joints=list(balancing_joints), cancel=_cancel_list(cancel),
                      integrator=integrator, rate_hz=rate_hz, damping=damping, **options)
        super().__init__(model, q0=q0, v0=v0, q_guess=q_guess, **kwargs)
        self._model = model
        self.joint_controller = None
        if kp is not None or kd is not None:
            if kp is None or kd is None:
                raise ValueError("the computed-torque stage needs both kp and kd")
            self.joint_controller = ReactionlessJointController(
                model, q0=q0, kp=kp, kd=kd, torque_limit=declared_torque_limit(model, torque_limit),
                q_guess=q_guess, **kwargs)

    def step(self, q_task: npt.ArrayLike, v_task: npt.ArrayLike,  # type: ignore[override]
             a_task: npt.ArrayLike, q_half: npt.ArrayLike | None = None,
             v_half: npt.ArrayLike | None = None, q_next: npt.ArrayLike | None = None,
             v_next: npt.ArrayLike | None = None) -> ReactionlessCommand:
        """One tick (Euler without the half/next samples): `ReactionlessCommand`."""
        status = super().step(q_task, v_task, a_task, q_half, v_half, q_next, v_next)
        c = self.command
        return ReactionlessCommand(
            q=np.asarray(c.q), v=np.asarray(c.v), a=np.asarray(c.a), q_full=np.asarray(c.q_full),
            v_full=np.asarray(c.v_full), a_full=np.asarray(c.a_full),
            momentum=np.asarray(c.momentum), shaking_force=np.asarray(c.shaking_force),
            shaking_moment=np.asarray(c.shaking_moment), condition=float(c.condition),
            status=int(status))

    def run(self, q_task: npt.ArrayLike, v_task: npt.ArrayLike,  # type: ignore[override]
            a_task: npt.ArrayLike) -> ReactionlessRun:
        """Ticks along the task motion sampled every dt/2 ((2 steps + 1, n_task) each, from
        this controller's current state): `ReactionlessRun` at the steps + 1 ticks."""
        r = super().run(q_task, v_task, a_task)
        N = np.asarray(r["q"]).shape[0]
        return ReactionlessRun(t=np.arange(N) * self.dt,
                               **{k: np.asarray(v) for k, v in r.items()})

    def follow(self, trajectory: Any, duration: float | None = None) -> ReactionlessRun:
        """Ticks along a trajectory of every actuated joint (a `mechbal.trajectory` object;
        the balancing joints' entries are ignored) from t = 0 to ``duration`` (default its end)."""
        from mechbal.trajectory import as_trajectory

        traj = as_trajectory(trajectory)
        if duration is None:
            duration = float(getattr(traj, "end_time", traj.duration))
        from mechbal.tables import check_run_ticks

        check_run_ticks(duration, 1.0 / self.dt, "duration")  # bounded work before the run
        steps = int(round(duration / self.dt))
        q, v, a = traj.evaluate(np.arange(2 * steps + 1) * (0.5 * self.dt))
        task = list(self.task_indices)
        return self.run(np.ascontiguousarray(np.atleast_2d(q)[:, task]),
                        np.ascontiguousarray(np.atleast_2d(v)[:, task]),
                        np.ascontiguousarray(np.atleast_2d(a)[:, task]))


class ReactionlessJointController(_JointTicks, _core.ReactionlessJointController):  # type: ignore[misc]
    """The reactionless controller followed by computed torque over the model (C++
    ``mechbal::ReactionlessJointController``): a joint controller over the actuated coordinates
    whose balancing joints follow the reactionless command (their desired entries are ignored),
    for `mechbal.simulate.closed_loop`; `ReactionlessController` with ``kp`` and ``kd`` builds
    one (its ``joint_controller``).

    Built as ``ReactionlessJointController(model, balancing_joints, q0, kp, kd, **options)``
    (the constructor is the C++ one):

    - ``model``: the ``MechanismModel``;
    - ``balancing_joints``: names of actuated joints;
    - ``q0``: actuated coordinates at the start [rad or m];
    - ``kp``: proportional gains [1/s^2], one per actuated joint; ``kd``: derivative gains [1/s];
    - ``options``: as `ReactionlessController` (``cancel``, ``integrator``, ``rate_hz``, ...),
      and ``torque_limit``, ``q_guess``.

    Ticks: ``step`` -> `JointCommand`, ``step_into``, ``run`` -> `ControlRun` (see
    `mechbal.control`); ``reactionless``: the reactionless controller inside.
    """


@dataclass(frozen=True)
class TaskSpaceRun:
    """Ticks t_n = n dt of an operational-space run: ``t`` (N,) [s], the command ``q``, ``v``
    and its acceleration feed-forward ``a`` (N, dof), its ``momentum`` [P; H_O] (N, 6), the
    frame's commanded ``frame_twist`` [v; w] (N, 6), the predicted ``shaking_force`` [N] and
    ``shaking_moment`` [N m] about O of the command (N, 3) and ``status`` (N,)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    momentum: np.ndarray
    frame_twist: np.ndarray
    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    status: np.ndarray


class ReactionlessTaskController(_core.ReactionlessTaskController):
    """Operational-space reactionless control (the reaction null space): a redundant open
    mechanism follows a desired twist of ``task_frame`` with ``v = J^+ x' + N z``, where ``z``
    minimises the ``cancel``-ed momentum components (their departure from the momentum at the
    start) within the task's null space (C++ ``mechbal::ReactionlessTaskController``). The
    acceleration feed-forward ``a = J^+ (x'' - J'v) + N w``, ``w = (S A N)^+ (-S W(q, v, 0) - S A
    J^+ (x'' - J'v))``, is the joint mode's ``S K_b a_b = S dh*/dt - S K_t a_t - S W`` in the null
    space (derivation: ``cpp/include/mechbal/control/reactionless.hpp``).

    Args:
        mechanism: a `mechbal.Mechanism` (open, every joint actuated).
        task_frame: a named frame of the mechanism.
        task_rows: the tracked twist components: ``"all"``, ``"linear"``, ``"angular"`` or
            ``"v_x"``, ..., ``"w_z"`` (a name or a list; O axes).
        cancel: the momentum components minimised, as `ReactionlessController`.
        integrator: ``"euler"`` or ``"rk4"``.
        rate_hz: tick rate [Hz].
        damping: damped least squares factor relative to the largest singular value.
        null_space: ``False`` drops the null-space term (``v = J^+ x'``): the reference that
            shows what the redundancy buys.
        q0: every coordinate at the start [rad or m] (default zeros).
        v0: every rate at the start [rad/s or m/s] (default rest).
        **options: ``max_condition``, ``max_rate`` [rad/s].
    """

    def __init__(self, mechanism: Any, task_frame: str, task_rows: Any = "all", cancel: Any = "moment",
                 integrator: str = "euler", rate_hz: float = 1000.0, damping: float = 1e-2, *,
                 null_space: bool = True, q0: npt.ArrayLike | None = None,
                 v0: npt.ArrayLike | None = None, **options: Any):
        model = getattr(mechanism, "model", mechanism)
        q0 = np.zeros(model.dof) if q0 is None else q0
        super().__init__(model, task_frame, _cancel_list(task_rows), _cancel_list(cancel), integrator,
                         rate_hz, damping, null_space=bool(null_space), q0=q0, v0=v0, **options)

    def run(self, twist: npt.ArrayLike,  # type: ignore[override]
            twist_rate: npt.ArrayLike | None = None) -> TaskSpaceRun:
        """Ticks along the desired frame twist [v (m/s); w (rad/s)] (O axes) sampled every dt/2
        ((2 steps + 1, 6)) and, for the acceleration feed-forward, its rate [m/s^2; rad/s^2] on
        the same grid (default: estimated from the samples, second order in dt):
        `TaskSpaceRun` at the steps + 1 ticks."""
        r = super().run(twist, twist_rate)
        N = np.asarray(r["q"]).shape[0]
        return TaskSpaceRun(t=np.arange(N) * self.dt, **{k: np.asarray(v) for k, v in r.items()})


# ---- feasibility of a reactionless motion before the run ---------------------------------------

class FrameMotion(NamedTuple):
    """The operational-space mode's commanded motion: every joint's ``start`` [rad or m], the
    frame's desired ``twist`` [v (m/s); w (rad/s)] and ``twist_rate`` on the half-step grid
    t_j = j dt / 2 ((2 steps + 1, 6) each, O axes) and the motion's ``duration`` [s]."""

    start: Any
    twist: Any
    twist_rate: Any
    duration: float


@dataclass(frozen=True)
class LimitDemand:
    """One declared limit against what the motion needs: the ``joint``, the ``quantity``
    (``"velocity"`` [rad/s or m/s], ``"effort"`` [N m or N], ``"position"`` [rad or m]), the
    ``peak_demand`` (|value|; for a position the largest q against the upper limit, or the
    largest -q against minus the lower limit), the ``limit``, the time of the peak ``peak_time`` [s], and ``min_duration`` [s]: the
    shortest duration of the same motion (time scaling) that keeps this limit (+inf when none
    does: a position limit, or a static torque above the effort limit)."""

    joint: str
    quantity: str
    peak_demand: float
    limit: float
    peak_time: float
    min_duration: float

    @property
    def exceeded(self) -> bool:
        """True when the demand is above the limit (or not a number)."""
        return not self.peak_demand <= self.limit


@dataclass(frozen=True)
class FeasibilityReport:
    """`feasibility`'s answer: ``feasible`` (every declared limit kept at ``duration``),
    ``duration`` [s], ``min_duration`` [s] (the shortest duration of the same motion that keeps
    every limit; +inf when none does; it may be shorter than ``duration``), every checked limit
    (``limits``, `LimitDemand`), and the motion's peak demand per actuated joint:
    ``peak_velocity`` [rad/s or m/s], ``peak_acceleration`` [rad/s^2 or m/s^2], ``peak_torque``
    [N m or N] (dicts by joint name)."""

    feasible: bool
    duration: float
    min_duration: float
    limits: tuple
    peak_velocity: dict
    peak_acceleration: dict
    peak_torque: dict

    @property
    def exceeded(self) -> list:
        """The limits the motion exceeds at ``duration``, worst first (by min_duration)."""
        return sorted((x for x in self.limits if x.exceeded), key=lambda x: -x.min_duration)

    def line(self) -> str:
        """One line: the worst exceeded limit (joint, peak demand, limit) and the shortest
        feasible duration; "feasible" otherwise."""
        if self.feasible:
            return f"feasible at {self.duration:g} s (the shortest duration keeping every limit: {self.min_duration:.4g} s)"
        w = self.exceeded[0]
        unit = {"velocity": "rad/s or m/s", "effort": "N m or N", "position": "rad or m"}[w.quantity]
        more = len(self.exceeded) - 1
        fit = (f"the same motion keeps every limit in {self.min_duration:.4g} s or longer (--fit-duration runs it so)"
               if np.isfinite(self.min_duration) else "no duration of the same motion keeps it")
        return (f"{w.joint} needs {w.quantity} {w.peak_demand:.4g} (at t = {w.peak_time:.4g} s) against its declared "
                f"limit {w.limit:.4g} {unit} in {self.duration:g} s" + (f" (and {more} more limits)" if more else "")
                + f": {fit}")

    def summary(self) -> dict:
        """The report as summary.json's ``feasibility`` (durations [s], demands and limits in SI)."""
        return {"feasible": self.feasible, "duration": self.duration,
                "min_duration": self.min_duration if np.isfinite(self.min_duration) else None,
                "limits": [dict(joint=x.joint, quantity=x.quantity, peak_demand=x.peak_demand, limit=x.limit,
                                peak_time=x.peak_time, exceeded=x.exceeded,
                                min_duration=x.min_duration if np.isfinite(x.min_duration) else None)
                           for x in self.limits],
                "peak_velocity": self.peak_velocity, "peak_acceleration": self.peak_acceleration,
                "peak_torque": self.peak_torque}


def _ctl(control: Any, key: str, default: Any = None) -> Any:
    if isinstance(control, dict):
        return control.get(key, default)
    value = getattr(control, key, default)
    return default if value is None else value


def feasibility(mechanism: Any, control: Any, motion: Any, *, q_guess: npt.ArrayLike | None = None) -> FeasibilityReport:
    """What a reactionless motion needs, computed open loop before any simulation, against the
    declared limits (the joints' velocity and effort limits, ``[control]`` ``max_rate``,
    ``max_speed``, ``torque_limit``; the balancing joints' position limits).

    The reactionless controller is run without any limit over the commanded motion (the momentum
    equation, joint or operational-space mode): the rates and accelerations of every actuated
    joint, and their torques (inverse dynamics of the commanded motion, gravity and springs
    included). Time scaling: started at rest, the same motion run in a duration T' follows the
    same path (the momentum equation is homogeneous in the rates), so its rates scale by T / T'
    and the torques' inertial part by (T / T')^2 (the static part stays): each limit's shortest
    duration follows exactly (not exact with ``home_gain`` or ``limit_gain``, which are not
    homogeneous).

    Args:
        mechanism: a `mechbal.Mechanism`.
        control: the ``[control]`` table (validated, or a dict): ``balancing_joints`` (joint
            mode) or ``task_frame`` (and ``task_rows``), ``cancel``, ``integrator``,
            ``rate_hz``, ``damping``, ``max_rate``, ``max_speed``, ``torque_limit``,
            ``home_gain``, ``limit_gain``.
        motion: joint mode: a `mechbal.trajectory` of every actuated joint (the balancing joints'
            entries are ignored; they start at its start); operational-space mode: a
            `FrameMotion`.
        q_guess: closed mechanisms: every coordinate near the assembly.

    Returns:
        `FeasibilityReport`.
    """
    from mechbal import verdict as vd
    from mechbal.trajectory import as_trajectory

    mech = mechanism
    names = list(mech.actuated_names)
    from mechbal.tables import check_run_ticks

    rate_hz = float(_ctl(control, "rate_hz", 1000.0))
    dt = 1.0 / rate_hz
    cancel = _cancel_list(_ctl(control, "cancel", ["moment"]))
    integrator = _ctl(control, "integrator", "rk4")
    damping = float(_ctl(control, "damping", 1e-2))
    frame = _ctl(control, "task_frame")
    if frame is not None:
        if not isinstance(motion, FrameMotion):
            raise TypeError("the operational-space mode (task_frame) takes a mechbal.control.FrameMotion")
        duration = float(motion.duration)
        check_run_ticks(duration, rate_hz, "rate_hz")
        steps = int(round(duration / dt))
        rows = _ctl(control, "task_rows", ["all"])
        task_ctrl = ReactionlessTaskController(mech, frame, rows, cancel, integrator, rate_hz, damping,
                                               q0=np.asarray(motion.start, float), max_rate=np.inf,
                                               velocity_limits=False)
        tr = task_ctrl.run(motion.twist, motion.twist_rate)
        q, v, a = tr.q, tr.v, tr.a
        q_full, v_full, a_full = q, v, a
        balancing = names
    else:
        traj = as_trajectory(motion)
        duration = float(getattr(traj, "duration"))
        check_run_ticks(duration, rate_hz, "rate_hz")
        steps = int(round(duration / dt))
        th = np.arange(2 * steps + 1) * (0.5 * dt)
        qa, va, aa = (np.atleast_2d(x) for x in traj.evaluate(th))
        balancing = list(_ctl(control, "balancing_joints", []))
        task = [i for i, n in enumerate(names) if n not in balancing]
        ctrl = ReactionlessController(mech, balancing, cancel, integrator, rate_hz, damping, q0=qa[0], v0=va[0],
                                      q_guess=q_guess, max_rate=np.inf, velocity_limits=False,
                                      position_limits=False, home_gain=float(_ctl(control, "home_gain", 0.0)),
                                      limit_gain=float(_ctl(control, "limit_gain", 0.0)))
        r = ctrl.run(np.ascontiguousarray(qa[:, task]), np.ascontiguousarray(va[:, task]),
                     np.ascontiguousarray(aa[:, task]))
        q, v, a = r.q, r.v, r.a
        q_full, v_full, a_full = r.q_full, r.v_full, r.a_full
    t = np.arange(len(q)) * dt
    # torques of the commanded motion: the whole, and its static part (gravity, springs)
    if mech.is_closed:
        m = mech.closed_motion(q, v, a, q_guess=q_guess, with_forces=True)
        tau = np.asarray(m.actuated_force)
        static = np.einsum("ndk,nd->nk", np.asarray(m.projection), np.asarray(mech.static_torque(m.q)))
    else:
        tau = np.asarray(mech.inverse_dynamics(q_full, v_full, a_full))
        static = np.asarray(mech.static_torque(q_full))
    inertial = tau - static
    limits = vd.limits_in_force(mech, control, balancing=balancing)
    checks = []
    model = mech.model
    coords = list(model.actuated_coordinates)
    for j, name in enumerate(names):
        lim = limits.get(name, {})
        if "velocity" in lim:
            x = np.abs(v[:, j])
            k = int(np.argmax(x))
            checks.append(LimitDemand(name, "velocity", float(x[k]), lim["velocity"], float(t[k]),
                                      duration * float(x[k]) / lim["velocity"]))
        if "effort" in lim:
            L = lim["effort"]
            x = np.abs(tau[:, j])
            k = int(np.argmax(x))
            # |c i + s| <= L for every sample, c = (T / T')^2: c <= (L - sign(i) s) / |i|
            i_, s_ = inertial[:, j], static[:, j]
            if np.any(np.abs(s_) > L):
                shortest = np.inf
            else:
                moving = np.abs(i_) > 0
                c = np.min((L - np.sign(i_[moving]) * s_[moving]) / np.abs(i_[moving])) if np.any(moving) else np.inf
                shortest = duration / np.sqrt(c) if c > 0 else np.inf
            checks.append(LimitDemand(name, "effort", float(x[k]), L, float(t[k]), float(shortest)))
        if name in balancing:   # the path does not depend on the duration: no duration fixes it
            lo, hi = float(model.lower_limits[coords[j]]), float(model.upper_limits[coords[j]])
            for bound, sign in ((hi, 1.0), (lo, -1.0)):
                if np.isfinite(bound):
                    x = sign * q[:, j]
                    k = int(np.argmax(x))
                    checks.append(LimitDemand(name, "position", float(x[k]), sign * bound, float(t[k]),
                                              np.inf if x[k] > sign * bound else 0.0))
    feasible = all(not x.exceeded for x in checks)
    shortest = max((x.min_duration for x in checks), default=0.0)
    peak = lambda x: {n: float(np.max(np.abs(x[:, j]))) for j, n in enumerate(names)}  # noqa: E731
    return FeasibilityReport(feasible=feasible, duration=duration, min_duration=float(shortest),
                             limits=tuple(checks), peak_velocity=peak(v), peak_acceleration=peak(a),
                             peak_torque=peak(tau))
