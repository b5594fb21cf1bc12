"""Configuration: TOML files -> validated models.

The schema of every case file is in :mod:`mechbal.schema` (pydantic models, strict: unknown keys
are errors); :func:`mechbal.schema.validate_case` checks a whole file before anything runs. Every
error is a :class:`ConfigError` naming the offending field by its dotted path (for example
``mechanism.joints[1].link.mass``) and the value found, and nothing is half-built: models are only
constructed once every field has been read and checked. The helpers here (``number``, ``vector``,
...) remain for code that checks values outside case files.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import math
import stat
import sys
from pathlib import Path
from typing import Any, Mapping

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from mechbal.registry import GENERAL_CASES_DIR as CASES_DIR, case_dirs  # noqa: E402


from mechbal.errors import ConfigError, ConfigWarning, short_repr  # noqa: F401 (re-exported)
from mechbal.spec import rotation_rpy  # noqa: F401 (re-exported)

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
    semi-definite and satisfy the triangle inequality of a physical body
    (:func:`mechbal.schema.inertia_matrix`)."""
    from pydantic_core import PydanticCustomError

    from mechbal.schema import inertia_matrix

    try:
        return inertia_matrix(value)
    except PydanticCustomError as exc:
        ctx = exc.context or {}
        v = ctx.get("value")
        raise ConfigError(field + ctx.get("sub", ""), ctx.get("message", exc.message()),
                          value if v is None else v) from None


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


def builtin_cases() -> dict[str, Path]:
    """Every built-in case file by name: the general cases and each paper's (the registry's
    folders, :mod:`mechbal.registry`)."""
    out: dict[str, Path] = {}
    for d in case_dirs():
        for p in sorted(d.glob("*.toml")):
            out.setdefault(p.stem, p)
    return dict(sorted(out.items()))


def case_path(name_or_path: str | Path) -> Path:
    """Path of a built-in case by name (``arm2link``) or of a user TOML file."""
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if not p.exists():
            raise ConfigError("case", "file not found", str(p))
        return p
    builtin = builtin_cases()
    if str(name_or_path) not in builtin:
        raise ConfigError("case", f"no such built-in case (available: {', '.join(builtin)})", str(name_or_path))
    return builtin[str(name_or_path)]


#: refuse case files larger than this (a case is a few kB; anything huge is a mistake)
MAX_CASE_BYTES = 4 * 1024 * 1024


def check_case_file(name_or_path: str) -> Path:
    """Path of the case after the checks that the TOML reader does not do: a regular file, not a
    folder, of reasonable size, UTF-8 text, valid TOML of reasonable nesting (raises
    :class:`ConfigError` naming the path)."""
    path = case_path(name_or_path)  # ConfigError for an unknown built-in name or a missing file
    try:
        st = path.stat()
    except OSError as exc:
        raise ConfigError("case", f"cannot be read: {exc.strerror}", str(path)) from None
    if stat.S_ISDIR(st.st_mode):
        raise ConfigError("case", "is a folder, not a case file", str(path))
    if not stat.S_ISREG(st.st_mode):
        raise ConfigError("case", "is not a regular file (a device, pipe or socket)", str(path))
    if st.st_size > MAX_CASE_BYTES:
        raise ConfigError("case", f"is {st.st_size} bytes, more than a case file can be "
                                  f"({MAX_CASE_BYTES} bytes)", str(path))
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ConfigError("case", f"cannot be read: {exc.strerror}", str(path)) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ConfigError(str(path), f"is not UTF-8 text (byte 0x{raw[exc.start]:02x} on line "
                                     f"{line}): save it as UTF-8", has_value=False) from None
    if path.suffix.lower() == ".urdf":
        return path  # XML: the URDF reader checks it
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(str(path), f"is not valid TOML: {exc}", has_value=False) from None
    except RecursionError:
        raise ConfigError(str(path), "nests arrays or tables too deeply to be a case file",
                          has_value=False) from None
    return path


def load_case(name_or_path: str | Path) -> dict:
    """Read a case file and check its ``[case]`` header (``name``, ``kind``)."""
    data = read_toml(case_path(name_or_path))
    header = require(data, "case", "")
    string(require(header, "name", "case"), "case.name")
    string(require(header, "kind", "case"), "case.kind")
    return data


# ---- serial chains ----------------------------------------------------------------------------

