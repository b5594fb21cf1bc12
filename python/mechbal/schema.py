"""The strict schema of every case file, as pydantic v2 models.

One model per case kind (``[case] kind = ...``), one nested model per table. Every table forbids
unknown keys (a misspelled key is an error that names it and the nearest known key), numbers are
strict (no booleans, no strings, finite, bounded) and integers are integers. Sizes that drive
memory or time (samples, joints, ticks) have upper bounds. :func:`validate_case` turns the first
problem into one :class:`~mechbal.errors.ConfigError` line naming the dotted field and the value,
then runs the checks that need more than one table (trajectory size against the mechanism's
degrees of freedom, cross references of the general mechanism format) and warns
(:class:`~mechbal.errors.ConfigWarning`) about likely unit mistakes.

:func:`json_schema` publishes the same models as JSON Schema for editors;
``python/mechbal/cases/mechbal.schema.json`` is its output for every kind
(``python -m mechbal.schema > python/mechbal/cases/mechbal.schema.json`` regenerates it; a test
keeps it current).
"""
import difflib
import json
import math
import sys
import warnings
from pathlib import Path
from typing import Annotated, Any, Literal, Optional, Union, get_args, get_origin

import numpy as np
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, PrivateAttr, TypeAdapter, ValidationError, \
    model_validator
from pydantic.json_schema import GenerateJsonSchema, WithJsonSchema
from pydantic_core import PydanticCustomError

from mechbal.errors import ConfigError, ConfigWarning, short_repr

# ---- bounds -------------------------------------------------------------------------------------
#: largest magnitude of any number in a case file (SI units: beyond it a value is absurd, and
#: products of a few such values still cannot overflow)
MAX_ABS = 1e12
#: samples of a trajectory (arrays of samples x bodies x 3 x 3 are built and exported)
MAX_SAMPLES = 1_000_000
#: samples x bodies of the exported pose arrays (~1 GB of float64 rotations and positions)
MAX_SAMPLE_BODIES = 4_000_000
#: joints of a mechanism (a spherical joint counts three once expanded)
MAX_JOINTS = 256
MAX_BODIES = 1024
MAX_FRAMES = 1024
#: controller ticks of one simulated run (duration x rate)
MAX_TICKS = 1_000_000
#: random configurations of a mass-matrix survey
MAX_CONFIGURATIONS = 100_000
#: thresholds of the unit warnings
WARN_MASS_KG = 1000.0
WARN_REACH_M = 5.0
WARN_LENGTH_M = 100.0
WARN_ANGLE_RAD = 2.0 * math.pi

# ---- value types --------------------------------------------------------------------------------
_NUM = dict(strict=True, allow_inf_nan=False)
Num = Annotated[float, Field(ge=-MAX_ABS, le=MAX_ABS, **_NUM)]
NonNeg = Annotated[float, Field(ge=0, le=MAX_ABS, **_NUM)]
Pos = Annotated[float, Field(gt=0, le=MAX_ABS, **_NUM)]
Mass = Annotated[float, Field(ge=0, le=MAX_ABS, description="kg", **_NUM)]
Length = Annotated[float, Field(ge=-MAX_ABS, le=MAX_ABS, description="m", **_NUM)]
Angle = Annotated[float, Field(ge=-MAX_ABS, le=MAX_ABS, description="rad", **_NUM)]
Duration = Annotated[float, Field(ge=1e-3, le=1e6, description="s", **_NUM)]
#: a controller's tick rate: at most one second per tick
Rate = Annotated[float, Field(ge=1, le=1e6, description="Hz", **_NUM)]
Samples = Annotated[int, Field(ge=3, le=MAX_SAMPLES, strict=True)]
Name = Annotated[str, Field(min_length=1, max_length=128, strict=True)]
Title = Annotated[str, Field(max_length=1000, strict=True)]


def _vec(n: int, item: Any = Num, description: str | None = None):
    return Annotated[list[item], Field(min_length=n, max_length=n, description=description)]


Vec2 = _vec(2)
Vec3 = _vec(3)
PosVec2 = _vec(2, Pos)
PosVec3 = _vec(3, Pos)
Xyz = _vec(3, Length, "m")
Rpy = _vec(3, Angle, "rad: roll, pitch, yaw (fixed axes x, then y, then z)")
JointValues = Annotated[list[Num], Field(min_length=1, max_length=MAX_JOINTS)]


def _custom(message: str, sub: str = "", value: Any = None, has_value: bool = True):
    """A validation error of ours: ``sub`` extends the location (``.axis``, ``[1][2]``); ``value``
    replaces the input shown."""
    return PydanticCustomError("mechbal", "{message}",
                               {"message": message, "sub": sub, "value": value, "has_value": has_value})


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def inertia_matrix(value: Any) -> np.ndarray:
    """An inertia tensor about the centre of mass [kg m^2] from a 3x3 list, three principal
    moments [Ixx, Iyy, Izz] or six values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]; it must be symmetric,
    positive semi-definite and satisfy the triangle inequality of a physical body (the checks of
    the C++ ``validate_rigid_body``). Raises a pydantic error (inside models) naming the entry."""
    shape = "must be a 3x3 matrix, [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]"
    if not isinstance(value, list):
        raise _custom(shape, value=value)
    rows = [x for x in value if isinstance(x, list)]
    if rows and (len(value) != 3 or len(rows) != 3):
        raise _custom(shape, value=value)
    entries = ([(f"[{i}][{k}]", x) for i, r in enumerate(value) for k, x in enumerate(r)] if rows
               else [(f"[{i}]", x) for i, x in enumerate(value)])
    if rows and any(len(r) != 3 for r in value):
        raise _custom(shape, value=value)
    if not rows and len(value) not in (3, 6):
        raise _custom(shape, value=value)
    for sub, x in entries:
        if not _is_number(x):
            raise _custom("must be a number", sub, x)
        if not math.isfinite(x):
            raise _custom("must be finite", sub, x)
        if abs(x) > MAX_ABS:
            raise _custom(f"must be between -{_fmt(MAX_ABS)} and {_fmt(MAX_ABS)}", sub, x)
    if rows:
        inertia = np.array(value, dtype=float)
    else:
        v = np.array(value, dtype=float)
        inertia = np.diag(v[:3])
        if len(v) == 6:
            inertia[0, 1] = inertia[1, 0] = v[3]
            inertia[0, 2] = inertia[2, 0] = v[4]
            inertia[1, 2] = inertia[2, 1] = v[5]
    scale = max(1.0, float(np.max(np.abs(inertia))))
    if np.max(np.abs(inertia - inertia.T)) > 1e-12 * scale:
        raise _custom("must be symmetric", value=value)
    p = np.linalg.eigvalsh(inertia)
    tol = 1e-12 * scale
    if p[0] < -tol:
        raise _custom(f"must be positive semi-definite, smallest principal moment is {p[0]:.6g}",
                      value=value)
    if p[2] > p[0] + p[1] + tol:
        raise _custom(f"violates the triangle inequality of a physical body: principal moments "
                      f"{p[0]:.6g}, {p[1]:.6g}, {p[2]:.6g}", value=value)
    return inertia


