"""A mechanism as plain data: `MechanismSpec`, built from a validated ``[mechanism]`` table.

This is what the general C++ ``MechanismModel`` is built from. Everything the TOML format lets a
user say in several ways is settled here:

* **Placements.** ``JointSpec.placement`` is the constant transform from the parent link's frame
  (the frame right after the parent joint's motion) to the joint frame at q = 0. For a root joint
  (parent ``base``) it is in O: ``mechanism.base`` composed with the joint's origin. The joint's
  ``origin = {xyz, rpy}``, ``mdh = {a, alpha, d, theta}`` (modified DH: Rx(alpha) Tx(a) Tz(d)
  Rz(theta)) or ``dh = {...}`` (standard DH: Rz(theta) before the joint, Tz(d) Tx(a) Rx(alpha)
  after it) becomes one placement: the standard-DH part after a joint (its *carry*) is moved into
  the placement of every child joint, and applied to every body and frame the user put on that
  link, so that the link frame is always the frame right after the joint's motion.
* **Bodies.** A joint's ``link = {mass, com, inertia}`` becomes a body named after the joint, kind
  ``link``; ``[[mechanism.bodies]]`` are added as given. Every body's centre of mass and inertia
  (about the centre of mass) are in its link's frame (``rpy`` and DH frames already applied); a
  body on ``base`` is in O (``mechanism.base`` applied).
* **Springs.** ``[[mechanism.springs]]`` anchors are given like a body's ``com``: in the frame
  the user described the link in (DH frame, ``mechanism.base`` for ``base``), moved here into the
  link frame (`SpringSpec`).
* **Spherical joints** become three revolute joints about z, y and x of the joint frame, named
  ``<name>_z``, ``<name>_y``, ``<name>_x``; the link ``<name>`` (its body, children, bodies and
  frames that name it) is the last one's, the two intermediate links are massless.
* **Order.** Joints are listed parents first (the file's order where it already is);
  ``MechanismSpec.independent_joints`` (moving joints that are not gear-coupled) is the order of
  the coordinates q of a trajectory.

Cross references are checked with errors naming the field: unknown parent, mimic joint, body
link or frame link (with the nearest name), duplicate names, cycles, a mimic of a fixed joint, of
itself or of another mimic.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechbal.errors import ConfigError

BASE = "base"


def rotation_rpy(rpy) -> np.ndarray:
    """Rotation matrix from roll-pitch-yaw (fixed axes x, then y, then z): Rz(y) Ry(p) Rx(r)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def transform_xyz_rpy(xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = rotation_rpy(rpy)
    T[:3, 3] = xyz
    return T


def _rx(t):
    return transform_xyz_rpy(rpy=(t, 0.0, 0.0))


def _rz(t):
    return transform_xyz_rpy(rpy=(0.0, 0.0, t))


def _tr(x, y, z):
    return transform_xyz_rpy(xyz=(x, y, z))


def dh_origin(a: float, alpha: float, d: float, theta: float, modified: bool) -> tuple[np.ndarray, np.ndarray]:
    """(origin, carry) of DH parameters. Modified (Craig): origin = Rx(alpha) Tx(a) Tz(d)
    Rz(theta), carry = I. Standard: origin = Rz(theta), and Tz(d) Tx(a) Rx(alpha) after the joint
    is the carry (the standard DH frame of the link, in the link frame)."""
    if modified:
        return _rx(alpha) @ _tr(a, 0, 0) @ _tr(0, 0, d) @ _rz(theta), np.eye(4)
    return _rz(theta), _tr(0, 0, d) @ _tr(a, 0, 0) @ _rx(alpha)


@dataclass(frozen=True, eq=False)
class JointSpec:
    """One joint of the tree: ``type`` revolute, prismatic or fixed; ``placement`` (4, 4) in the
    parent link's frame (root joints: in O); ``axis`` (3,) unit, in the joint frame; limits +-inf
    when absent; ``mimic`` None or (master joint name, ratio, offset): q = ratio q_master + offset."""
    name: str
    type: str
    parent: str
    placement: np.ndarray
    axis: np.ndarray
    lower: float = -math.inf
    upper: float = math.inf
    velocity: float = math.inf
    effort: float = math.inf
    mimic: tuple[str, float, float] | None = None


@dataclass(frozen=True, eq=False)
class BodySpec:
    """A rigid body on the link of joint ``link`` (or on ``base``): ``com`` (3,) and ``inertia``
    (3, 3) about the centre of mass, both in the link frame."""
    name: str
    kind: str
    link: str
    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True, eq=False)
