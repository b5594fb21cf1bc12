"""Configuration: TOML files -> validated models.

Every error is a :class:`ConfigError` naming the offending field by its dotted path (for example
``mechanism.joints[1].link.mass``) and the value found, and nothing is half-built: models are only
constructed once every field has been read and checked.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any, Mapping

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

CASES_DIR = Path(__file__).resolve().parent / "cases"


class ConfigError(ValueError):
    """A configuration value is missing, of the wrong type or out of range."""

    def __init__(self, field: str, message: str, value: Any = None, *, has_value: bool = True):
        self.field = field
        self.value = value
        text = f"{field}: {message}"
        if has_value:
            text += f" (got {value!r})"
        super().__init__(text)


_MISSING = object()


def require(table: Mapping[str, Any], key: str, path: str, default: Any = _MISSING) -> Any:
    """``table[key]``, or ``default``; a missing required key raises ConfigError naming it."""
    if not isinstance(table, Mapping):
        raise ConfigError(path, "must be a table", table)
    if key in table:
        return table[key]
    if default is _MISSING:
        raise ConfigError(f"{path}.{key}" if path else key, "is required", has_value=False)
    return default


def number(value: Any, field: str, *, minimum: float | None = None, positive: bool = False,
           maximum: float | None = None) -> float:
    """A finite real number, optionally bounded. Booleans are rejected."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(field, "must be a number", value)
    x = float(value)
    if not math.isfinite(x):
        raise ConfigError(field, "must be finite", value)
    if positive and x <= 0.0:
        raise ConfigError(field, "must be > 0", value)
    if minimum is not None and x < minimum:
        raise ConfigError(field, f"must be >= {minimum}", value)
    if maximum is not None and x > maximum:
        raise ConfigError(field, f"must be <= {maximum}", value)
    return x


