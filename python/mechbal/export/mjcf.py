"""MJCF (MuJoCo's model format) of any mechanism: `mjcf_text`.

What is written, for a `mechbal.Mechanism`:

* **Tree.** One ``<body>`` per link, named as `mechbal.export.common.link_labels` says (a
  URDF's link names kept), placed by its joint's placement at q = 0 (so MuJoCo's ``qpos`` is
  mechbal's joint value, ``qpos0`` = 0); the joint as a ``hinge`` / ``slide`` of the same name and
  axis at the body origin (a fixed joint: none, the body is welded to its parent); position limits
  as ``range`` (an end stop: ``solreflimit`` `LIMIT_SOLREF`, ``solimplimit`` `LIMIT_SOLIMP`,
  stiff and overdamped like the inelastic stops of `mechbal.simulate.passive`; a one-sided
  limit's other side at `ONE_SIDED`). The links joined to the root by fixed joints are static
  bodies of the world.
* **Bodies.** Every mechbal body (link inertia, counterweight, disc, motor, payload) keeps its
  own mass and inertia: the link's own body (named after the link) is the link body's
  ``<inertial>``, every other one a child ``<body>`` of that name without a joint (welded), with
  its ``<inertial>`` (``fullinertia`` about its centre of mass). ``inertiafromgeom="false"``: the
  geometry carries no mass. A body of zero mass and zero inertia is left out (a comment says so);
  a body of zero mass with inertia (a disc's rotor) keeps its inertia.
* **Gears.** A gear-coupled joint q = r q_master + c is a joint of its own tied by an equality
  ``joint`` constraint, ``polycoef="c r 0 0 0"``.
* **Loops.** Every named frame is a ``<site>``. A ``point`` loop is an equality ``connect``
  between the sites of its two frames, a ``weld`` loop a ``weld`` between them; an ``axis`` loop
  two ``connect`` constraints (the origins, and the points one length unit along the axes); a
  ``planar_point`` loop (the origin of B on the z axis of A) a ``connect`` between A's site and
  the point of B's link at A's origin in the assembled pose: exact when the loop moves in the
  plane normal to z_A, which is what the closure describes (MuJoCo has no point-on-line equality).
* **Constraint softness.** Loops and gears get ``solimp`` `SOLIMP` (nearly hard; MuJoCo's
  constraints are soft, which shows as a residual shaking force of a balanced linkage) and
  ``solref`` twice the time step (the stiffest MuJoCo allows). A closed mechanism's file has a
  time step of `CLOSED_TIMESTEP` and heavier minimum bodies (`CLOSED_MINIMUM_FRACTION`): together
  they hold every built-in linkage at its keyframe under its static actuator forces.
* **Springs.** A spatial ``<tendon>`` between two sites at the anchors, ``stiffness`` = the
  equivalent rate count rate / pulley_ratio^2, ``springlength`` = free_length - preload tension /
  stiffness (MuJoCo's spring force is -stiffness (length - springlength): the same tension as
  mechbal's preload + rate (d - free_length) at every length). A spring whose tension does not
  vanish at a length >= 0 (a heavy preload, or a rate of zero) raises ExportError.
* **Actuators.** A ``motor`` (gear 1) on every actuated joint (every coordinate of a tree), named
  after it; its torque limit as ``forcerange`` when the joint has one.
* **MuJoCo's minimum.** MuJoCo refuses a moving body (with the bodies welded to it) of no mass or
  of a zero principal moment of inertia (a point-mass link, a massless rotor's own link); such a
  link gets a body ``<link>_minimum`` at its origin (listed in `MjcfNames.minimum`): `MINIMUM`
  kg and kg m^2 in a tree, `CLOSED_MINIMUM_FRACTION` of the total mass at the mechanism's
  `length_scale` in a closed mechanism (`default_minimum_mass`; a massless link makes MuJoCo's
  loop constraints give way).
* **Inertias.** Principal moments and axes; MuJoCo refuses a triangle inequality A + B >= C
  broken by rounding, so the smallest moment keeps `TRIANGLE_MARGIN` of the trace to spare
  (`principal_moments`; a comment says where that moved a moment).
* **Pose.** A keyframe ``assembled`` with the joint values of the assembled pose (the loops
  closed; mechbal's q = 0 for a tree unless a pose is given).
* **Geometry** (to look at; no contacts, no mass): capsules from each link's origin to its child
  joints' origins, spheres for counterweights (steel density), cylinders for discs (about their
  largest principal axis), small spheres for motors and payloads.
* **Options.** Gravity, the integrator (`INTEGRATOR`: RK4) and the time step (`default_timestep`)
  in ``<option>``, and a comment saying why.

Names are kept (links, joints, frames as sites, springs as tendons, loops as equalities); where
two MuJoCo objects of one kind would share a name, the later one gets a suffix.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from xml.sax.saxutils import quoteattr

import numpy as np

from mechbal import _core
from mechbal.export.common import (ExportError, assembled_pose, fixed_to_root, full_joint_values,
                                   inertia_is_zero, link_labels, quat_of)

__all__ = ["mjcf_text", "MjcfNames", "mjcf_names", "AXIS_LENGTH", "ExportError"]

#: distance along the axis of the second point of an ``axis`` loop [m]
AXIS_LENGTH = 0.1
#: mass [kg] and principal moments [kg m^2] of the body added to a moving link whose bodies MuJoCo
#: would refuse (no mass, or a zero principal moment: a point mass, a massless rotor's link), at
#: the link origin: 100 times MuJoCo's mjMINVAL, far below what the comparisons resolve
MINIMUM = 1e-13
#: closed mechanisms (loops): the mass of the body added to each massless moving link, as a fraction
#: of the total mass. MuJoCo's loop constraints are soft in proportion to the inverse inertia of
#: the bodies and dofs they join (``body_invweight0``, ``dof_invweight0``), so a loop through a
#: link of `MINIMUM` kg gives way under any load (PAMINSA fell 3.9 rad in 0.5 s); with 1e-4 of
#: the total mass at the mechanism's length scale (`length_scale`) every built-in linkage holds its
#: keyframe to 5e-5 or better for 1 s (docs/guide.md, MuJoCo chapter). mechbal's prediction of
#: the file is of ``mech.with_bodies(minimum_bodies(mech))``.
CLOSED_MINIMUM_FRACTION = 1e-4
#: closed mechanisms: MuJoCo's time step [s]; the loops' ``solref`` time constant is twice it
#: (MuJoCo's smallest safe one), so the closure's stiffness grows as 1 / timestep^2
CLOSED_TIMESTEP = 2.5e-4
#: trees: MuJoCo's time step [s]
TREE_TIMESTEP = 1e-3
#: the integrator written in ``<option>``: the one of the documented figures (RK4: 4th order; a
#: free swing of 0.5 s at the file's step is 1e-4 to 1e-7 times closer than implicitfast's or
#: Euler's, docs/guide.md)
INTEGRATOR = "RK4"
INTEGRATORS = ("RK4", "implicitfast", "implicit", "Euler")
#: impedance of the loop and gear constraints (MuJoCo's solimp d0, d_width, width): near 1 so that
#: they are nearly hard (MuJoCo's default 0.9 0.95 lets a loaded linkage accelerate off its
#: closure: 6 % of a four-bar's unbalanced shaking force at the start of a motion, 5e-5 with this)
SOLIMP = (0.9999, 0.9999, 0.001)
#: margin kept on MuJoCo's triangle inequality of the principal moments, A + B >= C + margin x
#: trace (`principal_moments`): far below what any comparison resolves (1e-9), far above rounding
TRIANGLE_MARGIN = 1e-12
#: a joint limit as an end stop (``solreflimit``: time constant [s], damping ratio;
#: ``solimplimit``): stiff and overdamped, the inelastic stop of mechbal's passive simulation
#: (`mechbal.simulate.passive`): a penetration of about 1e-3 s times the impact rate and no
#: bounce (MuJoCo's default (0.02, 1) lets a pendulum sink 0.05 rad into its limit; a damping
#: ratio of 1 still throws it back off the limit at 14 % of its impact rate, 2 or more does not).
#: MuJoCo raises a time constant below twice the timestep to that (its refsafe flag).
LIMIT_SOLREF = (0.002, 3.0)
LIMIT_SOLIMP = (0.99, 0.999, 0.001)
#: the far side of a one-sided limit in ``range`` [rad or m] (MJCF ranges have two sides)
ONE_SIDED = 1e6
#: density of the counterweight spheres drawn [kg/m^3] (steel)
DENSITY = 7850.0


def _f(x: float) -> str:
    return repr(float(x))


def _v(x) -> str:
    return " ".join(_f(v) for v in np.asarray(x, float).reshape(-1))


@dataclass
class MjcfNames:
    """The MuJoCo names of a mechanism's parts: ``links`` (mechbal link -> body), ``bodies``
    (mechbal body -> MuJoCo body holding its inertia), ``sites`` (frame -> site), ``joints``
    (moving joints, mechbal = MuJoCo names), ``moving_roots``: the bodies whose parent does not
    move (the base reaction is what the world exerts through them), ``still``: the static
    bodies (the links joined to the root by fixed joints and their bodies), ``minimum``: the
    bodies of `MINIMUM` mass added so that MuJoCo accepts a link."""
    links: dict[str, str] = field(default_factory=dict)
    bodies: dict[str, str] = field(default_factory=dict)
    sites: dict[str, str] = field(default_factory=dict)
    joints: list[str] = field(default_factory=list)
    moving_roots: list[str] = field(default_factory=list)
    still: list[str] = field(default_factory=list)
    minimum: list[str] = field(default_factory=list)
    minimum_links: dict[str, str] = field(default_factory=dict)


class _Unique:
    def __init__(self):
        self.used: set[str] = set()

    def __call__(self, name: str) -> str:
        out, k = name, 1
        while out in self.used:
            k += 1
            out = f"{name}_{k}"
        self.used.add(out)
        return out


def principal_moments(inertia) -> tuple[np.ndarray, np.ndarray, float]:
    """(principal moments ascending, axes (columns, a rotation), raise) of an inertia as MuJoCo
    gets it: the moments within 1e-15 of the largest are zero, and the smallest ones are raised
    so that the triangle inequality A + B >= C holds with `TRIANGLE_MARGIN` of the trace to spare
    (``raise``: by how much in all [kg m^2], 0 when it already did). A physical inertia on the boundary
    (a thin rod, a flat plate, a URDF repair's nearest physical inertia) would otherwise fall on
    either side of MuJoCo's check with the last bit of rounding."""
    I = np.asarray(inertia, float)
    w, V = np.linalg.eigh(0.5 * (I + I.T))
    w = np.where(np.abs(w) <= 1e-15 * max(float(np.max(np.abs(w))), 1e-300), 0.0, w)
    w = np.maximum(w, 0.0)
    if np.linalg.det(V) < 0.0:
        V[:, 2] = -V[:, 2]
    margin = TRIANGLE_MARGIN * float(np.sum(w))
    before = w.copy()
    if margin > 0.0 and w[0] + w[1] < w[2] + margin:
        # ascending a <= b <= c: b >= margin and a >= c - b + margin give every slack >= margin
        # (a + b - c = margin at least, a + c - b >= a, b + c - a >= 2 b - margin)
        w[1] = max(w[1], margin)
        w[0] = max(w[0], w[2] - w[1] + margin)
    lift = float(np.sum(w - before))
    return w, V, lift


def _inertial(mass: float, com, inertia) -> str:
    """``<inertial>`` with the principal moments (``diaginertia``) and axes (``quat``): MuJoCo
    accepts a point mass's zero inertia there, not in ``fullinertia``; moments kept off the
    triangle boundary (`principal_moments`), a comment saying so where that moved one."""
    w, V, lift = principal_moments(inertia)
    note = (f" <!-- smallest principal moments raised by {lift:.3g} kg m^2: A + B >= C with "
            f"{TRIANGLE_MARGIN:g} of the trace to spare (MuJoCo refuses the boundary's rounding) -->" if lift else "")
    return (f'<inertial pos="{_v(com)}" quat="{_v(quat_of(V))}" mass="{_f(mass)}" '
            f'diaginertia="{_v(w)}"/>{note}')


def _needs_minimum(bodies) -> bool:
    """MuJoCo refuses a moving body whose mass, or any principal moment, summed over the bodies
    welded to it, is below mjMINVAL (1e-15)."""
    m = sum(float(b.mass) for b in bodies)
    low = sum(float(np.min(np.linalg.eigvalsh(np.asarray(b.inertia, float)))) for b in bodies)
    return m < MINIMUM * 1e3 or low < MINIMUM * 1e3


def _spring_constants(sp) -> tuple[float, float]:
    k = float(sp.count) * float(sp.rate) / float(sp.pulley_ratio) ** 2
    preload = float(sp.count) * float(sp.preload) / float(sp.pulley_ratio)
    if k <= 0.0:
        raise ExportError(f"spring '{sp.name}': a rate of {sp.rate} N/m (a constant force) has no MuJoCo "
                          "tendon spring")
    length = float(sp.free_length) - preload / k
    if length < 0.0:
        raise ExportError(f"spring '{sp.name}': its tension vanishes at a negative length ({length:.6g} m: "
                          "free_length - preload / rate), which a MuJoCo tendon spring cannot hold")
    return k, length


def mjcf_names(mech) -> MjcfNames:
    """The MuJoCo names `mjcf_text` gives ``mech``'s parts."""
    return _build(mech, None, None, 1e-3, names_only=True)[1]


def length_scale(mech) -> float:
    """The mechanism's length scale [m]: its largest joint offset, at least 5 cm."""
    d = mech.model.description
    return max([float(np.linalg.norm(np.asarray(j.placement)[:3, 3])) for j in d.joints] + [0.05])


def default_minimum_mass(mech) -> float:
    """Mass [kg] of the body added to each massless moving link: `MINIMUM` for a tree (far below
    what any comparison resolves), `CLOSED_MINIMUM_FRACTION` of the total mass for a closed
    mechanism (so that MuJoCo's loop constraints hold)."""
    return max(CLOSED_MINIMUM_FRACTION * float(mech.total_mass), MINIMUM) if mech.is_closed else MINIMUM


def default_timestep(mech) -> float:
    """MuJoCo's time step [s] written: `CLOSED_TIMESTEP` for a closed mechanism, else
    `TREE_TIMESTEP`."""
    return CLOSED_TIMESTEP if mech.is_closed else TREE_TIMESTEP


def minimum_inertia(mech, minimum_mass: float) -> float:
    """Principal moment [kg m^2] of the body of ``minimum_mass`` added to a link MuJoCo would
    refuse: `MINIMUM` at `MINIMUM`, else the mass at the mechanism's `length_scale` (a rotation
    of the link is then as stiff in MuJoCo's loop constraints as a translation)."""
    return MINIMUM if minimum_mass == MINIMUM else minimum_mass * length_scale(mech) ** 2


def minimum_bodies(mech, minimum_mass: float | None = None) -> list:
    """The bodies (``mechbal.Body``) the export adds so that MuJoCo accepts every moving link
    (`MjcfNames.minimum`): ``minimum_mass`` kg (default `default_minimum_mass`) at each such
    link's origin, principal moments `minimum_inertia`. ``mech.with_bodies`` of them is the
    mechanism MuJoCo integrates."""
    if minimum_mass is None:
        minimum_mass = default_minimum_mass(mech)
    names = mjcf_names(mech)
    inertia = minimum_inertia(mech, minimum_mass)
    return [_core.Body(n, link, float(minimum_mass), np.zeros(3), inertia * np.eye(3), "other")
            for link, n in names.minimum_links.items()]


def mjcf_text(mech, name: str | None = None, *, q=None, q_guess=None, timestep: float | None = None,
              minimum_mass: float | None = None, integrator: str = INTEGRATOR) -> str:
    """MJCF of ``mech`` (module docstring). ``q``: the pose of the keyframe (dof,); a closed
    mechanism is assembled from ``q`` or ``q_guess`` (`mechbal.export.common.assembled_pose`).
    ``timestep`` [s]: MuJoCo's (default `default_timestep`); ``minimum_mass``: of the body added
    to a link MuJoCo would refuse (`minimum_bodies`; default `default_minimum_mass`);
    ``integrator``: MuJoCo's (``RK4``, ``implicitfast``, ``implicit``, ``Euler``).
    ExportError (a ValueError, one line) when a part has no MuJoCo equivalent."""
    return _build(mech, q, q_guess, timestep, name=name, minimum_mass=minimum_mass, integrator=integrator)[0]


def _build(mech, q, q_guess, timestep, *, name=None, names_only=False, minimum_mass: float | None = None,
           integrator: str = INTEGRATOR):
    if minimum_mass is None:
        minimum_mass = default_minimum_mass(mech)
    if timestep is None:
        timestep = default_timestep(mech)
    if not (math.isfinite(timestep) and timestep > 0.0):
        raise ExportError(f"timestep must be a number > 0 [s], got {timestep}")
    if integrator not in INTEGRATORS:
        raise ExportError(f"integrator must be one of {', '.join(INTEGRATORS)}, got {integrator!r}")
    d = mech.model.description
    labels = link_labels(mech)
    still = fixed_to_root(mech)
    if names_only:
        pose = np.zeros(mech.dof)
    else:
        pose = assembled_pose(mech, q, q_guess)
    names = MjcfNames()
    body_name, site_name = _Unique(), _Unique()
    children: dict[str, list] = {}
    for j in d.joints:
        children.setdefault(j.parent, []).append(j)
    for link in [d.root_name] + [j.name for j in d.joints]:
        if link != d.root_name:
            names.links[link] = body_name(labels[link])
    by_link: dict[str, list] = {}
    for b in d.bodies:
        by_link.setdefault(b.link, []).append(b)
    own: dict[str, object] = {}  # link -> the body that is the link body's own inertial
    for link, bodies in by_link.items():
        if link == d.root_name:
            continue
        for b in bodies:
            if b.name in (link, labels[link]) and not inertia_is_zero(b):
                own[link] = b
                names.bodies[b.name] = names.links[link]
                break
    for b in d.bodies:
        if b.name not in names.bodies and not inertia_is_zero(b):
            names.bodies[b.name] = body_name(b.name)
    for f in d.frames:
        names.sites[f.name] = site_name(f.name)
    names.joints = [j.name for j in d.joints if j.type != _core.JointType.fixed]
    for j in d.joints:
        if j.name in still:
            names.still.append(names.links[j.name])
        elif j.parent in still:
            names.moving_roots.append(names.links[j.name])
    names.still += [names.bodies[b.name] for b in by_link.get(d.root_name, []) if b.name in names.bodies]
    for link in still - {d.root_name}:
        names.still += [names.bodies[b.name] for b in by_link.get(link, [])
                        if b.name in names.bodies and b is not own.get(link)]
    minimum_of: dict[str, str] = {}   # moving link -> the MINIMUM body added to it
    for j in d.joints:
        if j.type == _core.JointType.fixed:
            continue
        group, stack = [], [j.name]
        while stack:   # the link and the links welded to it by fixed joints
            link = stack.pop()
            group += [b for b in by_link.get(link, []) if not inertia_is_zero(b)]
            stack += [c.name for c in children.get(link, []) if c.type == _core.JointType.fixed]
        if _needs_minimum(group):
            minimum_of[j.name] = body_name(f"{labels[j.name]}_minimum")
            names.minimum.append(minimum_of[j.name])
            names.minimum_links[j.name] = minimum_of[j.name]
    if names_only:
        return "", names

    # poses at the assembled q (for the loops' extra sites)
    motion = mech.body_motion(pose)
    links = mech.link_names
    link_R = {n: np.asarray(motion.link_rotation[i]) for i, n in enumerate(links)}
    link_p = {n: np.asarray(motion.link_position[i]) for i, n in enumerate(links)}
    frame_T = {n: np.asarray(motion.frame_placement[i]) for i, n in enumerate(mech.frame_names)}
    frame_of = {f.name: f for f in d.frames}

    extra_sites: dict[str, list[str]] = {}   # link -> site lines
    equality: list[str] = []
    eq_name = _Unique()
    scale = length_scale(mech)

    imp = f' solref="{_f(2.0 * timestep)} 1" solimp="{_v(SOLIMP)}"'

    def add_site(link: str, nm: str, p) -> str:
        s = site_name(nm)
        extra_sites.setdefault(link, []).append(f'<site name={quoteattr(s)} pos="{_v(p)}" size="{_f(0.004 * scale)}" group="3"/>')
        return s

    def in_link(link: str, p_world) -> np.ndarray:
        return link_R[link].T @ (np.asarray(p_world, float) - link_p[link])

    for lp in d.loops:
        fa, fb = frame_of[lp.frame_a], frame_of[lp.frame_b]
        sa, sb = names.sites[fa.name], names.sites[fb.name]
        Ta, Tb = frame_T[fa.name], frame_T[fb.name]
        if lp.type == _core.LoopType.point:
            equality.append(f"<connect name={quoteattr(eq_name(lp.name))} site1={quoteattr(sa)} site2={quoteattr(sb)}{imp}/>")
        elif lp.type == _core.LoopType.weld:
            equality.append(f"<weld name={quoteattr(eq_name(lp.name))} site1={quoteattr(sa)} site2={quoteattr(sb)}{imp}/>")
        elif lp.type == _core.LoopType.planar_point:
            sb2 = add_site(fb.link, f"{lp.name}_b", in_link(fb.link, Ta[:3, 3]))
            equality.append(f"<connect name={quoteattr(eq_name(lp.name))} site1={quoteattr(sa)} site2={quoteattr(sb2)}{imp}/>")
        elif lp.type == _core.LoopType.axis:
            za, zb = Ta[:3, 2], Tb[:3, 2]
            sign = 1.0 if za @ zb >= 0.0 else -1.0
            sa2 = add_site(fa.link, f"{lp.name}_axis_a", in_link(fa.link, Ta[:3, 3] + AXIS_LENGTH * za))
            sb2 = add_site(fb.link, f"{lp.name}_axis_b", in_link(fb.link, Tb[:3, 3] + sign * AXIS_LENGTH * zb))
            equality.append(f"<connect name={quoteattr(eq_name(lp.name))} site1={quoteattr(sa)} site2={quoteattr(sb)}{imp}/>")
            equality.append(f"<connect name={quoteattr(eq_name(lp.name + '_axis'))} site1={quoteattr(sa2)} "
                            f"site2={quoteattr(sb2)}{imp}/>")
        else:  # pragma: no cover - every LoopType is handled above
            raise ExportError(f"loop '{lp.name}': type {lp.type} has no MJCF equivalent")
    for j in d.joints:
        if j.mimic_joint:
            equality.append(f"<joint name={quoteattr(eq_name(j.name + '_gear'))} joint1={quoteattr(j.name)} "
                            f"joint2={quoteattr(j.mimic_joint)} polycoef=\"{_f(j.mimic_offset)} "
                            f"{_f(j.mimic_ratio)} 0 0 0\"{imp}/>")

    tendons = []
    tendon_name = _Unique()
    for sp in d.springs:
        k, length = _spring_constants(sp)
        s1 = add_site(sp.link_a, f"{sp.name}_a", sp.anchor_a)
        s2 = add_site(sp.link_b, f"{sp.name}_b", sp.anchor_b)
        tendons += [f"<spatial name={quoteattr(tendon_name(sp.name))} stiffness=\"{_f(k)}\" "
                    f"springlength=\"{_f(length)}\" width=\"{_f(0.003 * scale)}\">",
                    f"  <site site={quoteattr(s1)}/>", f"  <site site={quoteattr(s2)}/>", "</spatial>"]

    # ---- bodies ----
    out = ['<mujoco model=' + quoteattr(name or mech.name) + '>',
           '  <!-- written by mechbal: every body with its own inertia; geometry for looking only -->',
           '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
           f'  <!-- MuJoCo options: integrator {integrator} '
           + ('(4th order: the one of mechbal\'s documented MuJoCo figures)' if integrator == "RK4" else '(as asked)')
           + f', time step {_f(timestep)} s'
           + (f'; the loops and gears are equality constraints with solref {_f(2.0 * timestep)} s (twice the '
              f'step: as stiff as MuJoCo allows) and solimp {_v(SOLIMP)}' if d.loops or any(j.mimic_joint for j in d.joints) else '')
           + (f'; each massless moving link carries {minimum_mass:.6g} kg ({minimum_mass / max(mech.total_mass, 1e-300):.3g} '
              'of the total mass: the *_minimum bodies) so that the loops hold under load'
              if d.loops and minimum_mass > MINIMUM and names.minimum else '')
           + ' -->',
           f'  <option timestep="{_f(timestep)}" integrator="{integrator}" gravity="{_v(d.gravity)}"/>',
           '  <default>',
           '    <geom contype="0" conaffinity="0" group="1"/>',
           '  </default>',
           '  <worldbody>']

    loop_frames = {lp.frame_a for lp in d.loops} | {lp.frame_b for lp in d.loops}
    tree_order: list[str] = []   # MuJoCo's joint (qpos) order: depth-first in the file

    def geoms(link: str, ind: str) -> list[str]:
        lines = []
        r = 0.012 * scale
        for c in children.get(link, []):
            p = np.asarray(c.placement)[:3, 3]
            if np.linalg.norm(p) > 1e-9:
                lines.append(f'{ind}<geom type="capsule" fromto="0 0 0 {_v(p)}" size="{_f(r)}" rgba="0.6 0.6 0.65 1"/>')
        for f in d.frames:   # to the loops' frames, so that a linkage looks closed
            if f.link == link and f.name in loop_frames:
                p = np.asarray(f.placement)[:3, 3]
                if np.linalg.norm(p) > 1e-9:
                    lines.append(f'{ind}<geom type="capsule" fromto="0 0 0 {_v(p)}" size="{_f(r)}" rgba="0.6 0.6 0.65 1"/>')
        if not lines:
            lines.append(f'{ind}<geom type="sphere" size="{_f(r)}" rgba="0.6 0.6 0.65 1"/>')
        return lines

    def body_geom(b, ind: str) -> list[str]:
        c = np.asarray(b.com, float)
        if b.kind == "counterweight":
            rad = (3.0 * max(float(b.mass), 1e-6) / (4.0 * math.pi * DENSITY)) ** (1.0 / 3.0)
            return [f'{ind}<geom type="sphere" pos="{_v(c)}" size="{_f(rad)}" rgba="0.8 0.3 0.2 1"/>']
        if b.kind == "disc":
            w, V = np.linalg.eigh(np.asarray(b.inertia, float))
            z = V[:, int(np.argmax(w))]
            x = np.cross(z, [1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.cross(z, [0.0, 1.0, 0.0])
            x /= np.linalg.norm(x)
            R = np.column_stack([x, np.cross(z, x), z])
            return [f'{ind}<geom type="cylinder" pos="{_v(c)}" quat="{_v(quat_of(R))}" '
                    f'size="{_f(0.04 * scale)} {_f(0.005 * scale)}" rgba="0.2 0.4 0.8 1"/>']
        if b.kind in ("motor", "payload"):
            return [f'{ind}<geom type="sphere" pos="{_v(c)}" size="{_f(0.02 * scale)}" rgba="0.3 0.3 0.3 1"/>']
        return []

    def sites(link: str, ind: str) -> list[str]:  # noqa: E306
        lines = []
        for f in d.frames:
            if f.link == link:
                T = np.asarray(f.placement, float)
                lines.append(f'{ind}<site name={quoteattr(names.sites[f.name])} pos="{_v(T[:3, 3])}" '
                             f'quat="{_v(quat_of(T[:3, :3]))}" size="{_f(0.006 * scale)}" group="2"/>')
        lines += [ind + s for s in extra_sites.get(link, [])]
        return lines

    body_index = {b.name: i for i, b in enumerate(mech.model.description.bodies)}

    def extra_bodies(link: str, ind: str) -> list[str]:
        lines = []
        for b in by_link.get(link, []):
            if inertia_is_zero(b):
                # never a name in a comment (a name may hold "--" or "-->"): its index only
                lines.append(f"{ind}<!-- bodies[{body_index[b.name]}]: zero mass and inertia, left out -->")
                continue
            if own.get(link) is b:
                continue
            lines.append(f'{ind}<body name={quoteattr(names.bodies[b.name])}>')
            lines.append(f'{ind}  {_inertial(b.mass, b.com, b.inertia)}')
            lines += body_geom(b, ind + "  ")
            lines.append(f'{ind}</body>')
        if link in minimum_of:
            lines.append(f"{ind}<!-- MuJoCo refuses a moving body without mass or with a zero principal moment -->")
            lines.append(f'{ind}<body name={quoteattr(minimum_of[link])}>')
            inertia = minimum_inertia(mech, minimum_mass)
            lines.append(f'{ind}  {_inertial(minimum_mass, np.zeros(3), inertia * np.eye(3))}')
            lines.append(f'{ind}</body>')
        return lines

    def emit(j, ind: str) -> None:
        T = np.asarray(j.placement, float)
        out.append(f'{ind}<body name={quoteattr(names.links[j.name])} pos="{_v(T[:3, 3])}" quat="{_v(quat_of(T[:3, :3]))}">')
        inner = ind + "  "
        if j.type != _core.JointType.fixed:
            typ = "hinge" if j.type == _core.JointType.revolute else "slide"
            attrs = f'name={quoteattr(j.name)} type="{typ}" axis="{_v(j.axis)}"'
            if math.isfinite(j.lower) or math.isfinite(j.upper):   # an end stop (one side: the other far)
                lower = j.lower if math.isfinite(j.lower) else -ONE_SIDED
                upper = j.upper if math.isfinite(j.upper) else ONE_SIDED
                attrs += (f' range="{_f(lower)} {_f(upper)}" solreflimit="{_v(LIMIT_SOLREF)}"'
                          f' solimplimit="{_v(LIMIT_SOLIMP)}"')
            out.append(f"{inner}<joint {attrs}/>")
            tree_order.append(j.name)
        b = own.get(j.name)
        if b is not None:
            out.append(f"{inner}{_inertial(b.mass, b.com, b.inertia)}")
            out.extend(body_geom(b, inner))
        out.extend(geoms(j.name, inner))
        out.extend(sites(j.name, inner))
        out.extend(extra_bodies(j.name, inner))
        for c in children.get(j.name, []):
            emit(c, inner)
        out.append(f"{ind}</body>")

    out.extend(sites(d.root_name, "    "))
    out.extend(extra_bodies(d.root_name, "    "))
    for j in children.get(d.root_name, []):
        emit(j, "    ")
    out.append("  </worldbody>")
    if tendons:
        out.append("  <tendon>")
        out.extend("    " + t for t in tendons)
        out.append("  </tendon>")
    if equality:
        out.append("  <equality>")
        out.extend("    " + e for e in equality)
        out.append("  </equality>")
    actuated = mech.actuated_names if mech.is_closed else mech.joint_names
    joint_of = {j.name: j for j in d.joints}
    out.append("  <actuator>")
    for n in actuated:
        j = joint_of[n]
        lim = f' forcerange="{_f(-j.effort_limit)} {_f(j.effort_limit)}"' if math.isfinite(j.effort_limit) else ""
        out.append(f'    <motor name={quoteattr(n)} joint={quoteattr(n)} gear="1"{lim}/>')
    out.append("  </actuator>")
    values = full_joint_values(mech, pose)
    out.append("  <keyframe>")
    out.append(f'    <key name="assembled" qpos="{_v([values[n] for n in tree_order])}"/>')
    out.append("  </keyframe>")
    out.append("</mujoco>")
    return "\n".join(out) + "\n", names
