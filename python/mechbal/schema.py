"""The strict schema of every case file, as pydantic v2 models.

One model per case kind (``[case] kind = ...``), one nested model per table. Every table forbids
unknown keys (a misspelled key is an error that names it and the nearest known key), numbers are
strict (no booleans, no strings, finite, bounded) and integers are integers. Sizes that drive
memory or time (samples, joints, ticks) have upper bounds. `validate_case` turns the first
problem into one `ConfigError` line naming the dotted field and the value,
then runs the checks that need more than one table (trajectory size against the mechanism's
degrees of freedom, cross references of the general mechanism format) and warns
(`ConfigWarning`) about likely unit mistakes.

`json_schema` publishes the same models as JSON Schema for editors;
``python/mechbal/cases/mechbal.schema.json`` is its output for every kind
(``python -m mechbal.schema > python/mechbal/cases/mechbal.schema.json`` regenerates it; a test
keeps it current).

Layer: Python core (docs/architecture.md).
"""
import difflib
import json
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Callable, Literal, Optional, Union, get_args, get_origin

import numpy as np
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, PrivateAttr, TypeAdapter, ValidationError, \
    model_validator
from pydantic.json_schema import GenerateJsonSchema, WithJsonSchema
from pydantic_core import PydanticCustomError

from mechbal.errors import ConfigError, ConfigWarning, short_repr
from mechbal.tables import (  # noqa: F401 (the tables and machinery this module builds on, re-exported)
    MAX_ABS, MAX_SAMPLES, MAX_SAMPLE_BODIES, MAX_JOINTS, MAX_BODIES, MAX_FRAMES, MAX_TICKS, check_run_ticks,
    MAX_CONFIGURATIONS, WARN_MASS_KG, WARN_REACH_M, WARN_LENGTH_M, WARN_ANGLE_RAD, _NUM, Num,
    NonNeg, Pos, Mass, Length, Angle, Duration, Rate, Samples, Name, Title, _vec, Vec2, Vec3,
    PosVec2, PosVec3, Xyz, Rpy, JointValues, _custom, _is_number, inertia_matrix, _check_inertia,
    _INERTIA_JSON, Inertia, Table, CaseHeader, Origin, DH, Limits, Mimic, LinkInertial, JointType,
    Joint, BodyKind, Body, Frame, Loop, SpringCount, PulleyRatio, MechanismSpring, Mechanism,
    ChainTrajectory, _fmt, _path, _unwrap, _type_at, _lengths, _allowed_keys, _choices,
    did_you_mean, _TYPE_WORDS, _at, _message, _errors_to_config_error, validate_table,
)

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
    """A case with a ``[mechanism]`` table: its `mechbal.spec.MechanismSpec`, built once."""
    _spec: Any = PrivateAttr(None)

    @property
    def spec(self):
        """The `mechbal.spec.MechanismSpec` of ``[mechanism]``."""
        if self._spec is None:
            from mechbal.spec import mechanism_spec

            self._spec = mechanism_spec(self.mechanism)  # type: ignore[attr-defined]
        return self._spec


#: the momentum components a reactionless controller can cancel ([control].cancel)
MomentumComponentName = Literal["moment", "force", "both", "moment_x", "moment_y", "moment_z",
                                "force_x", "force_y", "force_z"]


#: the twist components an operational-space controller tracks ([control].task_rows)
TwistComponentName = Literal["all", "linear", "angular", "v_x", "v_y", "v_z", "w_x", "w_y", "w_z"]
#: [control] keys that belong to one kind only
_CONTROL_ONLY = {"k": "decoupled", **{k: "reactionless" for k in (
    "balancing_joints", "cancel", "integrator", "damping", "max_rate", "home_gain", "limit_gain",
    "task_frame", "task_rows")}}
#: per actuated joint, each > 0
PerJoint = Annotated[list[Pos], Field(min_length=1, max_length=MAX_JOINTS)]


class ControlTolerance(Table):
    """``[control] tolerance``: the goal of a controlled run (`mechbal.verdict`). Defaults in
    `mechbal.verdict.DEFAULT_TOLERANCE`."""
    residual: Optional[Pos] = Field(None, description="each cancelled component's peak over its uncontrolled "
                                                      "peak (default 1e-6)")
    floor: Optional[Pos] = Field(None, description="absolute floor of a cancelled component's residual, N or N m "
                                                   "(default 1e-9)")
    position: Optional[Pos] = Field(None, description="task frame's path error, m (default 1e-6)")
    orientation: Optional[Pos] = Field(None, description="task frame's orientation error, rad (default 1e-6)")
    joint: Optional[Pos] = Field(None, description="closed loop: the plant's departure from the command, rad or m "
                                                   "(default 1e-2)")


