"""The strict schema of this paper's case files: Briot & Arakelian 2009: PAMINSA (kind ``paminsa``).

Registered with `mechbal.schema.register_case_model` when the paper package is imported
(`mechbal.registry`); `mechbal.schema.validate_case` then validates its cases.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Optional

from pydantic import AfterValidator, Field, model_validator
from pydantic.json_schema import WithJsonSchema

from mechbal.schema import (
    Angle, Balance, CaseHeader, Duration, Length, MAX_ABS, Mass, Num, Pos, Rate, Table, Vec3, Xyz,
    _NUM, _angle_warning, _check_ticks, _custom, _fmt, _is_number, _length_warning, _mass_warnings,
    _vec, did_you_mean, register_case_model,
)

def _check_vertical_mass_xy(value: Any) -> Any:
    if isinstance(value, str):
        if value != "centroid":
            raise _custom("must be 'centroid' or [x, y]" + did_you_mean(value, ["centroid"]), value=value)
        return value
    if not isinstance(value, list) or len(value) != 2:
        raise _custom("must be 'centroid' or [x, y]", value=value)
    for i, x in enumerate(value):
        if not _is_number(x):
            raise _custom("must be a number", f"[{i}]", x)
        if not math.isfinite(x) or abs(x) > MAX_ABS:
            raise _custom(f"must be finite, between -{_fmt(MAX_ABS)} and {_fmt(MAX_ABS)}", f"[{i}]", x)
    return value


class PaminsaGeometry(Table):
    k: Num = Field(description="pantograph magnification D_iF_i / B_iF_i")
    a: Length
    b: Length
    c: Length
    d: Length
    e: Length
    f: Length
    length_BG: Length
    length_AE: Length
    length_DF: Length
    length_CE: Length
    length_AF: Length
    length_CJ: Length
    length_MS5: Length
    length_MO: Length
    nominal_platform: Xyz
    nominal_rho: Length
    z_A: Length
    elbow: Num
    vertical_mass_xy: Annotated[Any, AfterValidator(_check_vertical_mass_xy), WithJsonSchema({
        "description": "'centroid' (of the B_i) or [x, y] in m",
        "anyOf": [{"const": "centroid"},
                  {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}]})
    ] = "centroid"
    vertical_mass_z0: Length
    cp3_ratio: Num


PaminsaLinkMasses = _vec(8, Mass, "kg, links 1..8")
PaminsaLinkInertias = _vec(8, Vec3, "kg m^2, principal [J_XX, J_YY, J_ZZ] of links 1..8")
PaminsaWristInertias = _vec(3, Vec3, "kg m^2, principal [J_XX, J_YY, J_ZZ] of wrist links 1..3")
WristAngles = _vec(3, Angle, "rad, z-x-z (phi, theta, psi)")


class PaminsaMasses(Table):
    platform: Mass
    links: PaminsaLinkMasses


class PaminsaInertias(Table):
    links: PaminsaLinkInertias
    wrist: PaminsaWristInertias


class PaminsaCounterweights(Table):
    # general_method: mechbal.balance.force on the case's [balance] slots (checked against the
    # closed form); closed_form: eqs 11, 14-16 corrected; paper_reported: 4.49 / 1.69 / 0.436 kg
    use: Literal["general_method", "closed_form", "paper_reported"] = "general_method"


class PaminsaTrajectory(Table):
    law: Literal["quintic", "cubic"] = "quintic"
    start: Xyz
    end: Xyz
    duration: Duration


class PaminsaWrist(Table):
    initial_angles: WristAngles
    rate_hz: Rate = 1000.0
    integrator: Literal["euler", "rk4"] = "rk4"
    max_rate: Pos = Field(1e3, description="rad/s per axis")
    max_condition: Annotated[float, Field(ge=1, le=MAX_ABS, **_NUM)] = 1e4
    damping: Pos = 1e-2


class PaminsaCaseHeader(CaseHeader):
    kind: Literal["paminsa"]


class PaminsaCase(Table):
    """PAMINSA: unbalanced, force-balanced and fully balanced (reactionless wrist)."""
    case: PaminsaCaseHeader
    geometry: PaminsaGeometry
    masses: PaminsaMasses
    inertias: PaminsaInertias
    counterweights: PaminsaCounterweights = PaminsaCounterweights()
    trajectory: PaminsaTrajectory
    wrist: PaminsaWrist
    balance: Optional[Balance] = Field(
        None, description="mechbal balance: the mechanism of mechbal.papers.paminsa (unbalanced, without its "
                          "placeholder counterweights); links are its joints (leg1_link3, leg1_guide, ...)")

    @model_validator(mode="after")
    def _ticks(self):
        _check_ticks(self.trajectory.duration, self.wrist.rate_hz, "trajectory.duration",
                     "duration x wrist.rate_hz")
        return self


def unit_warnings(case) -> list[tuple[str, str]]:
    """(field, message) of every likely unit mistake in a validated case of this paper."""
    out: list = []
    add = lambda w: w is not None and out.append(w)  # noqa: E731
    g = case.geometry
    lengths = [k for k in PaminsaGeometry.model_fields if k.startswith("length_")] + \
        ["a", "b", "c", "d", "e", "f", "nominal_rho", "z_A", "vertical_mass_z0"]
    for k in lengths:
        add(_length_warning(f"geometry.{k}", getattr(g, k)))
    reach = max(abs(getattr(g, k)) for k in lengths)
    masses = [("masses.platform", case.masses.platform)] + \
        [(f"masses.links[{i}]", x) for i, x in enumerate(case.masses.links)]
    out += _mass_warnings(masses, reach)
    for k, x in enumerate(case.wrist.initial_angles):
        add(_angle_warning(f"wrist.initial_angles[{k}]", x))
    return out


register_case_model("paminsa", PaminsaCase, unit_warnings=unit_warnings)


# ---- its summary.json (mechbal.summary_schema) -------------------------------------------------
from mechbal.summary_schema import (  # noqa: E402
    METRICS, detail, integer, number, numbers, register_summary, string, strings)

register_summary("run", "paminsa", {
    "paper": string(), "duration": number("s"), "samples": integer(),
    "tick_rate_hz": number("Hz", "Wrist controller rate (the case's rate_hz)."),
    "integrator": string(), "integrators_run": strings(),
    "wrist_initial_angles": numbers("rad"),
    "counterweights_used": string("general_method or closed_form."),
    "counterweight_masses": detail("Counterweight masses used [kg], by name and leg."),
    "counterweights": detail("Counterweights [kg] by the general method and the closed form, and their difference."),
    "counterweight_masses_paper_printed_eqs": detail("The paper's equations as printed [kg]."),
    "paper_counterweight_masses": detail("The paper's numbers [kg]."),
    "peak_shaking_force": METRICS["peak_shaking_force"],
    "peak_shaking_moment": METRICS["peak_shaking_moment"],
    "moment_reference": string(),
    "peak_shaking_force_norm_unbalanced": number("N"),
    "peak_shaking_moment_norm_unbalanced": number("N m"),
    "balanced_moment_residual_percent_of_unbalanced_peak": detail("Per integrator [%]."),
    "force_balanced_force_residual_relative": detail("Relative residual force, per variant."),
    "balanced_residual_explanation": string(),
    "peak_wrist_rate": numbers("rad/s"),
    "peak_wrist_rate_by_integrator": detail("Per integrator [rad/s]."),
    "wrist_angle_excursion": numbers("rad"),
    "condition_number_range": numbers(),
    "wrist_status_or": integer("All the wrist controller's status flags or-ed."),
    "z_moment_ratio_force_balanced_over_unbalanced": detail("About O and about the base centre [m]."),
    "discrepancies": {"type": "array", "description": "Where the paper's equations and numbers "
                      "disagree with first principles."},
})
