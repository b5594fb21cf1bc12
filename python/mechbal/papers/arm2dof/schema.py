"""The strict schema of this paper's case files: Arakelian, Le Baron & Mottu 2011: the 2-DOF arm (kind ``arm2dof``).

Registered with `mechbal.schema.register_case_model` when the paper package is imported
(`mechbal.registry`); `mechbal.schema.validate_case` then validates its cases.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Annotated, Literal, Optional

from pydantic import Field, model_validator

from mechbal.schema import (
    Balance, CaseHeader, Duration, Length, NonNeg, Pos, PosVec2, Rate, Samples, Table, Vec2, _NUM,
    _check_ticks, _length_warning, _mass_warnings, register_case_model,
)

class Arm2DofArm(Table):
    m1: Pos = Field(description="kg, link 1")
    m2: Pos = Field(description="kg, link 2")
    l1: Pos = Field(description="m, |AB|")
    l_s1: Length = Field(description="m, A -> S1 along AB")
    l_s2: Length = Field(description="m, B -> S2 along link 2")
    i_s1: NonNeg = Field(description="kg m^2 about S1")
    i_s2: NonNeg = Field(description="kg m^2 about S2")
    g: NonNeg = Field(9.81, description="m/s^2, along -z")


class Arm2DofCounterweights(Table):
    m_cw1: Pos = Field(description="kg")
    m_cw2: Pos = Field(description="kg")
    paper_r_cw: Optional[Vec2] = Field(None, description="m, the paper's reported radii")


class Arm2DofTrajectory(Table):
    start: Vec2
    end: Vec2
    duration: Duration
    samples: Samples = 1001


class Arm2DofController(Table):
    kp: PosVec2 = Field(description="s^-2")
    kd: PosVec2 = Field(description="s^-1")
    rate_hz: Rate = 1000.0
    duration: Duration = 2.0
    initial_error: Vec2 = [0.0, 0.0]
    perturbation: Annotated[float, Field(ge=0, le=0.9, **_NUM)] = 0.2
    torque_limit: Optional[PosVec2] = Field(None, description="N m; absent: unlimited")

    @model_validator(mode="after")
    def _ticks(self):
        _check_ticks(self.duration, self.rate_hz, ".duration")
        return self


class Arm2DofPaper(Table):
    step1_rms_reduction_pct: Optional[Vec2] = None
    step1_peak_reduction_pct: Optional[Vec2] = None
    step2_rms_reduction_pct: Optional[Vec2] = None
    step2_peak_reduction_pct: Optional[Vec2] = None


class Arm2DofCaseHeader(CaseHeader):
    kind: Literal["arm2dof"]


class Arm2DofCase(Table):
    """2-DOF arm: minimum-energy motion, computed torque, RMS-optimal counterweights."""
    case: Arm2DofCaseHeader
    arm: Arm2DofArm
    counterweights: Arm2DofCounterweights
    trajectory: Arm2DofTrajectory
    controller: Arm2DofController
    paper: Arm2DofPaper = Arm2DofPaper()
    balance: Optional[Balance] = Field(
        None, description="mechbal balance: links 'shoulder' and 'elbow' (x along each link); "
                          "without counterweights, those of [counterweights] on the link extensions")


def unit_warnings(case) -> list[tuple[str, str]]:
    """(field, message) of every likely unit mistake in a validated case of this paper."""
    out: list = []
    add = lambda w: w is not None and out.append(w)  # noqa: E731
    a = case.arm
    for k in ("l1", "l_s1", "l_s2"):
        add(_length_warning(f"arm.{k}", getattr(a, k)))
    reach = a.l1 + abs(a.l_s2) + abs(a.l_s1)
    out += _mass_warnings([("arm.m1", a.m1), ("arm.m2", a.m2),
                           ("counterweights.m_cw1", case.counterweights.m_cw1),
                           ("counterweights.m_cw2", case.counterweights.m_cw2)], reach)
    return out


register_case_model("arm2dof", Arm2DofCase, unit_warnings=unit_warnings)


# ---- its summary.json (mechbal.summary_schema) -------------------------------------------------
from mechbal.summary_schema import (  # noqa: E402
    METRICS, detail, number, numbers, register_summary, string, strings, integer)

register_summary("run", "arm2dof", {
    "source": string("The paper."), "samples": integer(), "duration": number("s"),
    "r_cw_general": numbers("m", "Counterweight radii sized by the general rms method (used by arm C)."),
    "r_cw": detail("The radii by the general method and the closed form, their difference [m] and the method."),
    "r_cw_numerical": numbers("m", "Radii by direct numerical minimisation."),
    "paper_r_cw": numbers("m", "The paper's radii."),
    "static_balancing_r_cw": numbers("m", "Radii that balance gravity statically."),
    "cubics": detail("The cubic of each joint's optimal radius: coefficients, real roots, torque change."),
    "rms_joint_torque": METRICS["rms_joint_torque"], "peak_joint_torque": METRICS["peak_joint_torque"],
    "rms_reduction_pct": detail("RMS torque reduction of each joint [%], arm B and C against A."),
    "peak_reduction_pct": detail("Peak torque reduction of each joint [%], arm B and C against A."),
    "paper_reduction_pct": detail("The paper's reductions [%]."),
    "first_step_readings": detail("The two readings of the paper's first step (radii [m], reductions [%])."),
    "kdl_vs_closed_form_max_rel_dev": number(None, "KDL against the closed-form dynamics (relative)."),
    "general_model_vs_closed_form_max_rel_dev": number(None, "The general model against the closed form."),
    "closed_loop_arm": string(),
    "max_tracking_error": detail("Largest tracking error [rad]: exact and perturbed model."),
    "closed_loop": detail("1 kHz computed torque on arm C: gains, rate_hz, duration [s], errors [rad]."),
    "closed_loop_bare_arm_B": detail("The same on arm B."),
    "discrepancies": strings("Where the paper's equations and numbers disagree with first principles."),
})