def _check_inertia(value: Any) -> Any:
    inertia_matrix(value)
    return value


_INERTIA_JSON = {
    "description": "kg m^2, about the centre of mass: [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, "
                   "Iyz] or a 3x3 matrix (symmetric, positive semi-definite, triangle inequality)",
    "anyOf": [
        {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
        {"type": "array", "items": {"type": "number"}, "minItems": 6, "maxItems": 6},
        {"type": "array", "minItems": 3, "maxItems": 3,
         "items": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}},
    ]}
Inertia = Annotated[Any, AfterValidator(_check_inertia), WithJsonSchema(_INERTIA_JSON)]


class Table(BaseModel):
    """A TOML table: unknown keys are errors, values are never coerced."""
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


class CaseHeader(Table):
    """``[case]``: what the file is."""
    name: Name = Field(description="the case's name (summary.json 'case')")
    kind: str = Field(description="which runner reads the file")
    title: Title = ""


# ---- the mechanism format (kinds serial_chain and mechanism) ----------------------------------

class Origin(Table):
    """A placement ``{xyz, rpy}`` (both optional): translation [m], then roll-pitch-yaw [rad]."""
    xyz: Xyz = [0.0, 0.0, 0.0]
    rpy: Rpy = [0.0, 0.0, 0.0]


class DH(Table):
    """Denavit-Hartenberg parameters (``mdh``: modified, Craig; ``dh``: standard)."""
    a: Length
    alpha: Angle
    d: Length = 0.0
    theta: Angle = 0.0


class Limits(Table):
    """Joint limits, all optional (absent: unbounded)."""
    lower: Optional[Num] = Field(None, description="rad or m")
    upper: Optional[Num] = Field(None, description="rad or m")
    velocity: Optional[Pos] = Field(None, description="rad/s or m/s")
    effort: Optional[Pos] = Field(None, description="N m or N")

    @model_validator(mode="after")
    def _ordered(self):
        if self.lower is not None and self.upper is not None and self.lower > self.upper:
            raise _custom(f"must be >= lower = {self.lower!r}", ".upper", self.upper)
        return self


class Mimic(Table):
    """Gear coupling: q = ratio * q[joint] + offset."""
    joint: Name
    ratio: Num = 1.0
    offset: Num = 0.0


class LinkInertial(Table):
    """The link's own body, in the link frame (the frame right after the joint's motion; for a
    ``dh`` joint the standard DH frame of the link)."""
    mass: Mass
    com: Xyz = [0.0, 0.0, 0.0]
    inertia: Inertia


JointType = Literal["revolute", "prismatic", "fixed", "spherical"]


class Joint(Table):
    """``[[mechanism.joints]]``: a joint and the link it moves (they share the name)."""
    name: Optional[Name] = Field(None, description="default joint<i> (1-based)")
    type: JointType = "revolute"
    parent: Optional[Name] = Field(
        None, description="parent joint's name or 'base'; default: the previous joint in the list "
                          "('base' for the first)")
    origin: Optional[Origin] = None
    mdh: Optional[DH] = None
    dh: Optional[DH] = None
    axis: Optional[Vec3] = Field(None, description="in the joint frame; default [0, 0, 1]")
    limits: Optional[Limits] = None
    mimic: Optional[Mimic] = None
    link: Optional[LinkInertial] = None

    @model_validator(mode="after")
    def _consistent(self):
        given = [k for k in ("origin", "mdh", "dh") if getattr(self, k) is not None]
        if len(given) > 1:
            raise _custom("give only one of origin, mdh, dh", value=given)
        if self.axis is not None:
            if given and given[0] != "origin":
                raise _custom("DH joints move along/about z; drop axis", ".axis", self.axis)
            if self.type in ("fixed", "spherical"):
                raise _custom(f"a {self.type} joint has no axis; drop it", ".axis", self.axis)
            scale = max(abs(x) for x in self.axis)
            if scale == 0.0 or np.linalg.norm(np.asarray(self.axis) / scale) * scale < 1e-12:
                raise _custom("must be a non-zero vector", ".axis", self.axis)
        for key in ("limits", "mimic"):
            if getattr(self, key) is not None and self.type in ("fixed", "spherical"):
                raise _custom(f"a {self.type} joint cannot have {key}", f".{key}",
                              getattr(self, key).model_dump())
        return self


BodyKind = Literal["link", "counterweight", "motor", "disc", "payload", "other"]


class Body(Table):
    """``[[mechanism.bodies]]``: an extra rigid body on a link."""
    name: Name
    kind: BodyKind = "other"
    link: Name = Field(description="name of the joint whose link carries it, or 'base'")
    mass: Mass
    com: Xyz = Field([0.0, 0.0, 0.0], description="m, in the link frame")
    inertia: Inertia
    rpy: Rpy = Field([0.0, 0.0, 0.0], description="rad, orientation of the inertia axes in the link frame")


class Frame(Table):
    """``[[mechanism.frames]]``: a named frame (tool, sensor) on a link."""
    name: Name
    link: Name = Field(description="name of the joint whose link carries it, or 'base'")
    origin: Origin = Origin()


class Loop(Table):
    """``[[mechanism.loops]]``: a loop closure between two named frames."""
    name: Name
    type: Literal["point", "planar_point", "axis", "weld"] = Field(
        "point", description="point (3 equations), planar_point (2, in the plane normal to frame_a's z), "
                             "axis (5: points coincide, z axes parallel), weld (6)")
    frame_a: Name = Field(description="a frame of [[mechanism.frames]]")
    frame_b: Name = Field(description="a frame of [[mechanism.frames]], on another branch")


SpringCount = Annotated[int, Field(ge=1, le=1000, strict=True, description="identical springs in parallel")]
PulleyRatio = Annotated[float, Field(gt=0, le=1000, description="k: the anchor distance changes k times "
                                                                "as much as each spring's length", **_NUM)]


class MechanismSpring(Table):
    """``[[mechanism.springs]]``: ``count`` identical linear springs of ``rate`` [N/m] each
    between anchor A on link ``link_a`` and anchor B on ``link_b`` (anchors in the frames the
    user described those links in, as a body's ``com``), carrying ``preload`` [N] each at the
    anchor distance ``free_length`` [m], through a block and tackle of ratio ``pulley_ratio``:
    tension at the anchors count preload / k + count rate / k^2 (d - free_length). Part of the
    model: the inverse dynamics, static torque and simulation include it."""
    name: Name
    link_a: Name = Field(description="joint whose link carries anchor A, or 'base'")
    anchor_a: Xyz = Field(description="m, in link_a's frame")
    link_b: Name = Field(description="joint whose link carries anchor B, or 'base'")
    anchor_b: Xyz = Field(description="m, in link_b's frame")
    rate: NonNeg = Field(description="N/m, of each spring")
    free_length: NonNeg = Field(0.0, description="m: anchor distance at which each spring carries only its preload")
    preload: NonNeg = Field(0.0, description="N: initial tension of each spring")
    count: SpringCount = 1
    pulley_ratio: PulleyRatio = 1.0


