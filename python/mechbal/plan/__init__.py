"""Balancing by motion: trajectories of the actuated joints that minimise shaking.

* `min_shaking`: a rest-to-rest (or given boundary velocities) motion of any mechanism that
  minimises the RMS or peak shaking force or moment, or a weighted sum with the actuator torques,
  within the joints' limits (`mechbal.plan.min_shaking`);
* `com_law`: the centre-of-mass law (a straight line of the total centre of mass with a
  bang-bang or minimum-jerk profile) where the centre of mass is an invertible function of the
  actuated joints (`mechbal.plan.com`).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from mechbal.plan.com import PROFILES, ComLawNotApplicable, ComLawResult, SampledMotion, com_law
from mechbal.plan.min_shaking import OBJECTIVES, Limits, PlanInfeasible, PlanResult, min_shaking
from mechbal.plan.spline import SplineTrajectory

__all__ = ["min_shaking", "com_law", "PlanResult", "ComLawResult", "PlanInfeasible", "Limits",
           "SplineTrajectory", "OBJECTIVES", "PROFILES", "ComLawNotApplicable", "SampledMotion"]
