"""Write a (balanced) mechanism back as a case file: TOML (any mechanism) and URDF (trees).

* :func:`toml_text`: a small TOML writer for case data (tables, arrays of tables, inline tables
  inside them, numbers written to round-trip exactly, strings, booleans, arrays).
* :func:`mechanism_table`: the ``[mechanism]`` table of a :class:`mechbal.Mechanism` from its
  model (joints as ``origin = {xyz, rpy}`` + ``axis`` in the parent link's frame, limits, gears,
  every body with its centre of mass and full inertia in its link frame, frames, loops, springs).
  The root link is written ``base`` (a URDF's may be ``world``); a frame named ``base`` (a URDF
  link of that name) is written ``base_frame``, since ``base`` is the TOML format's fixed base.
* :func:`urdf_text`: URDF of a mechanism without loops: one ``<link>`` per joint (named after
  it, as mechbal names links), its bodies merged into one ``<inertial>`` (exact for dynamics),
  joints ``revolute`` (``continuous`` without limits), ``prismatic``, ``fixed``, gears as
  ``<mimic>``. URDF has no gravity: the mechanism's is written in a comment.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import json
import math
from typing import Any, Mapping

import numpy as np

from mechbal import _core

_BARE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


def _key(k: str) -> str:
    return k if k and set(k) <= _BARE else json.dumps(k)


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
        return json.dumps(v, ensure_ascii=False)
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
    """TOML text of ``data`` (what :func:`tomllib.loads` reads back equal); ``header``: comment
    lines put first."""
    lines = [f"# {h}" if h else "#" for h in header.splitlines()] if header else []
    _table(lines, [], data)
    text = "\n".join(lines).lstrip("\n") + "\n"
    return text


# ---- Mechanism -> [mechanism] ----------------------------------------------------------------------

def rpy_of(R: np.ndarray) -> list[float]:
    """Roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll) (mechbal and URDF's convention)."""
    R = np.asarray(R, float)
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    if abs(R[2, 0]) < 1.0 - 1e-12:
        roll, yaw = math.atan2(R[2, 1], R[2, 2]), math.atan2(R[1, 0], R[0, 0])
    else:  # gimbal lock: roll and yaw turn about the same axis
        roll, yaw = 0.0, math.atan2(-R[0, 1], R[1, 1])
    return [roll, pitch, yaw]


def _inertia6(I: np.ndarray) -> list[float]:
    I = np.asarray(I, float)
    return [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]


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
               "inertia": _inertia6(b.inertia)} for b in d.bodies]
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


# ---- URDF -----------------------------------------------------------------------------------------

def _f(x: float) -> str:
    return repr(float(x))


def _v(x) -> str:
    return " ".join(_f(v) for v in x)


def merged_inertial(bodies) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it) of bodies on one link, in the link frame."""
    m = sum(float(b.mass) for b in bodies)
    if m <= 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    c = sum(float(b.mass) * np.asarray(b.com, float) for b in bodies) / m
    I = np.zeros((3, 3))
    for b in bodies:
        r = np.asarray(b.com, float) - c
        I += np.asarray(b.inertia, float) + float(b.mass) * (r @ r * np.eye(3) - np.outer(r, r))
    return m, c, 0.5 * (I + I.T)


def urdf_text(mech, name: str | None = None) -> str:
    """URDF of a mechanism without loops (ValueError for a closed one)."""
    from xml.sax.saxutils import quoteattr

    if mech.is_closed:
        raise ValueError("URDF describes trees only: this mechanism has loop closures (write TOML)")
    if mech.springs:
        raise ValueError("URDF has no springs: this mechanism has springs, which a URDF would silently "
                         "drop (write TOML)")
    d = mech.model.description
    g = np.asarray(d.gravity, float)
    out = ['<?xml version="1.0"?>',
           f"<!-- written by mechbal; gravity {_v(g)} m/s^2 in the base frame (URDF has no gravity) -->",
           f"<robot name={quoteattr(name or mech.name)}>"]
    by_link: dict[str, list] = {}
    for b in d.bodies:
        by_link.setdefault(b.link, []).append(b)

    def link(n: str) -> None:
        m, c, I = merged_inertial(by_link.get(n, []))
        if m <= 0.0:
            out.append(f"  <link name={quoteattr(n)}/>")
            return
        out.extend([f"  <link name={quoteattr(n)}>",
                "    <inertial>",
                f'      <origin xyz="{_v(c)}" rpy="0 0 0"/>',
                f'      <mass value="{_f(m)}"/>',
                f'      <inertia ixx="{_f(I[0, 0])}" ixy="{_f(I[0, 1])}" ixz="{_f(I[0, 2])}" '
                f'iyy="{_f(I[1, 1])}" iyz="{_f(I[1, 2])}" izz="{_f(I[2, 2])}"/>',
                "    </inertial>",
                "  </link>"])

    link(d.root_name)
    for j in d.joints:
        link(j.name)
        T = np.asarray(j.placement)
        typ = _TYPES[j.type]
        bounded = math.isfinite(j.lower) and math.isfinite(j.upper)
        if typ == "revolute" and not bounded:
            typ = "continuous"
        out.append(f"  <joint name={quoteattr(j.name)} type=\"{typ}\">")
        out.append(f"    <parent link={quoteattr(j.parent)}/>")
        out.append(f"    <child link={quoteattr(j.name)}/>")
        out.append(f'    <origin xyz="{_v(T[:3, 3])}" rpy="{_v(rpy_of(T[:3, :3]))}"/>')
        if typ != "fixed":
            out.append(f'    <axis xyz="{_v(j.axis)}"/>')
            attrs = []
            if typ != "continuous":
                lo = j.lower if math.isfinite(j.lower) else -1e9
                hi = j.upper if math.isfinite(j.upper) else 1e9
                attrs += [f'lower="{_f(lo)}"', f'upper="{_f(hi)}"']
            attrs.append(f'effort="{_f(j.effort_limit if math.isfinite(j.effort_limit) else 0.0)}"')
            attrs.append(f'velocity="{_f(j.velocity_limit if math.isfinite(j.velocity_limit) else 0.0)}"')
            out.append(f"    <limit {' '.join(attrs)}/>")
            if j.mimic_joint:
                out.append(f"    <mimic joint={quoteattr(j.mimic_joint)} multiplier=\"{_f(j.mimic_ratio)}\" "
                           f"offset=\"{_f(j.mimic_offset)}\"/>")
        out.append("  </joint>")
    out.append("</robot>")
    return "\n".join(out) + "\n"