class Mechanism(Table):
    """``[mechanism]``: a tree of joints with bodies, gears, frames, loop closures and springs."""
    gravity: Vec3 = Field([0.0, 0.0, -9.81], description="m/s^2, in O")
    base: Optional[Origin] = Field(None, description="placement of the root joints' base frame in O")
    joints: Annotated[list[Joint], Field(min_length=1, max_length=MAX_JOINTS)]
    bodies: Annotated[list[Body], Field(max_length=MAX_BODIES)] = []
    frames: Annotated[list[Frame], Field(max_length=MAX_FRAMES)] = []
    loops: Annotated[list[Loop], Field(max_length=MAX_FRAMES)] = []
    actuated: Annotated[list[Name], Field(max_length=MAX_JOINTS,
                                          description="actuated joints (required with loops)")] = []
    springs: Annotated[list[MechanismSpring], Field(max_length=MAX_BODIES)] = []


class ChainTrajectory(Table):
    """``[trajectory]``: rest-to-rest motion of the actuated joints (every independent joint of an
    open mechanism)."""
    law: Literal["quintic", "cubic"] = "quintic"
    start: JointValues = Field(description="one value per actuated joint (rad or m)")
    end: JointValues = Field(description="one value per actuated joint (rad or m)")
    duration: Duration
    samples: Samples = 501
    initial_guess: Optional[JointValues] = Field(
        None, description="closed mechanisms: every joint coordinate near the assembly at start "
                          "(picks the assembly mode of the loops), rad or m")


# ---- [balance]: the design variables of `mechbal balance` (mechbal.balance) -----------------

BalanceMethod = Literal["static", "force", "moment", "springs", "rms"]


class BalanceCounterweight(Table):
    """``[[balance.counterweights]]``: a counterweight the method may add (a point mass, plus
    ``inertia`` about its centre): its mass within [mass_min, mass_max] (or fixed: ``mass``),
    its centre within ``max_radius`` of ``center``, on the line ``direction`` through ``center``
    if given, or at ``position`` (given: only the mass is chosen); positions in the frame the user
    described the link in (DH frame for ``dh``). ``tie``: share the mass and position (each in its
    own link frame) of another counterweight of the table, e.g. the same counterweight on each
    identical leg of a parallel mechanism; a tied counterweight gives only name, link and tie."""
    name: Name = Field(description="the counterweight's body name (must be new)")
    link: Name = Field(description="name of the joint whose link carries it")
    mass: Optional[Mass] = Field(None, description="kg, a fixed mass (instead of mass_min / mass_max)")
    mass_min: Optional[Mass] = Field(None, description="kg (default 0)")
    mass_max: Optional[Mass] = Field(None, description="kg (absent: unbounded)")
    max_radius: Optional[NonNeg] = Field(None, description="m, largest distance from center (absent: unbounded)")
    center: Xyz = Field([0.0, 0.0, 0.0], description="m, in the link's frame")
    direction: Optional[Vec3] = Field(None, description="the counterweight slides on this line through center")
    position: Optional[Xyz] = Field(None, description="m, in the link's frame: the position is given, only "
                                                      "the mass is chosen (no center, direction, max_radius)")
    tie: Optional[Name] = Field(None, description="name of another counterweight of this table whose mass and "
                                                  "position (in each one's own link frame) this one shares")
    inertia: Optional[Inertia] = None

    @model_validator(mode="after")
    def _masses(self):
        given = self.model_fields_set
        if self.tie is not None:
            own = [k for k in ("mass", "mass_min", "mass_max", "max_radius", "center", "direction", "position",
                               "inertia") if k in given]
            if own:
                raise _custom(f"a counterweight tied to {self.tie!r} takes its mass, position and bounds from "
                              f"it: give only name, link and tie", f".{own[0]}", getattr(self, own[0]))
        if self.position is not None:
            for k in ("max_radius", "direction", "center"):
                if k in given:
                    raise _custom(f"the position is given ({self.position}): only the mass is chosen, so "
                                  f"give no {k}", f".{k}", getattr(self, k))
        if self.mass is not None and (self.mass_min is not None or self.mass_max is not None):
            raise _custom("give either mass or mass_min / mass_max", ".mass", self.mass)
        lo = self.mass_min or 0.0
        if self.mass_max is not None and self.mass_max < lo:
            raise _custom(f"must be >= mass_min = {lo!r}", ".mass_max", self.mass_max)
        if self.direction is not None and not any(self.direction):
            raise _custom("must be a non-zero vector", ".direction", self.direction)
        return self


AnchorBounds = Annotated[list[Xyz], Field(min_length=2, max_length=2,
                                           description="m: [lower xyz, upper xyz] the method may move the anchor in")]


class BalanceSpring(Table):
    """``[[balance.springs]]``: a spring the springs method may add (or size), as
    ``[[mechanism.springs]]`` but with ``rate`` optional: absent, it is chosen within
    ``rate_min`` .. ``rate_max`` by least squares (static balance over the workspace sample);
    ``anchor_a_bounds`` / ``anchor_b_bounds`` let the method move an anchor within a box (its
    coordinates with lower < upper)."""
    name: Name = Field(description="the spring's name (must be new)")
    link_a: Name = Field(description="joint whose link carries anchor A, or 'base'")
    anchor_a: Xyz = Field(description="m, in link_a's frame (the frame the link was described in)")
    link_b: Name = Field(description="joint whose link carries anchor B, or 'base'")
    anchor_b: Xyz = Field(description="m, in link_b's frame")
    free_length: NonNeg = Field(0.0, description="m: anchor distance at which each spring carries only its preload")
    rate: Optional[NonNeg] = Field(None, description="N/m, of each spring (absent: sized)")
    rate_min: Optional[NonNeg] = Field(None, description="N/m (default 0)")
    rate_max: Optional[NonNeg] = Field(None, description="N/m (absent: unbounded)")
    preload: NonNeg = Field(0.0, description="N: initial tension of each spring")
    count: SpringCount = 1
    pulley_ratio: PulleyRatio = 1.0
    anchor_a_bounds: Optional[AnchorBounds] = None
    anchor_b_bounds: Optional[AnchorBounds] = None

    @model_validator(mode="after")
    def _rates_and_bounds(self):
        if self.rate is not None and (self.rate_min is not None or self.rate_max is not None):
            raise _custom("give either rate or rate_min / rate_max", ".rate", self.rate)
        lo = self.rate_min or 0.0
        if self.rate_max is not None and self.rate_max < lo:
            raise _custom(f"must be >= rate_min = {lo!r}", ".rate_max", self.rate_max)
        for side in ("a", "b"):
            b = getattr(self, f"anchor_{side}_bounds")
            if b is not None and any(l > u for l, u in zip(b[0], b[1])):
                raise _custom("lower must be <= upper in every coordinate", f".anchor_{side}_bounds", b)
        return self


