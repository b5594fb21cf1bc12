"""Write a `mechbal.Mechanism` as a ``kind = "mechanism"`` case file (the TOML format of
docs/case_format.md): how the papers' generated mechanisms become shipped data.

Every joint is written with its parent, ``origin = {xyz, rpy}``, ``axis`` and ``mimic`` (the
format's defaults left out: type revolute, the previous joint as parent, an identity origin); every
body as a ``[[mechanism.bodies]]`` table (in the model's order, so body names and order survive
the round trip), frames, loops and the actuated joints. Numbers are written with ``repr`` (exact
round trip of the floats); rotations go through roll-pitch-yaw, so a placement read back differs
from the original by rounding (~1e-16) only. tests/python/test_papers_loops.py checks that the
shipped files equal what the generators produce.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from mechbal import _core
from mechbal.export.toml import _string as _str  # the one TOML string writer

__all__ = ["rpy_of", "case_toml"]

#: the JSON Schema (python/mechbal/cases/mechbal.schema.json) seen from a paper's cases/ folder
SCHEMA_FROM_PAPER_CASES = "../../../cases/mechbal.schema.json"

_TYPES = {_core.JointType.revolute: "revolute", _core.JointType.prismatic: "prismatic",
          _core.JointType.fixed: "fixed"}
_LOOPS = {_core.LoopType.point: "point", _core.LoopType.planar_point: "planar_point",
          _core.LoopType.axis: "axis", _core.LoopType.weld: "weld"}
_KINDS = ("link", "counterweight", "motor", "disc", "payload", "other")


def rpy_of(R: np.ndarray) -> tuple[float, float, float]:
    """Roll, pitch, yaw (fixed axes x, y, z: R = Rz(yaw) Ry(pitch) Rx(roll)) of a rotation."""
    R = np.asarray(R, float)
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    if abs(R[2, 0]) < 1.0 - 1e-12:
        roll = math.atan2(R[2, 1], R[2, 2])
        yaw = math.atan2(R[1, 0], R[0, 0])
    else:  # gimbal lock: only roll - yaw (or roll + yaw) is defined; take yaw = 0
        yaw = 0.0
        roll = math.atan2(-R[1, 2], R[1, 1])
    return roll, pitch, yaw


def _num(x: float) -> str:
    x = float(x)
    if x == 0.0:
        return "0.0"
    return repr(x)


def _vec(v) -> str:
    return "[" + ", ".join(_num(x) for x in np.asarray(v, float).ravel()) + "]"



def _origin(T: np.ndarray) -> str:
    T = np.asarray(T, float)
    rpy = rpy_of(T[:3, :3])
    if np.allclose(rpy, 0.0, atol=0.0):
        return "{ xyz = " + _vec(T[:3, 3]) + " }"
    return "{ xyz = " + _vec(T[:3, 3]) + ", rpy = " + _vec(rpy) + " }"


def _inertia(I: np.ndarray) -> str:
    I = np.asarray(I, float)
    if np.array_equal(I, np.diag(np.diag(I))):
        return _vec(np.diag(I))
    return "[" + ", ".join(_vec(row) for row in I) + "]"


def case_toml(mech, *, name: str, title: str, header: str, trajectory: Mapping[str, Any],
              comments: Mapping[str, str] | None = None) -> str:
    """The case file text of ``mech`` (``kind = "mechanism"``). ``header``: comment lines (without
    ``#``) at the top; ``trajectory``: the ``[trajectory]`` table (start, end, duration, samples,
    law, initial_guess); ``comments``: an end-of-line comment per joint, body, frame or loop name."""
    comments = dict(comments or {})
    d = mech.model.description
    out: list[str] = [f"#:schema {SCHEMA_FROM_PAPER_CASES}"]
    out += [("# " + line).rstrip() for line in header.strip("\n").splitlines()]
    out += ["[case]", f"name = {_str(name)}", 'kind = "mechanism"', f"title = {_str(title)}", ""]
    out += ["[mechanism]", f"gravity = {_vec(d.gravity)}"]
    out += ["actuated = [" + ", ".join(_str(a) for a in d.actuated) + "]", ""]

    def tail(key):
        c = comments.get(key)
        return f"   # {c}" if c else ""

    previous = "base"
    for j in d.joints:  # defaults left out: type revolute, parent the previous joint, origin identity
        out += ["[[mechanism.joints]]", f"name = {_str(j.name)}{tail(j.name)}"]
        if j.type != _core.JointType.revolute:
            out.append(f"type = {_str(_TYPES[j.type])}")
        if j.parent != previous:
            out.append(f"parent = {_str(j.parent)}")
        previous = j.name
        if not np.array_equal(np.asarray(j.placement), np.eye(4)):
            out.append(f"origin = {_origin(j.placement)}")
        if j.type != _core.JointType.fixed:
            out.append(f"axis = {_vec(j.axis)}")
        lim = {k: getattr(j, a) for k, a in (("lower", "lower"), ("upper", "upper"),
                                             ("velocity", "velocity_limit"), ("effort", "effort_limit"))}
        lim = {k: v for k, v in lim.items() if math.isfinite(v)}
        if lim:
            out.append("limits = { " + ", ".join(f"{k} = {_num(v)}" for k, v in lim.items()) + " }")
        if j.mimic_joint:
            out.append(f"mimic = {{ joint = {_str(j.mimic_joint)}, ratio = {_num(j.mimic_ratio)}, "
                       f"offset = {_num(j.mimic_offset)} }}")
        out.append("")
    for b in d.bodies:
        kind = b.kind if b.kind in _KINDS else "other"
        out += ["[[mechanism.bodies]]", f"name = {_str(b.name)}{tail(b.name)}", f"kind = {_str(kind)}",
                f"link = {_str(b.link)}", f"mass = {_num(b.mass)}"]
        if np.any(np.asarray(b.com) != 0.0):
            out.append(f"com = {_vec(b.com)}")
        out += [f"inertia = {_inertia(b.inertia)}", ""]
    for f in d.frames:
        out += ["[[mechanism.frames]]", f"name = {_str(f.name)}{tail(f.name)}", f"link = {_str(f.link)}",
                f"origin = {_origin(f.placement)}", ""]
    for lp in d.loops:
        out += ["[[mechanism.loops]]", f"name = {_str(lp.name)}{tail(lp.name)}",
                f"type = {_str(_LOOPS[lp.type])}", f"frame_a = {_str(lp.frame_a)}",
                f"frame_b = {_str(lp.frame_b)}", ""]
    out.append("[trajectory]")
    for key in ("law", "start", "end", "duration", "samples", "initial_guess"):
        if key not in trajectory:
            continue
        v = trajectory[key]
        if isinstance(v, str):
            out.append(f"{key} = {_str(v)}{tail('trajectory.' + key)}")
        elif isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            out.append(f"{key} = {int(v)}{tail('trajectory.' + key)}")
        elif np.ndim(v) == 0:
            out.append(f"{key} = {_num(v)}{tail('trajectory.' + key)}")
        else:
            out.append(f"{key} = {_vec(v)}{tail('trajectory.' + key)}")
    return "\n".join(out) + "\n"


def same_model(a, b, tol: float = 1e-12) -> list[str]:
    """Differences between two mechanisms' descriptions (names, structure, numbers to ``tol``):
    an empty list when they describe the same model."""
    da, db = a.model.description, b.model.description
    diff: list[str] = []

    def close(x, y):
        return np.allclose(np.asarray(x, float), np.asarray(y, float), rtol=0.0, atol=tol)

    def compare(what, xs: Sequence, ys: Sequence, fields):
        if [x.name for x in xs] != [y.name for y in ys]:
            diff.append(f"{what}: names differ")
            return
        for x, y in zip(xs, ys):
            for f in fields:
                vx, vy = getattr(x, f), getattr(y, f)
                ok = vx == vy if isinstance(vx, (str, _core.JointType, _core.LoopType)) else close(vx, vy)
                if not ok:
                    diff.append(f"{what} {x.name}.{f}: {vx!r} != {vy!r}")

    compare("joint", da.joints, db.joints, ("type", "parent", "placement", "axis", "mimic_joint",
                                            "mimic_ratio", "mimic_offset"))
    compare("body", da.bodies, db.bodies, ("kind", "link", "mass", "com", "inertia"))
    compare("frame", da.frames, db.frames, ("link", "placement"))
    compare("loop", da.loops, db.loops, ("type", "frame_a", "frame_b"))
    if list(da.actuated) != list(db.actuated):
        diff.append(f"actuated: {list(da.actuated)} != {list(db.actuated)}")
    if not close(da.gravity, db.gravity):
        diff.append("gravity differs")
    return diff
