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
  samples) with one `evaluate(t) -> Motion(q, v, a)`;
* `mechbal.simulate`: closed loop of any controller on any mechanism;
* `mechbal.sweep`: sensitivity and tolerance sweeps over a case's parameters;
* `mechbal.export`: URDF and MJCF files of a mechanism, bodies files, the MuJoCo engine;
* `mechbal.papers`: what exists only to reproduce a paper (closed forms, per-paper models);
* `mechbal.cases`: the built-in case studies and `run_case(name, out_dir)`.
* `load_case`: a case (a built-in case's name, a TOML or URDF file) read into a `LoadedCase`
  (`mechbal.case`).

Results are dataclasses with named fields (``shaking_force``, ``shaking_moment``,
``base_reaction_force``, ``joint_torque``, ...) and, for batches, a per-instant ``status`` array
of `Status` bit flags (0 = ok). The C++ core is ``mechbal._core`` (typed in
``_core.pyi``); use the modules above rather than reaching into it.

This package is a lazy facade (PEP 562): ``import mechbal`` loads no public module, each name
below is imported on first use, and no module of the package imports this one (so
``import mechbal.trajectory`` loads the trajectory module and what it needs, not the whole
package). It is also the top layer that tells `mechbal.registry` where the papers are.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from mechbal import registry as _registry

if TYPE_CHECKING:  # what mypy and readers see; at run time each name loads on first use (__getattr__)
    from mechbal import assembly, balance, cases, control, export, papers, simulate, sweep, trajectory
    from mechbal._core import Status, __version__
    from mechbal.case import LoadedCase, load_case
    from mechbal.config import ConfigError, ConfigWarning
    from mechbal.errors import PlausibilityWarning
    from mechbal.mechanism import (  # with the description objects of Mechanism.from_description
        BaseReaction, BatchArray, Body, BodyMotion, ClosedMotion, Frame, Joint, JointType, LoopConstraint, LoopType,
        Mechanism, MechanismDescription, MechanismModel, Momentum, ShakingWrench, Spring)

__all__ = [
    "Mechanism", "ShakingWrench", "BaseReaction", "Momentum", "BodyMotion", "ClosedMotion", "BatchArray",
    "Joint", "JointType", "Body", "Frame", "LoopConstraint", "LoopType", "MechanismDescription", "Spring",
    "MechanismModel", "Status", "ConfigError", "ConfigWarning", "PlausibilityWarning",
    "load_case", "LoadedCase", "balance", "control", "trajectory", "simulate", "assembly", "papers", "cases",
    "sweep", "export", "__version__",
]

#: the public subpackages and modules, each loaded on first use
_MODULES = {"assembly", "balance", "cases", "control", "export", "papers", "simulate", "sweep", "trajectory"}

#: public names and the module that holds each (loaded on first use)
_NAMES = {
    **dict.fromkeys(("Status", "__version__"), "_core"),
    **dict.fromkeys(("ConfigError", "ConfigWarning"), "config"),
    **dict.fromkeys(("LoadedCase", "load_case"), "case"),
    "PlausibilityWarning": "errors",
    **dict.fromkeys(("BaseReaction", "BatchArray", "BodyMotion", "ClosedMotion", "Mechanism", "Momentum",
                     "ShakingWrench", "Body", "Frame", "Joint", "JointType", "LoopConstraint", "LoopType",
                     "MechanismDescription", "MechanismModel", "Spring"), "mechanism"),
}

# Names that lived here before the public modules existed (kept so that existing scripts run);
# each has its home in a public module, listed in _MOVED.
_MOVED = {
    "ComputedTorque": "control", "DecoupledJointController": "control",
    "InverseDynamics": "control", "MechanismDynamics": "control",
    "KdlChainDynamics": "control", "TimeLaw": "trajectory",
    "ReactionlessWrist": "papers", "ReactionlessWristConfig": "papers", "WristIntegrator": "papers",
    "Arm2DofDynamics": "papers", "Arm2DofParameters": "papers", "PaminsaModel": "papers",
    "PaminsaParameters": "papers", "paminsa_kinematics": "papers",
    "paminsa_reactionless_run": "papers", "shaking_wrench": "papers", "FiveBarDynamics": "papers",
}
_LEGACY_CORE = {"RestToRestTrajectory", "validate_rigid_body"}


def __getattr__(name: str) -> Any:
    if name in _MODULES:
        return importlib.import_module(f"mechbal.{name}")
    if name in _NAMES:
        value = getattr(importlib.import_module(f"mechbal.{_NAMES[name]}"), name)
        globals()[name] = value  # found once
        return value
    if name in _MOVED:
        return getattr(importlib.import_module(f"mechbal.{_MOVED[name]}"), name)
    if name in _LEGACY_CORE:
        return getattr(importlib.import_module("mechbal._core"), name)
    raise AttributeError(f"module 'mechbal' has no attribute '{name}'")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


def _papers() -> _registry.PaperSource:
    """The paper source of `mechbal.registry`: the ``mechbal.papers`` package (the top layer
    registers it; no general module imports a paper)."""
    return importlib.import_module("mechbal.papers")  # type: ignore[return-value]


_registry.set_paper_source(_papers)
