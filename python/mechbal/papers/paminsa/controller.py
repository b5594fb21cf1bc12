"""PAMINSA's closed-form real-time controllers (Briot & Arakelian 2009), from Python: the C++
fast paths themselves (Python subclasses that add named batch results).

* `ReactionlessWrist`: wrist rates that keep the total angular momentum constant, so the shaking
  moment is zero (eqs 23-26, corrected);
* `PaminsaController`: the fully balanced PAMINSA tick: kinematics, D (eq 19), the reactionless
  wrist and the shaking wrench.

The general reactionless controller of any mechanism is `mechbal.control.ReactionlessController`
(the PAMINSA wrist is its regression test: the ``paminsa-reactionless`` case).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

import mechbal._core as _core

__all__ = ["ReactionlessWrist", "ReactionlessWristConfig", "WristIntegrator", "WristCommand", "WristRun",
           "PaminsaController", "PaminsaRun"]

ReactionlessWristConfig = _core.ReactionlessWristConfig
WristIntegrator = _core.WristIntegrator
WristCommand = _core.WristCommand


@dataclass(frozen=True)
class WristRun:
    """N ticks of the reactionless wrist: commanded ``wrist_angles`` [rad], ``wrist_rates``
    [rad/s], ``wrist_accelerations`` [rad/s^2] (N, 3), the condition number of N(q)
    ``condition`` (N,) and ``status`` (N,)."""

    wrist_angles: np.ndarray
    wrist_rates: np.ndarray
    wrist_accelerations: np.ndarray
    condition: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class PaminsaRun:
    """A fully balanced PAMINSA run at the ticks t_n = n dt: ``shaking_force`` [N] and
    ``shaking_moment`` [N m] about O (N, 3) of all 38 bodies; ``D`` [kg m^2/s] and ``D_dot``
    [N m] (eq 19); the wrist command ``wrist_angles``, ``wrist_rates``, ``wrist_accelerations``
    (N, 3); ``condition`` (N,); every body's motion ``com`` [m], ``com_velocity``,
    ``com_acceleration``, ``angular_velocity``, ``angular_acceleration`` (N, 38, 3),
    ``rotation`` (N, 38, 3, 3); ``status`` (N,)."""

    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    D: np.ndarray
    D_dot: np.ndarray
    wrist_angles: np.ndarray
    wrist_rates: np.ndarray
    wrist_accelerations: np.ndarray
    condition: np.ndarray
    com: np.ndarray
    com_velocity: np.ndarray
    com_acceleration: np.ndarray
    rotation: np.ndarray
    angular_velocity: np.ndarray
    angular_acceleration: np.ndarray
    status: np.ndarray


class ReactionlessWrist(_core.ReactionlessWrist):
    """Reactionless z-x-z wrist (Briot & Arakelian 2009, eqs 23-26, corrected): each tick
    commands wrist rates ``qdot = N(q)^-1 (H_target - D)`` so that the total angular momentum
    about O stays ``target_momentum``, which makes the shaking moment zero.

    Args:
        J1: inertia matrix of the first wrist link about its centre [kg m^2] (3, 3), link frame.
        J2: the same for the second wrist link.
        J3: the same for the third wrist link.
        config: `ReactionlessWristConfig` (rate [Hz], integrator, limits, damping).
        initial_angles: wrist angles at the start [rad] (3,).
        target_momentum: H_target [kg m^2/s] (3,), usually D at the rest the motion starts from.

    A tick ``step(D, D_dot, D_half, D_next) -> int`` takes D [kg m^2/s] and dD/dt [N m] of the
    rest of the mechanism at t_n (RK4 also D at t_n + dt/2 and t_n + dt) and leaves the
    `WristCommand` in ``command`` (angles, rates, accelerations, condition_number,
    status); ``step_into(D, D_dot, D_half, D_next, out) -> int`` is the fast tick (float64
    arrays; the command written into ``out`` (3, 3), rows angles [rad], rates [rad/s],
    accelerations [rad/s^2]); `run` ticks N times in one call.
    """

    def run(self, D: npt.ArrayLike, D_dot: npt.ArrayLike, D_half: npt.ArrayLike,  # type: ignore[override]
            D_next: npt.ArrayLike) -> WristRun:
        """N consecutive ticks, each argument (N, 3): `WristRun`."""
        r = super().run(D, D_dot, D_half, D_next)
        return WristRun(**{k: np.asarray(v) for k, v in r.items()})


class PaminsaController(_core.PaminsaController):
    """The fully balanced PAMINSA controller (Briot & Arakelian 2009): at each tick the
    platform motion gives the mechanism's kinematics and D (eq 19), the reactionless wrist
    cancels the shaking moment, and the shaking wrench of all 38 bodies is computed.

    Args:
        model: ``PaminsaModel`` (`mechbal.papers`), with its counterweights.
        config: `ReactionlessWristConfig` (the tick rate is ``config.rate_hz``).
        initial_wrist_angles: [rad] (3,).
        max_speed: |platform velocity| per component a tick accepts [m/s] (default 10).
        max_acceleration: |platform acceleration| per component [m/s^2] (default 1e3).

    Tick: ``reset(P, wrist_angles)`` at rest, then ``step(P, Pd, Pdd, P_half, Pd_half,
    Pdd_half, P_next, Pd_next, Pdd_next) -> int`` with the platform position [m], velocity
    [m/s] and acceleration [m/s^2] at t_n, t_n + dt/2 and t_n + dt; the result is in
    ``shaking_force`` [N], ``shaking_moment`` [N m], ``D``, ``D_dot`` and ``wrist_command``.
    Fast tick: ``step_into(now, half, next, out) -> int`` with (3, 3) float64 arrays whose rows
    are position, velocity, acceleration, the wrist command written into ``out`` (3, 3): rows
    angles, rates, accelerations. Batch: `run`.
    """

    def __init__(self, model: Any, config: Any, initial_wrist_angles: npt.ArrayLike,
                 max_speed: float = 10.0, max_acceleration: float = 1000.0):
        super().__init__(model, config, initial_wrist_angles, max_speed, max_acceleration)
        self._model = model
        self._config = config
        self._initial = np.array(initial_wrist_angles, dtype=float)

    def run(self, P_half: npt.ArrayLike, Pd_half: npt.ArrayLike,
            Pdd_half: npt.ArrayLike) -> PaminsaRun:
        """A whole run in one C++ call, from rest at ``P_half[0]`` with the wrist at
        ``initial_wrist_angles`` (a fresh controller: this object's tick state is not used).
        Platform motion sampled every dt/2 (dt = 1 / config.rate_hz): position [m], velocity
        [m/s], acceleration [m/s^2], each (2 steps + 1, 3). Results at the steps + 1 ticks."""
        r = _core.paminsa_reactionless_run(self._model, self._config, self._initial,
                                           P_half, Pd_half, Pdd_half)
        keys = PaminsaRun.__dataclass_fields__
        values = {k: np.asarray(r["status_per_instant" if k == "status" else k]) for k in keys}
        return PaminsaRun(**values)
