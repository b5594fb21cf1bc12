"""Write a mechanism as a case file (TOML): the files of the core's objects, as URDF and MJCF.

* `toml_text`: a small TOML writer for case data (tables, arrays of tables, inline tables
  inside them, numbers written to round-trip exactly, strings, booleans, arrays).
* `mechanism_table`: the ``[mechanism]`` table of a `mechbal.Mechanism` from its
  model (joints as ``origin = {xyz, rpy}`` + ``axis`` in the parent link's frame, limits, gears,
  every body with its centre of mass and full inertia in its link frame (the named form
  ``{ixx, iyy, izz, ixy, ixz, iyz}``), frames, loops, springs).
  The root link is written ``base`` (a URDF's may be ``world``); a frame named ``base`` (a URDF
  link of that name) is written ``base_frame``, since ``base`` is the TOML format's fixed base.
* `case_text`: a complete, commented case file of a mechanism (``[case]``, ``[mechanism]``,
  ``[trajectory]``, and a commented ``[control]`` to start from): `mechbal.Mechanism.to_toml`,
  ``mechbal init --from robot.urdf``.
* `urdf_text`: URDF of a tree without springs, `mechbal.export.urdf.urdf_text`
  (imported here for the callers of this module).

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from mechbal import _core
from mechbal.export.common import merged_inertial, rpy_of  # noqa: F401  (shared with the exporters)
from mechbal.export.urdf import urdf_text  # noqa: F401  (its home: mechbal.export.urdf)

_BARE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _string(s: str) -> str:
    """A TOML basic string holding ``s`` exactly: the quote, the backslash and every control
    character (U+0000..U+001F, U+007F) escaped; the one string writer of every TOML mechbal writes
    (case files, balanced.toml, the papers' generated cases). A lone surrogate, which no TOML
    string can hold, is a ValueError."""
    out = ['"']
    for ch in str(s):
        c = ord(ch)
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif c < 0x20 or c == 0x7F:
            out.append(f"\\u{c:04X}")
        elif 0xD800 <= c <= 0xDFFF:
            raise ValueError(f"TOML: cannot write the lone surrogate U+{c:04X} in a string")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _key(k: str) -> str:
    return k if k and set(k) <= _BARE else _string(k)


def _value(v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if not math.isfinite(x):
            raise ValueError(f"TOML: cannot write the non-finite number {x}")
        return repr(x)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, np.ndarray):
        return _value(v.tolist())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items() if x is not None) + " }"
    raise TypeError(f"TOML: cannot write a {type(v).__name__}")


def _is_table_array(v: Any) -> bool:
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, Mapping) for x in v)


def _table(lines: list[str], path: list[str], table: Mapping[str, Any], array: bool = False) -> None:
    scalars = [(k, v) for k, v in table.items()
               if v is not None and not (isinstance(v, Mapping) and not array) and not _is_table_array(v)]
    if path:
        lines.append("")
        name = ".".join(_key(p) for p in path)
        lines.append(f"[[{name}]]" if array else f"[{name}]")
    for k, v in scalars:
        lines.append(f"{_key(k)} = {_value(v)}")
    for k, v in table.items():
        if isinstance(v, Mapping) and not array:
            _table(lines, path + [k], v)
        elif _is_table_array(v):
            for item in v:
                _table(lines, path + [k], item, array=True)


def toml_text(data: Mapping[str, Any], header: str = "") -> str:
    """TOML text of ``data`` (what `tomllib.loads` reads back equal); ``header``: comment
    lines put first."""
    lines = [f"# {h}" if h else "#" for h in header.splitlines()] if header else []
    _table(lines, [], data)
    text = "\n".join(lines).lstrip("\n") + "\n"
    return text


# ---- Mechanism -> [mechanism] ----------------------------------------------------------------------



def inertia_table(I: np.ndarray) -> dict[str, float]:
    """The named form of an inertia, ``{ixx, iyy, izz, ixy, ixz, iyz}`` (what both case readers
    take; docs/case_format.md)."""
    I = np.asarray(I, float)
    return {"ixx": float(I[0, 0]), "iyy": float(I[1, 1]), "izz": float(I[2, 2]),
            "ixy": float(I[0, 1]), "ixz": float(I[0, 2]), "iyz": float(I[1, 2])}


_TYPES = {_core.JointType.revolute: "revolute", _core.JointType.prismatic: "prismatic",
          _core.JointType.fixed: "fixed"}


def mechanism_table(mech) -> dict:
    """The ``[mechanism]`` table of ``mech`` (see the module docstring)."""
    d = mech.model.description
    root = d.root_name

    def link_name(link: str) -> str:  # the TOML format calls the root 'base' (a URDF's may be 'world')
        return "base" if link == root else link

    joints = []
    for j in d.joints:
        T = np.asarray(j.placement)
        entry: dict[str, Any] = {"name": j.name, "type": _TYPES[j.type], "parent": link_name(j.parent),
                                 "origin": {"xyz": T[:3, 3].tolist(), "rpy": rpy_of(T[:3, :3])}}
        if j.type != _core.JointType.fixed:
            entry["axis"] = np.asarray(j.axis, float).tolist()
            lim = {k: float(v) for k, v in (("lower", j.lower), ("upper", j.upper),
                                            ("velocity", j.velocity_limit), ("effort", j.effort_limit))
                   if math.isfinite(v)}
            if lim:
                entry["limits"] = lim
            if j.mimic_joint:
                entry["mimic"] = {"joint": j.mimic_joint, "ratio": float(j.mimic_ratio), "offset": float(j.mimic_offset)}
        joints.append(entry)
    bodies = [{"name": b.name, "kind": b.kind if b.kind in ("link", "counterweight", "motor", "disc", "payload")
               else "other", "link": link_name(b.link), "mass": float(b.mass), "com": np.asarray(b.com, float).tolist(),
               "inertia": inertia_table(b.inertia)} for b in d.bodies]
    frames = []
    for f in d.frames:
        T = np.asarray(f.placement)
        frames.append({"name": "base_frame" if f.name == "base" else f.name, "link": link_name(f.link), "origin": {"xyz": T[:3, 3].tolist(), "rpy": rpy_of(T[:3, :3])}})
    out: dict[str, Any] = {"gravity": np.asarray(d.gravity, float).tolist(), "joints": joints}
    if bodies:
        out["bodies"] = bodies
    if frames:
        out["frames"] = frames
    springs = list(d.springs)
    if springs:
        out["springs"] = [{"name": sp.name,
                           "link_a": "base" if sp.link_a == root else sp.link_a,
                           "anchor_a": np.asarray(sp.anchor_a, float).tolist(),
                           "link_b": "base" if sp.link_b == root else sp.link_b,
                           "anchor_b": np.asarray(sp.anchor_b, float).tolist(),
                           "rate": float(sp.rate), "free_length": float(sp.free_length),
                           "preload": float(sp.preload), "count": int(sp.count),
                           "pulley_ratio": float(sp.pulley_ratio)} for sp in springs]
    loops = list(d.loops)
    if loops:
        names = {_core.LoopType.point: "point", _core.LoopType.planar_point: "planar_point",
                 _core.LoopType.axis: "axis", _core.LoopType.weld: "weld"}
        out["loops"] = [{"name": lp.name, "type": names[lp.type], "frame_a": lp.frame_a, "frame_b": lp.frame_b}
                        for lp in loops]
        out["actuated"] = list(d.actuated)
    return out


# ---- a whole case -----------------------------------------------------------------------------

def _case_name(name: str) -> str:
    """A [case] name from a robot's or a file's name: letters, digits, '-' and '_' kept."""
    out = "".join(c if c.isalnum() or c in "-_" else "-" for c in name).strip("-")
    return out[:128] or "mechanism"


def case_text(mech, *, name: str | None = None, title: str | None = None,
              trajectory: Mapping[str, Any] | None = None, source: str | None = None) -> str:
    """A complete case file (``kind = "mechanism"``) of ``mech``: what `mechbal.Mechanism.to_toml`
    and ``mechbal init --from`` write.

    ``[mechanism]`` is `mechanism_table` (every number written to round-trip exactly: the file
    reads back as the same model). ``[trajectory]``: ``trajectory`` when given (a table as a case
    file holds it), else the default motion of an open mechanism (`mechbal.trajectory.default_motion`,
    lengthened where the joints' velocity or effort limits need it:
    `mechbal.trajectory.quintic_within_limits`); a closed mechanism needs ``trajectory``
    (ValueError otherwise). Comments say what each table is and end with a ``[control]`` to start
    from (commented out)."""
    from mechbal.trajectory import default_motion, quintic_within_limits

    name = _case_name(name or mech.name)
    title = title if title is not None else f"{mech.name}" + (f" ({Path(source).name})" if source else "")
    if trajectory is None:
        if mech.is_closed:
            raise ValueError("to_toml: a closed mechanism has no default motion: give trajectory="
                             "{'law': 'quintic', 'start': [...], 'end': [...], 'duration': ...}")
        start, end = default_motion(mech)
        duration, _ = quintic_within_limits(mech, start, end, 2.0)
        trajectory = {"law": "quintic", "start": [float(x) for x in start], "end": [float(x) for x in end],
                      "duration": float(duration), "samples": 501}
    actuated = list(mech.actuated_names)
    frames = list(mech.frame_names)
    parts = [toml_text({"case": {"name": name, "kind": "mechanism", "title": title}}, header=(
        f"{name}: a mechbal case" + (f" written from {Path(source).name}" if source else "") + "\n"
        "(mechbal init --from, Mechanism.to_toml). Run it:  mechbal run THIS.toml --out out/" + name + "\n"
        "SI units, angles in radians; docs/case_format.md describes every key.")).rstrip("\n")]
    parts.append("\n# [mechanism]: the model as mechbal read it. Joints: origin = {xyz, rpy} in the parent\n"
                 "# link's frame, axis, limits (lower, upper [rad or m], velocity, effort). Bodies: mass [kg],\n"
                 "# centre of mass [m] and inertia about it [kg m^2] in their link's frame. Frames: named\n"
                 "# points a controller or a loop may use (task_frame).")
    parts.append(toml_text({"mechanism": mechanism_table(mech)}).rstrip("\n"))
    parts.append("\n# [trajectory]: the actuated joints from start to end [rad or m] in duration [s], one value\n"
                 "# per actuated joint in the order of [mechanism.joints]. Instead, law = \"line\" moves a frame\n"
                 "# (the [control] task_frame) by displacement = [dx, dy, dz] (m, O axes) and / or\n"
                 "# rotation = [rx, ry, rz] (rad) from its pose at start (no end).")
    parts.append(toml_text({"trajectory": dict(trajectory)}).rstrip("\n"))
    tool = frames[-1] if frames else "TOOL_FRAME"
    control = [
        "",
        "# [control]: what runs along [trajectory] (mechbal run / verify). Uncomment one of:",
        "# no controller, the mechanism let go from start (gravity, springs; the joint limits are stops):",
        "# [control]",
        '# kind = "passive"',
        "# or the reactionless controller: the tool frame on a line, every joint moving so that the",
        "# shaking moment about z stays cancelled (law = \"line\" above, displacement = [0.03, 0.0, 0.0]):",
        "# [control]",
        '# kind = "reactionless"',
        f"# task_frame = {_value(tool)}",
        '# task_rows = ["linear"]',
        f"# balancing_joints = {_value(actuated)}",
        '# cancel = ["moment_z"]',
    ]
    return "\n".join(parts) + "\n" + "\n".join(control) + "\n"