class BalanceDisc(Table):
    """``[[balance.discs]]`` (method moment): a counter-rotating disc the method may add on an axle
    of link ``carrier`` through ``position`` along ``axis`` (carrier frame), turning relative to
    the carrier by ``ratio`` times the rate of coordinate ``joint`` (a gear train: a gear coupling
    on the model). Its mass is part of the carrier's; ``inertia`` (axial, about the axle) and
    ``ratio`` absent are chosen by the method (mechbal.balance.DiscSlot)."""
    name: Name = Field(description="the disc's joint and body name (must be new)")
    carrier: Name = Field(description="link (joint name, or 'base') that carries the axle")
    joint: Name = Field(description="the coordinate the disc is geared to")
    axis: Vec3 = Field([1.0, 0.0, 0.0], description="the axle's direction in the carrier's frame")
    position: Xyz = Field([0.0, 0.0, 0.0], description="m, a point of the axle in the carrier's frame")
    ratio: Optional[Num] = Field(None, description="gear ratio (absent: chosen)")
    inertia: Optional[NonNeg] = Field(None, description="kg m^2, axial inertia (absent: chosen)")
    transverse_inertia: Optional[NonNeg] = Field(None, description="kg m^2 (absent: inertia / 2, a thin disc)")
    inertia_min: NonNeg = Field(0.0, description="kg m^2, bound on a chosen inertia")
    inertia_max: Optional[NonNeg] = Field(None, description="kg m^2, bound on a chosen inertia (absent: none)")
    ratio_min: Optional[Num] = Field(None, description="a chosen ratio below it is reported")
    ratio_max: Optional[Num] = Field(None, description="a chosen ratio above it is reported")

    @model_validator(mode="after")
    def _disc(self):
        if not any(self.axis):
            raise _custom("must be a non-zero vector", ".axis", self.axis)
        given = self.model_fields_set
        if self.inertia is not None:
            for k in ("inertia_min", "inertia_max"):
                if k in given:
                    raise _custom(f"the inertia is given ({self.inertia!r}): give no {k}", f".{k}", getattr(self, k))
        if self.inertia_max is not None and self.inertia_max < self.inertia_min:
            raise _custom(f"must be >= inertia_min = {self.inertia_min!r}", ".inertia_max", self.inertia_max)
        if self.ratio is not None:
            for k in ("ratio_min", "ratio_max"):
                if k in given:
                    raise _custom(f"the ratio is given ({self.ratio!r}): give no {k}", f".{k}", getattr(self, k))
        if self.ratio_min is not None and self.ratio_max is not None and self.ratio_max < self.ratio_min:
            raise _custom(f"must be >= ratio_min = {self.ratio_min!r}", ".ratio_max", self.ratio_max)
        return self


class BalanceInertia(Table):
    """``[[balance.inertias]]`` (method moment): central principal inertias of an existing body
    that the method may choose (mechbal.balance.InertiaSlot)."""
    name: Name
    body: Name = Field(description="an existing body of the mechanism")
    components: Annotated[list[Literal["Ixx", "Iyy", "Izz"]], Field(min_length=1, max_length=3)] = Field(
        ["Iyy"], description="which central principal inertias (link axes) are chosen")
    minimum: NonNeg = Field(0.0, description="kg m^2, lower bound of each")


class Balance(Table):
    """``[balance]``: what ``mechbal balance`` may change and what it must hold over."""
    method: Optional[BalanceMethod] = Field(None, description="default of --method")
    counterweights: Annotated[list[BalanceCounterweight], Field(max_length=MAX_BODIES)] = []
    springs: Annotated[list[BalanceSpring], Field(max_length=MAX_BODIES)] = []
    catalogue: Optional[Annotated[str, Field(min_length=1, max_length=4096, strict=True)]] = Field(
        None, description="springs method: a spring catalogue CSV to select off-the-shelf springs from "
                          "(path relative to the case file), or 'shipped' for mechbal's own")
    discs: Annotated[list[BalanceDisc], Field(max_length=MAX_BODIES)] = []
    inertias: Annotated[list[BalanceInertia], Field(max_length=MAX_BODIES)] = []
    mass_budget: Optional[Pos] = Field(None, description="kg, total counterweight mass")
    samples: Optional[Annotated[int, Field(ge=1, le=MAX_CONFIGURATIONS, strict=True)]] = Field(
        None, description="random workspace samples (static: 1000, force: 200 motions, moment: 200 poses)")
    seed: Annotated[int, Field(ge=0, le=2**63 - 1, strict=True)] = 0
    lower: Optional[JointValues] = Field(None, description="sample box, per independent (closed: actuated) joint")
    upper: Optional[JointValues] = None
    objective: Literal["rms", "peak"] = Field("rms", description="rms method: RMS or peak torque")
    coupling: Optional[Literal["per_joint", "total"]] = Field(
        None, description="rms method: each joint by its own link's slots (default, open) or all together")
    weights: Optional[JointValues] = Field(None, description="rms method, total coupling: per actuated joint")
    check_motions: Optional[Annotated[int, Field(ge=1, le=MAX_CONFIGURATIONS, strict=True)]] = Field(
        None, description="moment method: random motions the balanced angular momentum is checked on (1000)")

    @model_validator(mode="after")
    def _names(self):
        names = [c.name for c in self.counterweights]
        for i, c in enumerate(self.counterweights):
            if c.tie is not None and (c.tie not in names or c.tie == c.name):
                others = [n for n in names if n != c.name]
                what = "itself" if c.tie == c.name else "no counterweight of this table"
                raise _custom(f"names {what}{did_you_mean(c.tie, others) if c.tie != c.name else ''}",
                              f".counterweights[{i}].tie", c.tie)
        seen: dict[str, str] = {}
        for key in ("counterweights", "discs", "inertias"):
            for i, c in enumerate(getattr(self, key)):
                if c.name in seen:
                    raise _custom(f"is already the name of {seen[c.name]}", f".{key}[{i}].name", c.name)
                seen[c.name] = f"{key}[{i}]"
        return self


class _MechanismCase(Table):
    """A case with a ``[mechanism]`` table: its :class:`mechbal.spec.MechanismSpec`, built once."""
    _spec: Any = PrivateAttr(None)

    @property
    def spec(self):
        """The :class:`mechbal.spec.MechanismSpec` of ``[mechanism]``."""
        if self._spec is None:
            from mechbal.spec import mechanism_spec

            self._spec = mechanism_spec(self.mechanism)  # type: ignore[attr-defined]
        return self._spec


#: the momentum components a reactionless controller can cancel ([control].cancel)
MomentumComponentName = Literal["moment", "force", "both", "moment_x", "moment_y", "moment_z",
                                "force_x", "force_y", "force_z"]


