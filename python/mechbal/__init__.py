"""mechbal: balancing of mechanisms and real-time control of balanced robots.

The public API (SI units throughout: m, kg, kg m^2, rad, s, N, N m; base frame z up):

* `Mechanism`: the general mechanism model (URDF, TOML or description objects) and every
  algorithm over it: shaking force and moment, base reaction, inverse dynamics, mass matrix,
  regressors, loop closures;
* `mechbal.balance`: balancing by method (counterweights, shaking force, discs, springs, RMS
  torque);
* `mechbal.control`: the real-time controllers (computed torque, decoupled joint control,
  reactionless wrist, PAMINSA), tick by tick and in batch;
* `mechbal.trajectory`: desired motions (quintic, minimum-energy cubic, via points, a user's
  samples) with one `evaluate(t) -> (q, qd, qdd)`;
* `mechbal.simulate`: closed loop of any controller on any mechanism;
* `mechbal.papers`: what exists only to reproduce a paper (closed forms, per-paper models);
* `mechbal.cases`: the built-in case studies and `run_case(name, out_dir)`.

Results are dataclasses with named fields (``shaking_force``, ``shaking_moment``,
``base_reaction_force``, ``joint_torque``, ...) and, for batches, a per-instant ``status`` array
of `Status` bit flags (0 = ok). The C++ core is ``mechbal._core`` (typed in
``_core.pyi``); use the modules above rather than reaching into it.
"""
from __future__ import annotations

import importlib
from typing import Any

from mechbal._core import Status, __version__
from mechbal._core import (  # the description objects of Mechanism.from_description
    Body, Frame, Joint, JointType, LoopConstraint, LoopType, MechanismDescription, MechanismModel, Spring)
from mechbal.config import ConfigError, ConfigWarning, load_case
from mechbal.errors import PlausibilityWarning
from mechbal.mechanism import (
    BaseReaction, BatchArray, BodyMotion, ClosedMotion, Mechanism, Momentum, ShakingWrench)
from mechbal import assembly, balance, control, papers, simulate, trajectory

__all__ = [
    "Mechanism", "ShakingWrench", "BaseReaction", "Momentum", "BodyMotion", "ClosedMotion", "BatchArray",
    "Joint", "JointType", "Body", "Frame", "LoopConstraint", "LoopType", "MechanismDescription", "Spring",
    "MechanismModel", "Status", "ConfigError", "ConfigWarning", "PlausibilityWarning",
    "load_case", "balance", "control", "trajectory", "simulate", "assembly", "papers", "cases", "__version__",
]

# Names that lived here before the public modules existed (kept so that existing scripts run);
# each has its home in a public module, listed in _MOVED.
_MOVED = {
    "ComputedTorque": "control", "DecoupledJointController": "control",
    "ReactionlessWrist": "control", "ReactionlessWristConfig": "control",
    "WristIntegrator": "control", "InverseDynamics": "control", "MechanismDynamics": "control",
    "KdlChainDynamics": "control", "TimeLaw": "trajectory",
    "Arm2DofDynamics": "papers", "Arm2DofParameters": "papers", "PaminsaModel": "papers",
    "PaminsaParameters": "papers", "paminsa_kinematics": "papers",
    "paminsa_reactionless_run": "papers", "shaking_wrench": "papers", "FiveBarDynamics": "papers",
}
_LEGACY_CORE = {"RestToRestTrajectory", "validate_rigid_body"}


def __getattr__(name: str) -> Any:
    if name == "cases":
        return importlib.import_module("mechbal.cases")
    if name in _MOVED:
        return getattr(importlib.import_module(f"mechbal.{_MOVED[name]}"), name)
    if name in _LEGACY_CORE:
        from mechbal import _core

        return getattr(_core, name)
    raise AttributeError(f"module 'mechbal' has no attribute '{name}'")
