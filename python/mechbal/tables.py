"""The strict tables of the case format that the mechanism description needs, as pydantic v2
models, and the validation machinery of every table (core layer, below `mechbal.spec` and
`mechbal.schema`).

Every table forbids unknown keys (a misspelled key is an error that names it and the nearest known
key), numbers are strict (no booleans, no strings, finite, bounded) and integers are integers.
`validate_table` turns the first problem into one `ConfigError` line
naming the dotted field and the value. `mechbal.schema` builds the case kinds on these tables
and re-exports them.

Layer: Python core (docs/architecture.md).
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


def check_run_ticks(duration: float, rate_hz: float, field: str = "control.rate_hz") -> None:
    """Bounded work before a run starts: ``duration x rate_hz`` controller ticks at most
    `MAX_TICKS` (the C++ case reader the same), else a ConfigError naming ``field``. Every entry
    point that runs a controller over a duration calls it (the case readers, `mechbal.simulate`)."""
    ticks = float(duration) * float(rate_hz)
    if not ticks <= MAX_TICKS:
        raise ConfigError(field, f"duration x rate_hz must be <= {MAX_TICKS} ticks (a run of "
                                 f"{float(duration)!r} s)", ticks)


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


def name_problem(name: str) -> str:
    """Why ``name`` is not a valid name, or ``""``: the C++ model's rule (`mechbal::name_problem`,
    docs/case_format.md "Names"): printable text, no control character, surrogate or
    noncharacter, so that every file mechbal writes can hold it."""
    from mechbal import _core

    return _core.name_problem(name.encode("utf-8", "surrogatepass"))


def _check_name(name: str) -> str:
    why = name_problem(name)
    if why:
        raise _custom(why, value=name)
    return name


Name = Annotated[str, Field(min_length=1, max_length=128, strict=True), AfterValidator(_check_name)]
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


#: the named form of an inertia in TOML, ``inertia = {ixx = .., iyy = .., izz = .., ixy = ..,
#: ixz = .., iyz = ..}``, in the order of the six-value list form (products absent are 0)
INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")


def inertia_matrix(value: Any) -> np.ndarray:
    """An inertia tensor about the centre of mass [kg m^2] from a table of named entries
    ``{ixx, iyy, izz, ixy, ixz, iyz}`` (the three moments required, absent products 0, no other
    key), six values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], three principal moments [Ixx, Iyy, Izz] or a
    3x3 list; it must be symmetric, positive semi-definite and satisfy the triangle inequality of
    a physical body (the checks of the C++ ``validate_rigid_body``). Raises a pydantic error
    (inside models) naming the entry."""
    shape = ("must be a table {ixx, iyy, izz, ixy, ixz, iyz}, a 3x3 matrix, [Ixx, Iyy, Izz] or "
             "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]")
    named = isinstance(value, dict)
    if named:
        for key in value:
            if key not in INERTIA_KEYS:
                absent = [k for k in INERTIA_KEYS if k not in value]
                hint = did_you_mean(str(key), absent)
                if "did you" not in hint:
                    hint = did_you_mean(str(key), list(INERTIA_KEYS))
                # the key as _path writes one (quoted when it holds a newline, a dot, ...)
                raise _custom("unknown key" + hint, "." + _path((str(key),)), has_value=False)
        for key in INERTIA_KEYS[:3]:
            if key not in value:
                raise _custom("is required", f".{key}", has_value=False)
        entries = [(f".{k}", value[k]) for k in INERTIA_KEYS if k in value]
        rows = []
    elif not isinstance(value, list):
        raise _custom(shape, value=value)
    else:
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
        v = np.array([value.get(k, 0.0) for k in INERTIA_KEYS] if named else value, dtype=float)
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
    "description": "kg m^2, about the centre of mass: {ixx, iyy, izz, ixy, ixz, iyz} (products "
                   "absent are 0), [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], [Ixx, Iyy, Izz] or a 3x3 matrix "
                   "(symmetric, positive semi-definite, triangle inequality)",
    "anyOf": [
        {"type": "object", "required": ["ixx", "iyy", "izz"], "additionalProperties": False,
         "properties": {k: {"type": "number"} for k in INERTIA_KEYS}},
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


#: ``izz`` alone (planar mechanisms): the moment about the normal of the plane of motion [kg m^2]
Izz = Annotated[float, Field(ge=0, le=MAX_ABS, description="kg m^2, about the axis through the centre of "
                             "mass normal to the plane of motion (the joints' common axis); planar "
                             "mechanisms only, instead of inertia: a thin lamina in the plane of motion, "
                             "izz / 2 about every in-plane axis", **_NUM)]


def lamina_inertia(izz: float, normal=(0.0, 0.0, 1.0)) -> np.ndarray:
    """The inertia of ``izz`` given alone: a thin lamina in the plane normal to ``normal`` (in the
    body's axes): ``izz`` about the normal, ``izz / 2`` about every axis in the plane
    (perpendicular axis theorem: the two in-plane moments add up to izz), no products in those
    axes: ``izz / 2 (1 + n n^T)``. In planar motion (rotation about the normal only) the in-plane
    moments enter no result; this is the physical body with the least of them."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    return 0.5 * float(izz) * (np.eye(3) + np.outer(n, n))


def _one_inertia(table: Any):
    if table.inertia is None and table.izz is None:
        raise _custom("is required (or izz alone, for a planar mechanism)", ".inertia", None, has_value=False)
    if table.inertia is not None and table.izz is not None:
        raise _custom("give inertia or izz, not both", ".izz", table.izz)
    if table.izz is not None and "rpy" in table.model_fields_set:
        raise _custom("orients the inertia axes; izz alone is about the plane's normal: drop rpy", ".rpy",
                      table.rpy)
    return table


class LinkInertial(Table):
    """The link's own body, in the link frame (the frame right after the joint's motion; for a
    ``dh`` joint the standard DH frame of the link). ``inertia``, or ``izz`` alone where the
    mechanism is planar."""
    mass: Mass
    com: Xyz = [0.0, 0.0, 0.0]
    inertia: Optional[Inertia] = None
    izz: Optional[Izz] = None

    @model_validator(mode="after")
    def _inertia(self):
        return _one_inertia(self)


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
    inertia: Optional[Inertia] = None
    izz: Optional[Izz] = None
    rpy: Rpy = Field([0.0, 0.0, 0.0], description="rad, orientation of the inertia axes in the link frame")

    @model_validator(mode="after")
    def _inertia(self):
        return _one_inertia(self)


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


#: the time laws of ``[trajectory]``: rest-to-rest (quintic, minimum-energy cubic), a steady
#: rotation at constant speed, a motion planned to minimise shaking (`mechbal.plan`), or a line
#: of the [control] task frame
TrajectoryLaw = Literal["quintic", "cubic", "constant_speed", "min_shaking", "line"]
#: a displacement or a rotation vector of the line law: three numbers (O axes)
Vector3 = Annotated[list[Num], Field(min_length=3, max_length=3)]
#: what ``law = "min_shaking"`` minimises (`mechbal.plan.OBJECTIVES`)
PlanObjective = Literal["force_rms", "force_peak", "moment_rms", "moment_peak"]
#: the keys that only ``law = "min_shaking"`` takes
PLAN_KEYS = ("objective", "weights", "moment_point", "start_velocity", "end_velocity", "acceleration_limit",
             "torque_limit", "control_points", "smooth_ends", "com_profile")


class PlanWeights(Table):
    """``[trajectory] weights``: minimise ``force mean|F|^2 + moment mean|M|^2 + torque
    mean|tau|^2`` (SI units), instead of one ``objective``."""
    force: NonNeg = 0.0
    moment: NonNeg = 0.0
    torque: NonNeg = 0.0

    @model_validator(mode="after")
    def _some(self):
        if not (self.force or self.moment or self.torque):
            raise _custom("needs a weight > 0 (force, moment or torque)", value=self.model_dump())
        return self


def _positive_values(value: Any) -> Any:
    for i, x in enumerate(value):
        if not x > 0:
            raise _custom("must be > 0", f"[{i}]", x)
    return value


PositiveJointValues = Annotated[JointValues, AfterValidator(_positive_values)]
def _check_speeds(value: Any) -> Any:
    """A speed or rpm: a number, or a list of 1 .. MAX_JOINTS numbers (finite, within MAX_ABS)."""
    entries = [("", value)]
    if isinstance(value, list):
        if not 1 <= len(value) <= MAX_JOINTS:
            raise _custom(f"must have 1 to {MAX_JOINTS} values (one per actuated joint), or be one number",
                          value=value)
        entries = [(f"[{i}]", x) for i, x in enumerate(value)]
    for sub, x in entries:
        if not _is_number(x):
            raise _custom("must be a number, or a list of numbers (one per actuated joint)" if not sub
                          else "must be a number", sub, x)
        if not math.isfinite(x):
            raise _custom("must be finite", sub, x)
        if abs(x) > MAX_ABS:
            raise _custom(f"must be between -{_fmt(MAX_ABS)} and {_fmt(MAX_ABS)}", sub, x)
    return value


_SPEEDS_JSON = {"anyOf": [{"type": "number"},
                          {"type": "array", "items": {"type": "number"}, "minItems": 1, "maxItems": MAX_JOINTS}]}
#: a speed [rad/s or m/s] or rpm: one number for every actuated joint, or one per actuated joint
Speeds = Annotated[Any, AfterValidator(_check_speeds), WithJsonSchema(_SPEEDS_JSON)]
RPM_TO_RAD_S = 2.0 * math.pi / 60.0


class ChainTrajectory(Table):
    """``[trajectory]``: the motion of the actuated joints (every independent joint of an open
    mechanism). ``law = "quintic" | "cubic"``: rest-to-rest from ``start`` to ``end`` in
    ``duration``; ``law = "constant_speed"``: from ``start`` at ``speed`` [rad/s or m/s] or ``rpm``
    (exactly one) for ``duration`` seconds or ``revolutions`` turns (exactly one) of the fastest
    joint; ``law = "line"`` (the operational-space mode, ``[control] task_frame``): the task
    frame moves from its pose at ``start`` (joint positions) by ``displacement`` [m] and / or
    turns by ``rotation`` (a rotation vector [rad]), both in O's axes, on a straight line (and
    about one fixed axis) along the quintic law in ``duration``."""
    law: TrajectoryLaw = "quintic"
    start: JointValues = Field(description="one value per actuated joint (rad or m)")
    end: Optional[JointValues] = Field(None, description="rest-to-rest laws: one value per actuated joint (rad or m)")
    duration: Optional[Duration] = Field(None, description="s; constant_speed: or revolutions")
    speed: Optional[Speeds] = Field(
        None, description="constant_speed: rad/s (or m/s), one number for every actuated joint or one "
                          "per actuated joint; or rpm")
    rpm: Optional[Speeds] = Field(
        None, description="constant_speed: revolutions per minute, one number for every actuated joint "
                          "or one per actuated joint; or speed")
    revolutions: Optional[Annotated[float, Field(gt=0, le=1e6, **_NUM)]] = Field(
        None, description="constant_speed: turns of the fastest joint (duration = revolutions 2 pi / "
                          "max |speed|); or duration")
    displacement: Optional[Vector3] = Field(
        None, description="law = 'line': the task frame's displacement [dx, dy, dz] (m, O axes)")
    rotation: Optional[Vector3] = Field(
        None, description="law = 'line': the task frame's rotation vector theta k (rad, O axes)")
    samples: Samples = 501
    initial_guess: Optional[JointValues] = Field(
        None, description="closed mechanisms: every joint coordinate near the assembly at start, or "
                          "the actuated joints only (the passive ones are then solved on `branch`), "
                          "rad or m")
    branch: Optional[Literal["open", "crossed"]] = Field(
        None, description="closed mechanisms whose loops are four-bar-like (four parallel pivots): the "
                          "assembly at start; default open unless a full initial_guess picks it")
    objective: Optional[PlanObjective] = Field(
        None, description="min_shaking: what to minimise (default force_rms); or weights")
    weights: Optional[PlanWeights] = Field(
        None, description="min_shaking: weights of the mean squares of shaking force, shaking moment "
                          "and actuator torque; or objective")
    moment_point: Optional[Vec3] = Field(
        None, description="min_shaking: the point the shaking moment is taken about, m in O (default O)")
    start_velocity: Optional[JointValues] = Field(
        None, description="min_shaking: velocities at the start (default 0: from rest), rad/s or m/s")
    end_velocity: Optional[JointValues] = Field(
        None, description="min_shaking: velocities at the end (default 0: to rest), rad/s or m/s")
    acceleration_limit: Optional[PositiveJointValues] = Field(
        None, description="min_shaking: |acceleration| limit per actuated joint, rad/s^2 or m/s^2")
    torque_limit: Optional[PositiveJointValues] = Field(
        None, description="min_shaking: |torque| limit per actuated joint besides the joints' effort "
                          "limits, N m or N")
    control_points: Optional[Annotated[int, Field(ge=7, le=200, strict=True)]] = Field(
        None, description="min_shaking: control points per joint of the quintic B-spline (default 14)")
    smooth_ends: Optional[bool] = Field(
        None, description="min_shaking: also hold zero accelerations at both ends (default false)")
    com_profile: Optional[Literal["bang_bang", "cubic", "minimum_jerk", "none"]] = Field(
        None, description="min_shaking: the profile of the centre-of-mass law reported beside the plan "
                          "(default bang_bang; none: not computed)")

    @model_validator(mode="after")
    def _law_keys(self):
        if self.law != "min_shaking":
            for key in PLAN_KEYS:
                if getattr(self, key) is not None:
                    raise _custom(f"is for law = 'min_shaking' (law is '{self.law}')", f".{key}",
                                  getattr(self, key))
        elif self.objective is not None and self.weights is not None:
            raise _custom("give objective or weights, not both", ".weights", self.weights.model_dump())
        if self.law != "line":
            for key in ("displacement", "rotation"):
                if getattr(self, key) is not None:
                    raise _custom(f"is for law = 'line' (law is '{self.law}')", f".{key}", getattr(self, key))
        if self.law == "line":
            for key in ("end", "speed", "rpm", "revolutions"):
                if getattr(self, key) is not None:
                    raise _custom("is not for law = 'line' (the task frame's path: start, displacement "
                                  "and / or rotation, duration)", f".{key}", getattr(self, key))
            if self.displacement is None and self.rotation is None:
                raise _custom("law = 'line' needs displacement [dx, dy, dz] (m) and / or rotation "
                              "(rad)", ".displacement", None, has_value=False)
            if self.duration is None:
                raise _custom("law = 'line' needs duration", ".duration", None, has_value=False)
        elif self.law == "constant_speed":
            for key in ("end",):
                if getattr(self, key) is not None:
                    raise _custom("is for the rest-to-rest laws (quintic, cubic); a constant-speed "
                                  "motion has start, speed or rpm, and duration or revolutions",
                                  f".{key}", getattr(self, key))
            given = [k for k in ("speed", "rpm") if getattr(self, k) is not None]
            if len(given) != 1:
                if given:
                    raise _custom("give speed (rad/s) or rpm, not both", ".rpm", self.rpm)
                raise _custom("law = 'constant_speed' needs speed (rad/s) or rpm", ".speed", None,
                              has_value=False)
            timed = [k for k in ("duration", "revolutions") if getattr(self, k) is not None]
            if len(timed) != 1:
                if timed:
                    raise _custom("give duration or revolutions, not both", ".revolutions", self.revolutions)
                raise _custom("law = 'constant_speed' needs duration (s) or revolutions", ".duration",
                              None, has_value=False)
            if self.revolutions is not None and max(abs(x) for x in self.speeds(len(self.start))) == 0.0:
                raise _custom("needs a non-zero speed (every speed is 0)", ".revolutions", self.revolutions)
            if self.revolutions is not None and not 1e-3 <= self.motion_duration() <= 1e6:
                raise _custom(f"gives a duration of {self.motion_duration():.6g} s, outside 0.001 .. "
                              "1000000 s", ".revolutions", self.revolutions)
        else:
            for key in ("speed", "rpm", "revolutions"):
                if getattr(self, key) is not None:
                    raise _custom(f"is for law = 'constant_speed' (law is '{self.law}')", f".{key}",
                                  getattr(self, key))
            if self.end is None:
                raise _custom(f"law = '{self.law}' needs end", ".end", None, has_value=False)
            if self.duration is None:
                raise _custom(f"law = '{self.law}' needs duration", ".duration", None, has_value=False)
        return self

    def speeds(self, n: int) -> list[float]:
        """constant_speed: the speed of each of ``n`` actuated joints [rad/s or m/s] (rpm
        converted; one number applies to every joint). A list of another length is returned as
        given (the cross checks name it)."""
        key = "speed" if self.speed is not None else "rpm"
        value = getattr(self, key)
        scale = 1.0 if key == "speed" else RPM_TO_RAD_S
        if isinstance(value, list):
            return [float(x) * scale for x in value]
        return [float(value) * scale] * n

    def motion_duration(self) -> float:
        """The motion's duration [s] (constant_speed with revolutions: revolutions 2 pi / max |speed|)."""
        if self.duration is not None:
            return float(self.duration)
        top = max(abs(x) for x in self.speeds(len(self.start)))
        return float(self.revolutions) * 2.0 * math.pi / top


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
        lo = ctx.get("min_length") if lo is None else lo  # pydantic's own bounds when the
        hi = ctx.get("max_length") if hi is None else hi  # field's constraint is not found
        if lo is not None and lo == hi:
            text = f"must have {lo} values"
        elif typ == "too_short" and lo is None:
            text = "has too few values"
        elif typ == "too_long" and hi is None:
            text = "has too many values"
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
