"""Configuration: TOML files -> validated models.

The schema of every case file is in `mechbal.schema` (pydantic models, strict: unknown keys
are errors); `mechbal.schema.validate_case` checks a whole file before anything runs. Every
error is a `ConfigError` naming the offending field by its dotted path (for example
``mechanism.joints[1].link.mass``) and the value found, and nothing is half-built: models are only
constructed once every field has been read and checked. The helpers here (``number``, ``vector``,
...) remain for code that checks values outside case files.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import math
import os
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


def inertia(value: Any, field: str) -> np.ndarray:
    """An inertia tensor about the centre of mass [kg m^2]: a 3x3 list, three principal moments
    [Ixx, Iyy, Izz], or six values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]. Must be symmetric positive
    semi-definite and satisfy the triangle inequality of a physical body
    (`mechbal.schema.inertia_matrix`)."""
    from pydantic_core import PydanticCustomError

    from mechbal.schema import inertia_matrix

    try:
        return inertia_matrix(value)
    except PydanticCustomError as exc:
        ctx = exc.context or {}
        v = ctx.get("value")
        raise ConfigError(field + ctx.get("sub", ""), ctx.get("message", exc.message()),
                          value if v is None else v) from None


#: refuse case files larger than this (a case is a few kB; anything huge is a mistake)
MAX_CASE_BYTES = 4 * 1024 * 1024
#: refuse case files whose tables and arrays nest deeper than this (a case needs a handful)
MAX_CASE_DEPTH = 32


def read_regular_file(path: str | Path, field: str = "case", max_bytes: int = MAX_CASE_BYTES) -> bytes:
    """The bytes of ``path`` if it is a regular file of at most ``max_bytes``; otherwise a
    `ConfigError` naming ``field`` and the path, at once: a folder, a device (``/dev/zero``
    would be read forever), a FIFO (would block), a socket, a missing or unreadable file. The file
    is opened without blocking and checked on the open descriptor (no race with a rename)."""
    import stat

    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise ConfigError(field, "file not found", str(path)) from None
    except IsADirectoryError:
        raise ConfigError(field, "is a folder, not a file", str(path)) from None
    except OSError as exc:
        raise ConfigError(field, f"cannot be read: {exc.strerror or exc}", str(path)) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise ConfigError(field, "is a folder, not a file", str(path))
        if not stat.S_ISREG(st.st_mode):
            raise ConfigError(field, "is not a regular file (a device, pipe or socket)", str(path))
        if st.st_size > max_bytes:
            raise ConfigError(field, f"is {st.st_size} bytes, more than such a file can be "
                                     f"({max_bytes} bytes)", str(path))
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            total += len(chunk)
            if total > max_bytes:  # grew while being read
                raise ConfigError(field, f"is more than {max_bytes} bytes", str(path))
            chunks.append(chunk)
        return b"".join(chunks)
    except OSError as exc:
        raise ConfigError(field, f"cannot be read: {exc.strerror or exc}", str(path)) from None
    finally:
        os.close(fd)


def _nesting_depth(node: Any) -> int:
    """Deepest nesting of dicts and lists (iterative: any depth)."""
    deepest, stack = 0, [(node, 1)]
    while stack:
        x, d = stack.pop()
        if isinstance(x, dict):
            x = list(x.values())
        if isinstance(x, list):
            deepest = max(deepest, d)
            if d <= MAX_CASE_DEPTH + 1:
                stack.extend((v, d + 1) for v in x if isinstance(v, (dict, list)))
    return deepest


def parse_toml(raw: bytes, source: str) -> dict:
    """A TOML document (bytes of ``source``) as a dict, or a one-line `ConfigError`: not
    UTF-8 (names the line), invalid TOML, nested deeper than `MAX_CASE_DEPTH`."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ConfigError(source, f"is not UTF-8 text (byte 0x{raw[exc.start]:02x} on line "
                                  f"{line}): save it as UTF-8", has_value=False) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(source, f"is not valid TOML: {exc}", has_value=False) from None
    except RecursionError:
        data = None
    if data is None or _nesting_depth(data) > MAX_CASE_DEPTH:
        raise ConfigError(source, f"nests arrays or tables more than {MAX_CASE_DEPTH} deep, too "
                                  "deeply to be a case file", has_value=False)
    return data