class Control(Table):
    """``[control]``: a real-time controller run along the case's trajectory. ``kind =
    "reactionless"``: the balancing joints keep the cancelled momentum components at their
    initial value (:class:`mechbal.control.ReactionlessController`); ``mechbal run`` compares the
    motion with the balancing joints held (uncontrolled) and controlled."""
    kind: Literal["reactionless", "computed_torque", "decoupled"] = Field(
        description="which controller (mechbal run supports reactionless)")
    balancing_joints: Annotated[list[Name], Field(min_length=1, max_length=MAX_JOINTS)] = Field(
        description="actuated joints whose motion the controller computes")
    cancel: Annotated[list[MomentumComponentName], Field(min_length=1, max_length=9)] = ["moment"]
    integrator: Literal["euler", "rk4"] = "rk4"
    rate_hz: Rate = 1000.0
    damping: Annotated[float, Field(gt=0, lt=1, **_NUM)] = Field(
        1e-2, description="damped least squares near singularity, relative to the largest "
                          "singular value")
    max_rate: Pos = Field(100.0, description="balancing joints' rate limit (rad/s or m/s)")
    home_gain: NonNeg = Field(0.0, description="redundant balancing joints: pull towards the start pose (1/s)")
    limit_gain: NonNeg = Field(0.0, description="redundant balancing joints: push away from the joint limits")
    task_frame: Optional[Name] = Field(
        None, description="operational-space mode: [trajectory] is then the frame's path "
                          "(not yet supported by mechbal run)")

    @model_validator(mode="after")
    def _distinct(self):
        seen = set()
        for i, name in enumerate(self.balancing_joints):
            if name in seen:
                raise _custom("is listed twice", f".balancing_joints[{i}]", name)
            seen.add(name)
        return self


class SerialChainCaseHeader(CaseHeader):
    kind: Literal["serial_chain", "mechanism"]


class SerialChainCase(_MechanismCase):
    """A mechanism moving along a rest-to-rest trajectory (kinds ``serial_chain``, ``mechanism``)."""
    case: SerialChainCaseHeader
    mechanism: Mechanism
    trajectory: ChainTrajectory
    balance: Optional[Balance] = None
    control: Optional[Control] = None


# ---- rpsp (Heydari & Enferadi): the 3(RPSP)-S robot as data on the general model ----------------

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


# ---- arm2dof (Arakelian, Le Baron & Mottu 2011) ---------------------------------------------------

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


# ---- paminsa (Briot & Arakelian 2009) -------------------------------------------------------------

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


# ---- discs (Coutinho & Hess Coelho) ---------------------------------------------------------------

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


# ---- sweep files (mechbal sweep CASE --spec FILE; mechbal.sweep) --------------------------------------

#: rows of one sweep's table
MAX_EVALUATIONS = 10_000_000
SweepPath = Annotated[str, Field(min_length=1, max_length=300, strict=True)]


class SweepParameter(Table):
    """``[[sweep.parameters]]``: a swept number and its range (exactly one of tolerance, delta,
    lower + upper, std, values)."""
    path: SweepPath = Field(description="bodies.<body>.mass | .com[i] | .inertia[k] | .inertia[i][j], "
                                        "joints.<joint>.placement.xyz[i] | .placement.rpy[i] | .axis[i], "
                                        "gravity[i], design.<name>")
    distribution: Literal["uniform", "normal"] = Field(
        "uniform", description="uniform over the range, or normal (the range's half-width is 3 sigma)")
    tolerance: Optional[NonNeg] = Field(None, description="relative: nominal x (1 -+ tolerance), e.g. 0.02")
    delta: Optional[NonNeg] = Field(None, description="absolute: nominal -+ delta (units of the parameter)")
    lower: Optional[Num] = Field(None, description="absolute lower bound (with upper)")
    upper: Optional[Num] = Field(None, description="absolute upper bound (with lower)")
    mean: Optional[Num] = Field(None, description="normal law: mean (default the nominal value), with std")
    std: Optional[NonNeg] = Field(None, description="normal law: standard deviation")
    values: Optional[Annotated[list[Num], Field(min_length=1, max_length=10_000)]] = Field(
        None, description="a list: Monte Carlo draws from it, a grid takes each value")
    nominal: Optional[Num] = Field(None, description="overrides the mechanism's value; required for design.<name>")
    steps: Optional[Annotated[int, Field(ge=2, le=10_000, strict=True)]] = Field(
        None, description="grid: evenly spaced values across the range (default 3)")

    @model_validator(mode="after")
    def _one_range(self):
        given = [k for k in ("tolerance", "delta", "lower", "std", "values") if getattr(self, k) is not None]
        if self.upper is not None and self.lower is None:
            raise _custom("goes with lower", ".upper", self.upper)
        if self.lower is not None and self.upper is None:
            raise _custom("is required with lower", ".upper", has_value=False)
        if len(given) != 1:
            raise _custom("give exactly one range: tolerance, delta, lower and upper, std or values",
                          value=given or "none")
        if self.lower is not None and self.lower > self.upper:
            raise _custom(f"must be >= lower = {self.lower!r}", ".upper", self.upper)
        if self.std is not None and self.distribution != "normal":
            raise _custom('is for distribution = "normal"', ".std", self.std)
        if self.mean is not None and self.std is None:
            raise _custom("goes with std (a normal law)", ".mean", self.mean)
        if self.path.startswith("design.") and self.nominal is None:
            raise _custom("a design variable needs a nominal value", ".nominal", has_value=False)
        return self


class SweepPoses(Table):
    """``[sweep.poses]``: the workspace sample of the gravity-torque metrics."""
    source: Optional[Literal["trajectory", "uniform"]] = Field(
        None, description="trajectory: instants evenly spread along the case's trajectory (default); "
                          "uniform: random in lower/upper (default the joint limits or -+pi), from the seed")
    count: Annotated[int, Field(ge=1, le=100_000, strict=True)] = 100
    lower: Optional[JointValues] = Field(None, description="uniform: one value per actuated joint (rad or m)")
    upper: Optional[JointValues] = Field(None, description="uniform: one value per actuated joint (rad or m)")


class Sweep(Table):
    """``[sweep]``: what to vary, how, and what to measure."""
    name: Name
    title: Title = ""
    kind: Literal["monte_carlo", "sensitivity", "grid"] = Field(
        description="monte_carlo: random draws; sensitivity: one parameter at a time at the ends of its "
                    "range (tornado chart); grid: every combination")
    evaluations: Optional[Annotated[int, Field(ge=1, le=MAX_EVALUATIONS, strict=True)]] = Field(
        None, description="monte_carlo: number of draws")
    seed: Annotated[int, Field(ge=0, le=2**63 - 1, strict=True)] = 0
    metrics: Annotated[list[Name], Field(min_length=1, max_length=64, description=(
        "gravity_torque_peak | gravity_torque_rms | actuator_torque_peak | actuator_torque_rms | "
        "shaking_force_peak | shaking_force_rms | shaking_moment_peak | shaking_moment_rms, "
        "torques optionally .<joint>"))]
    parameters: Annotated[list[SweepParameter], Field(min_length=1, max_length=256)]
    poses: SweepPoses = SweepPoses()
    trajectory_samples: Optional[Samples] = Field(
        None, description="instants of the case's trajectory for the trajectory metrics (default the case's)")
    chunk_size: Optional[Annotated[int, Field(ge=1, le=1_000_000, strict=True)]] = Field(
        None, description="evaluations per task (default 4096 when only body parameters vary, else 64)")
    output: Literal["parquet", "csv"] = "parquet"

    @model_validator(mode="after")
    def _evaluations(self):
        if self.kind == "monte_carlo" and self.evaluations is None:
            raise _custom("is required for kind = \"monte_carlo\"", ".evaluations", has_value=False)
        if self.kind != "monte_carlo" and self.evaluations is not None:
            raise _custom(f"is only for kind = \"monte_carlo\" ({self.kind} sweeps have as many "
                          "evaluations as their parameters give)", ".evaluations", self.evaluations)
        return self


