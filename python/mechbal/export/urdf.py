"""URDF of a mechanism URDF can describe: a tree without springs.

* One ``<link>`` per mechbal link, named as `mechbal.export.common.link_labels` says (a
  URDF read by mechbal keeps its link names, its root included), its bodies merged into one
  ``<inertial>`` (exact for the dynamics; a body of zero mass keeps its rotational inertia, as a
  disc's rotor does).
* Joints ``revolute`` (``continuous`` without limits), ``prismatic``, ``fixed``, with their names,
  origins, axes and limits; gears as ``<mimic>``.
* A body besides its link's own (a counterweight, a disc, a URDF's ``base_link`` on the root)
  gets a ``<link>`` of its name fixed to its link (``<body>_fixed``), so that names and bodies
  come back from mechbal's URDF reader as they were; where that name is taken, it is merged into
  its link's ``<inertial>``.
* Every named frame that is not a link's name becomes a ``<link>`` of its own joined to its link
  by a fixed joint ``<frame>_fixed`` (URDF's way of naming a frame: ``tool0``, ``ee_link``).
* URDF has no gravity: the mechanism's is written in a comment.

A closed mechanism or one with springs raises `ExportError` (one
line), since a URDF would silently drop the loops or the springs; write MJCF or TOML instead.
"""
from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from mechbal import _core
from mechbal.export.common import ExportError, inertia_is_zero, link_labels, merged_inertial, rpy_of

__all__ = ["urdf_text", "urdf_refusal", "ExportError"]

_TYPES = {_core.JointType.revolute: "revolute", _core.JointType.prismatic: "prismatic",
          _core.JointType.fixed: "fixed"}


def _f(x: float) -> str:
    return repr(float(x))


def _v(x) -> str:
    return " ".join(_f(v) for v in x)


def urdf_refusal(mech) -> str | None:
    """Why URDF cannot describe ``mech`` (one line), or None when it can."""
    why = []
    if mech.is_closed:
        why.append(f"{len(list(mech.model.description.loops))} loop closure(s)")
    if mech.springs:
        why.append(f"{len(mech.springs)} spring(s)")
    if not why:
        return None
    return (f"URDF describes trees without springs: {mech.name} has " + " and ".join(why)
            + ", which a URDF would silently drop (write MJCF or TOML)")


def urdf_text(mech, name: str | None = None) -> str:
    """URDF of ``mech`` (see the module docstring); ExportError for loops or springs."""
    why = urdf_refusal(mech)
    if why:
        raise ExportError(why)
    d = mech.model.description
    labels = link_labels(mech)
    g = np.asarray(d.gravity, float)
    out = ['<?xml version="1.0"?>',
           f"<!-- written by mechbal; gravity {_v(g)} m/s^2 in the base frame (URDF has no gravity) -->",
           f"<robot name={quoteattr(name or mech.name)}>"]
    identity = np.eye(4)
    place: dict[str, tuple[str, bool]] = {labels[n]: (n, True) for n in labels}  # URDF link -> (link, identity)
    inertial: dict[str, list] = {n: [] for n in labels}
    body_links: list[tuple[str, object]] = []   # bodies with a URDF link of their own
    frame_at = {f.name: f for f in d.frames}
    for b in d.bodies:
        own = b.name == labels[b.link]
        if not own and b.name not in place and not inertia_is_zero(b):
            f = frame_at.get(b.name)
            if f is None or (f.link == b.link and np.array_equal(np.asarray(f.placement, float), identity)):
                place[b.name] = (b.link, True)
                body_links.append((b.name, b))
                continue
        inertial[b.link].append(b)

    def link(n: str, bodies) -> None:
        m, c, I = merged_inertial(bodies)
        if not bodies or (m == 0.0 and not np.any(I)):
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

    def joint(jname: str, typ: str, parent: str, child: str, T: np.ndarray) -> None:
        out.append(f"  <joint name={quoteattr(jname)} type=\"{typ}\">")
        out.append(f"    <parent link={quoteattr(parent)}/>")
        out.append(f"    <child link={quoteattr(child)}/>")
        out.append(f'    <origin xyz="{_v(T[:3, 3])}" rpy="{_v(rpy_of(T[:3, :3]))}"/>')

    used_joints = {j.name for j in d.joints}

    def fixed_name(base: str) -> str:
        n = base
        while n in used_joints:
            n += "_"
        used_joints.add(n)
        return n

    link(labels[d.root_name], inertial[d.root_name])
    for j in d.joints:
        link(labels[j.name], inertial[j.name])
        T = np.asarray(j.placement)
        typ = _TYPES[j.type]
        bounded = math.isfinite(j.lower) and math.isfinite(j.upper)
        if typ == "revolute" and not bounded:
            typ = "continuous"
        joint(j.name, typ, labels[j.parent], labels[j.name], T)
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
    # bodies beside their link's own: a URDF link each, fixed to their link
    for n, b in body_links:
        link(n, [b])
        joint(fixed_name(f"{n}_fixed"), "fixed", labels[b.link], n, identity)
        out.append("  </joint>")
    # frames that are not yet a URDF link at their place: a link of their own on a fixed joint
    for f in d.frames:
        T = np.asarray(f.placement, float)
        if place.get(f.name) == (f.link, True) and np.array_equal(T, identity):
            continue
        fname = f.name
        while fname in place:
            fname += "_frame"
        place[fname] = (f.link, False)
        out.append(f"  <link name={quoteattr(fname)}/>")
        joint(fixed_name(f"{fname}_fixed"), "fixed", labels[f.link], fname, T)
        out.append("  </joint>")
    out.append("</robot>")
    return "\n".join(out) + "\n"