class Control(Table):
    """``[control]``: a real-time controller run along the case's trajectory. ``kind =
    "reactionless"``: the balancing joints keep the cancelled momentum components at their
    initial value (`mechbal.control.ReactionlessController`), optionally followed by a
    computed-torque stage (``kp``, ``kd``); ``mechbal run`` compares the motion with the balancing
    joints held (uncontrolled) and controlled. ``computed_torque`` and ``decoupled``: joint
    controllers with the gains ``kp``, ``kd`` (the C++ ``mechbal::make_controller`` builds each
    kind from this table; `mechbal.control.joint_controller` in Python), run in closed loop along
    ``[trajectory]``."""
    kind: Literal["reactionless", "computed_torque", "decoupled", "passive"] = Field(
        description="which controller (mechbal run simulates each: computed_torque and decoupled in closed "
                    "loop along [trajectory]; reactionless; passive: no controller, "
                    "zero effort, the mechanism moves under gravity and springs from [trajectory]'s "
                    "start with its initial rates, over its duration)")
    balancing_joints: Optional[Annotated[list[Name], Field(min_length=1, max_length=MAX_JOINTS)]] = Field(
        None, description="reactionless (required without task_frame): actuated joints whose motion the "
                          "controller computes")
    cancel: Annotated[list[MomentumComponentName], Field(min_length=1, max_length=9)] = ["moment"]
    integrator: Literal["euler", "rk4"] = "rk4"
    rate_hz: Rate = 1000.0
    damping: Annotated[float, Field(gt=0, lt=1, **_NUM)] = Field(
        1e-2, description="damped least squares near singularity, relative to the largest "
                          "singular value")
    max_rate: Optional[Pos] = Field(
        None, description="balancing joints' rate limit (rad/s or m/s); the joint's declared velocity limit "
                          "when smaller; default: none beyond the declared limits")
    home_gain: NonNeg = Field(0.0, description="redundant balancing joints: pull towards the start pose (1/s)")
    limit_gain: NonNeg = Field(0.0, description="redundant balancing joints: push away from the joint limits")
    task_frame: Optional[Name] = Field(
        None, description="operational-space mode: a named frame; [trajectory] is then the frame's "
                          "path, from its pose at start to its pose at end (joint positions)")
    task_rows: Optional[Annotated[list[TwistComponentName], Field(min_length=1, max_length=8)]] = Field(
        None, description="operational-space mode: the frame's tracked twist components "
                          "(default all: linear and angular)")
    kp: Optional[PerJoint] = Field(
        None, description="proportional gains (1/s^2), one per actuated joint: required for "
                          "computed_torque and decoupled; reactionless: its computed-torque stage, with kd")
    kd: Optional[PerJoint] = Field(None, description="derivative gains (1/s), one per actuated joint")
    torque_limit: Optional[PerJoint] = Field(
        None, description="|tau| limit per actuated joint (N m or N); the joint's declared effort limit when "
                          "smaller; default: none beyond the declared limits")
    k: Optional[PerJoint] = Field(
        None, description="decoupled: the constant diagonal of the balanced mass matrix (default: "
                          "taken from the mechanism at q = 0)")
    max_speed: Optional[Pos] = Field(
        None, description="input range of every controller stage's joint speeds, measured and desired (rad/s "
                          "or m/s): beyond it a tick holds its command (out of range); default: none")
    tolerance: Optional[ControlTolerance] = Field(
        None, description="what counts as the goal met (the verdict of a run: ok, limited_by, exit code 6)")

    @model_validator(mode="after")
    def _rules(self):
        if self.kind == "passive":   # no controller: only the tick rate of the log
            for key in sorted(self.model_fields_set - {"kind", "rate_hz"}):
                raise _custom("is not for kind = 'passive' (no controller: only rate_hz)", f".{key}",
                              getattr(self, key))
            return self
        seen = set()
        for i, name in enumerate(self.balancing_joints or []):
            if name in seen:
                raise _custom("is listed twice", f".balancing_joints[{i}]", name)
            seen.add(name)
        for key in type(self).model_fields:
            only = _CONTROL_ONLY.get(key)
            if only is not None and key in self.model_fields_set and self.kind != only:
                raise _custom(f"is only for kind = {only!r}", f".{key}", getattr(self, key))
        if self.kind == "reactionless" and self.balancing_joints is None and self.task_frame is None:
            raise _custom("is required for kind = 'reactionless' (or task_frame: the operational-space "
                          "mode)", ".balancing_joints", has_value=False)
        if self.kind != "reactionless":
            for key in ("kp", "kd"):
                if getattr(self, key) is None:
                    raise _custom(f"is required for kind = {self.kind!r}", f".{key}", has_value=False)
        if self.kp is not None and self.kd is None:
            raise _custom("is required with kp (the computed-torque stage)", ".kd", has_value=False)
        if self.kd is not None and self.kp is None:
            raise _custom("is required with kd (the computed-torque stage)", ".kp", has_value=False)
        if self.task_rows is not None and self.task_frame is None:
            raise _custom("is for the operational-space mode: give task_frame", ".task_rows", self.task_rows)
        return self