class SweepFile(Table):
    """A sweep file: a ``[sweep]`` table over the case given on the command line."""
    sweep: Sweep


# ---- orthoglide (Martini, Troncossi, Carricato & Rivola 2015) -------------------------------------

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


#: case kind -> model (discs: case.mechanism -> model)
CASE_MODELS: dict[str, Any] = {
    "serial_chain": SerialChainCase,
    "mechanism": SerialChainCase,
    "arm2dof": Arm2DofCase,
    "paminsa": PaminsaCase,
    "rpsp": RpspCase,
    "discs": {"planar3r": Planar3rCase, "spatial3r": Spatial3rCase, "scara": ScaraCase,
              "fivebar": FivebarCase},
    "orthoglide": OrthoglideCase,
}
KINDS = tuple(CASE_MODELS)
CaseModel = Union[SerialChainCase, RpspCase, OrthoglideCase, Arm2DofCase, PaminsaCase, Planar3rCase,
                  Spatial3rCase, ScaraCase, FivebarCase]


def _check_ticks(duration: float, rate_hz: float, sub: str, what: str = "duration x rate_hz"):
    ticks = duration * rate_hz
    if ticks > MAX_TICKS:
        raise _custom(f"{what} must be <= {MAX_TICKS} ticks", sub, ticks)


# ---- error messages -----------------------------------------------------------------------------

def _fmt(x: Any) -> str:
    """A bound as people write it: 0, 1000000, 0.9, 1e+12."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return str(x)
    if float(x).is_integer() and abs(x) < 1e7:
        return str(int(x))
    return f"{x:g}"


def _path(loc: tuple, prefix: str = "") -> str:
    out = prefix
    for x in loc:
        if isinstance(x, int):
            out += f"[{x}]"
        else:
            x = str(x)
            if not x.isprintable() or any(c in x for c in ".[]\"' "):
                x = repr(x)  # a key with a newline or a dot stays one readable line
            out += f".{x}" if out else x
    return out


def _unwrap(t: Any) -> Any:
    while True:
        origin = get_origin(t)
        if origin is Annotated:
            t = get_args(t)[0]
        elif origin is Union or (sys.version_info >= (3, 10) and type(t).__name__ == "UnionType"):
            args = [a for a in get_args(t) if a is not type(None)]
            if len(args) != 1:
                return t
            t = args[0]
        else:
            return t


def _type_at(root: Any, loc: tuple) -> Any:
    """The annotation of the value at ``loc`` in model ``root`` (None if unknown)."""
    t: Any = root
    for x in loc:
        t = _unwrap(t)
        if isinstance(x, int):
            if get_origin(t) is not list:
                return None
            t = get_args(t)[0]
        elif isinstance(t, type) and issubclass(t, BaseModel) and x in t.model_fields:
            field = t.model_fields[x]
            t = field.annotation
            if field.metadata:
                t = Annotated[(t, *field.metadata)]
        else:
            return None
    return _unwrap(t)


def _lengths(root: Any, loc: tuple) -> tuple[Any, Any]:
    """(min_length, max_length) declared for the list at ``loc``."""
    parent = _type_at(root, loc[:-1])
    if not (loc and isinstance(parent, type) and issubclass(parent, BaseModel)
            and loc[-1] in parent.model_fields):
        return None, None
    lo = hi = None
    field = parent.model_fields[loc[-1]]
    metadata = list(field.metadata)
    t = field.annotation
    while True:  # Optional[Annotated[list, Field(...)]]
        if get_origin(t) is Annotated:
            metadata += list(get_args(t)[1:])
            t = get_args(t)[0]
        elif get_origin(t) is Union:
            args = [a for a in get_args(t) if a is not type(None)]
            if len(args) != 1:
                break
            t = args[0]
        else:
            break
    for m in metadata:
        lo = getattr(m, "min_length", None) if lo is None else lo
        hi = getattr(m, "max_length", None) if hi is None else hi
    return lo, hi


def _allowed_keys(root: Any, loc: tuple) -> list[str]:
    t = _type_at(root, loc)
    if isinstance(t, type) and issubclass(t, BaseModel):
        return list(t.model_fields)
    return []


def _choices(root: Any, loc: tuple) -> list[str]:
    t = _type_at(root, loc)
    if get_origin(t) is Literal:
        return [str(a) for a in get_args(t)]
    return []


def did_you_mean(word: str, allowed: list[str]) -> str:
    """`` (did you mean 'com'?)`` for the nearest allowed word, else the list of allowed words."""
    lower = {a.lower(): a for a in allowed}
    match = difflib.get_close_matches(word, allowed, n=1, cutoff=0.6) or \
        ([lower[word.lower()]] if word.lower() in lower else []) or \
        [lower[m] for m in difflib.get_close_matches(word.lower(), list(lower), n=1, cutoff=0.6)]
    if match:
        return f" (did you mean {match[0]!r}?)"
    if allowed:
        return f" (allowed: {', '.join(allowed)})"
    return ""


_TYPE_WORDS = {
    "float_type": "must be a number", "float_parsing": "must be a number",
    "int_type": "must be an integer", "int_parsing": "must be an integer",
    "int_from_float": "must be an integer", "string_type": "must be a string",
    "list_type": "must be a list", "dict_type": "must be a table", "model_type": "must be a table",
    "model_attributes_type": "must be a table", "finite_number": "must be finite",
    "bool_type": "must be true or false",
}


def _at(data: Any, loc: tuple) -> Any:
    for x in loc:
        try:
            data = data[x]
        except (KeyError, IndexError, TypeError):
            return None
    return data


def _message(err: dict, root: Any, prefix: str, data: Any = None) -> tuple[str, str, bool, Any]:
    """(field, message, has_value, value) of one pydantic error."""
    loc, typ, ctx = tuple(err.get("loc", ())), err.get("type", ""), err.get("ctx") or {}
    value = err.get("input")
    if typ == "mechbal":
        field = _path(loc, prefix) + ctx.get("sub", "")
        v = ctx.get("value")
        return field, ctx["message"], ctx.get("has_value", True), value if v is None else v
    field = _path(loc, prefix)
    if typ == "extra_forbidden":
        key = str(loc[-1]) if loc else "?"
        what = "unknown table" if isinstance(value, dict) else "unknown key"
        allowed = _allowed_keys(root, loc[:-1])
        table = _at(data, loc[:-1])
        if isinstance(table, dict):  # the user meant a key that is not there yet
            absent = [k for k in allowed if k not in table]
            hint = did_you_mean(key, absent)
            if "did you" in hint:
                return field, what + hint, False, None
        return field, what + did_you_mean(key, allowed), False, None
    if typ == "missing":
        return field, "is required", False, None
    if typ == "literal_error":
        choices = _choices(root, loc)
        hint = did_you_mean(value, choices) if isinstance(value, str) and choices else ""
        if hint.startswith(" (allowed"):
            hint = ""
        text = f"must be one of {', '.join(choices)}" if choices else "must be " + ctx.get("expected", "?")
        return field, text + hint, True, value
    bounds = {"greater_than_equal": (">=", "ge"), "greater_than": (">", "gt"),
              "less_than_equal": ("<=", "le"), "less_than": ("<", "lt")}
    if typ in bounds:
        op, key = bounds[typ]
        return field, f"must be {op} {_fmt(ctx.get(key))}", True, value
    if typ in ("too_short", "too_long"):
        lo, hi = _lengths(root, loc)
        if lo is not None and lo == hi:
            text = f"must have {lo} values"
        elif typ == "too_short":
            text = f"must have at least {lo} values"
        else:
            text = f"must have at most {hi} values"
        return field, text, True, value
    if typ in ("string_too_short",):
        return field, "must not be empty", True, value
    if typ in ("string_too_long",):
        return field, f"must have at most {ctx.get('max_length')} characters", True, value
    if typ in _TYPE_WORDS:
        text = _TYPE_WORDS[typ]
        if typ in ("float_type", "int_type") and _is_number(value) and not math.isfinite(float(value)):
            text = "must be finite"
        return field, text, True, value
    return field, err.get("msg", "is invalid"), True, value


def _errors_to_config_error(exc: ValidationError, root: Any, prefix: str = "", data: Any = None) -> ConfigError:
    errors = exc.errors(include_url=False)
    # an unknown key first: it usually explains the rest (a misspelled required key is also missing)
    errors.sort(key=lambda e: e.get("type") != "extra_forbidden")
    problems = []
    for err in errors:
        field, text, has_value, value = _message(err, root, prefix, data)
        line = f"{field}: {text}" if field else text
        if has_value:
            line += f" (got {short_repr(value)})"
        problems.append((field, line, text, has_value, value))
    field, _, text, has_value, value = problems[0]
    if len(problems) > 1:
        rest = "; ".join(p[1] for p in problems[1:4])
        more = f"; and {len(problems) - 4} more" if len(problems) > 4 else ""
        if has_value:
            text += f" (got {short_repr(value)})"
            has_value = False
        text += f"; also {rest}{more}"
    return ConfigError(field, text, value, has_value=has_value,
                       problems=[(p[0], p[1]) for p in problems])


def validate_table(model: type, data: Any, prefix: str = "") -> Any:
    """``model`` validated from ``data``; a ConfigError (fields under ``prefix``) if not."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise _errors_to_config_error(exc, model, prefix, data) from None
    except RecursionError:
        raise ConfigError(prefix or "case", "is nested too deeply", has_value=False) from None


