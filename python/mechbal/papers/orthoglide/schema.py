"""The strict schema of this paper's case files: Martini, Troncossi, Carricato & Rivola 2015: the Orthoglide (kind ``orthoglide``).

Registered with `mechbal.schema.register_case_model` when the paper package is imported
(`mechbal.registry`); `mechbal.schema.validate_case` then validates its cases.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Annotated, Literal, Optional

from pydantic import Field

from mechbal.errors import ConfigError
from mechbal.schema import (
    CaseHeader, MAX_JOINTS, Mechanism, Name, NonNeg, Num, Pos, PosVec2, Table, Xyz, _MechanismCase,
    _NUM, did_you_mean, register_case_model,
)

Count = Annotated[int, Field(ge=1, le=1000, strict=True)]


class OrthoglideSpring(Table):
    """``[[springs]]``: a zero-free-length tension spring between anchor A on link ``link_a`` and
    anchor B on ``link_b`` (positions in those links' frames); its rate is sized by least squares
    over the workspace grid (static balance) unless ``rate`` is given."""
    name: Name
    link_a: Name = Field(description="joint whose link carries anchor A, or 'base'")
    anchor_a: Xyz
    link_b: Name = Field(description="joint whose link carries anchor B, or 'base'")
    anchor_b: Xyz
    rate: Optional[Pos] = Field(None, description="N/m; absent: sized for static balance")


class JointValue(Table):
    joint: Name
    value: Num = Field(description="rad or m")


class OrthoglideRoles(Table):
    """``[roles]``: which frame, bodies and springs of the mechanism are the paper's P, m_p, m_s2,
    distal and proximal springs, and the warm start of the loop solve."""
    tool_frame: Name = Field(description="frame on the platform where the cutting force acts (P)")
    platform_body: Name = Field(description="body m_p")
    vertical_slider_body: Name = Field(description="body m_s2")
    distal_spring: Name
    proximal_spring: Name
    initial_guess: Annotated[list[JointValue], Field(max_length=MAX_JOINTS)] = Field(
        [], description="coordinates near the assembly mode (the loop solve's warm start); others start at 0")


class OrthoglideWorkspace(Table):
    """``[workspace]``: the cube the platform point P spans."""
    center: Xyz = Field(description="m, the workspace centre C")
    edge: Pos = Field(description="m, edge of the cube (parallel to the axes)")
    grid: Annotated[int, Field(ge=2, le=41, strict=True, description="static grid points per edge")] = 11


class OrthoglideCatalogue(Table):
    """``[catalogue]``: practical spring selection (Tables 1-2)."""
    file: Optional[Annotated[str, Field(min_length=1, max_length=4096, strict=True)]] = Field(
        None, description="spring catalogue CSV (default: the one shipped with mechbal)")
    counts: Annotated[list[Count], Field(min_length=2, max_length=2,
                                         description="springs per cluster: from, to")] = [1, 12]
    pulley_ratios: Annotated[list[Annotated[float, Field(ge=1, le=64, **_NUM)]],
                             Field(min_length=1, max_length=8)] = [1.0, 2.0, 4.0, 8.0]
    rate_tolerance: Annotated[float, Field(gt=0, le=1, **_NUM)] = 0.02


Speeds = Annotated[list[Pos], Field(min_length=1, max_length=4, description="m/s")]


class OrthoglidePaths(Table):
    """``[paths]``: Paths A (helix) and B (cube edges and diagonals), the rapid moves of C-F."""
    sample_period: Annotated[float, Field(ge=1e-4, le=0.1, description="s", **_NUM)] = 0.002
    max_acceleration: Pos = Field(14.715, description="m/s^2 on each axis (1.5 g)")
    helix_radius: Pos = Field(0.245, description="m")
    helix_speeds: Speeds = [0.8, 1.2]
    helix_vertical_ratio: Annotated[float, Field(ge=0, le=10, **_NUM)] = 1.0 / 6.0
    helix_acceleration: Pos = Field(4.905, description="m/s^2 of the helix's start and stop ramps")
    cube_speeds: Speeds = [0.6, 1.0]
    rapid_speed: Pos = Field(1.0, description="m/s")


class OrthoglidePocket(Table):
    corner: Xyz = Field(description="m, relative to C: the pocket's (x, y, z) lowest corner")
    size: PosVec2 = Field(description="m, along x and z")


class OrthoglideTask(Table):
    name: Name
    operation: Literal["roughing", "finishing", "deburring", "drilling"]
    feed: Pos = Field(description="m/s, v_f")
    force: NonNeg = Field(description="N, total cutting force F_c at the feed v_f")


class OrthoglideMachining(Table):
    """``[machining]``: Paths C-F (Table 3)."""
    pockets: Annotated[list[OrthoglidePocket], Field(min_length=1, max_length=8)]
    holes: Annotated[list[Xyz], Field(min_length=1, max_length=32, description="m, relative to C")]
    drill_depth: Pos = Field(description="m")
    approach_height: Pos = Field(description="m")
    tasks: Annotated[list[OrthoglideTask], Field(max_length=8)] = []


class OrthoglideSensitivity(Table):
    """``[sensitivity]``: Table 6."""
    relative: Annotated[float, Field(ge=0, le=0.9, **_NUM)] = 0.10
    anchor_offset: Annotated[float, Field(ge=0, le=1, description="m", **_NUM)] = 0.005


class OrthoglideCaseHeader(CaseHeader):
    kind: Literal["orthoglide"]


class OrthoglideCase(_MechanismCase):
    """The Orthoglide 5-axis and its spring gravity compensation (Martini et al. 2015)."""
    case: OrthoglideCaseHeader
    mechanism: Mechanism
    springs: Annotated[list[OrthoglideSpring], Field(min_length=1, max_length=16)]
    roles: OrthoglideRoles
    workspace: OrthoglideWorkspace
    catalogue: OrthoglideCatalogue = OrthoglideCatalogue()
    paths: OrthoglidePaths = OrthoglidePaths()
    machining: OrthoglideMachining
    sensitivity: OrthoglideSensitivity = OrthoglideSensitivity()


def _orthoglide_cross_checks(case: "OrthoglideCase") -> None:
    spec = case.spec
    links = ["base", *spec.joint_names]
    bodies = [b.name for b in spec.bodies]
    frames = [f.name for f in spec.frames]
    springs = [s.name for s in case.springs]
    if len(set(springs)) != len(springs):
        raise ConfigError("springs", "names must be unique", springs)
    if len(spec.actuated) != 3:
        raise ConfigError("mechanism.actuated", "must name the three sliders", list(spec.actuated))
    for i, s in enumerate(case.springs):
        for side in ("link_a", "link_b"):
            if getattr(s, side) not in links:
                raise ConfigError(f"springs[{i}].{side}", f"unknown link{did_you_mean(getattr(s, side), links)}",
                                  getattr(s, side))
    r = case.roles
    for key, allowed in (("tool_frame", frames), ("platform_body", bodies), ("vertical_slider_body", bodies),
                         ("distal_spring", springs), ("proximal_spring", springs)):
        if getattr(r, key) not in allowed:
            raise ConfigError(f"roles.{key}", f"unknown name{did_you_mean(getattr(r, key), allowed)}",
                              getattr(r, key))
    for i, jv in enumerate(r.initial_guess):
        if jv.joint not in spec.independent_joints:
            raise ConfigError(f"roles.initial_guess[{i}].joint", "not a joint with a coordinate"
                                                                 f"{did_you_mean(jv.joint, spec.independent_joints)}",
                              jv.joint)
    c = case.catalogue.counts
    if c[0] > c[1]:
        raise ConfigError("catalogue.counts", "must be [from, to] with from <= to", c)
    names = [t.name for t in case.machining.tasks]
    if len(set(names)) != len(names):
        raise ConfigError("machining.tasks", "names must be unique", names)


register_case_model("orthoglide", OrthoglideCase, cross_checks=_orthoglide_cross_checks)


# ---- its summary.json (mechbal.summary_schema) -------------------------------------------------
from mechbal.summary_schema import (  # noqa: E402
    detail, integer, number, number_map, register_summary, string, strings)

register_summary("run", "orthoglide", {
    "paper": string(), "frame": string("Base frame and gravity."), "dof": integer(),
    "actuated": strings(), "leg_length": number("m"),
    "workspace": detail("The workspace grid: center [m], edge [m], grid_points."),
    "lumped_masses": detail("The paper's lumped masses [kg]."),
    "spring_rates_N_per_mm": number_map("N/mm", "Sized spring rates (the paper's unit)."),
    "paper_spring_rates_N_per_mm": number_map("N/mm", "The paper's rates."),
    "closed_form_spring_rates_N_per_mm": number_map("N/mm", "Rates by eqs 18-19."),
    "anchor_offsets_mm": number_map("mm", "Spring anchor offsets (the paper's unit)."),
    "rate_sizing": detail("How the rates were sized (general springs method), residual [N]."),
    "acceptance": detail("Static motor force with the springs [N], potential energy variation [J]."),
    "clusters": detail("Off-the-shelf spring clusters chosen from the catalogue."),
    "table1": detail("The paper's Table 1, recomputed (mm, N/mm as the paper; forces [N])."),
    "paper_table1": detail("The paper's Table 1 as printed."),
    "paper_table2": detail("The paper's Table 2 as printed."),
    "table4": detail("Table 4 recomputed: motor forces [N], changes [%]."),
    "table5": detail("Table 5 recomputed."), "table6": detail("Table 6 recomputed."),
    "checks": detail("Power balance and closed-form checks (relative)."),
    "unbalanced_variant": string(),
    "discrepancies": strings("Where the paper's equations and numbers disagree with first principles."),
})