def chain_model(spec, field: str = "mechanism"):
    """A :class:`mechbal.ChainModel` from a :class:`mechbal.spec.MechanismSpec` that is a serial
    chain: moving joints one after the other, no gear coupling. Fixed joints are folded into the
    next joint's placement, and every body is merged into the one rigid body of the moving link
    that carries it (mass, centre of mass and inertia about it: exact for dynamics and momentum).
    Bodies on the base do not move and are left out. A tree or a gear coupling needs the general
    mechanism model: ConfigError naming it."""
    from mechbal._core import ChainModel, JointSpec, JointType

    from mechbal.spec import BASE

    by_name = {j.name: j for j in spec.joints}

    def moving_ancestor(name: str):
        """(the moving joint whose link carries the link of ``name``, or base; the transform
        from the link frame of ``name`` to that link's frame)."""
        T = np.eye(4)
        while name != BASE and by_name[name].type == "fixed":
            T = by_name[name].placement @ T
            name = by_name[name].parent
        return name, T

    moving = [j for j in spec.joints if j.type != "fixed"]
    if not moving:
        raise ConfigError(f"{field}.joints", "needs at least one moving joint", has_value=False)
    origins = []
    for k, j in enumerate(moving):
        if j.mimic is not None:
            raise ConfigError(f"{field}.joints", f"joint {j.name!r} is gear-coupled (mimic of "
                              f"{j.mimic[0]!r}): this runner takes serial chains; gear couplings "
                              f"need the general mechanism model", has_value=False)
        ancestor, T = moving_ancestor(j.parent)
        expected = moving[k - 1].name if k > 0 else BASE
        if ancestor != expected:
            raise ConfigError(f"{field}.joints", f"joint {j.name!r} branches from {ancestor!r}, not "
                              f"from {expected!r}: this runner takes serial chains; trees need the "
                              f"general mechanism model", has_value=False)
        origins.append(T @ j.placement)
    parts: dict[str, list] = {j.name: [] for j in moving}
    for b in spec.bodies:
        ancestor, T = moving_ancestor(b.link)
        if ancestor == BASE:
            continue  # does not move: no momentum, no torque
        R = T[:3, :3]
        parts[ancestor].append((b.mass, R @ b.com + T[:3, 3], R @ b.inertia @ R.T))
    specs = []
    for j, origin in zip(moving, origins):
        mass, com, inertia = _merge_bodies(parts[j.name])
        specs.append(JointSpec(j.name, JointType.revolute if j.type == "revolute" else JointType.prismatic,
                               origin, j.axis, mass, com, inertia))
    return ChainModel(specs, spec.gravity, np.eye(4))


def _merge_bodies(parts):
    """(mass, com, inertia about com) of rigid bodies on one link (same frame)."""
    if not parts:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    if len(parts) == 1:
        return parts[0]
    mass = sum(m for m, _, _ in parts)
    com = sum(m * c for m, c, _ in parts) / mass if mass > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for m, c, I in parts:
        d = c - com
        inertia += I + m * (d @ d * np.eye(3) - np.outer(d, d))
    return float(mass), com, 0.5 * (inertia + inertia.T)


def chain_from_config(table: Mapping[str, Any], field: str = "mechanism"):
    """Build a :class:`mechbal.ChainModel` from a ``[mechanism]`` table (the format of
    :mod:`mechbal.spec`: each ``[[mechanism.joints]]`` has ``name``, ``type``, ``axis`` (default
    [0, 0, 1], in the joint frame) and one of ``origin = {xyz, rpy}``, ``mdh = {a, alpha, d,
    theta}`` (modified DH) or ``dh = {...}`` (standard DH), and ``link = {mass, com, inertia}``
    with com and inertia (about the centre of mass) in the link frame (for ``dh``: in the standard
    DH frame of the link, converted here)). The table must describe a serial chain."""
    from mechbal.spec import mechanism_spec

    return chain_model(mechanism_spec(table, field), field)


def trajectory_from_config(table: Any, dof: int, field: str = "trajectory"):
    """A :class:`mechbal.RestToRestTrajectory` and the sample times from a ``[trajectory]`` table
    (a dict or a validated :class:`mechbal.schema.ChainTrajectory`) with ``law`` (quintic |
    cubic), ``start``, ``end`` (``dof`` values), ``duration`` [s] and ``samples`` (number of
    instants, 3 .. 1e6)."""
    from mechbal._core import RestToRestTrajectory, TimeLaw

    from mechbal.schema import ChainTrajectory, validate_table

    tr = table if isinstance(table, ChainTrajectory) else validate_table(ChainTrajectory, table, field)
    for key in ("start", "end"):
        v = getattr(tr, key)
        if len(v) != dof:
            raise ConfigError(f"{field}.{key}", f"must have {dof} values", v)
    traj = RestToRestTrajectory(np.array(tr.start, float), np.array(tr.end, float), tr.duration,
                                getattr(TimeLaw, tr.law))
    return traj, np.linspace(0.0, tr.duration, tr.samples)
