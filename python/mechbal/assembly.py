"""Assembly of closed mechanisms: which branch a four-bar-like loop is on, and the assembly at the
start of a motion on a requested branch (``[trajectory] branch = "open" | "crossed"``), from the
actuated joints alone.

A loop is **four-bar-like** when the cycle it closes has four pivots with parallel axes: three
revolute joints of the tree (fixed joints between them are allowed) and the loop's own pin (a
``point`` or ``planar_point`` closure), and the actuated joint of the cycle is one of the two
pivots on the ground link (the link where the two branches of the cycle meet: the base or any
link). Call O2 the actuated pivot, A the next pivot along the input link (the crank pin), B the
pin between the two passive links and O4 the other ground pivot. For one input angle B has two
positions, mirror images across the line A-O4. Viewed along the actuated joint's axis (so that
the crank turns counterclockwise), the loop is

* **open** when B lies to the left of the line from A to O4: ``((O4 - A) x (B - A)) . axis > 0``;
* **crossed** when it lies to the right.

This is the sign choice of Freudenstein's solution (Norton, *Design of Machinery*, eq 4.10: the
minus root is the open circuit): where the crank pin A is to the left of O2 -> O4, the open
branch is the uncrossed quadrilateral O2 A B O4 of the textbook figures. The sign changes only
where B crosses the line A-O4, a toggle (singular) position, so a branch is a circuit that the
loop solve follows; summary.json also reports the branch at the end of the motion. Loops that are
not four-bar-like have no branch name: pick their assembly with a full ``initial_guess``.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import mechbal._core as _core
from mechbal.errors import ConfigError

__all__ = ["FourBarLoop", "four_bar_loops", "loop_branches", "assemble", "Assembly", "BRANCHES"]

BRANCHES = ("open", "crossed")
#: candidate assemblies tried by `assemble` (a grid of the passive joints, then random ones)
MAX_TRIES = 256
#: |sin| between two axes below which they are parallel
PARALLEL_TOL = 1e-9


@dataclass(frozen=True)
class FourBarLoop:
    """A four-bar-like loop (module docstring): its name, the pivots around the cycle (joint
    names; ``None`` for the loop's own pin, P2), the link indices of the three joints' links, the
    loop's frame_a (its pin) and which pivot is actuated (0 or 3)."""

    name: str
    pivots: tuple
    links: tuple
    frame: str
    actuated: int


def _chain(parents: list[int], link: int) -> list[int]:
    out = []
    while link >= 0:
        out.append(link)
        link = parents[link]
    return out


def four_bar_loops(mech) -> tuple[list[FourBarLoop], dict[str, str]]:
    """(the four-bar-like loops of ``mech``, {loop name: why it is not four-bar-like} for the
    others). The parallel-axes check needs a pose: `loop_branches` makes it."""
    model = mech.model
    d = model.description
    links = list(model.link_names)
    parents = list(model.link_parents)
    joints = {j.name: j for j in d.joints}
    frame_link = {f.name: f.link for f in d.frames}
    actuated = {model.coordinate_names[i] for i in model.actuated_coordinates}
    found, other = [], {}
    for loop in d.loops:
        if loop.type not in (_core.LoopType.point, _core.LoopType.planar_point):
            other[loop.name] = f"a {loop.type.name} closure, not a pin"
            continue
        la, lb = (links.index(frame_link[f]) if frame_link[f] in links else -1 for f in (loop.frame_a, loop.frame_b))
        ca, cb = _chain(parents, la), _chain(parents, lb)
        common = set(ca) & set(cb)
        pa = [k for k in ca if k not in common]     # frame_a's link up to below the ground link
        pb = [k for k in cb if k not in common]
        path = [k for k in reversed(pa)] + [None] + pb   # P0 .. pin .. P3, fixed joints included
        moving = [k for k in path if k is None or joints[links[k]].type != _core.JointType.fixed]
        kinds = {joints[links[k]].type for k in moving if k is not None}
        if len(moving) != 4 or kinds != {_core.JointType.revolute}:
            other[loop.name] = (f"its cycle has {len(moving)} pivots (a four-bar has four: three revolute "
                                "joints and the loop's pin)")
            continue
        names = tuple(None if k is None else links[k] for k in moving)
        on = [i for i in (0, 3) if names[i] in actuated]
        if len(on) != 1 or sum(n in actuated for n in names if n is not None) != 1:
            other[loop.name] = "its actuated joint is not one of the two pivots on the ground link"
            continue
        found.append(FourBarLoop(loop.name, names, tuple(moving), loop.frame_a, on[0]))
    return found, other


def _branch(points: np.ndarray, axis: np.ndarray, k: int) -> str:
    """'open' or 'crossed' of the four pivots ``points`` (4, 3) around the cycle, the actuated
    pivot ``k`` (0 or 3) turning about ``axis`` (module docstring)."""
    o2, a, b, o4 = points if k == 0 else points[::-1]
    side = float(np.dot(np.cross(o4 - a, b - a), axis))
    return "open" if side > 0.0 else "crossed"


def loop_branches(mech, q, loops: list[FourBarLoop] | None = None) -> dict[str, str | None]:
    """{loop name: "open" | "crossed"} of every four-bar-like loop at the full coordinates ``q``
    ((dof,)); ``None`` for a loop whose pivot axes are not parallel there."""
    if loops is None:
        loops = four_bar_loops(mech)[0]
    if not loops:
        return {}
    motion = mech.body_motion(np.asarray(q, float))
    axes = {j.name: np.asarray(j.axis, float) for j in mech.model.description.joints}
    links = list(mech.model.link_names)
    frames = list(mech.frame_names)
    out: dict[str, str | None] = {}
    for lp in loops:
        pts, normals = [], []
        for name, link in zip(lp.pivots, lp.links):
            if name is None:
                pts.append(motion.frame_placement[frames.index(lp.frame), :3, 3])
                continue
            i = links.index(name)
            pts.append(motion.link_position[i])
            a = motion.link_rotation[i] @ axes[name]
            normals.append(a / np.linalg.norm(a))
        n = normals[0]
        if any(np.linalg.norm(np.cross(n, m)) > PARALLEL_TOL for m in normals[1:]):
            out[lp.name] = None
            continue
        axis = normals[0] if lp.actuated == 0 else normals[-1]   # the actuated joint's axis
        out[lp.name] = _branch(np.array(pts), axis, lp.actuated)
    return out


@dataclass(frozen=True)
class Assembly:
    """The assembly at the start of a motion: full coordinates ``q`` (dof,), the branch of each
    four-bar-like loop (``branches``), and how it was chosen (``source``: "branch" (requested),
    "initial_guess" (a full guess), "default" (open))."""

    q: np.ndarray
    branches: dict
    source: str

    def summary(self) -> dict:
        """What summary.json says about it (``loops.assembly``)."""
        return {"branch": dict(self.branches), "chosen_by": self.source}


def assemble(mech, q_actuated, *, branch: str | None = None, initial_guess=None,
             field: str = "trajectory") -> Assembly:
    """The assembly of closed ``mech`` at the actuated coordinates ``q_actuated`` (na,).

    * ``initial_guess`` of every coordinate (dof values) and no ``branch``: the loops are solved
      from it (the branch it lands on is reported);
    * otherwise (``branch`` given, an ``initial_guess`` of the actuated joints only (na values),
      or none): every four-bar-like loop on ``branch`` (default ``"open"``), searched from a grid
      of the passive joints (a full guess is tried first).

    ConfigError naming ``{field}.branch`` / ``{field}.initial_guess`` when the branch does not
    apply or the mechanism cannot be assembled there."""
    qa = np.asarray(q_actuated, float).reshape(-1)
    model = mech.model
    act, pas = list(model.actuated_coordinates), list(model.passive_coordinates)
    guess = None if initial_guess is None else np.asarray(initial_guess, float).reshape(-1)
    if guess is not None and guess.size not in (mech.dof, len(act)):
        raise ConfigError(f"{field}.initial_guess", f"must have {mech.dof} values (every joint coordinate: "
                          f"{', '.join(model.coordinate_names)}) or {len(act)} (the actuated joints: "
                          f"{', '.join(mech.actuated_names)})", guess.tolist())
    if branch is not None and branch not in BRANCHES:
        raise ConfigError(f"{field}.branch", "must be 'open' or 'crossed'", branch)
    loops, other = four_bar_loops(mech)
    if branch is not None and not loops:
        why = "; ".join(f"{k}: {v}" for k, v in other.items())
        raise ConfigError(f"{field}.branch", f"applies to four-bar-like loops only ({why}); give a full "
                          "initial_guess instead", branch)

    def solve(g):
        m = mech.closed_motion(qa, q_guess=g)
        if int(m.status) & ~int(_core.Status.singular):
            return None
        return np.asarray(m.q, float)

    full = guess is not None and guess.size == mech.dof
    if full and branch is None:
        q = solve(guess)
        if q is None:
            raise ConfigError(f"{field}.initial_guess", "the loops cannot be assembled from it at the "
                              "trajectory's start", guess.tolist())
        return Assembly(q, loop_branches(mech, q, loops), "initial_guess")
    if not loops:   # nothing to choose between: the passive joints from zero (or the guess)
        g = np.zeros(mech.dof)
        g[act] = qa if guess is None else guess
        q = solve(g)
        if q is None:
            raise ConfigError(f"{field}.initial_guess" if guess is not None else field,
                              "the loops cannot be assembled at the trajectory's start from zero passive "
                              "joints: give a full initial_guess", has_value=False)
        return Assembly(q, {}, "initial_guess" if guess is not None else "default")
    want = branch or "open"
    rng = np.random.default_rng(0)
    grid = np.linspace(-np.pi, np.pi, 8, endpoint=False)
    candidates = []
    if full:
        candidates.append(guess)
    base = np.zeros(mech.dof)
    base[act] = qa
    if len(pas) <= 2:
        for vals in np.array(np.meshgrid(*[grid] * len(pas))).reshape(len(pas), -1).T:
            g = base.copy()
            g[pas] = vals
            candidates.append(g)
    while len(candidates) < MAX_TRIES:
        g = base.copy()
        g[pas] = rng.uniform(-np.pi, np.pi, len(pas))
        candidates.append(g)
    seen_any = False
    for g in candidates[:MAX_TRIES]:
        q = solve(g)
        if q is None:
            continue
        seen_any = True
        b = loop_branches(mech, q, loops)
        if all(v == want for v in b.values()):
            return Assembly(q, b, "branch" if branch is not None else "default")
    if not seen_any:
        raise ConfigError(field, "the loops cannot be assembled at the trajectory's start (no assembly "
                                 f"found from {MAX_TRIES} guesses): check the geometry and start", has_value=False)
    raise ConfigError(f"{field}.branch", f"no assembly with every four-bar-like loop {want} at the "
                      f"trajectory's start (from {MAX_TRIES} guesses)", want)