# ---- the whole file -----------------------------------------------------------------------------

def _unknown_key_near(table: dict, wanted: str, allowed: list[str], prefix: str) -> None:
    """A missing ``wanted`` key is most likely misspelled: name the unknown key nearest to it."""
    unknown = [k for k in table if isinstance(k, str) and k not in allowed]
    near = difflib.get_close_matches(wanted, unknown, n=1, cutoff=0.6)
    if near:
        what = "unknown table" if isinstance(table[near[0]], dict) else "unknown key"
        raise ConfigError(_path((near[0],), prefix), f"{what} (did you mean {wanted!r}?)",
                          has_value=False)


def _model_for(config: Any) -> type:
    if not isinstance(config, dict):
        raise ConfigError("case file", "must be a TOML document (a table)", config)
    header = config.get("case")
    if header is None:
        _unknown_key_near(config, "case", [], "")
        raise ConfigError("case", "is required", has_value=False)
    if not isinstance(header, dict):
        raise ConfigError("case", "must be a table", header)
    header_keys = list(DiscsCaseHeader.model_fields)
    kind = header.get("kind")
    if kind is None:
        _unknown_key_near(header, "kind", header_keys, "case")
        raise ConfigError("case.kind", "is required", has_value=False)
    if not isinstance(kind, str):
        raise ConfigError("case.kind", "must be a string", kind)
    if kind not in CASE_MODELS:
        hint = did_you_mean(kind, list(KINDS))
        raise ConfigError("case.kind", f"unknown kind{hint if 'did you' in hint else ''} "
                                       f"(known: {', '.join(KINDS)})", kind)
    model = CASE_MODELS[kind]
    if isinstance(model, dict):
        mech = header.get("mechanism")
        if mech is None:
            _unknown_key_near(header, "mechanism", header_keys, "case")
            raise ConfigError("case.mechanism", f"is required for kind {kind!r} (one of "
                                                f"{', '.join(model)})", has_value=False)
        if not isinstance(mech, str) or mech not in model:
            hint = did_you_mean(mech, list(model)) if isinstance(mech, str) else ""
            hint = hint if "did you" in hint else ""
            raise ConfigError("case.mechanism", f"must be one of {', '.join(model)}{hint}", mech)
        model = model[mech]
    return model


def validate_case(config: Any, *, warn: bool = True):
    """The validated model of a whole case file (a dict from TOML), or a ConfigError naming the
    first problem: unknown or misspelled keys and tables anywhere, types, ranges, sizes, and the
    checks across tables. Likely unit mistakes are warned about (:class:`ConfigWarning`).
    Idempotent: a validated model is returned as is."""
    if isinstance(config, BaseModel):
        return config
    model = _model_for(config)
    case = validate_table(model, config)
    _cross_checks(case)
    if warn:
        for field, message in unit_warnings(case):
            warnings.warn(f"{field}: {message}", ConfigWarning, stacklevel=2)
    return case


def _cross_checks(case: Any) -> None:
    if isinstance(case, OrthoglideCase):
        _orthoglide_cross_checks(case)
    if isinstance(case, RpspCase):
        _rpsp_cross_checks(case)
    if isinstance(case, SerialChainCase):
        spec = case.spec  # cross references of the mechanism (ConfigError naming the field)
        names = list(spec.actuated) if spec.loops else spec.independent_joints
        if not names:
            raise ConfigError("mechanism.joints", "needs at least one moving joint that is not a mimic",
                              has_value=False)
        for key in ("start", "end"):
            v = getattr(case.trajectory, key)
            if len(v) != len(names):
                raise ConfigError(f"trajectory.{key}", f"must have {len(names)} values (one per "
                                                       f"{'actuated' if spec.loops else 'independent'} "
                                                       f"joint: {', '.join(names)})", v)
        n_bodies = max(1, len(spec.bodies))
        if case.trajectory.samples * n_bodies > MAX_SAMPLE_BODIES:
            raise ConfigError("trajectory.samples", f"must be <= {MAX_SAMPLE_BODIES // n_bodies} for "
                                                    f"{n_bodies} bodies (samples x bodies <= "
                                                    f"{MAX_SAMPLE_BODIES})", case.trajectory.samples)


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