def _control_cross_checks(control: Control, spec: Any, actuated: list[str]) -> None:
    """``[control]`` against the mechanism (as the C++ reader's load_case): per-joint sizes, the
    balancing joints among the actuated ones, the task frame among the frames."""
    for key in ("kp", "kd", "torque_limit", "k"):
        v = getattr(control, key)
        if v is not None and len(v) != len(actuated):
            raise ConfigError(f"control.{key}", f"must have {len(actuated)} values (one per actuated "
                                                f"joint: {', '.join(actuated)})", v)
    for i, b in enumerate(control.balancing_joints or []):
        if b not in actuated:
            raise ConfigError(f"control.balancing_joints[{i}]",
                              f"is not an actuated joint{did_you_mean(b, actuated)}", b)
    if (control.kind == "reactionless" and control.task_frame is None and control.balancing_joints is not None
            and len(control.balancing_joints) == len(actuated)):
        raise ConfigError("control.balancing_joints", "lists every actuated joint: none is left to follow "
                                                      "[trajectory] (keep one out, or give task_frame: the "
                                                      "operational-space mode)", control.balancing_joints)
    if control.task_frame is not None:
        frames = [f.name for f in spec.frames]
        if control.task_frame not in frames:
            raise ConfigError("control.task_frame",
                              f"is not a frame of the mechanism{did_you_mean(control.task_frame, frames)}",
                              control.task_frame)


class SerialChainCaseHeader(CaseHeader):
    kind: Literal["serial_chain", "mechanism"]


class SerialChainCase(_MechanismCase):
    """A mechanism moving along a rest-to-rest trajectory (kinds ``serial_chain``, ``mechanism``)."""
    case: SerialChainCaseHeader
    mechanism: Mechanism
    trajectory: ChainTrajectory
    balance: Optional[Balance] = None
    control: Optional[Control] = None


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
        "peak_gravity_torque | rms_gravity_torque | peak_joint_torque | rms_joint_torque | "
        "peak_shaking_force | rms_shaking_force | peak_shaking_moment | rms_shaking_moment, "
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


#: case kind -> model (or, for kinds that several mechanisms share, ``[case] mechanism`` -> model), its
#: checks across tables and its unit warnings; the general kinds here, a paper's when its package is
#: imported (`register_case_model`, found through `mechbal.registry`)
@dataclass(frozen=True)
class CaseKind:
    model: Any
    cross_checks: Optional[Callable[[Any], None]] = None
    unit_warnings: Optional[Callable[[Any], list]] = None


_KINDS: dict[str, CaseKind] = {}


def register_case_model(kind: str, model: Any, *, cross_checks: Optional[Callable[[Any], None]] = None,
                        unit_warnings: Optional[Callable[[Any], list]] = None) -> None:
    """Register the pydantic model of the case files of ``kind`` (a dict ``{[case] mechanism: model}``
    where one kind holds several mechanisms), the checks across its tables (raise ConfigError) and
    its unit warnings (``[(field, message)]``)."""
    _KINDS[kind] = CaseKind(model, cross_checks, unit_warnings)


register_case_model("serial_chain", SerialChainCase)
register_case_model("mechanism", SerialChainCase)


def case_models() -> dict[str, Any]:
    """Every registered case kind -> its model (the general kinds and every paper's)."""
    from mechbal.registry import papers

    papers()
    return {k: v.model for k, v in _KINDS.items()}


def __getattr__(name: str) -> Any:
    # CASE_MODELS / KINDS: every kind, the papers' included (they register when first asked for)
    if name == "CASE_MODELS":
        return case_models()
    if name == "KINDS":
        return tuple(case_models())
    raise AttributeError(f"module 'mechbal.schema' has no attribute {name!r}")


