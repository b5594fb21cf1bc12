"""The strict schema of this paper's case files: Heydari & Enferadi: the 3(RPSP)-S robot as data on the general model (kind ``rpsp``).

Registered with `mechbal.schema.register_case_model` when the paper package is imported
(`mechbal.registry`); `mechbal.schema.validate_case` then validates its cases.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import math
from typing import Annotated, Literal, Optional

from pydantic import Field

from mechbal.errors import ConfigError
from mechbal.schema import (
    Angle, Balance, CaseHeader, Duration, JointValues, MAX_BODIES, MAX_JOINTS, MAX_SAMPLE_BODIES,
    Mass, Mechanism, Name, NonNeg, Num, Pos, Samples, Table, Vec3, _MechanismCase, did_you_mean,
    mechanism_unit_warnings, register_case_model,
)

NameList = Annotated[list[Name], Field(min_length=1, max_length=MAX_BODIES)]


class RpspBalancing(Table):
    """``[balancing]``: what the unbalanced robot does not have, and the counterweight bodies the
    methods size (one list per paper name, one body per leg)."""
    extra_linkage: Annotated[list[Name], Field(max_length=MAX_JOINTS)] = Field(
        description="joints of the extra linkage (with their links, bodies, frames and loops)")
    m_P: NameList = Field(description="bodies: counterweights on A_iD_i (eq 23)")
    m_N: NameList = Field(description="bodies: counterweights on D_iC_i (eq 25)")
    m_F: NameList = Field(description="bodies: counterweights on the rotary arm (eq 27)")
    platform: Annotated[list[Name], Field(max_length=MAX_BODIES)] = Field(
        [], description="bodies: the platform's counterweight(s)")


class RpspMotion(Table):
    """``[motion]``: the paper's platform motion phi_x = A sin(2 pi t / T), phi_y = 0,
    phi_z = B sin(f pi t / T)."""
    platform: Name = Field(description="the spherical joint the motion drives")
    roll_amplitude: Angle = Field(1.0, description="A [rad]")
    yaw_amplitude: Angle = Field(math.pi / 6, description="B [rad]")
    yaw_factor: Num = Field(0.125, description="f")
    period: Duration = Field(2 * math.pi, description="T [s]")
    duration: Duration = Field(description="s: the balanced / unbalanced comparison")
    samples: Samples = 2001
    survey_duration: Duration = Field(2 * math.pi, description="s: the conditioning survey")
    survey_samples: Samples = 6284
    initial_guess: JointValues = Field(
        description="every joint coordinate at t = 0, in coordinate order (rad or m): the assembly mode")


class RpspCounterweights(Table):
    m_P: Mass
    m_N: Mass
    m_F: Mass


class RpspPaper(Table):
    """``[paper]``: the paper's parameters and reported numbers (closed-form checks)."""
    a: Pos = Field(description="m, |O A_i|")
    h: Pos = Field(description="m, column height")
    lambda_i: Vec3 = Field(description="rad, angles of u_i from x_B (eq 4)")
    alpha_i: Vec3 = Field(description="rad, angles of v_i from x_M (eq 5)")
    m_p: Mass
    m_E: Mass
    m_Q: Mass
    m_H: Mass
    m_K: Mass
    r_H: Num
    r_K: Num
    r_P: Num
    r_F: Num
    r_N: Num
    r_Q: Num
    AE: Pos = Field(description="m")
    AD: Pos = Field(description="m")
    DC: Pos = Field(description="m")
    counterweights_kg: RpspCounterweights
    mean_reduction_pct: Vec3
    table_times: Annotated[list[NonNeg], Field(min_length=1, max_length=100)]


class RpspCaseHeader(CaseHeader):
    kind: Literal["rpsp"]


class RpspCase(_MechanismCase):
    """The 3(RPSP)-S robot (Heydari & Enferadi): the mechanism as data, sized and compared."""
    case: RpspCaseHeader
    mechanism: Mechanism
    balancing: RpspBalancing
    motion: RpspMotion
    paper: RpspPaper
    balance: Optional[Balance] = Field(
        None, description="mechbal balance: the design variables (default: the [balancing] counterweight "
                          "bodies as fixed-position slots)")


