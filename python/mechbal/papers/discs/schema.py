"""The strict schema of this paper's case files: Coutinho & Hess Coelho: the serial arms and the 5R with discs (kind ``discs``).

Registered with `mechbal.schema.register_case_model` when the paper package is imported
(`mechbal.registry`); `mechbal.schema.validate_case` then validates its cases.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Annotated, Literal, Optional

from pydantic import Field, model_validator

from mechbal.schema import (
    Balance, CaseHeader, Duration, Inertia, Length, MAX_ABS, MAX_CONFIGURATIONS, Name, NonNeg, Num,
    Pos, PosVec2, PosVec3, Samples, Table, Vec2, Vec3, _NUM, _custom, _length_warning,
    _mass_warnings, register_case_model,
)

class DiscsTrajectory3(Table):
    start: Vec3
    end: Vec3
    duration: Duration
    samples: Samples = 301


class DiscsTrajectory2(Table):
    start: Vec2
    end: Vec2
    duration: Duration
    samples: Samples = 301


class DiscsController3(Table):
    kp: PosVec3 = Field(description="s^-2")
    kd: PosVec3 = Field(description="s^-1")


class DiscsController2(Table):
    kp: PosVec2 = Field(description="s^-2")
    kd: PosVec2 = Field(description="s^-1")


class DiscsSampling(Table):
    configurations: Annotated[int, Field(ge=10, le=MAX_CONFIGURATIONS, strict=True)] = 1000
    seed: Annotated[int, Field(ge=0, le=2**63 - 1, strict=True)] = 0


class DiscsSensitivity(Table):
    parameters: Annotated[list[Name], Field(max_length=64)] = []
    errors_pct: Annotated[list[Num], Field(max_length=64)] = [1.0, 5.0, 10.0]


class SerialDiscsParameters(Table):
    l1: Annotated[float, Field(gt=0, le=MAX_ABS, description="m", **_NUM)]
    l2: Annotated[float, Field(gt=0, le=MAX_ABS, description="m", **_NUM)]
    m1: Annotated[float, Field(gt=0, le=MAX_ABS, description="kg", **_NUM)]
    m2: Annotated[float, Field(gt=0, le=MAX_ABS, description="kg", **_NUM)]
    m3: Annotated[float, Field(gt=0, le=MAX_ABS, description="kg", **_NUM)]


class Planar3rInertia(Table):
    link1: Inertia
    link2: Inertia
    link3: Inertia
    disc4: Inertia
    disc5: Inertia
    disc6: Inertia
    disc7: Inertia


class Spatial3rInertia(Table):
    link1: Inertia
    link2: Inertia
    link3: Inertia
    disc4: Inertia
    disc5: Inertia


class ScaraInertia(Spatial3rInertia):
    pass


class _UnbalancedLinks(Table):
    link1: Optional[Inertia] = None
    link2: Optional[Inertia] = None
    link3: Optional[Inertia] = None


class Planar3rUnbalanced(_UnbalancedLinks):
    lg1: Length
    lg2: Length
    lg3: Length


class Spatial3rUnbalanced(_UnbalancedLinks):
    lg2: Length
    lg3: Length


class ScaraUnbalanced(_UnbalancedLinks):
    lg1: Length
    lg2: Length


class FivebarParameters(Table):
    a1: Pos
    a2: Pos
    b1: Pos
    b2: Pos
    d: NonNeg
    mp1: Pos
    mp2: Pos
    md1: Pos
    md2: Pos
    mP: Pos
    mP1_share: NonNeg

    @model_validator(mode="after")
    def _share(self):
        if self.mP1_share > self.mP:
            raise _custom(f"must be <= mP = {self.mP!r}", ".mP1_share", self.mP1_share)
        if not (abs(self.d) <= 1e-12 and abs(self.b1 - self.a2) <= 1e-12 * max(1.0, self.a2)
                and abs(self.b2 - self.a1) <= 1e-12 * max(1.0, self.a1)):
            raise _custom("a general 5R cannot be made constant-diagonal (C11): use the "
                          "parallelogram d = 0, b1 = a2, b2 = a1",
                          value={k: getattr(self, k) for k in ("d", "a1", "a2", "b1", "b2")})
        return self


class FivebarInertia(Table):
    proximal1: Inertia
    proximal2: Inertia
    distal1: Inertia
    distal2: Inertia


class FivebarUnbalanced(Table):
    cp1: Length
    cp2: Length
    cd1: Length
    cd2: Length


class DiscsCaseHeader(CaseHeader):
    kind: Literal["discs"]
    mechanism: Literal["planar3r", "spatial3r", "scara", "fivebar"] = Field(
        description="which of the paper's mechanisms")


class Planar3rHeader(DiscsCaseHeader):
    mechanism: Literal["planar3r"]


class Spatial3rHeader(DiscsCaseHeader):
    mechanism: Literal["spatial3r"]


class ScaraHeader(DiscsCaseHeader):
    mechanism: Literal["scara"]


class FivebarHeader(DiscsCaseHeader):
    mechanism: Literal["fivebar"]


class _DiscsCase(Table):
    sampling: DiscsSampling = DiscsSampling()
    sensitivity: DiscsSensitivity = DiscsSensitivity()
    balance: Optional[Balance] = Field(
        None, description="mechbal balance: the statically balanced mechanism without discs (links joint1..3 "
                          "of mechbal.papers.discs; five-bar: theta1, theta12, theta2, theta22)")


class Planar3rCase(_DiscsCase):
    """Planar 3R + 4 counter-rotating discs (Coutinho & Hess Coelho, Sec. 3.1)."""
    case: Planar3rHeader
    parameters: SerialDiscsParameters
    inertia: Planar3rInertia
    unbalanced: Planar3rUnbalanced
    trajectory: DiscsTrajectory3
    controller: DiscsController3


class Spatial3rCase(_DiscsCase):
    """Spatial 3R + 2 counter-rotating discs (Coutinho & Hess Coelho, Sec. 3.2)."""
    case: Spatial3rHeader
    parameters: SerialDiscsParameters
    inertia: Spatial3rInertia
    unbalanced: Spatial3rUnbalanced
    trajectory: DiscsTrajectory3
    controller: DiscsController3


class ScaraCase(_DiscsCase):
    """SCARA (RRP) + 2 counter-rotating discs (Coutinho & Hess Coelho, Sec. 3.3)."""
    case: ScaraHeader
    parameters: SerialDiscsParameters
    inertia: ScaraInertia
    unbalanced: ScaraUnbalanced
    trajectory: DiscsTrajectory3
    controller: DiscsController3


class FivebarCase(_DiscsCase):
    """Parallelogram 5R, leg-wise static balancing."""
    case: FivebarHeader
    parameters: FivebarParameters
    inertia: FivebarInertia
    unbalanced: FivebarUnbalanced
    trajectory: DiscsTrajectory2
    controller: DiscsController2


def unit_warnings(case) -> list[tuple[str, str]]:
    """(field, message) of every likely unit mistake in a validated case of this paper."""
    out: list = []
    add = lambda w: w is not None and out.append(w)  # noqa: E731
    p = case.parameters
    lengths = [k for k in ("l1", "l2", "a1", "a2", "b1", "b2", "d") if hasattr(p, k)]
    for k in lengths:
        add(_length_warning(f"parameters.{k}", getattr(p, k)))
    reach = sum(abs(getattr(p, k)) for k in lengths)
    masses = [(f"parameters.{k}", getattr(p, k)) for k in type(p).model_fields
              if k.startswith("m") and k != "mP1_share"]
    out += _mass_warnings(masses, reach)
    return out


register_case_model("discs", {"planar3r": Planar3rCase, "spatial3r": Spatial3rCase, "scara": ScaraCase,
                              "fivebar": FivebarCase}, unit_warnings=unit_warnings)


# ---- its summary.json (mechbal.summary_schema) -------------------------------------------------
from mechbal.summary_schema import (  # noqa: E402
    METRICS, anything, detail, integer, number, numbers, per_variant, register_summary, string)

register_summary("run", "discs", {
    "mechanism": string("planar3r, spatial3r, scara or fivebar."), "source": string("The paper."),
    "balancing": detail("Static balancing: centre-of-mass offsets l_g [m], the decoupled inertias k [kg m^2]."),
    "discs": detail("The discs by the general method and the closed form, and their difference."),
    "l_g": anything("Centre-of-mass offsets after static balancing [m] (a list, or by link)."),
    "k": numbers("kg m^2", "Decoupled (constant, diagonal) inertias."),
    "beta": number(None, "Disc gear ratio."), "gamma": number(None, "Disc gear ratio."),
    "K_cross": number("kg m^2", "Cross inertia of the five-bar (zero when decoupled)."),
    "inertia_conditions": detail("The spatial 3R's corrected inertia conditions [kg m^2]."),
    "configurations": integer("Random configurations checked."), "seed": integer(),
    **{k: number(None, "Relative measure of the mass matrix's coupling (before / after balancing).")
       for k in ("offdiag_ratio_before", "offdiag_ratio_after", "coupling_coefficient_before",
                 "coupling_coefficient_after", "diag_variation_before", "diag_variation_after",
                 "diag_vs_k_after", "trajectory_balanced_vs_k_qdd_max_abs")},
    "peak_gravity_torque": per_variant("N m", "Largest |gravity torque| over the configurations.",
                                       vector=False),
    "peak_velocity_terms": per_variant("N m", "Largest |velocity terms| over the configurations.",
                                       vector=False),
    "peak_joint_torque": METRICS["peak_joint_torque"],
    "decoupled_control": detail("Decoupled joint control of the balanced mechanism."),
    "shaking_wrench_on_trajectory": detail("Peak shaking force [N] and moment [N m] along the trajectory."),
    "sensitivity": {"type": "array", "items": {"type": "object"},
                    "description": "Coupling after a parameter error (error_pct [%])."},
    "corrections": {"type": "array", "items": {"type": "object"},
                    "description": "The paper's equations that are corrected, and how."},
    "corrections_note": string(),
})