class FrameSpec:
    """A named frame: ``placement`` (4, 4) in the frame of the link of joint ``link`` (or in O
    for ``base``)."""
    name: str
    link: str
    placement: np.ndarray


@dataclass(frozen=True, eq=False)
class LoopSpec:
    """A loop closure between frames ``frame_a`` and ``frame_b``: ``type`` point (3 equations),
    planar_point (2), axis (5) or weld (6); see ``cpp/include/mechbal/algorithm/loops.hpp``."""
    name: str
    type: str
    frame_a: str
    frame_b: str


@dataclass(frozen=True, eq=False)
class SpringSpec:
    """A spring between anchor ``anchor_a`` (3,) on the link of joint ``link_a`` (or ``base``) and
    ``anchor_b`` on ``link_b``, both in the link frames (DH frames and ``mechanism.base`` already
    applied); ``rate`` [N/m] each, ``free_length`` [m], ``preload`` [N], ``count``,
    ``pulley_ratio`` (see ``cpp/include/mechbal/model/model.hpp``, ``Spring``)."""
    name: str
    link_a: str
    anchor_a: np.ndarray
    link_b: str
    anchor_b: np.ndarray
    rate: float
    free_length: float = 0.0
    preload: float = 0.0
    count: int = 1
    pulley_ratio: float = 1.0


@dataclass(frozen=True, eq=False)
class MechanismSpec:
    gravity: np.ndarray
    joints: list[JointSpec]
    bodies: list[BodySpec] = field(default_factory=list)
    frames: list[FrameSpec] = field(default_factory=list)
    loops: list[LoopSpec] = field(default_factory=list)
    #: actuated joints (the independent coordinates q#); empty without loops means every joint
    actuated: list[str] = field(default_factory=list)
    #: link name -> (4, 4) placement, in the link frame, of the frame the user described the link
    #: in (the standard-DH frame of a ``dh`` joint; ``mechanism.base`` for ``base``); absent:
    #: the identity. Balancing reports counterweight positions in these frames.
    link_frames: dict[str, np.ndarray] = field(default_factory=dict)
    springs: list[SpringSpec] = field(default_factory=list)

    def joint(self, name: str) -> JointSpec:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    @property
    def independent_joints(self) -> list[str]:
        """Moving joints that are not gear-coupled: the coordinates q, in this order."""
        return [j.name for j in self.joints if j.type != "fixed" and j.mimic is None]

    @property
    def dof(self) -> int:
        return len(self.independent_joints)

    def bodies_on(self, link: str) -> list[BodySpec]:
        return [b for b in self.bodies if b.link == link]


def _hint(word: str, allowed: list[str]) -> str:
    from mechbal.tables import did_you_mean

    return did_you_mean(word, allowed)