def _rpsp_cross_checks(case: "RpspCase") -> None:
    spec = case.spec
    joints = {j.name: j for j in spec.joints}
    bodies = [b.name for b in spec.bodies]
    if not spec.loops:
        raise ConfigError("mechanism.loops", "the rpsp kind needs the loop closures", has_value=False)
    for i, name in enumerate(case.balancing.extra_linkage):
        if name not in joints:
            raise ConfigError(f"balancing.extra_linkage[{i}]", "no such joint" + did_you_mean(name, list(joints)),
                              name)
    for key in ("m_P", "m_N", "m_F", "platform"):
        for i, name in enumerate(getattr(case.balancing, key)):
            if name not in bodies:
                raise ConfigError(f"balancing.{key}[{i}]", "no such body" + did_you_mean(name, bodies), name)
    p = case.motion.platform
    wanted = [f"{p}_z", f"{p}_y", f"{p}_x"]
    if any(w not in joints for w in wanted):
        raise ConfigError("motion.platform", "must name a spherical joint" + did_you_mean(p, list(joints)), p)
    coords = spec.independent_joints
    if len(case.motion.initial_guess) != len(coords):
        raise ConfigError("motion.initial_guess", f"must have {len(coords)} values (every joint with a "
                          f"coordinate: {', '.join(coords)})", list(case.motion.initial_guess))
    for key, n in (("samples", case.motion.samples), ("survey_samples", case.motion.survey_samples)):
        if n * max(1, len(bodies)) > MAX_SAMPLE_BODIES:
            raise ConfigError(f"motion.{key}", f"must be <= {MAX_SAMPLE_BODIES // max(1, len(bodies))} "
                              f"for {len(bodies)} bodies", n)


register_case_model("rpsp", RpspCase, cross_checks=_rpsp_cross_checks,
                    unit_warnings=lambda case: mechanism_unit_warnings(case.mechanism))


# ---- its summary.json (mechbal.summary_schema) -------------------------------------------------
from mechbal.summary_schema import (  # noqa: E402
    METRICS, detail, integer, number, number_map, numbers, register_summary, string, strings)

register_summary("run", "rpsp", {
    "paper": string(), "variants": strings(), "duration": number("s"), "samples": integer(),
    "counterweight_masses": number_map("kg", "Sized counterweights (general method)."),
    "counterweight_masses_per_leg": detail("Per leg [kg]."),
    "counterweight_masses_eqs_29_31": number_map("kg", "By the paper's eqs 29-31."),
    "paper_counterweight_masses": number_map("kg", "The paper's numbers."),
    "platform_counterweight_mass": numbers("kg"),
    "general_method": detail("The general force-balancing method's run."),
    "counterweights": detail("Counterweights [kg] by the general method and the closed form, and their difference."),
    "eq28_coefficients_with_paper_masses": numbers("kg"),
    "peak_shaking_force": METRICS["peak_shaking_force"],
    "rms_shaking_force": METRICS["rms_shaking_force"],
    "balanced_over_unbalanced_peak": numbers(),
    "peak_platform_shaking_force": numbers("N"),
    "mean_reduction_pct": numbers("%"), "mean_reduction_pct_paper_masses": numbers("%"),
    "rms_reduction_pct": numbers("%"), "rms_reduction_pct_paper_masses": numbers("%"),
    "paper_mean_reduction_pct": numbers("%"), "mean_reduction_note": string(),
    "tables": detail("The paper's tables recomputed (t [s], forces [N])."),
    "paper_tables": detail("The paper's tables as printed (forces [N])."),
    "total_mass": number_map("kg", "Per variant."), "added_mass": number("kg"),
    "loops": detail("Loop solve: min_rcond, t_min_rcond [s], residuals [m]."),
    "ik_agreement": detail("Closed-form inverse kinematics against the loop solve ([m], [rad])."),
    "survey": detail("Survey of the workspace: reach [m], intervals [s]."),
    "discrepancies": strings("Where the paper's equations and numbers disagree with first principles."),
})
