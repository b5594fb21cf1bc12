"""What the counterweight methods share (static, force, rms): slots in the user's frames, probe
columns of the regressors, workspace samples, closed-loop projection, and the two-stage solve of
a balancing condition that is linear in the counterweights' mass moments.

**Why linear.** A counterweight of mass m whose centre of mass is at p in the frame of link L
adds the 10 inertial parameters ``[m, m p, I_c + m (|p|^2 E - p p^T)]`` (about the link origin,
the regressors' convention) to that link. The gravity torque and the linear momentum depend only
on the first four, (m, h = m p): ``G(q) = G_0(q) + sum_k Y_g,L_k(q)[:, 0:4] (m_k, h_k)`` and
``P(q, v) = P_0(q, v) + sum_k Y_P,L_k(q, v)[:, 0:4] (m_k, h_k)``. The columns of a link are the
same for every body on it, so they are read from a *probe*: a copy of the mechanism whose only
bodies are one zero-mass body per slot link.

**Two stages.** (1) The exact least squares ``min |A x + b|`` over the stacked samples, with its
rank, its residual, the minimum-norm solution and a basis of the undetermined combinations (the
null space of A). (2) Among the least-squares solutions, the one with the least added mass that
satisfies the slots' bounds (mass range, distance ``max_radius`` from ``center``, on the line
``direction``) and the mass budget: if there is one the balance is as good as the least squares
allow and the bounds only chose among equals; if there is none, the constrained least squares
(convex: the bounds are linear or second-order cones in (m, h)) is solved instead, and the active
bounds are reported as what limited the balance.

Positions are in the frame the user described each link in (`Mechanism.user_frame`):
the variables are (m, h_user) with ``h_link = R h_user + m t`` for the user frame (R, t).

**Fixed positions.** A slot whose position is given (``position``, or ``max_radius = 0``) has one
unknown, its mass: its four columns collapse to one, ``(1, p)``, and the balance is an exact linear
least squares in the masses (Briot & Arakelian's counterweights at the points of their eqs 11-16).

**Tied slots.** Slots tied to another (``tie``) share its unknowns (m, h_user): the same mass at
the same position in each one's own link frame, as identical legs of a parallel mechanism do.
Their columns are summed (x = E x_group), the bounds are the group's, and the mass budget counts
each member. Without the tie such a system is often rank-deficient (legs driven by one actuator
move no momentum along some combinations of their counterweights).

Layer: methods (docs/architecture.md)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from mechbal import _core
from mechbal.balance.result import BalanceResult, CounterweightDesign, CounterweightSlot

#: a least-squares residual below this fraction of the unbalanced one counts as exact
EXACT_RTOL = 1e-9
#: singular values below this fraction of the largest are zero (undetermined combinations)
RANK_RTOL = 1e-10
#: bounds met to this (relative) tolerance are active
ACTIVE_RTOL = 1e-7


# ---- slots ----------------------------------------------------------------------------------------

@dataclass
class Slot:
    """A `CounterweightSlot` checked against a mechanism: ``T`` (4, 4) is the user frame
    of ``link`` in the link frame (the link's own, or that of the named frame the slot gave as
    its ``link``, e.g. a URDF link); ``center``, ``direction`` (unit or None) and ``inertia`` are
    in the user frame, as given."""

    name: str
    link: str
    mass_min: float
    mass_max: float
    max_radius: float
    center: np.ndarray
    direction: np.ndarray | None
    inertia: np.ndarray
    T: np.ndarray
    field: str
    #: the name the user gave: the link, or a named frame on it (positions are in that frame)
    given: str = ""
    #: the position is given (``position`` or ``max_radius = 0``): only the mass is unknown
    fixed_position: bool = False
    #: the slot whose unknowns this one shares (the root of its tie chain); None: its own
    tie: str | None = None

    @property
    def mass_fixed(self) -> bool:
        return math.isfinite(self.mass_max) and self.mass_max - self.mass_min <= 1e-15 * max(1.0, self.mass_max)

    def link_point(self, p_user: np.ndarray) -> np.ndarray:
        return self.T[:3, :3] @ np.asarray(p_user, float) + self.T[:3, 3]

    def link_inertia(self) -> np.ndarray:
        R = self.T[:3, :3]
        return R @ self.inertia @ R.T


def _finite(x: Any, what: str) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: must be a number (got {x!r})") from None
    if math.isnan(v):
        raise ValueError(f"{what}: must be a number (got nan)")
    return v


_TIED_OWN = (("mass_min", 0.0), ("mass_max", math.inf), ("max_radius", math.inf), ("direction", None),
             ("inertia", None), ("position", None))


def normalise_slots(mech, design: Sequence[CounterweightSlot], *, need_radius: bool = True,
                    field_name: str = "design") -> list[Slot]:
    """Check the slots against ``mech`` (ValueError naming ``design[i].field``): a moving link,
    0 <= mass_min <= mass_max, max_radius >= 0, a non-zero direction, unique names that are not
    already bodies of the mechanism, a ``position`` without ``center``, ``direction`` or a finite
    ``max_radius``, a ``tie`` naming another slot of the design (and no bounds of its own: a tied
    slot takes its group's). With ``need_radius`` a slot whose mass and position are free needs a
    finite ``max_radius`` or ``mass_min > 0`` (otherwise the lightest counterweight is a zero mass
    at an infinite distance)."""
    if isinstance(design, CounterweightSlot):
        design = [design]
    design = list(design)
    if not design:
        raise ValueError(f"{field_name}: no counterweight slots: give at least one")
    names = set(mech.body_names)
    out: list[Slot] = []
    moving = set(mech.link_names[1:])
    frames = {fr.name: fr for fr in mech.model.description.frames}
    slot_names = [getattr(s, "name", None) for s in design]
    for i, s in enumerate(design):
        f = f"{field_name}[{i}]"
        if not isinstance(s, CounterweightSlot):
            raise ValueError(f"{f}: must be a mechbal.balance.CounterweightSlot (got {type(s).__name__})")
        if s.name in names:
            raise ValueError(f"{f}.name: '{s.name}' is already a body of the mechanism or another slot")
        names.add(s.name)
        link, T = s.link, None
        if link not in moving and link in frames and frames[link].link in moving:
            # a named frame on a link (a URDF link's own frame): positions are in that frame
            T = mech.user_frame(frames[link].link) @ np.asarray(frames[link].placement, float)
            link = frames[link].link
        if link not in moving:
            import difflib
            hint = difflib.get_close_matches(str(s.link), sorted(moving) + sorted(frames), n=1)
            more = f" (did you mean '{hint[0]}'?)" if hint else f" (moving links: {', '.join(sorted(moving))})"
            what = "the base does not move" if s.link == mech.model.root_name else "no moving link named"
            raise ValueError(f"{f}.link: {what} '{s.link}'{more}")
        T = mech.user_frame(link) if T is None else T
        if s.tie is not None:
            if s.tie == s.name:
                raise ValueError(f"{f}.tie: a slot cannot be tied to itself ('{s.tie}')")
            if s.tie not in slot_names:
                from mechbal.schema import did_you_mean
                raise ValueError(f"{f}.tie: no counterweight slot named '{s.tie}' in the design"
                                 f"{did_you_mean(str(s.tie), [n for n in slot_names if n and n != s.name])}")
            own = [k for k, default in _TIED_OWN if not _is_default(getattr(s, k), default)]
            if any(float(x) != 0.0 for x in s.center):
                own.insert(0, "center")
            if own:
                raise ValueError(f"{f}.{own[0]}: '{s.name}' is tied to '{s.tie}' and takes its mass, position "
                                 f"and bounds from it: give no {own[0]} of its own")
            out.append(Slot(s.name, link, 0.0, math.inf, math.inf, np.zeros(3), None, np.zeros((3, 3)), T, f,
                            s.link, False, s.tie))
            continue
        lo, hi = _finite(s.mass_min, f"{f}.mass_min"), _finite(s.mass_max, f"{f}.mass_max")
        if lo < 0 or math.isinf(lo):
            raise ValueError(f"{f}.mass_min: must be >= 0 and finite (got {lo})")
        if hi < lo:
            raise ValueError(f"{f}.mass_max: must be >= mass_min = {lo} (got {hi})")
        R = _finite(s.max_radius, f"{f}.max_radius")
        if R < 0:
            raise ValueError(f"{f}.max_radius: must be >= 0 (got {R})")
        c = np.array([_finite(x, f"{f}.center") for x in s.center], float)
        if c.shape != (3,):
            raise ValueError(f"{f}.center: must have 3 values (got {list(s.center)})")
        fixed = R == 0.0
        if s.position is not None:
            if math.isfinite(R):
                raise ValueError(f"{f}.max_radius: the position is given (position = {list(s.position)}): "
                                 f"only the mass is chosen, so give no max_radius (got {R})")
            if s.direction is not None:
                raise ValueError(f"{f}.direction: the position is given (position = {list(s.position)}): "
                                 f"give either position or direction (got {list(s.direction)})")
            if np.any(c != 0.0):
                raise ValueError(f"{f}.center: the position is given (position = {list(s.position)}): give "
                                 f"either position or center (got {list(s.center)})")
            c = np.array([_finite(x, f"{f}.position") for x in s.position], float)
            if c.shape != (3,):
                raise ValueError(f"{f}.position: must have 3 values (got {list(s.position)})")
            R, fixed = 0.0, True
        if need_radius and not fixed and math.isinf(R) and lo == 0.0 and hi > 0.0:
            raise ValueError(f"{f}: give max_radius (or mass_min > 0, or a fixed position): with none, the "
                             "lightest counterweight is a vanishing mass at an infinite distance")
        u = None
        if s.direction is not None and not fixed:
            u = np.array([_finite(x, f"{f}.direction") for x in s.direction], float)
            if u.shape != (3,) or not np.linalg.norm(u) > 0 or not np.all(np.isfinite(u)):
                raise ValueError(f"{f}.direction: must be 3 finite values, not all zero (got {list(s.direction)})")
            u = u / np.linalg.norm(u)
        I = np.zeros((3, 3)) if s.inertia is None else np.asarray(s.inertia, float)
        if I.shape == (3,):
            I = np.diag(I)
        if I.shape != (3, 3) or not np.all(np.isfinite(I)):
            raise ValueError(f"{f}.inertia: must be a 3x3 matrix or 3 principal moments")
        out.append(Slot(s.name, link, lo, hi, R, c, u, 0.5 * (I + I.T), T, f, s.link, fixed))
    # ties: every slot shares the unknowns of the root of its chain, and takes its bounds
    by_name = {s.name: s for s in out}
    for s in out:
        seen, root = [s.name], s
        while root.tie is not None:
            root = by_name[root.tie]
            if root.name in seen:
                raise ValueError(f"{s.field}.tie: the ties form a cycle ({' -> '.join(seen + [root.name])})")
            seen.append(root.name)
        if root is not s:
            s.tie = root.name
            s.mass_min, s.mass_max, s.max_radius = root.mass_min, root.mass_max, root.max_radius
            s.center, s.direction, s.fixed_position = root.center.copy(), root.direction, root.fixed_position
            # the inertia is the root's in its user frame, carried to the member's user frame axes
            s.inertia = root.inertia.copy()
    return out


def _is_default(value, default) -> bool:
    if default is None:
        return value is None
    try:
        return float(value) == default
    except (TypeError, ValueError):
        return False


def tied_groups(slots: Sequence[Slot]) -> dict[str, list[str]]:
    """{root: [root, members...]} of every group of two or more tied slots."""
    groups: dict[str, list[str]] = {}
    for s in slots:
        if s.tie is not None:
            groups.setdefault(s.tie, [s.tie]).append(s.name)
    return groups


def tie_matrix(slots: Sequence[Slot]) -> tuple[np.ndarray, list[Slot], np.ndarray]:
    """(E (4K, 4G), the G group roots, members per group): x of every slot = E x of the roots."""
    roots = [s for s in slots if s.tie is None]
    index = {s.name: g for g, s in enumerate(roots)}
    E = np.zeros((4 * len(slots), 4 * len(roots)))
    count = np.zeros(len(roots))
    for k, s in enumerate(slots):
        g = index[s.tie if s.tie is not None else s.name]
        E[4 * k:4 * k + 4, 4 * g:4 * g + 4] = np.eye(4)
        count[g] += 1
    return E, roots, count


def probe_mechanism(mech, slots: Sequence[Slot]):
    """(probe, column) : ``probe`` is ``mech`` with only one zero-mass body per distinct slot
    link, and ``column[k]`` the first regressor column (of 10) of slot k's link in the probe."""
    links = list(dict.fromkeys(s.link for s in slots))
    bodies = [_core.Body(f"__probe_{i}", link, 0.0, np.zeros(3), np.zeros((3, 3)), "other")
              for i, link in enumerate(links)]
    probe = mech.with_bodies(bodies, replace=True, name=f"{mech.name}-probe")
    return probe, [10 * links.index(s.link) for s in slots]


def user_columns(Y: np.ndarray, slots: Sequence[Slot], column: Sequence[int]) -> np.ndarray:
    """(.., 4K) columns of the unknowns (m_k, h_k in the user frame) from a probe regressor
    (.., 10 L): ``h_link = R h_user + m t``."""
    cols = []
    for s, c in zip(slots, column):
        Ym, Yh = Y[..., c], Y[..., c + 1:c + 4]
        R, t = s.T[:3, :3], s.T[:3, 3]
        cols.append(np.concatenate([(Ym + Yh @ t)[..., None], Yh @ R], axis=-1))
    return np.concatenate(cols, axis=-1)


def unknown_names(slots: Sequence[Slot]) -> list[str]:
    return [f"{s.name}.{k}" for s in slots for k in ("mass", "mass_moment_x", "mass_moment_y", "mass_moment_z")]


def length_scale(mech) -> float:
    """A characteristic length of the mechanism [m] (its joints' offsets), to weigh the mass
    unknowns against the mass moments."""
    d = mech.model.description
    L = sum(float(np.linalg.norm(np.asarray(j.placement)[:3, 3])) for j in d.joints)
    return L if L > 1e-6 else 1.0


def objective_data(kind: str, mech, slots: Sequence[Slot], probe, col, q, C=None):
    """The `mechbal.balance.optimal.Objective` of ``kind`` over the poses ``q`` (closed: C the
    coupling matrices, the actuated coordinates' inertia and torques): "mass" (None: the default),
    "inertia" (per slot W: the mean trace of the joint-space inertia a point mass adds, plus the
    slots' own central inertias as a constant), "torque" (the static torque rows over the
    poses)."""
    from mechbal.balance import optimal

    if kind not in optimal.OBJECTIVES:
        raise ValueError(f"objective: must be one of {', '.join(optimal.OBJECTIVES)} (got {kind!r})")
    if kind == "mass":
        return None
    if kind == "inertia":
        W = optimal.inertia_weights(mech, slots, q, C)
        return optimal.Objective("inertia", W=W)
    Y = probe.gravity_regressor(q)
    A = user_columns(Y, slots, col)
    b = mech.gravity_torque(q)
    if C is not None:
        A = np.einsum("nij,nik->njk", C, A)
        b = np.einsum("nij,ni->nj", C, b)
    return optimal.Objective("torque", rows=(A.reshape(-1, A.shape[-1]), b.reshape(-1)))


# ---- samples ----------------------------------------------------------------------------------------

def sample_box(mech, lower=None, upper=None, coordinates: str = "independent"):
    """(lower, upper) of the sampled coordinates: the given bounds, else the joint limits where
    finite, else [-pi, pi] (revolute) or [-0.5, 0.5] m (prismatic). ``coordinates``: "independent"
    (every q) or "actuated" (q# of a closed mechanism)."""
    idx = (list(mech.model.actuated_coordinates) if coordinates == "actuated" else list(range(mech.dof)))
    lo = np.asarray(mech.model.lower_limits, float)[idx]
    hi = np.asarray(mech.model.upper_limits, float)[idx]
    types = {j.name: j.type for j in mech.model.description.joints}
    names = [mech.joint_names[i] for i in idx]
    default = np.array([0.5 if types.get(n) == _core.JointType.prismatic else math.pi for n in names])
    lo = np.where(np.isfinite(lo), lo, -default)
    hi = np.where(np.isfinite(hi), hi, default)
    if lower is not None:
        lo = np.broadcast_to(np.asarray(lower, float), lo.shape).copy()
    if upper is not None:
        hi = np.broadcast_to(np.asarray(upper, float), hi.shape).copy()
    if np.any(hi < lo):
        raise ValueError(f"samples: upper bound below lower bound ({list(lo)} .. {list(hi)})")
    return lo, hi


def _nearest_neighbour_order(x: np.ndarray) -> np.ndarray:
    """A greedy path through the points (so that warm-started loop solves move little)."""
    n = len(x)
    if n <= 2:
        return np.arange(n)
    order = [int(np.argmin(x[:, 0]))]
    left = np.ones(n, bool)
    left[order[0]] = False
    for _ in range(n - 1):
        d = np.sum((x - x[order[-1]]) ** 2, axis=1)
        d[~left] = np.inf
        k = int(np.argmin(d))
        order.append(k)
        left[k] = False
    return np.array(order)


@dataclass
class ClosedSamples:
    """Solved closed-loop samples: full ``q`` (N, dof), ``v`` (N, dof) or None, coupling matrices
    ``C`` (N, dof, na) with v = C v#, and ``dropped`` instants that could not be assembled."""

    q_actuated: np.ndarray
    q: np.ndarray
    v: np.ndarray | None
    C: np.ndarray
    dropped: int


def closed_samples(mech, q_actuated, v_actuated=None, q_guess=None) -> ClosedSamples:
    """Solve the loops at the actuated positions (visited along a nearest-neighbour path from
    ``q_guess`` so each solve warm-starts the next) and the coupling matrix C at each (one
    velocity solve per actuated joint). Instants that cannot be assembled or are singular are
    dropped (counted)."""
    qa = np.atleast_2d(np.asarray(q_actuated, float))
    order = _nearest_neighbour_order(qa)
    qa = qa[order]
    va = None if v_actuated is None else np.atleast_2d(np.asarray(v_actuated, float))[order]
    na = qa.shape[1]
    cols, status, q = [], None, None
    for i in range(na):
        e = np.zeros_like(qa)
        e[:, i] = 1.0
        m = mech.closed_motion(qa, e, q_guess=q_guess)
        cols.append(m.v)
        status = m.status if status is None else status | m.status
        q = m.q
    C = np.stack(cols, axis=-1)
    ok = np.asarray(status) == 0
    v = None if va is None else np.einsum("nij,nj->ni", C, va)
    return ClosedSamples(qa[ok], q[ok], None if v is None else v[ok], C[ok], int(np.sum(~ok)))


# ---- the linear solve ---------------------------------------------------------------------------------

@dataclass
class LinearSolution:
    """What `solve_mass_moments` found. ``x`` (4K,): (m, h_user) per slot; ``residual`` and
    ``residual_before``: RMS of A x + b and of b over the rows; ``least_squares_residual``: RMS of
    the unconstrained optimum; ``rank`` of A; ``undetermined``: the combinations of unknowns that
    change nothing (a basis of the null space of A); ``active_bounds``; ``limited_by``."""

    x: np.ndarray
    residual: float
    residual_before: float
    least_squares_residual: float
    rank: int
    unknowns: int
    undetermined: list[str]
    active_bounds: list[str]
    limited_by: list[str]
    stage: str
    singular_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: the minimum-norm least-squares solution without bounds, per slot (mass, position)
    unconstrained: dict = field(default_factory=dict)
    #: a lower bound of the lightest design's added mass [kg] (the last relaxation's optimum);
    #: None when no least-squares solution meets the bounds
    lower_bound: float | None = None
    #: the conic solver's certificate (`mechbal.balance.optimal`): stages, duality gaps; None when
    #: solved without it
    certificate: dict | None = None

    def result(self, method: str, slots: Sequence[Slot], design: dict[str, CounterweightDesign],
               residual: float, units: str, metrics: dict[str, Any],
               balanced: Any) -> BalanceResult[CounterweightDesign]:
        """The `BalanceResult` of a method that solved this linear problem (static, force):
        its rank, bounds, undetermined combinations and tied groups."""
        return BalanceResult(method=method, design=design, residual=residual,
                             residual_before=self.residual_before, residual_units=units,
                             rank=self.rank, unknowns=self.unknowns, limited_by=self.limited_by,
                             metrics=metrics, balanced=balanced, active_bounds=self.active_bounds,
                             undetermined=self.undetermined, tied=tied_groups(slots),
                             unconstrained=self.unconstrained)


@dataclass
class LinearProblem:
    """A counterweight balance that is linear in the slots' (m, h): ``A x + b`` over the rows of
    the samples (``static.problem``, ``force.problem``), the objective data of stage 2 and
    ``after(balanced) -> (residual, metrics)``, the residual recomputed from a balanced model.
    `solve` runs `solve_mass_moments` (any budget or residual target), `result` makes the
    `BalanceResult` of a solution."""

    method: str
    mechanism: Any
    slots: list
    A: np.ndarray
    b: np.ndarray
    L: float
    what: str
    components: list
    objective: Any
    units: str
    after: Any
    q: np.ndarray | None = None
    C: np.ndarray | None = None
    v: np.ndarray | None = None

    def __post_init__(self):
        # the rows once reduced to their triangular factor (|A x + b|^2 = |R x + c|^2 + rest): the
        # solves of a front then never touch the N rows again
        if self.A.shape[0] > self.A.shape[1]:
            Q, R = np.linalg.qr(self.A)
            c = Q.T @ self.b
            e = self.b - Q @ c        # the rows' part no design reaches (not |b|^2 - |c|^2: cancellation)
            self._compressed = (R, c, float(e @ e))
        else:
            self._compressed = (self.A, self.b, 0.0)

    def solve(self, *, mass_budget: float | None = None, residual_target: float | None = None,
              certified: bool | None = None) -> LinearSolution:
        """The design of `solve_mass_moments` for this budget and residual target."""
        R, c, rest = self._compressed
        return solve_mass_moments(R, c, self.slots, mass_budget=mass_budget, L=self.L, what=self.what,
                                  components=self.components, objective=self.objective,
                                  residual_target=residual_target, certified=certified,
                                  rows=self.A.shape[0], rest=rest, full=(self.A, self.b))

    def result(self, sol: LinearSolution) -> BalanceResult[CounterweightDesign]:
        design_out, placed = design_from_solution(sol.x, self.slots, sol.active_bounds)
        balanced = balanced_mechanism(self.mechanism, placed)
        residual, metrics = self.after(balanced)
        metrics.update({
            "least_squares_residual": sol.least_squares_residual,
            # conditioning of the design (smallest / largest singular value of the least squares
            # over the free variables, masses scaled by the mechanism's length): how well the
            # samples separate the slots' effects
            "singular_value_ratio": (float(sol.singular_values[-1] / sol.singular_values[0])
                                     if len(sol.singular_values) and sol.singular_values[0] > 0 else None),
            "solve": sol.stage,
            "added_mass": float(sum(m for _, m, _ in placed)),
        })
        if sol.certificate is not None:
            metrics["optimality"] = sol.certificate
        return sol.result(self.method, self.slots, design_out, residual, self.units, metrics, balanced)


def _rref(M: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    M = M.astype(float).copy()
    rows, cols = M.shape
    r = 0
    for c in range(cols):
        if r >= rows:
            break
        p = r + int(np.argmax(np.abs(M[r:, c])))
        if abs(M[p, c]) <= tol:
            continue
        M[[r, p]] = M[[p, r]]
        M[r] /= M[r, c]
        for i in range(rows):
            if i != r:
                M[i] -= M[i, c] * M[r]
        r += 1
    M[np.abs(M) < tol] = 0.0
    return M[:r]


def describe_null_space(Z: np.ndarray, names: Sequence[str]) -> list[str]:
    """Each basis vector of the null space as ``"a name + b name"``: a direction (masses in kg,
    moments in kg m) along which the unknowns can move together without changing the condition
    (reduced row echelon form, so most are a single unknown or a short combination)."""
    if Z.shape[1] == 0:
        return []
    out = []
    for row in _rref(Z.T):
        row = row / np.max(np.abs(row))
        terms = [(c, n) for c, n in zip(row, names) if abs(c) > 1e-9]
        if len(terms) == 1:
            out.append(terms[0][1])
        else:
            out.append(" ".join(f"{'+' if c > 0 else '-'} {abs(c):.6g} {n}" for c, n in terms).lstrip("+ "))
    return out


class _Design:
    """The design freedom of the slots as an affine map x = P y + x_c from the free variables y
    to (m, h_user) per slot: per slot its mass (scaled by the length scale L: y = m L, so that
    every variable is in kg m) unless fixed, and its offset moment d = m (p - center) (3 values,
    or 1 along ``direction``): h = m center + d. The bounds are functions of y: mass range and
    budget (linear), ``|d| <= max_radius m`` (linear along a direction, a second-order cone
    otherwise)."""

    def __init__(self, slots: Sequence[Slot], mass_budget: float | None, L: float, count=None):
        self.slots, self.L = list(slots), L
        #: members per slot (a tied group counts each of its slots in the mass budget)
        self.count = np.ones(len(slots)) if count is None else np.asarray(count, float)
        n = 4 * len(slots)
        cols, names, self.mass_var, self.d_vars = [], [], [], []
        xc = np.zeros(n)
        for k, s in enumerate(slots):
            i = 4 * k
            if s.mass_fixed:
                xc[i] = s.mass_min
                xc[i + 1:i + 4] = s.mass_min * s.center
                self.mass_var.append(None)
            else:
                c = np.zeros(n)
                c[i] = 1.0 / L
                c[i + 1:i + 4] = s.center / L
                self.mass_var.append(len(cols))
                cols.append(c), names.append(f"{s.name}.mass")
            if s.fixed_position:   # h = m p: the mass is the only unknown
                dirs, labels = [], []
            elif s.direction is not None:
                dirs, labels = [s.direction], ["mass_moment_along_direction"]
            else:
                dirs, labels = list(np.eye(3)), ["mass_moment_x", "mass_moment_y", "mass_moment_z"]
            idx = []
            for u, lab in zip(dirs, labels):
                c = np.zeros(n)
                c[i + 1:i + 4] = u
                idx.append(len(cols))
                cols.append(c), names.append(f"{s.name}.{lab}")
            self.d_vars.append(idx)
        self.P = np.array(cols).T.reshape(n, len(cols))
        self.xc = xc
        self.names = names
        self.budget = mass_budget if mass_budget is not None and math.isfinite(mass_budget) else None
        ny = len(cols)
        # linear inequalities G y + g >= 0, each with a name and a scale (kg or kg m)
        G, g, lin_names, lin_scale = [], [], [], []
        for k, s in enumerate(slots):
            j = self.mass_var[k]
            if j is not None:
                r = np.zeros(ny)
                r[j] = 1.0 / L
                G.append(r), g.append(-s.mass_min), lin_names.append(f"{s.name}.mass_min"), lin_scale.append(1.0)
                if math.isfinite(s.mass_max):
                    G.append(-r), g.append(s.mass_max), lin_names.append(f"{s.name}.mass_max"), lin_scale.append(1.0)
            if s.direction is not None and math.isfinite(s.max_radius) and not s.fixed_position:
                (jd,) = self.d_vars[k]
                for sign in (1.0, -1.0):  # R m -+ d >= 0
                    r = np.zeros(ny)
                    r[jd] = -sign
                    const = 0.0
                    if j is not None:
                        r[j] = s.max_radius / L
                    else:
                        const = s.max_radius * s.mass_min
                    G.append(r), g.append(const), lin_names.append(f"{s.name}.max_radius"), lin_scale.append(L)
        if self.budget is not None:
            r = np.zeros(ny)
            const = self.budget
            for k, s in enumerate(slots):
                if self.mass_var[k] is None:
                    const -= self.count[k] * s.mass_min
                else:
                    r[self.mass_var[k]] = -self.count[k] / L
            G.append(r), g.append(const), lin_names.append("mass_budget"), lin_scale.append(1.0)
        self.G = np.array(G).reshape(-1, ny)
        self.g = np.array(g)
        self.lin_names, self.lin_scale = lin_names, np.array(lin_scale)
        self.cones = [k for k, s in enumerate(slots)
                      if s.direction is None and math.isfinite(s.max_radius) and not s.fixed_position]
        self.mass_row = np.zeros(ny)  # total free mass (kg) = mass_row @ y
        for k, j in enumerate(self.mass_var):
            if j is not None:
                self.mass_row[j] = self.count[k] / L

    def x(self, y):
        return self.P @ y + self.xc

    def project(self, y):
        """``y`` with the slots' bounds met exactly where an interior-point solve left them met to
        its tolerance: masses into their ranges, each offset moment scaled into its radius (a
        change of the order of the solver's feasibility tolerance)."""
        y = np.array(y, float)
        for k, s in enumerate(self.slots):
            j = self.mass_var[k]
            if j is not None:
                y[j] = min(max(y[j], s.mass_min * self.L), s.mass_max * self.L)
            m = y[j] / self.L if j is not None else s.mass_min
            if math.isfinite(s.max_radius) and not s.fixed_position and self.d_vars[k]:
                d = y[self.d_vars[k]]
                nd = float(np.linalg.norm(d))
                if nd > s.max_radius * m:
                    y[self.d_vars[k]] = d * (s.max_radius * max(m, 0.0) / nd)
        if self.budget is not None:
            total = float(self.mass_row @ y) + sum(self.count[k] * s.mass_min for k, s in enumerate(self.slots)
                                                   if self.mass_var[k] is None)
            if total > self.budget and total > 0:
                # a budget met to the tolerance: scale the free masses and moments down together
                f = max(self.budget - (total - float(self.mass_row @ y)), 0.0) / max(float(self.mass_row @ y), 1e-300)
                if f < 1.0:
                    for k in range(len(self.slots)):
                        if self.mass_var[k] is not None:
                            y[self.mass_var[k]] *= f
                            y[self.d_vars[k]] *= f
        return y

    def _mass(self, k, y):
        j = self.mass_var[k]
        return (y[j] / self.L, 1.0 / self.L) if j is not None else (self.slots[k].mass_min, 0.0)

    def cone(self, y):
        """(R m - |d|) / L (>= 0), kg; |d| smoothed at d = 0 by 1e-12 L."""
        out = []
        eps = 1e-12 * self.L
        for k in self.cones:
            m, _ = self._mass(k, y)
            d = y[self.d_vars[k]]
            out.append((self.slots[k].max_radius * m - math.sqrt(d @ d + eps * eps)) / self.L)
        return np.array(out)

    def cone_jac(self, y):
        J = np.zeros((len(self.cones), len(y)))
        eps = 1e-12 * self.L
        for r, k in enumerate(self.cones):
            _, dm = self._mass(k, y)
            d = y[self.d_vars[k]]
            if self.mass_var[k] is not None:
                J[r, self.mass_var[k]] = self.slots[k].max_radius * dm / self.L
            J[r, self.d_vars[k]] = -d / math.sqrt(d @ d + eps * eps) / self.L
        return J

    def slack(self, y):
        """[(name, slack in its unit, scale)] of every inequality: >= 0 when met."""
        out = []
        if len(self.g):
            for name, v, sc in zip(self.lin_names, self.G @ y + self.g, self.lin_scale):
                out.append((name, float(v), float(sc)))
        for k in self.cones:
            m, _ = self._mass(k, y)
            out.append((f"{self.slots[k].name}.max_radius",
                        float(self.slots[k].max_radius * m - np.linalg.norm(y[self.d_vars[k]])), self.L))
        return out

    def violation(self, y, mscale) -> float:
        """Largest violation, in kg (moments divided by L), relative to the mass scale."""
        return max([0.0] + [-v / (sc * mscale) for _, v, sc in self.slack(y)])

    def active(self, y, mscale) -> list[str]:
        return list(dict.fromkeys(n for n, v, sc in self.slack(y) if v <= ACTIVE_RTOL * sc * mscale))

    def scipy(self, to_y, jac_y):
        cons = []
        if len(self.g):
            cons.append({"type": "ineq", "fun": lambda z: (self.G @ to_y(z) + self.g) / self.lin_scale,
                         "jac": lambda z: (self.G @ jac_y) / self.lin_scale[:, None]})
        if self.cones:
            cons.append({"type": "ineq", "fun": lambda z: self.cone(to_y(z)),
                         "jac": lambda z: self.cone_jac(to_y(z)) @ jac_y})
        return cons


def _slsqp(fun, starts, cons, violation, tol, maxiter=1000, ftol=1e-16):
    """Best SLSQP result over the starts (feasible first, then the least objective); trust-constr
    when SLSQP finds nothing feasible."""
    from scipy.optimize import minimize

    best, best_key = None, None
    for start in starts:
        for method in ("SLSQP",):
            r = minimize(fun, start, jac=True, method=method, constraints=cons,
                         options=dict(ftol=ftol, maxiter=maxiter))
            key = (violation(r.x) > tol, float(fun(r.x)[0]))
            if best is None or key < best_key:
                best, best_key = r.x, key
    return best


#: the cone cuts stop when every cone |d| <= R m is met to this fraction of the mass scale
CONE_RTOL = 1e-11
#: at most this many rounds of cone cuts (each one linear program)
MAX_CUT_ROUNDS = 200


def _start_directions() -> np.ndarray:
    """The 14 unit directions of the first outer approximation of a 3-D cone: +-axes and the
    eight diagonals (a polytope circumscribing the cone's cross-section ball)."""
    diag = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], float) / math.sqrt(3.0)
    return np.vstack([np.eye(3), -np.eye(3), diag])