def _move_body(T: np.ndarray, com: np.ndarray, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    R = T[:3, :3]
    return R @ com + T[:3, 3], R @ inertia @ R.T


#: |sin| (revolute) or |cos| (prismatic) of the angle between a joint axis and the plane normal
#: below which a mechanism is planar for ``izz`` alone
PLANAR_TOL = 1e-9


def plane_normal(joints: list[JointSpec], rotation_in_o: dict, f: str, izz: float) -> np.ndarray:
    """The normal (in O, at q = 0) of the plane a planar mechanism moves in: the common axis of its
    revolute joints, every prismatic axis perpendicular to it (then every link rotates about it
    only, at every q). ConfigError naming ``f`` (a body's ``izz``) when the mechanism is not
    planar."""
    n = None
    for js in joints:
        if js.type == "revolute":
            a = rotation_in_o[js.name] @ js.axis
            n = a / np.linalg.norm(a)
            break
    if n is None:
        raise ConfigError(f, "izz alone needs a planar mechanism with a revolute joint (its axis is the "
                             "plane's normal); give inertia = [Ixx, Iyy, Izz]", izz)
    for js in joints:
        if js.type not in ("revolute", "prismatic"):
            continue
        a = rotation_in_o[js.name] @ js.axis
        a = a / np.linalg.norm(a)
        off = np.linalg.norm(np.cross(a, n)) if js.type == "revolute" else abs(float(a @ n))
        if off > PLANAR_TOL:
            raise ConfigError(f, "izz alone needs a planar mechanism (every revolute axis parallel, every "
                                 f"prismatic axis perpendicular to {np.round(n, 6).tolist()} in O): joint "
                                 f"{js.name!r} ({js.type}) has axis {np.round(a, 6).tolist()}; give "
                                 "inertia = [Ixx, Iyy, Izz]", izz)
    return n


def mechanism_spec(mechanism: Any, field: str = "mechanism") -> MechanismSpec:
    """The `MechanismSpec` of a ``[mechanism]`` table (a dict, validated here, or a
    validated `mechbal.tables.Mechanism`); ConfigError naming the field otherwise."""
    from mechbal.tables import Mechanism, inertia_matrix, lamina_inertia, validate_table

    m = mechanism if isinstance(mechanism, Mechanism) else validate_table(Mechanism, mechanism, field)
    base = transform_xyz_rpy(m.base.xyz, m.base.rpy) if m.base is not None else np.eye(4)
    jf = lambda i: f"{field}.joints[{i}]"  # noqa: E731

    # names: user joints, the joints they expand into, what a reference to each name means
    names = [j.name or f"joint{i + 1}" for i, j in enumerate(m.joints)]
    declared: dict[str, str] = {}  # joint name in the spec -> field that declares it
    link_joint: dict[str, str] = {}  # name a user may refer to -> spec joint whose link it is
    expansions: dict[int, list[str]] = {}
    for i, (j, name) in enumerate(zip(m.joints, names)):
        f = f"{jf(i)}.name"
        if name == BASE:
            raise ConfigError(f, f"{BASE!r} is the name of the fixed base; choose another", name)
        parts = [f"{name}_z", f"{name}_y", f"{name}_x"] if j.type == "spherical" else [name]
        for n in dict.fromkeys(parts + [name]):
            if n in declared or n in link_joint:
                other = declared.get(n) or declared.get(link_joint[n])
                what = f"the joint {n!r}" + (f" of the spherical joint {name!r}" if n != name else "")
                raise ConfigError(f, f"duplicate name: {what} is also declared by {other}", name)
        for n in parts:
            declared[n] = jf(i) if n == name else f"{jf(i)} (spherical {name!r})"
            link_joint[n] = n
        link_joint[name] = parts[-1]
        expansions[i] = parts
    references = list(link_joint) + [BASE]

    def resolve(ref: str, f: str, what: str) -> str:
        if ref == BASE:
            return BASE
        if ref not in link_joint:
            raise ConfigError(f, f"unknown {what}{_hint(ref, references)}", ref)
        return link_joint[ref]

    # parents (default: the previous joint in the list), cycles
    parent_index: dict[int, int | None] = {}
    index_of = {n: i for i, parts in expansions.items() for n in parts + [names[i]]}
    parent_name: dict[int, str] = {}
    for i, j in enumerate(m.joints):
        ref = j.parent if j.parent is not None else (names[i - 1] if i > 0 else BASE)
        parent = resolve(ref, f"{jf(i)}.parent", "parent joint")
        parent_name[i] = parent
        k = None if parent == BASE else index_of[parent]
        if k == i and parent in expansions[i]:
            raise ConfigError(f"{jf(i)}.parent", "a joint cannot be its own parent", ref)
        parent_index[i] = k
    for i in range(len(m.joints)):
        path, k = [i], parent_index[i]
        while k is not None:
            if k in path:
                cycle = path[path.index(k):] + [k]
                start = min(cycle)
                raise ConfigError(f"{jf(start)}.parent",
                                  "joints form a cycle: " + " -> ".join(names[c] for c in cycle),
                                  parent_name[start])
            path.append(k)
            k = parent_index[k]

    # parents first, the file's order where it already is
    order, placed = [], set()
    while len(order) < len(m.joints):
        for i in range(len(m.joints)):
            if i not in placed and (parent_index[i] is None or parent_index[i] in placed):
                order.append(i)
                placed.add(i)

    # placements and carries
    origin_of, carry_of = {}, {}
    for i, j in enumerate(m.joints):
        if j.mdh is not None or j.dh is not None:
            d = j.mdh if j.mdh is not None else j.dh
            origin_of[i], carry_of[i] = dh_origin(d.a, d.alpha, d.d, d.theta, modified=j.mdh is not None)
        else:
            o = j.origin
            origin_of[i] = transform_xyz_rpy(o.xyz, o.rpy) if o is not None else np.eye(4)
            carry_of[i] = np.eye(4)

    carry_by_joint = {n: (carry_of[i] if n == parts[-1] else np.eye(4))
                      for i, parts in expansions.items() for n in parts}

    def frame_of_link(link: str) -> np.ndarray:
        """What a user's coordinates on the link of spec joint ``link`` are multiplied by to be
        in the link frame: the standard-DH carry of its joint, or the base placement."""
        return base if link == BASE else carry_by_joint[link]

    joints: list[JointSpec] = []
    for i in order:
        j = m.joints[i]
        parent = parent_name[i]
        placement = frame_of_link(parent) @ origin_of[i]
        if j.type == "spherical":
            parts = expansions[i]
            for n, p, axis, ax in zip(parts, [parent, parts[0], parts[1]], "zyx",
                                      ([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])):
                joints.append(JointSpec(n, "revolute", p, placement if axis == "z" else np.eye(4),
                                        np.array(ax)))
            continue
        axis = np.array(j.axis if j.axis is not None else [0.0, 0.0, 1.0], dtype=float)
        axis = axis / np.max(np.abs(axis))
        axis = axis / np.linalg.norm(axis)
        lim = j.limits
        get = lambda key, default: default if lim is None or getattr(lim, key) is None \
            else float(getattr(lim, key))  # noqa: E731
        mimic = None
        if j.mimic is not None:
            f = f"{jf(i)}.mimic.joint"
            ref = j.mimic.joint
            k = index_of.get(ref)
            if k is not None and m.joints[k].type == "spherical" and ref == names[k]:
                raise ConfigError(f, f"{ref!r} is a spherical joint: name one of "
                                     f"{', '.join(expansions[k])}", ref)
            master = resolve(ref, f, "joint")
            if master == BASE:
                raise ConfigError(f, "the base does not move: name a joint", ref)
            if master == names[i]:
                raise ConfigError(f, "a joint cannot mimic itself", ref)
            mj = m.joints[index_of[master]]
            if mj.type == "fixed":
                raise ConfigError(f, "mimics a fixed joint, which does not move", ref)
            if mj.mimic is not None:
                raise ConfigError(f, f"mimics {master!r}, itself a mimic of {mj.mimic.joint!r}: "
                                     f"couple to {mj.mimic.joint!r} directly", ref)
            mimic = (master, float(j.mimic.ratio), float(j.mimic.offset))
        joints.append(JointSpec(names[i], j.type, parent, placement, axis,
                                lower=get("lower", -math.inf), upper=get("upper", math.inf),
                                velocity=get("velocity", math.inf), effort=get("effort", math.inf),
                                mimic=mimic))

    # bodies: each joint's own link, then the extra bodies
    bodies: list[BodySpec] = []
    body_field: dict[str, str] = {}

    def add_body(name, kind, link, mass, com, inertia, f):
        if name in body_field:
            raise ConfigError(f, f"duplicate body name: {name!r} is also {body_field[name]}", name)
        body_field[name] = f
        c, inertia = _move_body(frame_of_link(link), np.asarray(com, dtype=float), inertia)
        bodies.append(BodySpec(name, kind, link, float(mass), c, 0.5 * (inertia + inertia.T)))

    rotation_in_o = {BASE: np.eye(3)}   # link frames in O at q = 0 (for izz alone)
    for js in joints:
        rotation_in_o[js.name] = rotation_in_o[js.parent] @ js.placement[:3, :3]

    def lamina(link: str, izz: float, f: str) -> np.ndarray:
        """izz alone: the lamina in the plane of motion, in the frame the user described ``link`` in."""
        n = plane_normal(joints, rotation_in_o, f, izz)
        return lamina_inertia(izz, (rotation_in_o[link] @ frame_of_link(link)[:3, :3]).T @ n)

    for i in order:
        j = m.joints[i]
        if j.link is not None:
            link = expansions[i][-1]
            inertia = (inertia_matrix(j.link.inertia) if j.link.izz is None
                       else lamina(link, j.link.izz, f"{jf(i)}.link.izz"))
            add_body(names[i], "link", link, j.link.mass, j.link.com, inertia, f"{jf(i)}.link")
    for b_i, b in enumerate(m.bodies):
        f = f"{field}.bodies[{b_i}]"
        link = resolve(b.link, f"{f}.link", "link")
        R = rotation_rpy(b.rpy)
        inertia = R @ inertia_matrix(b.inertia) @ R.T if b.izz is None else lamina(link, b.izz, f"{f}.izz")
        add_body(b.name, b.kind, link, b.mass, b.com, inertia, f"{f}.name")

    frames: list[FrameSpec] = []
    frame_field: dict[str, str] = {}
    for f_i, fr in enumerate(m.frames):
        f = f"{field}.frames[{f_i}]"
        if fr.name in frame_field:
            raise ConfigError(f"{f}.name", f"duplicate frame name: also {frame_field[fr.name]}", fr.name)
        if fr.name == BASE:
            raise ConfigError(f"{f}.name", f"{BASE!r} is the name of the fixed base; choose another",
                              fr.name)
        frame_field[fr.name] = f
        link = resolve(fr.link, f"{f}.link", "link")
        frames.append(FrameSpec(fr.name, link,
                                frame_of_link(link) @ transform_xyz_rpy(fr.origin.xyz, fr.origin.rpy)))

    loops: list[LoopSpec] = []
    loop_field: dict[str, str] = {}
    for l_i, lp in enumerate(m.loops):
        f = f"{field}.loops[{l_i}]"
        if lp.name in loop_field:
            raise ConfigError(f"{f}.name", f"duplicate loop name: also {loop_field[lp.name]}", lp.name)
        loop_field[lp.name] = f
        for key in ("frame_a", "frame_b"):
            name = getattr(lp, key)
            if name not in frame_field:
                raise ConfigError(f"{f}.{key}", "no such frame (define it in [[mechanism.frames]])"
                                  + _hint(name, list(frame_field)), name)
        loops.append(LoopSpec(lp.name, lp.type, lp.frame_a, lp.frame_b))
    springs: list[SpringSpec] = []
    spring_field: dict[str, str] = {}
    for s_i, sp in enumerate(m.springs):
        f = f"{field}.springs[{s_i}]"
        if sp.name in spring_field:
            raise ConfigError(f"{f}.name", f"duplicate spring name: also {spring_field[sp.name]}", sp.name)
        spring_field[sp.name] = f
        ends = []
        for side in ("a", "b"):
            link = resolve(getattr(sp, f"link_{side}"), f"{f}.link_{side}", "link")
            T = frame_of_link(link)
            ends.append((link, T[:3, :3] @ np.asarray(getattr(sp, f"anchor_{side}"), float) + T[:3, 3]))
        if ends[0][0] == ends[1][0]:
            raise ConfigError(f"{f}.link_b", "both anchors are on the same link, so the spring never changes "
                                             "length", sp.link_b)
        springs.append(SpringSpec(sp.name, ends[0][0], ends[0][1], ends[1][0], ends[1][1], float(sp.rate),
                                  float(sp.free_length), float(sp.preload), int(sp.count),
                                  float(sp.pulley_ratio)))

    independent = [j.name for j in joints if j.type != "fixed" and j.mimic is None]
    for a_i, name in enumerate(m.actuated):
        if name not in independent:
            raise ConfigError(f"{field}.actuated[{a_i}]", "not a joint with its own coordinate"
                              + _hint(name, independent), name)
    if len(set(m.actuated)) != len(m.actuated):
        raise ConfigError(f"{field}.actuated", "names a joint twice", list(m.actuated))
    if loops and not m.actuated:
        raise ConfigError(f"{field}.actuated", "a mechanism with loops must name its actuated joints",
                          has_value=False)
    link_frames = {n: frame_of_link(n) for n in [BASE, *(j.name for j in joints)]}
    link_frames = {n: T for n, T in link_frames.items() if not np.array_equal(T, np.eye(4))}
    return MechanismSpec(np.array(m.gravity, dtype=float), joints, bodies, frames, loops,
                         list(m.actuated), link_frames, springs)