def _check_ticks(duration: float, rate_hz: float, sub: str, what: str = "duration x rate_hz"):
    ticks = duration * rate_hz
    if ticks > MAX_TICKS:
        raise _custom(f"{what} must be <= {MAX_TICKS} ticks", sub, ticks)


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
    header_keys = [*CaseHeader.model_fields, "mechanism"]
    kind = header.get("kind")
    if kind is None:
        _unknown_key_near(header, "kind", header_keys, "case")
        raise ConfigError("case.kind", "is required", has_value=False)
    if not isinstance(kind, str):
        raise ConfigError("case.kind", "must be a string", kind)
    models = case_models()
    if kind not in models:
        hint = did_you_mean(kind, list(models))
        raise ConfigError("case.kind", f"unknown kind{hint if 'did you' in hint else ''} "
                                       f"(known: {', '.join(models)})", kind)
    model = models[kind]
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
    checks across tables. Likely unit mistakes are warned about (`ConfigWarning`).
    Idempotent: a validated model is returned as is."""
    if isinstance(config, BaseModel):
        return config
    model = _model_for(config)
    case = validate_table(model, config)
    _cross_checks(case)
    if warn:
        from mechbal import plausibility

        for field, message in unit_warnings(case):
            warnings.warn(f"{field}: {message}", ConfigWarning, stacklevel=2)
        plausibility.warn(plausibility.case_problems(config))
    return case


def _cross_checks(case: Any) -> None:
    kind = _KINDS.get(case.case.kind)
    if kind is not None and kind.cross_checks is not None:
        kind.cross_checks(case)
    if isinstance(case, SerialChainCase):
        spec = case.spec  # cross references of the mechanism (ConfigError naming the field)
        names = list(spec.actuated) if spec.loops else spec.independent_joints
        if not names:
            raise ConfigError("mechanism.joints", "needs at least one moving joint that is not a mimic",
                              has_value=False)
        for key in ("start", "end", "speed", "rpm"):
            v = getattr(case.trajectory, key)
            if isinstance(v, list) and len(v) != len(names):
                raise ConfigError(f"trajectory.{key}", f"must have {len(names)} values (one per "
                                                       f"{'actuated' if spec.loops else 'independent'} "
                                                       f"joint: {', '.join(names)})"
                                  + (" or one number" if key in ("speed", "rpm") else ""), v)
        if not spec.loops:
            for key in ("initial_guess", "branch"):
                if getattr(case.trajectory, key) is not None:
                    raise ConfigError(f"trajectory.{key}", "is for closed mechanisms (with "
                                      "[[mechanism.loops]]); this one has no loop", getattr(case.trajectory, key))
        n_bodies = max(1, len(spec.bodies))
        if case.trajectory.samples * n_bodies > MAX_SAMPLE_BODIES:
            raise ConfigError("trajectory.samples", f"must be <= {MAX_SAMPLE_BODIES // n_bodies} for "
                                                    f"{n_bodies} bodies (samples x bodies <= "
                                                    f"{MAX_SAMPLE_BODIES})", case.trajectory.samples)
        if case.control is not None:
            _control_cross_checks(case.control, spec, names)
            check_run_ticks(case.trajectory.motion_duration(), case.control.rate_hz)



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


def mechanism_unit_warnings(m: Any) -> list[tuple[str, str]]:
    """(field, message) of every likely unit mistake in a validated ``[mechanism]`` table."""
    out: list = []
    add = lambda w: w is not None and out.append(w)  # noqa: E731
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
    return out


def unit_warnings(case: Any) -> list[tuple[str, str]]:
    """(field, message) of every likely unit mistake in a validated case (a paper's kinds: the
    ``unit_warnings`` it registers)."""
    if isinstance(case, SerialChainCase):
        return mechanism_unit_warnings(case.mechanism)
    kind = _KINDS.get(case.case.kind)
    if kind is not None and kind.unit_warnings is not None:
        return kind.unit_warnings(case)
    return []


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
    CASE_MODELS = case_models()
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
        raise ValueError(f"unknown kind {kind!r} (known: {', '.join(CASE_MODELS)}, and sweep files: sweep)")
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
    # run as ``python -m``, this file is ``__main__``: the papers register their kinds in the
    # imported ``mechbal.schema``, so ask that one
    import importlib

    schema = importlib.import_module("mechbal.schema")
    try:
        text = schema.schema_text(args[0] if args else None)
    except ValueError as exc:
        print(f"mechbal.schema: {exc}", file=sys.stderr)
        return 2
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