def lightest_within_bounds(dsg: "_Design", y0: np.ndarray, Z: np.ndarray, mscale: float):
    """The lightest design among the least-squares solutions y = y0 + Z z that meet the bounds:

        min  sum_k count_k m_k   over z
        s.t. G y + g >= 0                 (mass ranges, mass budget, radius along a line)
             |d_k| <= R_k m_k              (radius around a centre: a second-order cone)

    a convex program. It is solved by outer approximation: each cone is replaced by the tangent
    planes u . d <= R m of a set of unit directions u (14 at first); the linear program (HiGHS,
    ``scipy.optimize.linprog``) is solved, a tangent plane is added at each cone the solution
    leaves (u = d / |d|), until every cone is met to CONE_RTOL of the mass scale. Each linear
    program is a relaxation, so its optimum is a lower bound of the true one (the dual of the last
    one is a dual certificate of the convex program); the last solution, polished on the exact cones
    by SLSQP, meets them to CONE_RTOL and stays on the least-squares set.

    Returns (y, lower bound [kg]) or None when no least-squares solution meets the bounds (or the
    solver fails)."""
    from scipy.optimize import linprog

    ny = len(y0)
    c = (dsg.mass_row @ Z) / mscale
    rows, rhs = [], []
    if len(dsg.g):               # G (y0 + Z z) + g >= 0  ->  -G Z z <= G y0 + g, in kg
        sc = (dsg.lin_scale * mscale)[:, None]
        rows.append(-(dsg.G @ Z) / sc)
        rhs.append((dsg.G @ y0 + dsg.g) / sc[:, 0])

    def cut(k, u):
        """u . d - R m <= 0 as a row over z (in kg)."""
        s = dsg.slots[k]
        j = dsg.mass_var[k]
        a = u @ Z[dsg.d_vars[k]]
        r = -(u @ y0[dsg.d_vars[k]])
        if j is not None:
            a = a - s.max_radius / dsg.L * Z[j]
            r = r + s.max_radius / dsg.L * y0[j]
        else:
            r = r + s.max_radius * s.mass_min
        return a / (dsg.L * mscale), r / (dsg.L * mscale)

    for k in dsg.cones:
        for u in _start_directions():
            a, r = cut(k, u)
            rows.append(a[None, :]), rhs.append(np.array([r]))
    bound = None
    z_last = None
    for _ in range(MAX_CUT_ROUNDS):
        A_ub = np.vstack(rows) if rows else None
        b_ub = np.concatenate(rhs) if rhs else None
        res = linprog(c, A_ub=A_ub, b_ub=b_ub, bounds=[(None, None)] * Z.shape[1], method="highs",
                      options=dict(primal_feasibility_tolerance=1e-10, dual_feasibility_tolerance=1e-10))
        if res.status != 0:
            return None
        z = res.x
        y = y0 + Z @ z
        bound = float(dsg.mass_row @ y)
        if z_last is not None and np.array_equal(z, z_last):
            # stalled: the last round's cuts did not move the optimum (they are met to the LP's
            # feasibility tolerance, 1e-10, above CONE_RTOL), so every further round would add the
            # same cuts again and solve the same LP; the polish below meets the cones instead
            break
        z_last = z
        worst, added = 0.0, False
        for k in dsg.cones:
            m, _ = dsg._mass(k, y)
            dk = y[dsg.d_vars[k]]
            nd = float(np.linalg.norm(dk))
            over = (nd - dsg.slots[k].max_radius * m) / (dsg.L * mscale)
            worst = max(worst, over)
            if over > CONE_RTOL and nd > 0:
                a, r = cut(k, dk / nd)
                rows.append(a[None, :]), rhs.append(np.array([r]))
                added = True
        if not added:
            break
    if dsg.cones:
        # the cuts meet the cones to CONE_RTOL in mass, which leaves an error of its square root in
        # a position along a flat direction: polish on the exact cones from the relaxation's
        # optimum (SLSQP, starting at the optimal active set), kept when it is as light and feasible
        to_y = lambda zz: y0 + Z @ zz  # noqa: E731
        g = c.copy()
        zp = _slsqp(lambda zz: (float(c @ zz), g), [z], dsg.scipy(to_y, Z),
                    lambda zz: dsg.violation(to_y(zz), mscale), 1e-12)
        if (dsg.violation(to_y(zp), mscale) <= 1e-11
                and float(dsg.mass_row @ to_y(zp)) <= bound + 1e-9 * mscale):
            z = zp
    # y stays on the least-squares set (y0 + Z z): each cone is met to CONE_RTOL of the mass scale
    # (a radius beyond its bound by that fraction), which is kept rather than pulling d onto the
    # cone and leaving the least squares
    y = y0 + Z @ z
    if dsg.violation(y, mscale) > 1e-9:
        return None
    return y, bound