# ---- unit warnings -------------------------------------------------------------------------------

def _angle_warning(field: str, x: float):
    if abs(x) > WARN_ANGLE_RAD:
        return field, f"{x:g} rad is more than 2*pi in magnitude: degrees? (angles are in radians)"
    return None


def _length_warning(field: str, x: float):
    if abs(x) > WARN_LENGTH_M:
        return field, f"{x:g} m is more than {WARN_LENGTH_M:g} m: millimetres? (lengths are in metres)"
    return None


def _mass_warnings(masses: list[tuple[str, float]], reach: float):
    if reach >= WARN_REACH_M:
        return []
    return [(f, f"{m:g} kg on a mechanism of reach {reach:.3g} m: grams? (masses are in kg)")
            for f, m in masses if m > WARN_MASS_KG]


def unit_warnings(case: Any) -> list[tuple[str, str]]:
    """(field, message) of every likely unit mistake in a validated case."""
    out = []
    add = lambda w: w is not None and out.append(w)  # noqa: E731
    if isinstance(case, (SerialChainCase, RpspCase)):
        m = case.mechanism
        reach = 0.0
        origins = [("mechanism.base", m.base)] if m.base is not None else []
        masses = []
        for i, j in enumerate(m.joints):
            f = f"mechanism.joints[{i}]"
            if j.origin is not None:
                origins.append((f"{f}.origin", j.origin))
                reach += float(np.linalg.norm(j.origin.xyz))
            for key in ("dh", "mdh"):
                dh = getattr(j, key)
                if dh is not None:
                    for a in ("alpha", "theta"):
                        add(_angle_warning(f"{f}.{key}.{a}", getattr(dh, a)))
                    for a in ("a", "d"):
                        add(_length_warning(f"{f}.{key}.{a}", getattr(dh, a)))
                    reach += abs(dh.a) + abs(dh.d)
            if j.link is not None:
                masses.append((f"{f}.link.mass", j.link.mass))
                for k, x in enumerate(j.link.com):
                    add(_length_warning(f"{f}.link.com[{k}]", x))
        for i, b in enumerate(m.bodies):
            f = f"mechanism.bodies[{i}]"
            masses.append((f"{f}.mass", b.mass))
            for k, x in enumerate(b.com):
                add(_length_warning(f"{f}.com[{k}]", x))
            for k, x in enumerate(b.rpy):
                add(_angle_warning(f"{f}.rpy[{k}]", x))
            reach = max(reach, float(np.linalg.norm(b.com)))
        for i, fr in enumerate(m.frames):
            origins.append((f"mechanism.frames[{i}].origin", fr.origin))
        for f, o in origins:
            for k, x in enumerate(o.xyz):
                add(_length_warning(f"{f}.xyz[{k}]", x))
            for k, x in enumerate(o.rpy):
                add(_angle_warning(f"{f}.rpy[{k}]", x))
        out += _mass_warnings(masses, reach)
    elif isinstance(case, Arm2DofCase):
        a = case.arm
        for k in ("l1", "l_s1", "l_s2"):
            add(_length_warning(f"arm.{k}", getattr(a, k)))
        reach = a.l1 + abs(a.l_s2) + abs(a.l_s1)
        out += _mass_warnings([("arm.m1", a.m1), ("arm.m2", a.m2),
                               ("counterweights.m_cw1", case.counterweights.m_cw1),
                               ("counterweights.m_cw2", case.counterweights.m_cw2)], reach)
    elif isinstance(case, PaminsaCase):
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
    elif isinstance(case, (Planar3rCase, Spatial3rCase, ScaraCase, FivebarCase)):
        p = case.parameters
        lengths = [k for k in ("l1", "l2", "a1", "a2", "b1", "b2", "d") if hasattr(p, k)]
        for k in lengths:
            add(_length_warning(f"parameters.{k}", getattr(p, k)))
        reach = sum(abs(getattr(p, k)) for k in lengths)
        masses = [(f"parameters.{k}", getattr(p, k)) for k in type(p).model_fields
                  if k.startswith("m") and k != "mP1_share"]
        out += _mass_warnings(masses, reach)
    return out


# ---- JSON Schema ----------------------------------------------------------------------------------

class _TomlJsonSchema(GenerateJsonSchema):
    """TOML has no null: an optional key is simply absent, so drop the ``null`` alternative."""

    def nullable_schema(self, schema):
        return self.generate_inner(schema["schema"])

    def default_schema(self, schema):
        out = super().default_schema(schema)
        if "default" in out:
            out["default"] = _drop_none(out["default"])
            if out["default"] is None:
                del out["default"]
        return out


def _drop_none(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _drop_none(v) for k, v in x.items() if v is not None}
    return x


def _case_models(kind: str | None) -> list[type]:
    if kind is None:
        models = []
        for m in CASE_MODELS.values():
            for x in (m.values() if isinstance(m, dict) else [m]):
                if x not in models:
                    models.append(x)
        return models + [SweepFile]
    if kind == "sweep":
        return [SweepFile]
    if kind not in CASE_MODELS:
        raise ValueError(f"unknown kind {kind!r} (known: {', '.join(KINDS)}, and sweep files: sweep)")
    m = CASE_MODELS[kind]
    return list(m.values()) if isinstance(m, dict) else [m]


def json_schema(kind: str | None = None) -> dict:
    """JSON Schema of the case files of ``kind`` (all kinds when None), for editors (taplo / Even
    Better TOML: ``#:schema ./mechbal.schema.json`` at the top of a case file)."""
    models = _case_models(kind)
    target = models[0] if len(models) == 1 else Union[tuple(models)]
    schema = TypeAdapter(target).json_schema(schema_generator=_TomlJsonSchema)
    head = {"$schema": "http://json-schema.org/draft-07/schema#",
            "title": f"mechbal case file{'' if kind is None else f' (kind {kind})'}"
                     + (" or sweep file" if kind is None else ""),
            "description": "A mechbal case (python/mechbal/cases/*.toml): [case] kind selects the "
                           "tables. Generated from mechbal.schema; SI units, angles in radians."}
    return {**head, **schema}


SCHEMA_FILE = Path(__file__).resolve().parent / "cases" / "mechbal.schema.json"


def schema_text(kind: str | None = None) -> str:
    return json.dumps(json_schema(kind), indent=2, sort_keys=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``python -m mechbal.schema [KIND]``: print the JSON Schema (of every kind by default).
    The shipped file is regenerated with
    ``python -m mechbal.schema > python/mechbal/cases/mechbal.schema.json``."""
    args = list(sys.argv[1:] if argv is None else argv)
    if args and args[0] in ("-h", "--help"):
        print(main.__doc__)
        return 0
    try:
        text = schema_text(args[0] if args else None)
    except ValueError as exc:
        print(f"mechbal.schema: {exc}", file=sys.stderr)
        return 2
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
