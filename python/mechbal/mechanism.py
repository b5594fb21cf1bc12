"""The general mechanism model from Python: `Mechanism`.

A `Mechanism` wraps the C++ ``MechanismModel`` (a tree of revolute, prismatic and fixed
joints, any number of named bodies on each link, gear couplings, named frames and gravity; see
``cpp/include/mechbal/model/model.hpp`` for the frame conventions) and exposes every algorithm over it.

Every method takes either one sample (1-D arrays of ``dof`` values) or a batch ((N, dof) arrays),
evaluated in one C++ call. A single sample given as 1-D float64 numpy arrays goes straight to the
C++ algorithm (no conversion, no Python-level checking: about Pinocchio's cost per call,
``bench/bench_python.py``); any other input takes the general path, which converts and checks it.
One sample returns plain arrays and raises `ValueError` when the
input is rejected (wrong size, non-finite, overflow); a batch returns arrays with a leading N axis
and a per-instant status (0 = ok; see `mechbal.Status`): the result dataclasses have a
``status`` field, and the plain-array results are `BatchArray` with a ``status``
attribute. A rejected instant is flagged in its status and its values are NaN (rotations and
placements: the identity), never zeros that would pass for a result. Arrays of real numbers
only: complex, string, boolean and object arrays are a `TypeError`.

Units: SI throughout (m, kg, kg m^2, rad, N, N m); world quantities in the base frame O; moments
and angular momenta about O's origin.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import contextlib as _contextlib
import contextvars as _contextvars
from types import SimpleNamespace as _SimpleNamespace
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

import mechbal._core as _core
from mechbal._core import (  # the description objects of Mechanism.from_description
    Body, Frame, Joint, JointType, LoopConstraint, LoopType, MechanismDescription, MechanismModel, Spring)

#: what the public methods return: float64 arrays
FloatArray = npt.NDArray[np.float64]
#: per-instant statuses of a batch (bit flags of `mechbal.Status`, 0 = ok) and its good rows
StatusArray = npt.NDArray[np.uint32]
BoolArray = npt.NDArray[np.bool_]

if TYPE_CHECKING:
    #: what the overloads call one sample (q of shape (dof,)) and a batch (N, dof): lists, or numpy
    #: arrays whose shape the type checker knows (np.zeros(n) is 1-D, np.zeros((N, n)) 2-D); an
    #: array of unknown shape matches both and the result is typed as either
    Sample = Union[Sequence[float], np.ndarray[tuple[int], np.dtype[Any]]]
    Samples = Union[Sequence[Sequence[float]], np.ndarray[tuple[int, int], np.dtype[Any]]]

__all__ = ["Mechanism", "ShakingWrench", "BaseReaction", "Momentum", "BodyMotion", "ClosedMotion",
           "BatchArray", "StatusArray", "BoolArray", "UrdfRepairWarning", "urdf_reading", "INERTIAL_PARAMETER_NAMES",
           "Body", "Frame", "Joint", "JointType", "LoopConstraint", "LoopType", "MechanismDescription",
           "MechanismModel", "Spring"]

#: The order of a body's 10 inertial parameters in the regressors and
#: `Mechanism.inertial_parameters` (Pinocchio's): mass, first moments m c, then the inertia about
#: the link origin, lower triangle row by row. The TOML format's list form is ``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`` (moments, then
#: products) and its named form ``{ixx, iyy, izz, ixy, ixz, iyz}``: docs/case_format.md.
INERTIAL_PARAMETER_NAMES = ("m", "mcx", "mcy", "mcz", "ixx", "ixy", "iyy", "ixz", "iyz", "izz")


class BatchArray(np.ndarray):
    """A batch result (N, ...) with its per-instant ``status`` (N,) (uint32 bit flags of
    `mechbal.Status`, 0 = ok); rows whose status is not 0 hold NaN. ``ok`` is the boolean
    mask of the good rows. Slicing or arithmetic gives plain results: read ``status`` first."""

    status: StatusArray

    def __new__(cls, values: npt.ArrayLike, status: npt.ArrayLike) -> BatchArray:
        obj = np.asarray(values).view(cls)
        obj.status = np.asarray(status)
        return obj

    def __array_finalize__(self, obj):
        parent = getattr(obj, "status", None)
        # a view of the whole batch keeps the statuses; anything else (a row, a product) has none
        self.status = (parent if parent is not None and self.shape[:1] == obj.shape[:1]  # type: ignore[assignment]
                       else None)

    def __array_wrap__(self, obj, context=None, return_scalar=False):
        # ufunc results are plain arrays (a status means "these rows as computed")
        out = np.asarray(obj)
        return out[()] if return_scalar else out

    @property
    def ok(self) -> BoolArray:
        """Boolean mask (N,) of the instants whose status is ok."""
        return np.asarray(self.status) == 0

    def __reduce__(self):  # pickled as a plain array and its status
        return (BatchArray, (np.asarray(self), self.status))

class UrdfRepairWarning(UserWarning):
    """A harmless defect of a URDF file that the lenient reading repaired (the message names the
    URDF element and the repair); ``strict=True`` refuses the file instead."""


_URDF_READING = _contextvars.ContextVar("urdf_reading", default={"strict": False, "allow_massless": False})


@_contextlib.contextmanager
def urdf_reading(*, strict: bool = False, allow_massless: bool = False):
    """Defaults of `Mechanism.from_urdf` within the block (the CLI's ``--strict`` and
    ``--allow-massless`` reach every URDF a command reads this way)."""
    token = _URDF_READING.set({"strict": bool(strict), "allow_massless": bool(allow_massless)})
    try:
        yield
    finally:
        _URDF_READING.reset(token)



@dataclass(frozen=True)
class ShakingWrench:
    """Momenta about O and their rates: the shaking force [N] and moment [N m] (Briot &
    Arakelian 2009, eqs 1-4). Shapes (3,) for one sample, (N, 3) for a batch."""

    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    linear_momentum: np.ndarray
    angular_momentum: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class BaseReaction:
    """Wrench the base exerts on the moving mechanism, gravity included: force [N], moment about
    O [N m]. The bodies that do not move (on the root link, or on links joined to it by fixed
    joints only: a URDF's ``base_link``) are the base's own and do not count; ``support_force``
    and ``support_moment`` are the same wrench with them (what the ground exerts on the base and
    everything it carries)."""

    base_reaction_force: np.ndarray
    base_reaction_moment: np.ndarray
    status: np.ndarray
    support_force: np.ndarray | None = None
    support_moment: np.ndarray | None = None


@dataclass(frozen=True)
class Momentum:
    """Linear momentum [kg m/s] and angular momentum about O [kg m^2/s]."""

    linear_momentum: np.ndarray
    angular_momentum: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class BodyMotion:
    """Every body's motion in O: ``com`` (.., B, 3), ``rotation`` (.., B, 3, 3) body (= link axes)
    to O, ``com_velocity``, ``com_acceleration``, ``angular_velocity``, ``angular_acceleration``
    (.., B, 3); link frames ``link_rotation`` (.., L, 3, 3), ``link_position`` (.., L, 3); named
    frames ``frame_placement`` (.., F, 4, 4)."""

    com: np.ndarray
    rotation: np.ndarray
    com_velocity: np.ndarray
    com_acceleration: np.ndarray
    angular_velocity: np.ndarray
    angular_acceleration: np.ndarray
    link_rotation: np.ndarray
    link_position: np.ndarray
    frame_placement: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class ClosedMotion:
    """Solved motion of a closed mechanism: full ``q``, ``v``, ``a`` (.., dof), the reciprocal
    condition ``rcond`` of the passive Jacobian A°, the closure ``residual`` (max |Phi|),
    Newton ``iterations``, ``status`` and, when asked, ``actuated_force`` (.., na)."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    rcond: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    status: np.ndarray
    actuated_force: np.ndarray | None = None
    #: the coupling matrix C (.., dof, na): v = C v#, a = C a# + c
    projection: np.ndarray | None = None


def _real_array(value, name: str) -> np.ndarray:
    """float64 array of ``value``; TypeError naming ``name`` for complex, string, boolean or object
    values (no silent truncation or parsing)."""
    a = np.asarray(value)
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be a real numeric array (int or float values), got dtype {a.dtype}")
    return np.asarray(a, dtype=float)


#: the status of an accepted single instant (what ``status[0]`` of a batch of one reads)
_OK = np.uint32(0)


def _status_text(code: int) -> str:
    names = [s.name for s in _core.Status.__members__.values() if int(s) and int(code) & int(s)]
    return " | ".join(names) or "ok"


class Mechanism:
    """A mechanism: the general model plus every algorithm over it (see the module docstring).

    Build one with `from_urdf`, `from_toml` or `from_description`.
    """

    def __init__(self, model: "_core.MechanismModel", *, name: str = "mechanism",
                 source: str | None = None, link_frames=None):
        if not isinstance(model, _core.MechanismModel):
            raise TypeError(f"model must be a mechbal._core.MechanismModel, got {type(model).__name__}")
        self.model = model  # also builds the per-sample workspace (see the ``model`` property)
        if not isinstance(name, str):
            raise TypeError(f"name must be a str, got {type(name).__name__}")
        # as bytes (pybind11 passes them to std::string unchanged): a lone surrogate reaches the
        # check as invalid UTF-8 instead of failing the conversion
        why = _core.name_problem(name.encode("utf-8", "surrogatepass"))  # type: ignore[arg-type]
        if why:  # the character set of every name (docs/case_format.md, Names): files hold it
            raise ValueError(f"name {why} (got {name!r})")
        self.name = name
        self.source = source
        #: link -> (4, 4) placement in the link frame of the frame the user described the link in
        #: (see `user_frame`); absent links: the identity
        self.link_frames = {str(k): np.array(v, dtype=float) for k, v in (link_frames or {}).items()}
        from mechbal import plausibility

        plausibility.warn(plausibility.mechanism_problems(self))

    @property
    def model(self) -> "_core.MechanismModel":
        """The C++ ``MechanismModel`` (immutable)."""
        return self._model

    @model.setter
    def model(self, model: "_core.MechanismModel") -> None:
        self._model = model
        # one MechanismData for the per-sample calls: a 1-D float64 array goes straight to the
        # C++ algorithm; anything else (or a rejected instant) takes the general path below
        self._single = _SimpleNamespace(**_core.mechanism_single_sample(model, _OK, ShakingWrench))

    def __getstate__(self):
        state = self.__dict__.copy()
        state.pop("_single", None)  # rebuilt from the model
        return state

    def __setstate__(self, state):
        state = dict(state)
        model = state.pop("_model", None)
        if model is None:
            model = state.pop("model")
        self.__dict__.update(state)
        self.model = model

    # ---- construction ------------------------------------------------------------------------
    @classmethod
    def from_description(cls, joints: Sequence["_core.Joint"], bodies: Sequence["_core.Body"] = (),
                         frames: Sequence["_core.Frame"] = (), gravity=(0.0, 0.0, -9.81),
                         root_name: str = "base", name: str = "mechanism",
                         loops: Sequence["_core.LoopConstraint"] = (),
                         actuated: Sequence[str] = (),
                         springs: Sequence["_core.Spring"] = ()) -> "Mechanism":
        """From C++ description objects (`mechbal.Joint`, `mechbal.Body`,
        `mechbal.Frame`, `mechbal.LoopConstraint`, `mechbal.Spring`) and the
        names of the actuated joints (required with loops). Raises ValueError naming the field on
        bad input."""
        desc = _core.MechanismDescription(list(joints), list(bodies), list(frames),
                                          _real_array(gravity, "gravity"), root_name, list(loops),
                                          list(actuated), list(springs))
        return cls(_core.MechanismModel(desc), name=name)

    @classmethod
    def from_urdf(cls, path: str | Path, *, strict: bool | None = None,
                  allow_massless: bool | None = None) -> "Mechanism":
        """Read a URDF file through urdfdom in C++ (the same reader an embedded controller uses):
        links with inertials become bodies named after the links, revolute / continuous /
        prismatic / fixed joints keep their names (continuous = revolute without position
        limits, one coordinate), ``mimic`` becomes a gear coupling, limits are kept, and every
        URDF link is a named frame (see ``cpp/include/mechbal/io/urdf.hpp`` for the mapping).

        By default the reading is lenient: it loads what Pinocchio loads, repairing harmless
        defects with one `UrdfRepairWarning` each, naming the URDF element and the repair
        (a ``<mimic>`` on a fixed joint, or of a joint that does not exist, ignored; a body's
        non-physical inertia replaced by the nearest physical one, the warning saying whether the
        body is negligible -- mass at most 1e-4 of the URDF's total -- or the dynamics change; a
        negligible non-physical placeholder on the fixed root dropped). ``strict=True`` refuses them. A URDF with no
        ``<inertial>`` on any moving link is refused unless ``allow_massless=True`` (kinematics
        only). None: the defaults of `urdf_reading` (False unless set, e.g. by the CLI's
        ``--strict`` / ``--allow-massless``).
        Raises `mechbal.config.ConfigError` (a ValueError) naming the URDF element."""
        import warnings

        from mechbal.config import ConfigError, read_regular_file

        path = Path(path)
        field = f"URDF file '{path}'"
        if not path.exists():
            raise ConfigError(field, "not found", has_value=False)
        # a regular file of bounded size, at once (not /dev/zero, a FIFO, a folder): ConfigError
        read_regular_file(path, field, _core.MAX_URDF_BYTES)
        defaults = _URDF_READING.get()
        strict = defaults["strict"] if strict is None else bool(strict)
        allow_massless = defaults["allow_massless"] if allow_massless is None else bool(allow_massless)
        try:
            model, repairs = _core.read_urdf(str(path), strict=strict, allow_massless=allow_massless)
            for text in repairs:
                warnings.warn(UrdfRepairWarning(f"{field}: {text}"), stacklevel=2)
        except ValueError as exc:
            message = str(exc)
            if message.startswith(field + ": "):
                message = message[len(field) + 2:]
            raise ConfigError(field, message, has_value=False) from None
        return cls(model, name=path.stem, source=str(path))

    @classmethod
    def from_urdf_string(cls, xml: str, name: str = "urdf") -> "Mechanism":
        """As `from_urdf`, from a URDF document held in a string."""
        from mechbal.config import ConfigError

        try:
            model = _core.mechanism_from_urdf_string(xml)
        except ValueError as exc:
            field, _, message = str(exc).partition(": ")  # the C++ message names its element first
            raise ConfigError(field, message, has_value=False) from None
        return cls(model, name=name)

    @classmethod
    def from_toml(cls, path: str | Path) -> "Mechanism":
        """Read the ``[mechanism]`` table of a TOML case file (serial chains, trees, extra bodies,
        gear couplings, frames; see the README's "Describing a mechanism")."""
        from mechbal.config import ConfigError, case_path, read_toml
        from mechbal.spec import mechanism_spec

        path = case_path(path)
        config = read_toml(path)
        if "mechanism" not in config:
            raise ConfigError("mechanism", "is required", has_value=False)
        return cls.from_spec(mechanism_spec(config["mechanism"]), name=path.stem, source=str(path))

    @classmethod
    def from_spec(cls, spec, name: str = "mechanism", source: str | None = None) -> "Mechanism":
        """From a `mechbal.spec.MechanismSpec` (what the TOML reader produces)."""
        from mechbal.config import ConfigError

        types = {"revolute": _core.JointType.revolute, "prismatic": _core.JointType.prismatic,
                 "fixed": _core.JointType.fixed}
        loop_types = {"point": _core.LoopType.point, "planar_point": _core.LoopType.planar_point,
                      "axis": _core.LoopType.axis, "weld": _core.LoopType.weld}
        joints = []
        for j in spec.joints:
            kw = {}
            if j.mimic is not None:
                kw = dict(mimic_joint=j.mimic[0], mimic_ratio=float(j.mimic[1]), mimic_offset=float(j.mimic[2]))
            joints.append(_core.Joint(j.name, types[j.type], j.parent, np.asarray(j.placement, float),
                                      np.asarray(j.axis, float), float(j.lower), float(j.upper),
                                      float(j.velocity), float(j.effort), **kw))
        bodies = [_core.Body(b.name, b.link, float(b.mass), np.asarray(b.com, float),
                             np.asarray(b.inertia, float), b.kind) for b in spec.bodies]
        frames = [_core.Frame(f.name, f.link, np.asarray(f.placement, float)) for f in spec.frames]
        loops = [_core.LoopConstraint(lp.name, loop_types[lp.type], lp.frame_a, lp.frame_b)
                 for lp in getattr(spec, "loops", [])]
        springs = [_core.Spring(sp.name, sp.link_a, np.asarray(sp.anchor_a, float), sp.link_b,
                                np.asarray(sp.anchor_b, float), float(sp.rate), float(sp.free_length),
                                float(sp.preload), int(sp.count), float(sp.pulley_ratio))
                   for sp in getattr(spec, "springs", [])]
        desc = _core.MechanismDescription(joints, bodies, frames, np.asarray(spec.gravity, float), "base",
                                          loops, list(getattr(spec, "actuated", [])), springs)
        try:
            model = _core.MechanismModel(desc)
        except ValueError as exc:
            raise ConfigError("mechanism", str(exc), has_value=False) from None
        return cls(model, name=name, source=source, link_frames=getattr(spec, "link_frames", None))

    def user_frame(self, link: str) -> FloatArray:
        """(4, 4) placement, in the link frame of ``link`` (the frame right after its joint's
        motion), of the frame the user described that link in: the standard-DH frame of a ``dh``
        joint of a TOML file, ``mechanism.base`` for ``base``, the identity otherwise (URDF link
        frames, ``origin`` and ``mdh`` joints). A point p given by the user is ``T @ [p, 1]``."""
        if link not in self.link_names:
            import difflib
            hint = difflib.get_close_matches(link, self.link_names, n=1)
            raise ValueError(f"link: no link named '{link}'" + (f" (did you mean '{hint[0]}'?)" if hint
                                                                else f" (links: {', '.join(self.link_names)})"))
        return self.link_frames.get(link, np.eye(4)).copy()

    def with_bodies(self, bodies: Sequence["_core.Body"], *, replace: bool = False,
                    name: str | None = None) -> "Mechanism":
        """A copy with ``bodies`` (`mechbal.Body`, com and inertia in the link frames)
        added to its own (``replace``: instead of its own): same joints, frames, loops, gravity
        and user frames. Raises ValueError naming the problem (duplicate name, unknown link)."""
        d = self.model.description
        own = [] if replace else list(d.bodies)
        desc = _core.MechanismDescription(list(d.joints), own + list(bodies), list(d.frames),
                                          np.asarray(d.gravity, float), d.root_name, list(d.loops),
                                          list(d.actuated), list(d.springs))
        return Mechanism(_core.MechanismModel(desc), name=name or self.name, source=self.source,
                         link_frames=self.link_frames)

    def with_springs(self, springs: Sequence["_core.Spring"], *, replace: bool = False,
                     name: str | None = None) -> "Mechanism":
        """A copy with ``springs`` (`mechbal.Spring`, anchors in the link frames) added to
        its own (``replace``: instead of its own): same joints, bodies, frames, loops, gravity
        and user frames. Raises ValueError naming the problem (duplicate name, unknown link,
        negative rate...)."""
        d = self.model.description
        own = [] if replace else list(d.springs)
        desc = _core.MechanismDescription(list(d.joints), list(d.bodies), list(d.frames),
                                          np.asarray(d.gravity, float), d.root_name, list(d.loops),
                                          list(d.actuated), own + list(springs))
        return Mechanism(_core.MechanismModel(desc), name=name or self.name, source=self.source,
                         link_frames=self.link_frames)

    # ---- export --------------------------------------------------------------------------------
    def to_mjcf(self, path: str | Path | None = None, *, q: npt.ArrayLike | None = None,
                q_guess: npt.ArrayLike | None = None, name: str | None = None,
                timestep: float | None = None) -> str:
        """MuJoCo model (MJCF) of this mechanism: tree, gears, loops, springs, every body with its
        own inertia, names kept (`mechbal.export.mjcf`); ``q``: the keyframe's pose (a closed
        mechanism is assembled from ``q`` or ``q_guess``); ``timestep`` [s]: MuJoCo's (default
        1 ms for a tree, 0.25 ms for a closed mechanism: `mechbal.export.mjcf.default_timestep`).
        Writes ``path`` when given; returns the text. Raises `mechbal.export.ExportError` (a
        ValueError) for what MJCF cannot hold."""
        from mechbal.export.mjcf import mjcf_text

        text = mjcf_text(self, name, q=q, q_guess=q_guess, timestep=timestep)
        if path is not None:
            Path(path).write_text(text)
        return text

    def to_toml(self, path: str | Path | None = None, *, name: str | None = None,
                title: str | None = None, trajectory: Mapping[str, Any] | None = None) -> str:
        """A complete, commented case file of this mechanism (``kind = "mechanism"``, what
        ``mechbal init --from robot.urdf`` prints; `mechbal.export.toml.case_text`): ``[case]``,
        ``[mechanism]`` (every joint, body, frame, spring and loop, numbers that round-trip:
        `from_toml` reads back this model), ``[trajectory]`` (``trajectory``, a table as a case file
        holds it, or an open mechanism's default motion) and a commented ``[control]``. Writes
        ``path`` when given; returns the text."""
        from mechbal.export.toml import case_text

        text = case_text(self, name=name, title=title, trajectory=trajectory, source=self.source)
        if path is not None:
            Path(path).write_text(text)
        return text

    def to_urdf(self, path: str | Path | None = None, *, name: str | None = None) -> str:
        """URDF of this mechanism (`mechbal.export.urdf`: link names, frames and every body's
        inertia kept). Raises `mechbal.export.ExportError` for loops or springs, which
        URDF cannot describe. Writes ``path`` when given; returns the text."""
        from mechbal.export.urdf import urdf_text

        text = urdf_text(self, name)
        if path is not None:
            Path(path).write_text(text)
        return text

    # ---- structure ---------------------------------------------------------------------------
    @property
    def dof(self) -> int:
        """Number of independent coordinates (gear-coupled joints follow their master)."""
        return self.model.dof

    @property
    def joint_names(self) -> list[str]:
        """Names of the joints whose positions are the coordinates q, in order."""
        return list(self.model.coordinate_names)

    @property
    def link_names(self) -> list[str]:
        """Link names, the base first (each joint moves the link of its name)."""
        return list(self.model.link_names)

    @property
    def body_names(self) -> list[str]:
        """Names of the bodies (links' inertias, counterweights, motors, discs...), in model order."""
        return list(self.model.body_names)

    @property
    def frame_names(self) -> list[str]:
        """Names of the named frames (URDF links, tool and sensor frames, loop-closure frames)."""
        return list(self.model.frame_names)

    @property
    def total_mass(self) -> float:
        """Total mass of all bodies [kg]."""
        return float(self.model.total_mass)

    @property
    def gravity(self) -> FloatArray:
        """Gravity acceleration in O [m/s^2] (3,)."""
        return np.array(self.model.gravity)

    @property
    def bodies(self) -> list[_core.Body]:
        """The bodies (``mechbal.Body``: name, link, mass [kg], com [m], inertia [kg m^2])."""
        return list(self.model.bodies)

    @property
    def springs(self) -> list[_core.Spring]:
        """The springs (``mechbal.Spring``: name, link_a, anchor_a, link_b, anchor_b [m, link
        frames], rate [N/m], free_length [m], preload [N], count, pulley_ratio), in model order."""
        return list(self.model.springs)

    @property
    def spring_names(self) -> list[str]:
        """Names of the springs, in model order (the columns of `spring_lengths`)."""
        return list(self.model.spring_names)

    @property
    def is_closed(self) -> bool:
        """True when the mechanism has loop closures."""
        return bool(self.model.is_closed)

    @property
    def actuated_names(self) -> list[str]:
        """Actuated joints: the independent coordinates q# of the closed-loop methods."""
        names = self.joint_names
        return [names[i] for i in self.model.actuated_coordinates]

    @property
    def passive_names(self) -> list[str]:
        """Passive joints of a closed mechanism (solved from the loop closures)."""
        names = self.joint_names
        return [names[i] for i in self.model.passive_coordinates]

    def __repr__(self) -> str:
        springs = f", {self.model.num_springs} springs" if self.model.num_springs else ""
        return (f"<Mechanism {self.name!r}: {self.dof} dof, {len(self.link_names) - 1} joints, "
                f"{len(self.body_names)} bodies{springs}, {self.total_mass:.4g} kg>")

    # ---- argument handling -------------------------------------------------------------------
    def _args(self, names: tuple[str, ...], values: tuple) -> tuple[bool, list[np.ndarray]]:
        arrays = []
        single = None
        for name, value in zip(names, values):
            a = np.asarray(value)
            if a.dtype.kind not in "iuf":
                raise TypeError(f"{name} must be a real numeric array (int or float values), got "
                                f"dtype {a.dtype}")
            a = np.ascontiguousarray(a, dtype=float)
            if a.ndim == 1:
                is_single = True
                a = a.reshape(1, -1)
            elif a.ndim == 2:
                is_single = False
            else:
                raise ValueError(f"{name} must have shape ({self.dof},) or (N, {self.dof}), got {a.shape}")
            if a.shape[1] != self.dof:
                raise ValueError(f"{name} must have shape ({self.dof},) or (N, {self.dof}), "
                                 f"got {np.asarray(value).shape}")
            if single is None:
                single = is_single
            elif single != is_single or a.shape[0] != arrays[0].shape[0]:
                raise ValueError(f"{name} has shape {np.asarray(value).shape}, which does not match "
                                 f"{names[0]} {np.asarray(values[0]).shape}")
            arrays.append(a)
        return bool(single), arrays

    def _finish(self, single: bool, result: dict, keys: Sequence[str]):
        status = np.asarray(result["status"])
        if single:
            if status[0] != 0:
                raise ValueError(f"{self.name}: input rejected ({_status_text(int(status[0]))}); "
                                 "q, v, a must be finite, of the right size, and give finite results")
            return [np.asarray(result[k])[0] for k in keys], status[0]
        return [BatchArray(result[k], status) for k in keys], status

    # ---- algorithms --------------------------------------------------------------------------
    @overload
    def inverse_dynamics(self, q: Sample, v: Sample, a: Sample) -> FloatArray: ...
    @overload
    def inverse_dynamics(self, q: Samples, v: Samples, a: Samples) -> BatchArray: ...
    @overload
    def inverse_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike, a: npt.ArrayLike) -> FloatArray: ...

    def inverse_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike, a: npt.ArrayLike) -> FloatArray:
        """Joint forces tau = M(q) a + C(q, v) v + G(q) + K(q) [N m or N] (K: the springs' joint
        forces, `spring_torque`), gear couplings projected.
        A batch returns a `BatchArray` (N, dof) whose ``status`` (N,) flags the rejected
        instants (their rows are NaN)."""
        tau = self._single.inverse_dynamics(q, v, a)
        if tau is not None:
            return tau
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (tau,), _ = self._finish(single, _core.mechanism_inverse_dynamics(self.model, q, v, a),
                                 ["joint_torque"])
        return tau

    def mass_matrix(self, q: npt.ArrayLike) -> FloatArray:
        """Joint-space mass matrix M(q) (dof, dof) [kg m^2, kg]; a batch gives (N, dof, dof)."""
        M = self._single.mass_matrix(q)
        if M is not None:
            return M
        single, (q,) = self._args(("q",), (q,))
        (M,), _ = self._finish(single, _core.mechanism_mass_matrix(self.model, q), ["mass_matrix"])
        return M

    @overload
    def gravity_torque(self, q: Sample) -> FloatArray: ...
    @overload
    def gravity_torque(self, q: Samples) -> BatchArray: ...
    @overload
    def gravity_torque(self, q: npt.ArrayLike) -> FloatArray: ...

    def gravity_torque(self, q: npt.ArrayLike) -> FloatArray:
        """Gravity torques G(q): the joint forces that hold the weights still [N m or N]; with
        springs, `static_torque` is what holds the mechanism still."""
        g = self._single.gravity_torque(q)
        if g is not None:
            return g
        single, (q,) = self._args(("q",), (q,))
        (g,), _ = self._finish(single, _core.mechanism_gravity_torque(self.model, q), ["gravity_torque"])
        return g

    def static_torque(self, q: npt.ArrayLike) -> FloatArray:
        """G(q) + K(q): the joint forces that hold the mechanism still, gravity and springs [N m
        or N] (`gravity_torque` without springs). Zero over the workspace exactly when the
        springs balance the mechanism statically."""
        single, (q,) = self._args(("q",), (q,))
        (g,), _ = self._finish(single, _core.mechanism_static_torque(self.model, q), ["static_torque"])
        return g

    def _springs(self, q, key: str):
        single, (q,) = self._args(("q",), (q,))
        (x,), _ = self._finish(single, _core.mechanism_springs(self.model, q), [key])
        return x

    def spring_torque(self, q: npt.ArrayLike) -> FloatArray:
        """K(q) = dV_springs/dq: the joint forces that hold the springs still [N m or N] (the
        convention of `gravity_torque`; ``cpp/include/mechbal/algorithm/springs.hpp``)."""
        return self._springs(q, "spring_torque")

    def spring_lengths(self, q: npt.ArrayLike) -> FloatArray:
        """Anchor distance d of each spring [m]: (S,) or (N, S), columns as `spring_names`."""
        return self._springs(q, "spring_length")

    def spring_tension(self, q: npt.ArrayLike) -> FloatArray:
        """Tension at each spring's anchors, count preload / k + K_eq (d - free_length) [N]."""
        return self._springs(q, "spring_tension")

    @overload
    def spring_energy(self, q: Sample) -> float: ...
    @overload
    def spring_energy(self, q: Samples) -> BatchArray: ...
    @overload
    def spring_energy(self, q: npt.ArrayLike) -> float | BatchArray: ...

    def spring_energy(self, q: npt.ArrayLike) -> float | BatchArray:
        """Elastic energy of all springs [J] (zero when each is at its free length): a float, or (N,)."""
        e = self._springs(q, "spring_energy")
        return float(e) if np.ndim(e) == 0 else e

    @overload
    def potential_energy(self, q: Sample) -> float: ...
    @overload
    def potential_energy(self, q: Samples) -> BatchArray: ...
    @overload
    def potential_energy(self, q: npt.ArrayLike) -> float | BatchArray: ...

    def potential_energy(self, q: npt.ArrayLike) -> float | BatchArray:
        """Gravity (-sum m g . c, zero at O) plus springs' energy [J]: constant over the workspace
        exactly when the mechanism is statically balanced. A float, or (N,)."""
        e = self._springs(q, "potential_energy")
        return float(e) if np.ndim(e) == 0 else e

    def bias_torque(self, q: npt.ArrayLike, v: npt.ArrayLike) -> FloatArray:
        """C(q, v) v + G(q) + K(q) [N m or N] (springs included: the inverse dynamics at a = 0)."""
        single, (q, v) = self._args(("q", "v"), (q, v))
        (b,), _ = self._finish(single, _core.mechanism_bias_torque(self.model, q, v), ["bias_torque"])
        return b

    def center_of_mass(self, q: npt.ArrayLike) -> FloatArray:
        """Centre of mass of all bodies in O [m]: (3,) or (N, 3)."""
        c = self._single.center_of_mass(q)
        if c is not None:
            return c
        single, (q,) = self._args(("q",), (q,))
        (c,), _ = self._finish(single, _core.mechanism_center_of_mass(self.model, q), ["center_of_mass"])
        return c

    def momentum(self, q: npt.ArrayLike, v: npt.ArrayLike) -> Momentum:
        """Linear momentum and angular momentum about O."""
        single, (q, v) = self._args(("q", "v"), (q, v))
        (P, H), st = self._finish(single, _core.mechanism_momentum(self.model, q, v),
                                  ["linear_momentum", "angular_momentum"])
        return Momentum(P, H, st)

    def momentum_matrix(self, q: npt.ArrayLike) -> FloatArray:
        """A(q) with [P; H_O] = A(q) v: (6, dof), linear rows first."""
        single, (q,) = self._args(("q",), (q,))
        (A,), _ = self._finish(single, _core.mechanism_momentum_matrix(self.model, q), ["momentum_matrix"])
        return A

    def shaking_wrench(self, q: npt.ArrayLike, v: npt.ArrayLike, a: npt.ArrayLike) -> ShakingWrench:
        """Shaking force F = dP/dt [N] and shaking moment M_O = dH_O/dt [N m] about O, with the
        momenta, for the motion (q, v, a) (Briot & Arakelian 2009, eqs 1-4)."""
        w = self._single.shaking_wrench(q, v, a)
        if w is not None:
            return w
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (F, M, P, H), st = self._finish(
            single, _core.mechanism_shaking_wrench(self.model, q, v, a, False),
            ["shaking_force", "shaking_moment", "linear_momentum", "angular_momentum"])
        return ShakingWrench(F, M, P, H, st)

    def base_reaction(self, q: npt.ArrayLike, v: npt.ArrayLike, a: npt.ArrayLike) -> BaseReaction:
        """Wrench the base exerts on the moving mechanism, gravity included: force = dP/dt - m g,
        moment about O = dH_O/dt - (m c) x g, m and m c over the bodies that move (those on the
        root link and on links fixed to it are the base's own: their weight is not carried by the
        mechanism). ``support_force`` / ``support_moment``: the same over every body."""
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (F, M, SF, SM), st = self._finish(
            single, _core.mechanism_shaking_wrench(self.model, q, v, a, True),
            ["base_reaction_force", "base_reaction_moment", "support_reaction_force", "support_reaction_moment"])
        return BaseReaction(F, M, st, SF, SM)

    def body_motion(self, q: npt.ArrayLike, v: npt.ArrayLike | None = None,
                    a: npt.ArrayLike | None = None) -> BodyMotion:
        """Every body's pose, velocity and acceleration in O (v and a default to zero)."""
        q_arr = _real_array(q, "q")
        v = np.zeros_like(q_arr) if v is None else v
        a = np.zeros_like(q_arr) if a is None else a
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        keys = ["com", "rotation", "com_velocity", "com_acceleration", "angular_velocity",
                "angular_acceleration", "link_rotation", "link_position", "frame_placement"]
        values, st = self._finish(single, _core.mechanism_kinematics(self.model, q, v, a), keys)
        return BodyMotion(**{k: np.asarray(x) for k, x in zip(keys, values)}, status=st)

    def body_poses(self, q: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(com, rotation) of every body: (B, 3) and (B, 3, 3), or with a leading N axis."""
        m = self.body_motion(q)
        if np.ndim(m.status) == 0:
            return m.com, m.rotation
        return BatchArray(m.com, m.status), BatchArray(m.rotation, m.status)

    def frame_placement(self, q: npt.ArrayLike, frame: str) -> FloatArray:
        """4x4 placement of a named frame in O."""
        T = self._single.frame_placement(q, frame)
        if T is not None:
            return T
        i = self._frame(frame)
        m = self.body_motion(q)
        T = m.frame_placement[..., i, :, :]
        return T if np.ndim(m.status) == 0 else BatchArray(T, m.status)

    def frame_jacobian(self, q: npt.ArrayLike, frame: str) -> FloatArray:
        """[v; w] = J(q) qdot of a named frame's origin, O's axes: (6, dof)."""
        J = self._single.frame_jacobian(q, frame)
        if J is not None:
            return J
        self._frame(frame)
        single, (q,) = self._args(("q",), (q,))
        (J,), _ = self._finish(single, _core.mechanism_frame_jacobian(self.model, q, frame), ["jacobian"])
        return J

    def torque_regressor(self, q: npt.ArrayLike, v: npt.ArrayLike, a: npt.ArrayLike) -> FloatArray:
        """Y(q, v, a) with tau = Y pi, pi the stacked 10 inertial parameters of every body
        ([m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], c and I about the link origin, link frame; column
        k is ``inertial_parameter_names[k]``)."""
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (Y,), _ = self._finish(single, _core.mechanism_torque_regressor(self.model, q, v, a), ["regressor"])
        return Y

    def gravity_regressor(self, q: npt.ArrayLike) -> FloatArray:
        """Y(q) with G(q) = Y pi."""
        single, (q,) = self._args(("q",), (q,))
        (Y,), _ = self._finish(single, _core.mechanism_gravity_regressor(self.model, q), ["regressor"])
        return Y

    def momentum_regressor(self, q: npt.ArrayLike, v: npt.ArrayLike) -> FloatArray:
        """Y(q, v) with [P; H_O] = Y pi (6, 10 B)."""
        single, (q, v) = self._args(("q", "v"), (q, v))
        (Y,), _ = self._finish(single, _core.mechanism_momentum_regressor(self.model, q, v), ["regressor"])
        return Y

    @property
    def inertial_parameter_names(self) -> list[str]:
        """The name of each entry of `inertial_parameters` and each regressor column,
        ``<body>.<parameter>`` with the parameters in the order of ``INERTIAL_PARAMETER_NAMES``
        (``m, mcx, mcy, mcz, ixx, ixy, iyy, ixz, iyz, izz``)."""
        return [f"{b.name}.{p}" for b in self.model.bodies for p in INERTIAL_PARAMETER_NAMES]

    def inertial_parameters(self) -> FloatArray:
        """pi: the stacked 10 inertial parameters of every body, in the regressors' convention
        (``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` per body, inertia about the link
        origin in the link frame; `inertial_parameter_names` names each entry)."""
        out = []
        for b in self.model.bodies:
            m, c, I = b.mass, np.asarray(b.com), np.asarray(b.inertia)
            Io = I + m * (c @ c * np.eye(3) - np.outer(c, c))
            out.append([m, *(m * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])
        return np.array(out, dtype=float).reshape(-1)

    # ---- closed loops --------------------------------------------------------------------------
    def closed_motion(self, q_actuated: npt.ArrayLike, v_actuated: npt.ArrayLike | None = None,
                      a_actuated: npt.ArrayLike | None = None, *, q_guess: npt.ArrayLike | None = None,
                      max_iterations: int = 50, tolerance: float = 1e-13, singular_rcond: float = 1e-7,
                      with_forces: bool = False) -> "ClosedMotion":
        """Solve the loop closures along a motion of the actuated joints (1-D: one instant; 2-D:
        (N, na) in time order, each instant warm-starting the next from ``q_guess`` (default: zeros)).
        Returns the full q, v, a (the coupling-matrix method: v = C v#, a = C a# + c), the reciprocal
        condition of the passive Jacobian, the closure residual, Newton iterations, statuses
        (``singular`` near a parallel singularity; ``solver_error`` where the mechanism cannot be
        assembled: that instant's q, v, a are NaN), and with ``with_forces`` the actuated forces
        tau# = C^T tau [N m or N]. Rows are independent: a failed instant does not poison the next
        ones, which start from the last good solution (or ``q_guess``)."""
        qa = _real_array(q_actuated, "q_actuated")
        va = np.zeros_like(qa) if v_actuated is None else _real_array(v_actuated, "v_actuated")
        aa = np.zeros_like(qa) if a_actuated is None else _real_array(a_actuated, "a_actuated")
        na = len(self.model.actuated_coordinates)
        single = qa.ndim == 1
        arrays = []
        for name, x in (("q_actuated", qa), ("v_actuated", va), ("a_actuated", aa)):
            x = np.asarray(x)
            if x.dtype.kind not in "biuf":
                raise TypeError(f"{name} must be a real numeric array, got dtype {x.dtype}")
            x = np.ascontiguousarray(x, dtype=float).reshape(1, -1) if single else np.ascontiguousarray(x, float)
            if x.ndim != 2 or x.shape[1] != na or x.shape[0] != (1 if single else qa.shape[0]):
                raise ValueError(f"{name} must have shape ({na},) or (N, {na}) like q_actuated, got "
                                 f"{np.asarray(x).shape}")
            arrays.append(x)
        guess = np.zeros(self.dof) if q_guess is None else _real_array(q_guess, "q_guess")
        r = _core.mechanism_closed_motion(self.model, arrays[0], arrays[1], arrays[2], guess,
                                          max_iterations, tolerance, singular_rcond, with_forces)
        out = {k: np.asarray(v) for k, v in r.items()}
        if single:
            out = {k: v[0] for k, v in out.items()}
        return ClosedMotion(q=out["q"], v=out["v"], a=out["a"], rcond=out["rcond"], residual=out["residual"],
                            iterations=out["iterations"], status=out["status"],
                            actuated_force=out.get("actuated_force"), projection=out.get("projection"))

    def actuated_forces(self, q_actuated: npt.ArrayLike, v_actuated: npt.ArrayLike,
                        a_actuated: npt.ArrayLike, **kw: Any) -> FloatArray:
        """Actuated forces tau# = C^T tau(q, v, a) of the closed mechanism [N m or N]; for one
        instant raises ValueError when the loops cannot be solved there."""
        m = self.closed_motion(q_actuated, v_actuated, a_actuated, with_forces=True, **kw)
        if np.ndim(m.status) == 0 and (int(m.status) & ~int(_core.Status.singular)):
            raise ValueError(f"{self.name}: the loops cannot be solved here ({_status_text(int(m.status))})")
        assert m.actuated_force is not None  # asked for with_forces
        if np.ndim(m.status) == 0:
            return m.actuated_force
        return BatchArray(m.actuated_force, m.status)

    def reduced_mass_matrix(self, q_actuated: npt.ArrayLike, *,
                            q_guess: npt.ArrayLike | None = None) -> tuple[FloatArray, FloatArray]:
        """(C^T M C, C^T G): mass matrix and gravity forces in the actuated coordinates. One
        instant raises ValueError where the loops cannot be solved; a batch gives
        `BatchArray` results whose ``status`` flags the failed instants (NaN rows)."""
        qa = np.atleast_2d(_real_array(q_actuated, "q_actuated"))
        guess = np.zeros(self.dof) if q_guess is None else _real_array(q_guess, "q_guess")
        r = _core.mechanism_closed_mass_matrix(self.model, np.ascontiguousarray(qa), guess)
        if np.ndim(q_actuated) == 1:
            st = int(np.asarray(r["status"])[0])
            if st & ~int(_core.Status.singular):
                raise ValueError(f"{self.name}: the loops cannot be solved here ({_status_text(st)})")
            return r["reduced_mass_matrix"][0], r["actuated_gravity"][0]
        return (BatchArray(r["reduced_mass_matrix"], r["status"]),
                BatchArray(r["actuated_gravity"], r["status"]))

    def _frame(self, frame: str) -> int:
        i = self.model.frame_index(frame)
        if i < 0:
            import difflib
            hint = difflib.get_close_matches(frame, self.frame_names, n=1)
            more = f" (did you mean '{hint[0]}'?)" if hint else f" (frames: {', '.join(self.frame_names)})"
            raise ValueError(f"frame: no frame named '{frame}'{more}")
        return i