def solve_mass_moments(A: np.ndarray, b: np.ndarray, slots: Sequence[Slot], *,
                       mass_budget: float | None = None, L: float = 1.0,
                       what: str = "the balancing condition",
                       components: Sequence[str] | None = None, objective: Any = None,
                       residual_target: float | None = None,
                       certified: bool | None = None, rows: int | None = None, rest: float = 0.0,
                       full: tuple[np.ndarray, np.ndarray] | None = None) -> LinearSolution:
    """The two stages of the module docstring for ``A x + b = 0`` (rows: every sample and
    component; x: (m, h_user) per slot). The least squares is over the design's free variables
    (a fixed mass is not an unknown; a slot with a direction has one moment along it).
    ``components``: the names of the components of one sample (the rows are sample-major), e.g.
    "gravity torque of joint 'elbow'": ``limited_by`` names those the slots cannot cancel.

    ``objective`` (`mechbal.balance.optimal.Objective`, per slot: default the added mass) and
    ``residual_target`` (RMS over the rows): the lexicographic convex program of
    `mechbal.balance.optimal` (least residual, then the least objective among the designs of that
    residual, or within the target). ``certified``: solve it with the conic solver (the
    ``optimal`` extra) and keep its certificate in ``certificate``; None: when the extra is
    installed (otherwise the mass objective by polyhedral cuts and SLSQP, without certificate;
    another objective or a target then needs the extra). ``rows``, ``rest``, ``full``: ``A``, ``b``
    are a compressed form of the ``full`` rows (their triangular factor: `LinearProblem`), whose RMS
    is ``sqrt((|A x + b|^2 + rest) / rows)``."""
    A = np.asarray(A, float)
    b = np.asarray(b, float).reshape(-1)
    if A.shape[0] == 0:
        raise ValueError("samples: no usable sample (every closed-loop sample failed to assemble?)")
    E, roots, count = tie_matrix(slots)      # tied slots share their group's unknowns
    A = A @ E
    dsg = _Design(roots, mass_budget, L, count)
    Ay = A @ dsg.P
    by = A @ dsg.xc + b
    ny = Ay.shape[1]
    nrows = A.shape[0] if rows is None else int(rows)
    before = float(np.sqrt((b @ b + rest) / nrows))
    rms = lambda y: float(np.sqrt((np.sum((Ay @ y + by) ** 2) + rest) / nrows))  # noqa: E731
    if ny:
        U, sv, Vt = np.linalg.svd(Ay, full_matrices=False)
        rank = int(np.sum(sv > RANK_RTOL * sv[0])) if sv[0] > 0 else 0
        y0 = Vt[:rank].T @ ((U[:, :rank].T @ -by) / sv[:rank])
        Z = Vt[rank:].T
    else:
        sv, rank, y0, Z = np.zeros(0), 0, np.zeros(0), np.zeros((0, 0))
    ls = rms(y0)
    unit = np.array([1.0 / L if n.endswith(".mass") else 1.0 for n in dsg.names])
    undetermined = describe_null_space(unit[:, None] * Z, dsg.names)
    mscale = max([1.0] + [abs(s.mass_min) for s in roots] + [abs(v) / L for v in y0])
    tol = 1e-9

    from mechbal.balance import optimal

    if certified is None:
        certified = optimal.available() or objective is not None or residual_target is not None
    certificate = None
    y_limits = None
    d = Z.shape[1]
    y = y0
    lower_bound = None
    if certified:
        obj = optimal.Objective() if objective is None else objective
        if obj.kind == "inertia" and obj.W is not None:     # per slot -> per tied group (x_k = x_root)
            Wg = [np.zeros((4, 4)) for _ in roots]
            for k in range(len(slots)):
                g = int(np.argmax(E[4 * k]))
                Wg[g // 4] += obj.W[k]
            obj = optimal.Objective("inertia", W=Wg, constant=obj.constant)
        if obj.kind == "torque" and obj.rows is not None:
            obj = optimal.Objective("torque", rows=(obj.rows[0] @ E, obj.rows[1]))
        conv = optimal.solve(dsg, Ay, by, Z, mscale, objective=obj, residual_target=residual_target, y0=y0,
                             rows=nrows, rest=rest)
        # y as solved, on the least-residual set: the bounds are met to the solver's feasibility
        # tolerance (``bound_violation``, relative to the mass scale), as the cuts below meet them to
        # CONE_RTOL, rather than projected onto them at the cost of the residual
        y = conv.y
        y_limits = conv.y_least
        certificate = conv.certificate(obj.kind)
        certificate["least_residual"] = conv.least_residual
        certificate["objective_value"] = conv.objective
        certificate["residual_target"] = residual_target
        certificate["bound_violation"] = dsg.violation(y, mscale)
        stage = ("least residual within the bounds, then the least " + obj.kind +
                 (f" within the residual target {residual_target:.6g}" if residual_target is not None else
                  " among its designs") + " (convex program, certified)")
        d = 0   # skip the uncertified stages below
    if d and not certified:
        # stage 2a: the lightest least-squares solution within the bounds: a convex program (linear
        # objective, linear bounds, second-order cones), solved by HiGHS on polyhedral outer
        # approximations of the cones (`lightest_within_bounds`)
        found = lightest_within_bounds(dsg, y0, Z, mscale)
        if found is not None:
            y, lower_bound = found
        else:
            y = y0
    elif not certified and dsg.violation(y0, mscale) <= tol:
        lower_bound = float(dsg.mass_row @ y0)
    if not certified:
        stage = "least squares within the bounds"
    if not certified and dsg.violation(y, mscale) > tol:
        # stage 2b: no least-squares solution meets the bounds: constrained least squares, on the
        # triangular factor (|A y + b|^2 = |R y + Q^T b|^2 + const: ny x ny, whatever the rows)
        Qf, Rf = np.linalg.qr(Ay)
        cf = Qf.T @ by
        bs = max(float(cf @ cf), 1e-300)

        def g(yy):
            r = Rf @ yy + cf
            return float(r @ r) / bs, 2.0 * (Rf.T @ r) / bs

        starts = [y, np.zeros(ny)]
        y = _slsqp(g, starts, dsg.scipy(lambda yy: yy, np.eye(ny)), lambda yy: dsg.violation(yy, mscale), tol,
                   ftol=1e-13)
        if Z.shape[1]:
            # lexicographic: the lightest of the designs with this residual (same A y: y + Z z)
            found = lightest_within_bounds(dsg, y, Z, mscale)
            if found is not None:
                y = found[0]
        stage = "constrained least squares (the bounds exclude every least-squares solution)"
    x = E @ dsg.x(y)
    residual = rms(y)
    # the bounds that limit the balance: those active at the least-residual design (where a band
    # design stands in for it, it may sit ~1e-6 inside them)
    active = dsg.active(y if y_limits is None else y_limits, mscale)
    limited = []
    scale = max(before, 1e-300)
    x0 = E @ dsg.x(y0)
    unconstrained = unconstrained_design(x0, slots)
    if ls > EXACT_RTOL * scale:
        left = uncancelled((Ay @ y0 + by) if full is None else (full[0] @ E @ dsg.x(y0) + full[1]),
                           components, EXACT_RTOL * scale)
        limited.append(f"impossible: rank {rank} of {ny} unknowns and a least-squares residual of "
                       f"{ls:.6g} (RMS; {100 * ls / scale:.3g} % of the unbalanced {before:.6g}): these "
                       f"slots cannot make {what} zero over the samples"
                       + (f"; not cancelled: {left}" if left else ""))
    if residual_target is not None and residual <= residual_target * (1 + 1e-6) + EXACT_RTOL * scale:
        limited = []     # the target was asked for and is met
    elif residual > max(ls * (1 + 1e-6), EXACT_RTOL * scale):
        limited += [f"bound: {a}" for a in active] or ["bound: the solver could not meet the bounds "
                                                      f"(violation {dsg.violation(y, mscale):.3g})"]
        limited.append(f"unconstrained: without the bounds the least squares (residual {ls:.6g}) asks "
                       f"for {describe_unconstrained(unconstrained)}")
    return LinearSolution(x, residual, before, ls, rank, ny, undetermined, active, limited, stage, sv,
                          unconstrained=unconstrained, lower_bound=lower_bound, certificate=certificate)


def uncancelled(r: np.ndarray, components: Sequence[str] | None, floor: float) -> str:
    """The components of the residual rows ``r`` (sample-major) that are not cancelled, largest
    first, with their RMS: "gravity torque of joint 'rocker' (RMS 0.31), ...". Components below
    1e-6 of the largest (or ``floor``) are cancelled."""
    if not components:
        return ""
    n = len(components)
    r = np.asarray(r, float).reshape(-1, n)
    per = np.sqrt(np.mean(r ** 2, axis=0))
    top = float(per.max()) if per.size else 0.0
    keep = [i for i in np.argsort(-per) if per[i] > max(1e-6 * top, floor)]
    return ", ".join(f"{components[i]} (RMS {per[i]:.3g})" for i in keep)


def unconstrained_design(x: np.ndarray, slots: Sequence[Slot]) -> dict:
    """{slot: {mass, mass_moment, position}} of the (minimum-norm) least-squares solution without
    any bound: what the balance asks for, before the mass ranges, radii and budget."""
    out = {}
    for k, s in enumerate(slots):
        m, h = float(x[4 * k]), np.array(x[4 * k + 1:4 * k + 4])
        p = s.center.copy() if s.fixed_position or abs(m) <= 1e-12 else h / m
        out[s.name] = {"mass": m, "mass_moment": h, "position": p,
                       "radius": float(np.linalg.norm(p - s.center))}
    return out


def describe_unconstrained(design: dict) -> str:
    """The mass moments m p (what the balance fixes) and masses of the minimum-norm solution."""
    return "; ".join(f"{n} mass moment [{', '.join(f'{v:.4g}' for v in d['mass_moment'])}] kg m "
                     f"(minimum-norm mass {d['mass']:.4g} kg)" for n, d in design.items())


def design_from_solution(x: np.ndarray, slots: Sequence[Slot],
                         active: Sequence[str]) -> tuple[dict[str, CounterweightDesign], list[Any]]:
    """(design dict per slot, [(slot, mass, position_user)]) from (m, h_user) per slot: position
    h/m (on the slot's line when it has a direction; the given one when it is fixed); a vanishing
    mass sits at the centre. Tied slots say which slot they are tied to (``tied_to``)."""
    design: dict[str, CounterweightDesign] = {}
    placed: list[Any] = []
    for k, s in enumerate(slots):
        m, h = float(x[4 * k]), np.array(x[4 * k + 1:4 * k + 4])
        if s.fixed_position:
            m, p = max(m, 0.0), s.center.copy()
        elif m > 1e-12 * max(1.0, abs(s.mass_max) if math.isfinite(s.mass_max) else 1.0):
            p = h / m
            if s.direction is not None:
                p = s.center + s.direction * float(s.direction @ (p - s.center))
        else:
            m, p = max(m, 0.0), s.center.copy()
        design[s.name] = _slot_design(s, m, p, active)
        placed.append((s, m, p))
    return design, placed


def _slot_design(s: Slot, m: float, p: np.ndarray, active: Sequence[str],
                 method: str | None = None) -> CounterweightDesign:
    given = s.given or s.link
    frame = (f"frame '{given}' (on link '{s.link}')" if given != s.link else
             f"the frame link '{s.link}' is described in" + ("" if np.allclose(s.T, np.eye(4)) else " (its DH frame)"))
    return CounterweightDesign(
        link=s.link, mass=m, position=p, radius=float(np.linalg.norm(p - s.center)),
        mass_moment=m * p, frame=frame,
        bounds={"mass_min": s.mass_min, "mass_max": _or_none(s.mass_max),
                "max_radius": _or_none(s.max_radius), "center": s.center, "direction": s.direction},
        active_bounds=[a[len(key) + 1:] for key in [s.tie or s.name] for a in active
                       if a.startswith(key + ".")],
        signed_distance=(float(s.direction @ (p - s.center)) if s.direction is not None else None),
        fixed_position=bool(s.fixed_position), tied_to=s.tie, method=method)


def _or_none(x: float):
    """An unbounded bound is absent (None in summary.json), not infinity."""
    return float(x) if math.isfinite(x) else None


def reduction_pct(before, after):
    """100 (1 - after / before) per entry; None where before is 0 (nothing to reduce)."""
    b, a = np.atleast_1d(np.asarray(before, float)), np.atleast_1d(np.asarray(after, float))
    return [None if bi == 0 else 100.0 * (1.0 - ai / bi) for bi, ai in zip(b, a)]


def balanced_mechanism(mech, placed) -> Any:
    """``mech`` with each slot's counterweight added as a body of kind ``counterweight`` (point
    mass plus the slot's inertia)."""
    bodies = [_core.Body(s.name, s.link, float(m), s.link_point(p), s.link_inertia(), "counterweight")
              for s, m, p in placed]
    return mech.with_bodies(bodies, name=f"{mech.name}-balanced")
