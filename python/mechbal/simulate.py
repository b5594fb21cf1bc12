"""Batch simulation through the C++ core: a whole trajectory per call, numpy in, numpy out."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechbal import _core


@dataclass
class ChainRun:
    """One serial chain evaluated along a trajectory (all arrays in the base frame, SI units)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    names: list[str]
    mass: np.ndarray
    inertia_body: np.ndarray
    bodies: dict  # com, com_velocity, com_acceleration, rotation, angular_velocity, ...
    wrench: dict  # force, moment, linear_momentum, angular_momentum
    torque: np.ndarray
    support_force: np.ndarray
    support_moment: np.ndarray
    extra: dict = field(default_factory=dict)


def run_chain(model: _core.ChainModel, trajectory: _core.RestToRestTrajectory,
              t: np.ndarray) -> ChainRun:
    """Kinematics, shaking wrench (eqs 1-4 of Briot & Arakelian 2009) and KDL inverse dynamics of
    a serial chain along ``trajectory`` sampled at ``t``."""
    t = np.asarray(t, float)
    q, qd, qdd = trajectory.evaluate_batch(t)
    bodies = _core.chain_kinematics(model, q, qd, qdd)
    names = [j.name for j in model.joints]
    mass = np.array([j.mass for j in model.joints])
    inertia_body = np.array([j.inertia for j in model.joints])
    wrench = _core.shaking_wrench(mass, inertia_body, bodies["com"], bodies["com_velocity"],
                                  bodies["com_acceleration"], bodies["rotation"],
                                  bodies["angular_velocity"], bodies["angular_acceleration"])
    dyn = _core.KdlChainDynamics(model).inverse_dynamics(q, qd, qdd)
    return ChainRun(t=t, q=q, qd=qd, qdd=qdd, names=names, mass=mass, inertia_body=inertia_body,
                    bodies=bodies, wrench=wrench, torque=dyn["tau"],
                    support_force=dyn["support_force"], support_moment=dyn["support_moment"])