def integer(value: Any, field: str, *, minimum: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(field, "must be an integer", value)
    if minimum is not None and value < minimum:
        raise ConfigError(field, f"must be >= {minimum}", value)
    return int(value)


def string(value: Any, field: str, choices: tuple[str, ...] | None = None) -> str:
    if not isinstance(value, str):
        raise ConfigError(field, "must be a string", value)
    if choices is not None and value not in choices:
        raise ConfigError(field, f"must be one of {', '.join(choices)}", value)
    return value


def vector(value: Any, field: str, size: int | None = None) -> np.ndarray:
    """A list of finite numbers, of length ``size`` when given."""
    if not isinstance(value, (list, tuple)):
        raise ConfigError(field, "must be a list of numbers", value)
    if size is not None and len(value) != size:
        raise ConfigError(field, f"must have {size} values", value)
    return np.array([number(v, f"{field}[{i}]") for i, v in enumerate(value)], dtype=float)


def inertia(value: Any, field: str) -> np.ndarray:
    """An inertia tensor about the centre of mass [kg m^2]: a 3x3 list, three principal moments
    [Ixx, Iyy, Izz], or six values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]. Must be symmetric positive
    semi-definite and satisfy the triangle inequality of a physical body."""
    if isinstance(value, (list, tuple)) and len(value) == 3 and all(
            isinstance(r, (list, tuple)) for r in value):
        rows = [vector(r, f"{field}[{i}]", 3) for i, r in enumerate(value)]
        I = np.array(rows)
    elif isinstance(value, (list, tuple)) and len(value) in (3, 6):
        v = vector(value, field)
        I = np.diag(v[:3])
        if len(v) == 6:
            I[0, 1] = I[1, 0] = v[3]
            I[0, 2] = I[2, 0] = v[4]
            I[1, 2] = I[2, 1] = v[5]
    else:
        raise ConfigError(field, "must be a 3x3 matrix, [Ixx, Iyy, Izz] or "
                                 "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]", value)
    from mechbal._core import validate_rigid_body

    try:
        validate_rigid_body(1.0, I, field)
    except ValueError as exc:
        msg = str(exc).replace(f"{field}.inertia ", "")
        raise ConfigError(field, msg, value) from None
    return I


def rotation_rpy(rpy: np.ndarray) -> np.ndarray:
    """Rotation matrix from roll-pitch-yaw (fixed axes x, then y, then z): Rz(y) Ry(p) Rx(r)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def transform(value: Any, field: str) -> np.ndarray:
    """A 4x4 homogeneous transform from ``{xyz = [...], rpy = [...]}`` (both optional)."""
    if not isinstance(value, Mapping):
        raise ConfigError(field, "must be a table {xyz = [x, y, z], rpy = [r, p, y]}", value)
    unknown = set(value) - {"xyz", "rpy"}
    if unknown:
        raise ConfigError(field, f"unknown keys {sorted(unknown)}", value)
    T = np.eye(4)
    T[:3, 3] = vector(value.get("xyz", [0.0, 0.0, 0.0]), f"{field}.xyz", 3)
    T[:3, :3] = rotation_rpy(vector(value.get("rpy", [0.0, 0.0, 0.0]), f"{field}.rpy", 3))
    return T


def read_toml(path: str | Path) -> dict:
    path = Path(path)
    try:
        with path.open("rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise ConfigError("case", "file not found", str(path)) from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(str(path), f"is not valid TOML: {exc}", has_value=False) from None


def case_path(name_or_path: str | Path) -> Path:
    """Path of a built-in case by name (``arm2link``) or of a user TOML file."""
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if not p.exists():
            raise ConfigError("case", "file not found", str(p))
        return p
    builtin = CASES_DIR / f"{name_or_path}.toml"
    if not builtin.exists():
        names = ", ".join(sorted(x.stem for x in CASES_DIR.glob("*.toml")))
        raise ConfigError("case", f"no such built-in case (available: {names})", str(name_or_path))
    return builtin


def load_case(name_or_path: str | Path) -> dict:
    """Read a case file and check its ``[case]`` header (``name``, ``kind``)."""
    data = read_toml(case_path(name_or_path))
    header = require(data, "case", "")
    string(require(header, "name", "case"), "case.name")
    string(require(header, "kind", "case"), "case.kind")
    return data


# ---- serial chains ----------------------------------------------------------------------------

def _dh_origin(table: Mapping[str, Any], field: str, modified: bool) -> tuple[np.ndarray, np.ndarray]:
    """(origin, X) from DH parameters. Modified (Craig): origin = Rx(alpha) Tx(a) Tz(d) Rz(theta),
    X = I. Standard: the joint rotates before Tz(d) Tx(a) Rx(alpha), which we carry as X into the
    next joint's origin (the link's own frame is the frame right after the joint)."""
    a = number(require(table, "a", field), f"{field}.a")
    alpha = number(require(table, "alpha", field), f"{field}.alpha")
    d = number(require(table, "d", field, 0.0), f"{field}.d")
    theta = number(require(table, "theta", field, 0.0), f"{field}.theta")

    def rx(t):
        T = np.eye(4)
        T[:3, :3] = rotation_rpy([t, 0, 0])
        return T

    def rz(t):
        T = np.eye(4)
        T[:3, :3] = rotation_rpy([0, 0, t])
        return T

    def tr(x, y, z):
        T = np.eye(4)
        T[:3, 3] = [x, y, z]
        return T

    if modified:
        return rx(alpha) @ tr(a, 0, 0) @ tr(0, 0, d) @ rz(theta), np.eye(4)
    return rz(theta), tr(0, 0, d) @ tr(a, 0, 0) @ rx(alpha)


def chain_from_config(table: Mapping[str, Any], field: str = "mechanism"):
    """Build a :class:`mechbal.ChainModel` from a ``[mechanism]`` table.

    Each ``[[mechanism.joints]]`` has ``name``, ``type`` (revolute | prismatic), ``axis`` (default
    [0, 0, 1], in the joint frame) and one of ``origin = {xyz, rpy}``, ``mdh = {a, alpha, d,
    theta}`` (modified DH) or ``dh = {...}`` (standard DH), and ``link = {mass, com, inertia}`` with
    com and inertia (about the centre of mass) in the link frame (for ``dh``: in the standard DH
    frame of the link, converted here).
    """
    from mechbal._core import ChainModel, JointSpec, JointType

    gravity = vector(require(table, "gravity", field, [0.0, 0.0, -9.81]), f"{field}.gravity", 3)
    base = transform(require(table, "base", field, {}), f"{field}.base")
    joints_raw = require(table, "joints", field)
    if not isinstance(joints_raw, list) or not joints_raw:
        raise ConfigError(f"{field}.joints", "must be a non-empty array of tables", joints_raw)
    specs = []
    carry = np.eye(4)  # standard DH: constant transform after the previous joint
    for i, jt in enumerate(joints_raw):
        jf = f"{field}.joints[{i}]"
        if not isinstance(jt, Mapping):
            raise ConfigError(jf, "must be a table", jt)
        name = string(require(jt, "name", jf, f"joint{i + 1}"), f"{jf}.name")
        jtype = string(require(jt, "type", jf, "revolute"), f"{jf}.type", ("revolute", "prismatic"))
        kinds = [k for k in ("origin", "mdh", "dh") if k in jt]
        if len(kinds) > 1:
            raise ConfigError(jf, "give only one of origin, mdh, dh", sorted(kinds))
        kind = kinds[0] if kinds else "origin"
        X = np.eye(4)
        if kind == "origin":
            origin = transform(jt.get("origin", {}), f"{jf}.origin")
            axis = vector(require(jt, "axis", jf, [0.0, 0.0, 1.0]), f"{jf}.axis", 3)
        else:
            origin, X = _dh_origin(require(jt, kind, jf), f"{jf}.{kind}", modified=(kind == "mdh"))
            if "axis" in jt:
                raise ConfigError(f"{jf}.axis", "DH joints move along/about z; drop axis", jt["axis"])
            axis = np.array([0.0, 0.0, 1.0])
        if np.linalg.norm(axis) < 1e-12:
            raise ConfigError(f"{jf}.axis", "must be a non-zero vector", list(axis))
        link = require(jt, "link", jf)
        lf = f"{jf}.link"
        mass = number(require(link, "mass", lf), f"{lf}.mass", minimum=0.0)
        com = vector(require(link, "com", lf, [0.0, 0.0, 0.0]), f"{lf}.com", 3)
        I = inertia(require(link, "inertia", lf), f"{lf}.inertia")
        if kind == "dh":  # com/inertia given in the DH frame = link frame * X
            com = X[:3, :3] @ com + X[:3, 3]
            I = X[:3, :3] @ I @ X[:3, :3].T
        specs.append(JointSpec(name, JointType.revolute if jtype == "revolute" else JointType.prismatic,
                               carry @ origin, axis, mass, com, I))
        carry = X
    return ChainModel(specs, gravity, base)


def trajectory_from_config(table: Mapping[str, Any], dof: int, field: str = "trajectory"):
    """A :class:`mechbal.RestToRestTrajectory` and the sample times from a ``[trajectory]`` table
    with ``law`` (quintic | cubic), ``start``, ``end`` (``dof`` values), ``duration`` [s] and
    ``samples`` (number of instants, >= 3)."""
    from mechbal._core import RestToRestTrajectory, TimeLaw

    law = string(require(table, "law", field, "quintic"), f"{field}.law", ("quintic", "cubic"))
    start = vector(require(table, "start", field), f"{field}.start", dof)
    end = vector(require(table, "end", field), f"{field}.end", dof)
    duration = number(require(table, "duration", field), f"{field}.duration", positive=True)
    samples = integer(require(table, "samples", field, 501), f"{field}.samples", minimum=3)
    traj = RestToRestTrajectory(start, end, duration, getattr(TimeLaw, law))
    return traj, np.linspace(0.0, duration, samples)