def read_toml(path: str | Path) -> dict:
    """A TOML case file as a dict: a regular file of at most `MAX_CASE_BYTES`, UTF-8, valid
    TOML nested at most `MAX_CASE_DEPTH` deep; anything else is a `ConfigError`."""
    path = Path(path)
    return parse_toml(read_regular_file(path, "case"), str(path))


def builtin_cases() -> dict[str, Path]:
    """Every built-in case file by name: the general cases and each paper's (the registry's
    folders, `mechbal.registry`)."""
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


def check_case_file(name_or_path: str) -> Path:
    """Path of the case after the checks that the TOML reader does not do: a regular file, not a
    folder, of reasonable size, UTF-8 text, valid TOML of reasonable nesting (raises
    `ConfigError` naming the path)."""
    import mechbal._core as _core

    path = case_path(name_or_path)  # ConfigError for an unknown built-in name or a missing file
    if path.suffix.lower() == ".urdf":
        read_regular_file(path, "case", _core.MAX_URDF_BYTES)
        return path  # XML: the URDF reader checks the rest
    parse_toml(read_regular_file(path, "case", MAX_CASE_BYTES), str(path))
    return path


def read_case(name_or_path: str | Path) -> dict:
    """The tables of a case file (a built-in case's name or a path) as a dict, its ``[case]``
    header's ``name`` and ``kind`` checked; the case itself: `mechbal.case.load_case`."""
    data = read_toml(case_path(name_or_path))
    header = require(data, "case", "")
    string(require(header, "name", "case"), "case.name")
    string(require(header, "kind", "case"), "case.kind")
    return data


def trajectory_from_config(table: Any, dof: int, field: str = "trajectory"):
    """The trajectory and the sample times from a ``[trajectory]`` table (a dict or a validated
    `mechbal.schema.ChainTrajectory`): ``law = "quintic" | "cubic"``, ``start``, ``end``
    (``dof`` values), ``duration`` [s]: a `mechbal.RestToRestTrajectory`; ``law =
    "constant_speed"``, ``start``, ``speed`` [rad/s] or ``rpm`` (one number or ``dof``), and
    ``duration`` [s] or ``revolutions``: a `mechbal.trajectory.ConstantSpeed`. ``samples``
    instants (3 .. 1e6) over ``[0, duration]``."""
    from mechbal._core import RestToRestTrajectory, TimeLaw

    from mechbal.schema import ChainTrajectory, validate_table
    from mechbal.trajectory import ConstantSpeed

    tr = table if isinstance(table, ChainTrajectory) else validate_table(ChainTrajectory, table, field)
    if tr.law == "min_shaking":
        raise ConfigError(f"{field}.law", "'min_shaking' is a planned motion: `mechbal run` plans it "
                                          "(mechbal.plan.min_shaking); this command needs a fixed law "
                                          "(quintic, cubic, constant_speed)", tr.law)
    if tr.law == "line":
        raise ConfigError(f"{field}.law", "'line' is the path of the [control] task_frame (the reactionless "
                          "controller's operational-space mode), not a motion of the joints: give task_frame, "
                          "or a joint-space law (quintic, cubic) with end", "line")
    keys = ("start", "speed", "rpm") if tr.law == "constant_speed" else ("start", "end")
    for key in keys:
        v = getattr(tr, key)
        if isinstance(v, list) and len(v) != dof:
            raise ConfigError(f"{field}.{key}", f"must have {dof} values" + (
                " (or one number for every joint)" if key in ("speed", "rpm") else ""), v)
    duration = tr.motion_duration()
    if tr.law == "constant_speed":
        traj = ConstantSpeed(np.array(tr.start, float), np.array(tr.speeds(dof), float), duration)
    else:
        traj = RestToRestTrajectory(np.array(tr.start, float), np.array(tr.end, float), duration,
                                    getattr(TimeLaw, tr.law))
    return traj, np.linspace(0.0, duration, tr.samples)


def law_name(traj: Any) -> str:
    """The time law of a trajectory from `trajectory_from_config` (summary.json's ``law``)."""
    law = traj.law
    return law if isinstance(law, str) else str(law.name)
