"""Spring static balancing, for any mechanism (issue 11, method 4).

A mechanism is statically balanced when its total potential energy -- gravity plus springs -- is
constant over the workspace; then the static joint forces vanish:
``gravity_torque(q) + spring_torque(q) = dV/dq = 0`` (Martini, Troncossi, Carricato & Rivola 2015,
eqs 11-14; Herder 2001). This module generalises the paper's distal and proximal devices (eqs 5-6,
9-10, 15-19) to springs between any two anchor points of any two links.

**Spring model** (one `SpringSlot`). ``count`` identical springs in
parallel, each of rate ``rate`` [N/m] and initial tension ``preload`` [N], act between anchor A on
``link_a`` and anchor B on ``link_b`` through a block and tackle of ratio ``k = pulley_ratio``: the
anchor distance d changes k times as much as the springs' length. By virtual work (cable tension T
at the anchors, spring force f_s each: ``T dd = count f_s dd/k``) the tension at the anchors is
``T = count f_s / k`` and the equivalent rate at the anchors is

    K_eq = dT/dd = count * rate / k**2                       (Martini et al. 2015, Tables 1-2)

``free_length`` L0 is the anchor distance at which each spring carries only its preload (a direct
spring's own free length; with cables, set by the cable length), so

    T(d) = count * preload / k + K_eq (d - L0),   V(d) = count * preload / k (d - L0) + K_eq (d - L0)^2 / 2.

A zero-free-length (ZFL) spring has L0 = 0 and no preload: T = K_eq d, V = K_eq d^2 / 2 (eqs 6, 10).
The model holds while every spring is stretched (d >= L0); the result flags samples where not.

**Generalised forces.** With u = (r_B - r_A)/d and J_A, J_B the linear rows of the Jacobians of
the anchor points, the joint forces that hold the springs still (the convention of
`mechbal.Mechanism.gravity_torque`) are

    spring_torque = dV/dq = T (J_B - J_A)^T u = J_A^T f - J_B^T f,   f = -T u

(f the force the spring exerts on B). The springs are elements of the mechanism model
(``mechbal.Spring``, ``cpp/include/mechbal/algorithm/springs.hpp``): lengths, tensions, energy and
these joint forces are computed there, and the balanced mechanism returned by `balance`
carries its springs, so its inverse dynamics, static torque and simulation include them. A slot
becomes a model spring through `model_spring` (an anchor given in a named frame, e.g. a DH
frame, moved into its link's frame).

**Sizing** (`balance`). For fixed anchors, free lengths and preloads, T and V are affine in
the rates, so "gravity torque + spring torque = 0 at every sample" is a linear least-squares
problem in the equivalent rates (bounds: 0 <= rate <= rate_max; rank and residual reported).
Anchors left free within bounds (``anchor_a_bounds``, ``anchor_b_bounds``) are found by nonlinear
least squares (scipy ``least_squares``) around that linear solve (variable projection). Closed
mechanisms are balanced in their actuated coordinates (C^T (G + tau_s) = 0 on the loop-solved
configurations).

**Catalogue selection** (`select_springs`, `load_catalogue`): clusters of identical
off-the-shelf springs and a block-and-tackle ratio whose equivalent rate and peak force meet the
theoretical ones, with the anchor correction the chosen rate implies (for a ZFL spring
``rate * anchor offset`` is what balances: eqs 15-19, Table 1 second row) and the total spring
mass (Table 2).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import csv
import dataclasses
import io
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np

from mechbal import _core
from mechbal.balance.result import BalanceResult, SpringSlot
from mechbal.mechanism import Mechanism

__all__ = ["spring_torque", "potential_energy", "spring_energy", "spring_tension", "spring_lengths",
           "gravity_potential_energy", "equivalent_rate", "balance", "model_spring", "with_springs",
           "design_from_table", "CatalogueSpring", "SpringCluster", "load_catalogue", "select_springs",
           "select_for_result"]



# ------------------------------------------------------------------------------------------------
# Spring laws
# ------------------------------------------------------------------------------------------------
def equivalent_rate(slot: SpringSlot) -> float:
    """K_eq = count * rate / pulley_ratio**2 [N/m]: the rate seen at the anchors (module docstring)."""
    if slot.rate is None:
        raise ValueError(f"springs.{slot.name}.rate: not set (size it with mechbal.balance.springs.balance)")
    return _count(slot) * float(slot.rate) / float(slot.pulley_ratio) ** 2


def _count(slot: SpringSlot) -> int:
    return int(getattr(slot, "count", 1))


def _preload_at_anchors(slot: SpringSlot) -> float:
    return _count(slot) * float(getattr(slot, "preload", 0.0)) / float(slot.pulley_ratio)


def _check_slot(slot: SpringSlot) -> None:
    name = f"springs.{slot.name}"
    if not (slot.pulley_ratio > 0 and math.isfinite(slot.pulley_ratio)):
        raise ValueError(f"{name}.pulley_ratio: must be > 0 (got {slot.pulley_ratio})")
    if _count(slot) < 1:
        raise ValueError(f"{name}.count: must be >= 1 (got {_count(slot)})")
    if not (slot.free_length >= 0 and math.isfinite(slot.free_length)):
        raise ValueError(f"{name}.free_length: must be >= 0 (got {slot.free_length})")
    if slot.rate is not None and not (slot.rate >= 0 and math.isfinite(slot.rate)):
        raise ValueError(f"{name}.rate: must be >= 0 (got {slot.rate})")
    for side in ("a", "b"):
        a = np.asarray(getattr(slot, f"anchor_{side}"), float)
        if a.shape != (3,) or not np.all(np.isfinite(a)):
            raise ValueError(f"{name}.anchor_{side}: must be 3 finite numbers (got {getattr(slot, f'anchor_{side}')})")


# ------------------------------------------------------------------------------------------------
# The springs on the model: a SpringSlot becomes a mechbal.Spring of the mechanism (C++ model)
# ------------------------------------------------------------------------------------------------
def _reference(mechanism: Mechanism, slot: SpringSlot, side: str) -> tuple[str, np.ndarray]:
    """(link, (4, 4) placement of the anchor's reference frame in the link frame) of an anchor:
    ``link_a``/``link_b`` names a link (a joint's name, or the root) or a named frame."""
    ref = getattr(slot, f"link_{side}")
    if ref in mechanism.link_names:
        return ref, np.eye(4)
    for f in mechanism.model.description.frames:
        if f.name == ref:
            return f.link, np.asarray(f.placement, float)
    from mechbal.schema import did_you_mean
    more = did_you_mean(ref, sorted(set(mechanism.link_names) | set(mechanism.frame_names)))
    raise ValueError(f"springs.{slot.name}.link_{side}: no link or frame named '{ref}'{more}")


def model_spring(mechanism: Mechanism, slot: SpringSlot, *, anchors=None, probe: bool = False) -> "_core.Spring":
    """The `mechbal.Spring` of a slot on ``mechanism`` (anchors moved into the link frames
    when the slot names a frame). ``anchors``: (anchor_a, anchor_b) overriding the slot's;
    ``probe``: a unit-tension spring (tension 1 N at any length, no rate) whose energy is the
    anchor distance d and whose joint force is dd/dq -- what the least squares are built from."""
    _check_slot(slot)
    aa, ab = (slot.anchor_a, slot.anchor_b) if anchors is None else anchors
    ends = []
    for side, anchor in (("a", aa), ("b", ab)):
        link, T = _reference(mechanism, slot, side)
        ends.append((link, T[:3, :3] @ np.asarray(anchor, float) + T[:3, 3]))
    if probe:
        return _core.Spring(slot.name, ends[0][0], ends[0][1], ends[1][0], ends[1][1], 0.0, 0.0, 1.0, 1, 1.0)
    if slot.rate is None:
        raise ValueError(f"springs.{slot.name}.rate: not set (size it with mechbal.balance.springs.balance)")
    return _core.Spring(slot.name, ends[0][0], ends[0][1], ends[1][0], ends[1][1], float(slot.rate),
                        float(slot.free_length), float(getattr(slot, "preload", 0.0)), _count(slot),
                        float(slot.pulley_ratio))


def with_springs(mechanism: Mechanism, springs: Sequence[SpringSlot], *, replace: bool = False,
                 name: str | None = None) -> Mechanism:
    """``mechanism`` with the (sized) slots as springs of its model (``replace``: instead of its
    own springs): what its inverse dynamics, static torque, energy and simulation then include."""
    try:
        return mechanism.with_springs([model_spring(mechanism, s) for s in springs], replace=replace, name=name)
    except ValueError as exc:
        if str(exc).startswith("springs."):
            raise
        raise ValueError(f"springs: {exc}") from None


def _geometry(mechanism: Mechanism, springs: Sequence[SpringSlot], q: np.ndarray,
              overrides: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None):
    """Per spring: anchor distance d (N,) and its gradient dd/dq (N, dof), from the model (a
    unit-tension probe spring: its energy is d, its joint force dd/dq)."""
    out = []
    for s in springs:
        probe = model_spring(mechanism, s, anchors=(overrides or {}).get(s.name), probe=True)
        m = mechanism.with_springs([probe], replace=True)
        r = _core.mechanism_springs(m.model, np.ascontiguousarray(q, dtype=float))
        if np.any(np.asarray(r["status"]) != 0):
            raise ValueError(f"springs.{s.name}: its length cannot be evaluated at some samples (non-finite)")
        out.append((np.asarray(r["spring_length"])[:, 0], np.asarray(r["spring_torque"])))
    return out


def _prepare(mechanism: Mechanism, springs, q):
    springs = list(springs)
    for s in springs:
        _check_slot(s)
    q = np.asarray(q, float)
    single = q.ndim == 1
    return springs, np.atleast_2d(q), single


def _evaluated(mechanism: Mechanism, springs: Sequence[SpringSlot], need_rate: bool = True) -> Mechanism:
    """The mechanism with exactly these springs (its own replaced); without ``need_rate`` an
    unsized slot counts with rate 0 (for lengths)."""
    if not need_rate:
        springs = [s if s.rate is not None else dataclasses.replace(s, rate=0.0) for s in springs]
    return with_springs(mechanism, springs, replace=True)


# ------------------------------------------------------------------------------------------------
# Public helpers: evaluated by the model with exactly the given springs (its own replaced)
# ------------------------------------------------------------------------------------------------
def spring_lengths(mechanism: Mechanism, springs: Sequence[SpringSlot], q) -> np.ndarray:
    """Anchor distances d [m] of each spring: (S,) for one configuration, (N, S) for a batch."""
    springs, q2, single = _prepare(mechanism, springs, q)
    d = _evaluated(mechanism, springs, need_rate=False).spring_lengths(q2)
    return d[0] if single else d


def spring_tension(mechanism: Mechanism, springs: Sequence[SpringSlot], q) -> np.ndarray:
    """Tension T [N] at the anchors of each spring (module docstring): (S,) or (N, S)."""
    springs, q2, single = _prepare(mechanism, springs, q)
    T = _evaluated(mechanism, springs).spring_tension(q2)
    return T[0] if single else T


def spring_energy(mechanism: Mechanism, springs: Sequence[SpringSlot], q) -> np.ndarray:
    """Elastic potential energy of all springs [J] (zero when every spring is at its free length):
    a float for one configuration, (N,) for a batch."""
    springs, q2, single = _prepare(mechanism, springs, q)
    V = np.atleast_1d(_evaluated(mechanism, springs).spring_energy(q2))
    return float(V[0]) if single else V


def gravity_potential_energy(mechanism: Mechanism, q) -> np.ndarray:
    """-m g . c(q) [J]: the gravity potential energy of all bodies, zero at the base origin."""
    c = mechanism.center_of_mass(q)
    V = -mechanism.total_mass * (np.asarray(c) @ mechanism.gravity)
    return float(V) if np.ndim(V) == 0 else V


def potential_energy(mechanism: Mechanism, springs: Sequence[SpringSlot], q) -> np.ndarray:
    """Total potential energy, gravity plus springs [J]: constant over the workspace exactly when
    the mechanism is statically balanced (Martini et al. 2015, eq 11)."""
    springs, q2, single = _prepare(mechanism, springs, q)
    V = np.atleast_1d(_evaluated(mechanism, springs).potential_energy(q2))
    return float(V[0]) if single else V


def spring_torque(mechanism: Mechanism, springs: Sequence[SpringSlot], q) -> np.ndarray:
    """Joint forces that hold the springs still, dV_springs/dq = J_A^T f - J_B^T f [N m or N]
    (f the force each spring exerts on its anchor B), in the coordinates of ``mechanism``
    (for a closed mechanism the full tree coordinates: project with C^T). Same convention as
    `mechbal.Mechanism.gravity_torque`: the static motor torque is their sum.
    (dof,) for one configuration, (N, dof) for a batch."""
    springs, q2, single = _prepare(mechanism, springs, q)
    tau = _evaluated(mechanism, springs).spring_torque(q2)
    return tau[0] if single else tau
# ------------------------------------------------------------------------------------------------
# Sizing
# ------------------------------------------------------------------------------------------------
def _coupling_matrices(mechanism: Mechanism, samples: np.ndarray, q_guess=None, closure_tolerance: float = 1e-13):
    """Loop-solved configurations q (N, dof) and coupling matrices C (N, dof, na) of a closed
    mechanism over actuated samples (N, na)."""
    na = len(mechanism.model.actuated_coordinates)
    guess = None if q_guess is None else np.asarray(q_guess, float)
    m = mechanism.closed_motion(samples, q_guess=guess, tolerance=closure_tolerance)
    bad = np.asarray(m.status).astype(np.int64) & ~int(_core.Status.singular)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"samples[{i}]: the loops cannot be solved there (status {int(m.status[i])}); "
                         "give reachable actuated positions in a continuous order, or q_guess")
    C = np.zeros((len(samples), mechanism.dof, na))
    for k in range(na):
        e = np.zeros_like(samples)
        e[:, k] = 1.0
        C[:, :, k] = mechanism.closed_motion(samples, e, q_guess=guess, tolerance=closure_tolerance).v
    return np.asarray(m.q), C


def _as_springs(design) -> list[SpringSlot]:
    if isinstance(design, SpringSlot):
        return [design]
    if isinstance(design, Mapping):
        design = design.get("springs", [])
    springs = list(design)
    for s in springs:
        if not isinstance(s, SpringSlot):
            raise TypeError(f"design: springs must be SpringSlot objects, got {type(s).__name__}")
    names = [s.name for s in springs]
    if len(set(names)) != len(names):
        raise ValueError(f"design: spring names must be unique (got {names})")
    if not springs:
        raise ValueError("design: no spring slots")
    return springs


def _bounds_of(slot: SpringSlot, side: str):
    b = getattr(slot, f"anchor_{side}_bounds", None)
    if b is None:
        return None
    lo, hi = (np.asarray(x, float) for x in b)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(lo > hi):
        raise ValueError(f"springs.{slot.name}.anchor_{side}_bounds: must be (lower xyz, upper xyz) with "
                         f"lower <= upper (got {b})")
    return lo, hi


def balance(mechanism: Mechanism, design, samples, *, q_guess=None, tolerance: float = 1e-9,
            max_nfev: int = 200, catalogue=None, closure_tolerance: float = 1e-13, **options) -> BalanceResult:
    """Size springs so that gravity torque + spring torque = 0 over a workspace sample.

    ``design``: `SpringSlot` objects (or ``{"springs": [...]}``).
    A slot with ``rate=None`` has its rate chosen (0 <= rate <= ``rate_max``); a slot with
    ``anchor_a_bounds`` / ``anchor_b_bounds`` has those anchor coordinates chosen within the
    bounds (coordinates with equal lower and upper bounds stay fixed).
    ``samples``: configurations (N, dof); for a closed mechanism the actuated positions (N, na)
    (solved with ``closed_motion`` from ``q_guess``, in the given order) and the balance holds in
    the actuated coordinates; ``closure_tolerance`` [m] of that loop solve (stiff springs need a
    tighter one: a closure error e leaves about K e on the actuators).

    Returns a `BalanceResult`: ``design[name]`` with ``rate`` [N/m] (each spring),
    ``equivalent_rate`` [N/m] at the anchors, the anchors, ``peak_tension`` [N],
    ``min_stretch`` [m]; ``residual`` the peak static joint force left (gravity + springs) [N m
    or N], ``residual_before`` the peak gravity torque; ``rank``/``unknowns`` of the linear rate
    problem; ``limited_by`` naming a rank deficiency, an active bound, a slack spring or an
    impossibility; ``metrics`` with peak and RMS static torque per joint before and after and the
    potential-energy variation (max - min [J]) before and after; ``elements`` the sized slots;
    ``balanced`` the mechanism with the sized springs as elements of its model (what the static
    torque after, the tensions and the energy are evaluated on). The springs cancel the static
    torque of ``mechanism`` as it is (gravity, and the springs it may already have).
    With ``catalogue`` (a path, a list of `CatalogueSpring`, or "shipped"),
    ``metrics["catalogue"]`` holds the ranked clusters of `select_for_result` per spring.
    """
    from scipy.optimize import least_squares, lsq_linear

    if options:
        raise TypeError(f"balance() got unexpected options: {', '.join(sorted(options))}")
    springs = _as_springs(design)
    for s in springs:
        _check_slot(s)
    samples = np.atleast_2d(np.asarray(samples, float))
    closed = mechanism.is_closed
    if closed:
        na = len(mechanism.model.actuated_coordinates)
        if samples.shape[1] != na:
            raise ValueError(f"samples: a closed mechanism is sampled by its {na} actuated positions "
                             f"(N, {na}), got {samples.shape}")
        q, C = _coupling_matrices(mechanism, samples, q_guess, closure_tolerance)
    else:
        if samples.shape[1] != mechanism.dof:
            raise ValueError(f"samples: must have shape (N, {mechanism.dof}), got {samples.shape}")
        q, C = samples, None
    if not np.all(np.isfinite(q)):
        raise ValueError("samples: must be finite")

    for s in springs:  # names the bad link or frame before any work
        model_spring(mechanism, s, probe=True)
    # what the springs must cancel: the static torque of the mechanism as it is (its weights and
    # any springs it already has)
    G = np.atleast_2d(mechanism.static_torque(q))

    def project(x):  # (N, dof, ...) -> actuated rows, flattened per sample
        return np.einsum("ndk,nd...->nk...", C, x) if closed else x

    Gp = project(G)
    n_rows = Gp.size
    free = [i for i, s in enumerate(springs) if s.rate is None]
    fixed = [i for i, s in enumerate(springs) if s.rate is not None]

    # free anchor coordinates: (slot index, side, coordinate index, lower, upper)
    free_coords = []
    for i, s in enumerate(springs):
        for side in ("a", "b"):
            b = _bounds_of(s, side)
            if b is None:
                continue
            for c in range(3):
                if b[1][c] > b[0][c]:
                    free_coords.append((i, side, c, b[0][c], b[1][c]))
    x0 = []
    for i, side, c, lo, hi in free_coords:
        x0.append(float(np.clip(getattr(springs[i], f"anchor_{side}")[c], lo, hi)))

    def anchors_from(x):
        out = {s.name: [np.array(s.anchor_a, float), np.array(s.anchor_b, float)] for s in springs}
        for xv, (i, side, c, _, _) in zip(x, free_coords):
            out[springs[i].name][0 if side == "a" else 1][c] = xv
        return {k: (v[0], v[1]) for k, v in out.items()}

    # scaled equivalent-rate unknowns: K_eq = scale * z (conditioning of the linear problem)
    def linear_system(x):
        geo = _geometry(mechanism, springs, q, anchors_from(x))
        rhs = -Gp.copy()
        cols = []
        for i, (s, (d, grad)) in enumerate(zip(springs, geo)):
            x_s = d - s.free_length
            if i in fixed:
                T = _preload_at_anchors(s) + equivalent_rate(s) * x_s
                rhs -= project(T[:, None] * grad)
            else:
                rhs -= project(_preload_at_anchors(s) * grad)
                cols.append(project(x_s[:, None] * grad).reshape(-1))
        A = np.stack(cols, axis=1) if cols else np.zeros((n_rows, 0))
        return A, rhs.reshape(-1), geo

    def bounds_K():
        lo, hi = [], []
        for i in free:
            s = springs[i]
            f = _count(s) / s.pulley_ratio ** 2
            lo.append(f * float(getattr(s, "rate_min", 0.0)))
            hi.append(f * float(s.rate_max))
        return np.array(lo), np.array(hi)

    Klo, Khi = bounds_K()

    def solve_rates(A, rhs):
        if A.shape[1] == 0:
            return np.zeros(0), []
        scale = np.linalg.norm(A, axis=0)
        scale[scale == 0] = 1.0
        As = A / scale
        z, *_ = np.linalg.lstsq(As, rhs, rcond=None)
        K = z / scale
        if np.all(K >= Klo - 1e-12 * np.maximum(1, np.abs(K))) and np.all(K <= Khi):
            return np.clip(K, Klo, Khi), []
        r = lsq_linear(As, rhs, bounds=(Klo * scale, np.where(np.isinf(Khi), np.inf, Khi * scale)),
                       method="bvls", tol=1e-14)
        K = r.x / scale
        active = [f"bound: {springs[i].name}.rate {'>= rate_min' if abs(K[j] - Klo[j]) <= 1e-12 * max(1, Khi[j] if np.isfinite(Khi[j]) else 1) else '<= rate_max'}"
                  for j, i in enumerate(free)
                  if abs(K[j] - Klo[j]) <= 1e-12 * max(1.0, abs(K[j])) or (np.isfinite(Khi[j]) and abs(K[j] - Khi[j]) <= 1e-12 * abs(Khi[j]))]
        return K, active

    x_opt = np.array(x0)
    nls = None
    if free_coords:
        def fun(x):
            A, rhs, _ = linear_system(x)
            K, _ = solve_rates(A, rhs)
            return A @ K - rhs

        lo = np.array([fc[3] for fc in free_coords])
        hi = np.array([fc[4] for fc in free_coords])
        nls = least_squares(fun, x_opt, bounds=(lo, hi), x_scale="jac", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=max_nfev)
        x_opt = nls.x

    A, rhs, geo = linear_system(x_opt)
    K, active = solve_rates(A, rhs)
    unknowns = len(free)
    rank = int(np.linalg.matrix_rank(A / np.where(np.linalg.norm(A, axis=0) > 0, np.linalg.norm(A, axis=0), 1.0),
                                     tol=1e-10)) if unknowns else 0

    # the sized springs
    chosen = anchors_from(x_opt)
    sized: list[SpringSlot] = []
    for i, s in enumerate(springs):
        aa, ab = chosen[s.name]
        rate = s.rate
        if i in free:
            rate = float(K[free.index(i)] * s.pulley_ratio ** 2 / _count(s))
        sized.append(dataclasses.replace(s, rate=rate, anchor_a=tuple(map(float, aa)), anchor_b=tuple(map(float, ab))))

    # evaluation of the sized design on the same sample, by the model with the springs on it
    balanced = with_springs(mechanism, sized)
    columns = [balanced.spring_names.index(s.name) for s in sized]
    lengths = np.atleast_2d(balanced.spring_lengths(q))[:, columns]
    tensions = np.atleast_2d(balanced.spring_tension(q))[:, columns]
    design_out: dict[str, dict[str, Any]] = {}
    limited: list[str] = []
    for i, s in enumerate(sized):
        d, T = lengths[:, i], tensions[:, i]
        x_s = d - s.free_length
        design_out[s.name] = {
            "rate": s.rate, "rate_N_per_mm": s.rate / 1000.0, "equivalent_rate": equivalent_rate(s),
            "count": _count(s), "pulley_ratio": s.pulley_ratio, "free_length": s.free_length,
            "preload": float(getattr(s, "preload", 0.0)),
            "link_a": s.link_a, "anchor_a": list(s.anchor_a), "link_b": s.link_b, "anchor_b": list(s.anchor_b),
            "peak_tension": float(np.max(T)), "min_tension": float(np.min(T)),
            "peak_length": float(np.max(d)), "min_length": float(np.min(d)),
            "min_stretch": float(np.min(x_s)),
            "peak_force_per_spring": float(np.max(T)) * s.pulley_ratio / _count(s),
        }
        if np.min(x_s) < -1e-12 and equivalent_rate(s) > 0:
            limited.append(f"slack: {s.name} is shorter than its free length at some samples "
                           f"(min stretch {np.min(x_s):.4g} m): the spring model does not hold there")
    static_before = Gp
    static_after = project(np.atleast_2d(balanced.static_torque(q)))
    residual = float(np.max(np.abs(static_after))) if static_after.size else 0.0
    residual_before = float(np.max(np.abs(static_before))) if static_before.size else 0.0
    V_before = np.atleast_1d(mechanism.potential_energy(q))
    V = np.atleast_1d(balanced.potential_energy(q))
    exact_tol = tolerance * max(1.0, residual_before)
    limited += active
    # the rates the least squares asks for without bounds (anchors as chosen), and what stops them
    unconstrained = _unconstrained_rates(A, rhs, springs, free, Klo, Khi)
    for name, u in unconstrained["springs"].items():
        for i, a in enumerate(limited):
            if a.startswith(f"bound: {name}.rate"):
                limited[i] = f"{a} ({u['stopped_by']})"
    active_bounds = [a[len("bound: "):].split(" ")[0].rsplit(".rate", 1)[0]
                     + (".rate_min" if ">= rate_min" in a else ".rate_max") for a in active]
    notes = []
    if unknowns and rank < unknowns:
        msg = (f"rank {rank} < {unknowns} unknowns: some spring rates act alike over the sample "
               "(the minimum-norm rates are reported)")
        (limited if residual > exact_tol else notes).append(msg)
    for i, side, c, lo, hi in free_coords:
        val = chosen[springs[i].name][0 if side == "a" else 1][c]
        if residual > exact_tol and (abs(val - lo) <= 1e-9 * max(1, abs(lo)) or abs(val - hi) <= 1e-9 * max(1, abs(hi))):
            limited.append(f"bound: {springs[i].name}.anchor_{side}[{c}] at {'lower' if abs(val - lo) <= abs(val - hi) else 'upper'} bound {val:.6g}")
            active_bounds.append(f"{springs[i].name}.anchor_{side}_bounds[{c}]")
    if residual > exact_tol:
        limited.append(f"impossible: gravity + spring torque {residual:.3g} N m remains (relative "
                       f"{residual / max(residual_before, 1e-300):.2e}); these slots cannot make the "
                       "potential energy constant over the sample; without bounds the least squares "
                       f"asks for {_describe_rates(unconstrained)} (peak static torque "
                       f"{unconstrained['residual']:.3g} N m)")
    names = mechanism.actuated_names if closed else mechanism.joint_names

    def per_joint(x):
        return {n: {"peak": float(np.max(np.abs(x[:, j]))), "rms": float(np.sqrt(np.mean(x[:, j] ** 2)))}
                for j, n in enumerate(names)}

    metrics = {
        "static_torque_before": per_joint(static_before), "static_torque_after": per_joint(static_after),
        "potential_energy_variation_before": float(np.ptp(V_before)),
        "potential_energy_variation_after": float(np.ptp(V)),
        "samples": int(len(q)),
        "spring_mass_note": "springs are massless here; add their mass as bodies if they move",
        "notes": notes,
    }
    if nls is not None:
        metrics["anchor_search"] = {"evaluations": int(nls.nfev), "status": int(nls.status),
                                    "message": str(nls.message)}
    result = BalanceResult(method="springs", design=design_out, residual=residual,
                           residual_before=residual_before, residual_units="N m (N on prismatic joints)",
                           rank=rank if unknowns else None, unknowns=unknowns, limited_by=limited,
                           metrics=metrics, balanced=balanced, elements=sized,
                           active_bounds=list(dict.fromkeys(active_bounds)), unconstrained=unconstrained)
    if catalogue is not None:
        springs_cat = catalogue if isinstance(catalogue, Sequence) and not isinstance(catalogue, str) \
            else load_catalogue(None if str(catalogue) == "shipped" else catalogue)
        clusters = select_for_result(mechanism, result, q, springs_cat)
        metrics["catalogue"] = {
            "source": "mechbal/data/springs.csv" if isinstance(catalogue, str) and catalogue == "shipped"
            else (str(catalogue) if isinstance(catalogue, (str, Path)) else "given"),
            "note": "clusters of identical catalogue springs behind a block and tackle, ranked by total "
                    "spring mass (Martini et al. 2015, Tables 1-2); the anchors stay, so a chosen rate "
                    "that differs from the sized one leaves a small residual",
            "springs": {name: [c.summary() for c in cands] for name, cands in clusters.items()}}
        for name, cands in clusters.items():
            if not cands:
                notes.append(f"catalogue: no cluster implements {name} (rate "
                             f"{design_out[name]['equivalent_rate']:.4g} N/m, peak {design_out[name]['peak_tension']:.4g} N)")
    return result


# ------------------------------------------------------------------------------------------------
# mechbal balance CASE --method springs: the [balance] table
# ------------------------------------------------------------------------------------------------
DEFAULT_SAMPLES = 1000


def design_from_table(table, mechanism: Mechanism):
    """(design, samples, options) of a validated ``[balance]`` table for `balance` (what
    ``mechbal balance --method springs`` runs): the ``[[balance.springs]]`` slots with their
    anchors moved from the frames the user described the links in (`Mechanism.user_frame`)
    into the link frames; ``balance.samples`` (default 1000) random poses in
    ``balance.lower``..``balance.upper`` (default the joint limits, else +-pi / +-0.5 m) drawn
    with ``balance.seed`` -- for a closed mechanism its actuated coordinates, in a nearest-neighbour
    order so that the warm-started loop solves move little; ``balance.catalogue`` (a CSV path
    relative to the case file, or "shipped") as the ``catalogue`` option. ConfigError naming the
    field otherwise."""
    from mechbal.balance import common
    from mechbal.errors import ConfigError
    from mechbal.schema import did_you_mean

    entries = list(table.springs) if table is not None else []
    if not entries:
        raise ConfigError("balance.springs", "no spring slots: add [[balance.springs]] entries (name, link_a, "
                                             "anchor_a, link_b, anchor_b, rate or rate_min / rate_max)",
                          has_value=False)
    root = mechanism.model.root_name
    links = mechanism.link_names
    frames = mechanism.frame_names
    slots = []
    for i, e in enumerate(entries):
        field = f"balance.springs[{i}]"
        anchors, refs, bounds = [], [], []
        for side in ("a", "b"):
            ref = getattr(e, f"link_{side}")
            link = root if ref == "base" else ref
            a = np.asarray(getattr(e, f"anchor_{side}"), float)
            b = getattr(e, f"anchor_{side}_bounds")
            b = None if b is None else (np.asarray(b[0], float), np.asarray(b[1], float))
            if link in links:
                T = mechanism.user_frame(link)
                R, t = T[:3, :3], T[:3, 3]
                a = R @ a + t
                if b is not None:
                    if not np.allclose(np.abs(R), np.eye(3)) or not np.allclose(R, np.diag(np.diag(R))):
                        raise ConfigError(f"{field}.anchor_{side}_bounds", "anchor bounds on a link described in "
                                          "a rotated frame (a DH frame) are not supported: give them on "
                                          "a link without rotation", [list(x) for x in b])
                    lo, hi = R @ b[0] + t, R @ b[1] + t
                    b = (np.minimum(lo, hi), np.maximum(lo, hi))
            elif link not in frames:
                raise ConfigError(f"{field}.link_{side}", "no link (joint name or 'base') or frame of that name"
                                  + did_you_mean(ref, sorted(set(links + frames + ["base"]) - {root})), ref)
            refs.append(link)
            anchors.append(tuple(float(x) for x in a))
            bounds.append(None if b is None else (tuple(map(float, b[0])), tuple(map(float, b[1]))))
        rate_max = e.rate_max if e.rate_max is not None else math.inf
        slots.append(SpringSlot(
            name=e.name, link_a=refs[0], anchor_a=anchors[0], link_b=refs[1], anchor_b=anchors[1],
            free_length=float(e.free_length), rate=None if e.rate is None else float(e.rate),
            pulley_ratio=float(e.pulley_ratio), rate_max=rate_max, preload=float(e.preload), count=int(e.count),
            rate_min=float(e.rate_min or 0.0), anchor_a_bounds=bounds[0], anchor_b_bounds=bounds[1]))
        try:
            model_spring(mechanism, dataclasses.replace(slots[-1], rate=slots[-1].rate or 0.0))
        except ValueError as exc:
            raise ConfigError(field, str(exc), has_value=False) from None
    n = table.samples if table.samples is not None else DEFAULT_SAMPLES
    coordinates = "actuated" if mechanism.is_closed else "independent"
    width = len(mechanism.actuated_names) if mechanism.is_closed else mechanism.dof
    for key in ("lower", "upper"):
        v = getattr(table, key)
        if v is not None and len(v) != width:
            raise ConfigError(f"balance.{key}", f"must have {width} values (one per "
                                                f"{'actuated' if mechanism.is_closed else 'independent'} joint)", list(v))
    try:
        lo, hi = common.sample_box(mechanism, table.lower, table.upper, coordinates=coordinates)
    except ValueError as exc:
        raise ConfigError("balance.upper", str(exc), list(table.upper or [])) from None
    rng = np.random.default_rng(table.seed)
    samples = lo + (hi - lo) * rng.random((int(n), len(lo)))
    if mechanism.is_closed:
        samples = samples[common._nearest_neighbour_order(samples)]
    options: dict[str, Any] = {}
    if table.catalogue is not None:
        cat = table.catalogue
        if cat != "shipped":
            path = Path(cat)
            if not path.is_absolute() and mechanism.source:
                path = Path(mechanism.source).parent / path
            if not path.is_file():
                raise ConfigError("balance.catalogue", "no such spring catalogue file (give a CSV path relative "
                                                       "to the case file, or 'shipped')", cat)
            try:
                cat = load_catalogue(path)
            except ValueError as exc:
                raise ConfigError("balance.catalogue", str(exc), has_value=False) from None
        options["catalogue"] = cat
    return slots, samples, options


# ------------------------------------------------------------------------------------------------
# Catalogue selection (Martini et al. 2015, Tables 1-2)
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CatalogueSpring:
    """One off-the-shelf extension spring (SI units): ``rate`` [N/m], ``max_force`` [N] (the
    largest force it may carry), ``free_length`` [m], ``mass`` [kg], ``outer_diameter`` [m],
    ``initial_tension`` [N], ``code`` (the catalogue's reference)."""

    code: str
    rate: float
    max_force: float
    free_length: float
    mass: float
    outer_diameter: float
    initial_tension: float = 0.0


#: CSV columns (units in the names); lines starting with '#' are comments
CATALOGUE_COLUMNS = ("code", "rate_N_per_mm", "max_force_N", "free_length_mm", "mass_g",
                     "outer_diameter_mm")


def load_catalogue(path: str | Path | None = None) -> list[CatalogueSpring]:
    """Read a spring catalogue CSV (columns ``code, rate_N_per_mm, max_force_N, free_length_mm,
    mass_g, outer_diameter_mm`` and optionally ``initial_tension_N``; '#' lines are comments).
    Without ``path``, the small catalogue shipped with mechbal (``mechbal/data/springs.csv``).
    Raises ValueError naming the row and column of a bad value."""
    if path is None:
        text = resources.files("mechbal").joinpath("data/springs.csv").read_text(encoding="utf-8")
        where = "mechbal/data/springs.csv"
    else:
        where = str(path)
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise ValueError(f"{where}: cannot read the spring catalogue ({exc.strerror or exc})") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    missing = [c for c in CATALOGUE_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise ValueError(f"{where}: missing column(s) {', '.join(missing)} (need {', '.join(CATALOGUE_COLUMNS)})")
    out = []
    for row_no, row in enumerate(reader, start=1):
        vals = {}
        for col in CATALOGUE_COLUMNS[1:] + ("initial_tension_N",):
            raw = row.get(col)
            if raw is None or (col == "initial_tension_N" and raw.strip() == ""):
                vals[col] = 0.0
                continue
            try:
                v = float(raw)
            except ValueError:
                raise ValueError(f"{where}: row {row_no}, {col}: not a number ({raw!r})") from None
            if not math.isfinite(v) or v < 0 or (v == 0 and col in ("rate_N_per_mm", "max_force_N")):
                raise ValueError(f"{where}: row {row_no}, {col}: must be a finite number > 0 (got {raw})")
            vals[col] = v
        code = (row.get("code") or "").strip()
        if not code:
            raise ValueError(f"{where}: row {row_no}, code: empty")
        out.append(CatalogueSpring(code=code, rate=vals["rate_N_per_mm"] * 1e3, max_force=vals["max_force_N"],
                                   free_length=vals["free_length_mm"] * 1e-3, mass=vals["mass_g"] * 1e-3,
                                   outer_diameter=vals["outer_diameter_mm"] * 1e-3,
                                   initial_tension=vals["initial_tension_N"]))
    if not out:
        raise ValueError(f"{where}: no springs")
    return out


@dataclass(frozen=True)
class SpringCluster:
    """A practical implementation of a theoretical spring: ``count`` identical catalogue springs
    in parallel behind a block and tackle of ratio ``pulley_ratio`` (``moving_pulleys`` in a
    cascade of single moving pulleys, each doubling the ratio, when the ratio is a power of 2).

    ``equivalent_rate`` = count * rate / pulley_ratio**2 [N/m] at the anchors and its relative
    ``rate_error`` to the theoretical rate; ``peak_force`` [N] at the anchors with the chosen rate
    and ``force_per_spring`` = peak_force * pulley_ratio / count [N] (<= the spring's max force);
    ``anchor_offset`` [m]: the offset (a ZFL spring's balancing lever: rate * offset is what
    balances, Martini et al. eqs 15-19) corrected for the chosen rate, None when not given;
    ``total_mass`` [kg] of the springs; ``force_margin`` = max_force / force_per_spring."""

    spring: CatalogueSpring
    count: int
    pulley_ratio: float
    equivalent_rate: float
    rate_error: float
    peak_force: float
    force_per_spring: float
    force_margin: float
    anchor_offset: float | None
    total_mass: float

    @property
    def moving_pulleys(self) -> int | None:
        m = math.log2(self.pulley_ratio) if self.pulley_ratio >= 1 else -1
        return int(round(m)) if abs(m - round(m)) < 1e-12 else None

    def summary(self) -> dict[str, Any]:
        return {"code": self.spring.code, "spring_rate_N_per_mm": self.spring.rate / 1e3,
                "count": self.count, "pulley_ratio": self.pulley_ratio, "moving_pulleys": self.moving_pulleys,
                "equivalent_rate_N_per_mm": self.equivalent_rate / 1e3, "rate_error": self.rate_error,
                "peak_force": self.peak_force, "force_per_spring": self.force_per_spring,
                "spring_max_force": self.spring.max_force, "force_margin": self.force_margin,
                "anchor_offset_mm": None if self.anchor_offset is None else self.anchor_offset * 1e3,
                "total_spring_mass": self.total_mass}


def select_springs(rate: float, peak_force: float, catalogue: Sequence[CatalogueSpring] | str | Path | None = None,
                   *, anchor_offset: float | None = None, counts: Iterable[int] = range(1, 13),
                   pulley_ratios: Iterable[float] = (1, 2, 4, 8), rate_tolerance: float = 0.02,
                   peak_force_at: Callable[[float], float] | None = None,
                   max_candidates: int = 10) -> list[SpringCluster]:
    """Ranked clusters of identical catalogue springs behind a block and tackle that implement a
    theoretical spring of equivalent ``rate`` [N/m] carrying ``peak_force`` [N] at its anchors
    (Martini et al. 2015, Tables 1-2).

    A candidate (spring, count n, ratio k) has ``K_eq = n rate_s / k^2`` within ``rate_tolerance``
    (relative) of ``rate``; its peak force at the anchors is ``peak_force_at(K_eq)`` when given
    (recompute it from the mechanism with the corrected anchors), else ``peak_force * K_eq /
    rate`` (same peak anchor distance); each spring carries ``peak * k / n``, which must not
    exceed its max force. With ``anchor_offset`` (the ZFL balancing offset, e.g. delta_y of eq 18),
    the offset that keeps ``rate * offset`` is reported: ``anchor_offset * rate / K_eq``.

    Ranked by total spring mass, then |rate error|, then fewer moving pulleys and fewer springs.
    Returns at most ``max_candidates`` (empty when nothing fits)."""
    if not (rate > 0 and math.isfinite(rate)):
        raise ValueError(f"rate: must be > 0 (got {rate})")
    if not (peak_force >= 0 and math.isfinite(peak_force)):
        raise ValueError(f"peak_force: must be >= 0 (got {peak_force})")
    springs = catalogue if isinstance(catalogue, Sequence) and not isinstance(catalogue, str) else load_catalogue(catalogue)
    out = []
    for sp in springs:
        for n in counts:
            for k in pulley_ratios:
                K = n * sp.rate / k ** 2
                err = K / rate - 1.0
                if abs(err) > rate_tolerance:
                    continue
                peak = float(peak_force_at(K)) if peak_force_at is not None else peak_force * K / rate
                per = peak * k / n
                if per > sp.max_force:
                    continue
                out.append(SpringCluster(
                    spring=sp, count=int(n), pulley_ratio=float(k), equivalent_rate=K, rate_error=err,
                    peak_force=peak, force_per_spring=per,
                    force_margin=sp.max_force / per if per > 0 else math.inf,
                    anchor_offset=None if anchor_offset is None else anchor_offset * rate / K,
                    total_mass=n * sp.mass))
    out.sort(key=lambda c: (round(c.total_mass, 9), abs(c.rate_error), c.pulley_ratio, c.count, c.spring.code))
    return out[:max_candidates]


def select_for_result(mechanism: Mechanism, result: BalanceResult, samples, catalogue=None, *,
                      offsets: Mapping[str, tuple[str, int]] | None = None, **select_options) -> dict[str, list[SpringCluster]]:
    """Catalogue clusters for every spring of a `balance` result, with the peak force
    recomputed on ``samples`` (open mechanisms: configurations) for each candidate's rate and
    corrected anchor. ``offsets[name] = ("a" or "b", coordinate)`` names the anchor coordinate
    that is the spring's balancing offset (a ZFL spring balances with ``rate * offset``
    constant): it is moved to keep that product; without it the anchors stay and only the rate
    changes (then the balance is approximate: check with `spring_torque`)."""
    offsets = dict(offsets or {})
    q = np.atleast_2d(np.asarray(samples, float))
    out = {}
    for s in result.elements:
        K0 = equivalent_rate(s)
        if K0 <= 0:
            out[s.name] = []
            continue
        side, c = offsets.get(s.name, (None, None))
        offset = None if side is None else float(getattr(s, f"anchor_{side}")[c])

        def peak_at(K, s=s, side=side, c=c, offset=offset):
            anchor = list(getattr(s, f"anchor_{side}")) if side else None
            if side:
                anchor[c] = offset * K0 / K
            trial = dataclasses.replace(s, rate=K * s.pulley_ratio ** 2 / _count(s), count=_count(s),
                                        **({f"anchor_{side}": tuple(anchor)} if side else {}))
            return float(np.max(spring_tension(mechanism, [trial], q)))

        def peak_with_cluster(K, s=s, peak_at=peak_at):
            return peak_at(K)

        out[s.name] = select_springs(K0, float(result.design[s.name]["peak_tension"]), catalogue,
                                     anchor_offset=offset, peak_force_at=peak_with_cluster, **select_options)
    return out


def _unconstrained_rates(A, rhs, springs, free, Klo, Khi) -> dict:
    """The least-squares rates without bounds for the chosen anchors: {"springs": {name: {rate,
    equivalent_rate, stopped_by}}, "residual": peak static torque they leave [N m]}. ``stopped_by``
    says what keeps the bounded solution from it: the sign (a negative rate is a spring that pushes:
    its anchors are on the wrong side of the joint it should hold, move anchor_a or anchor_b across
    it), rate_min or rate_max, or nothing."""
    out: dict[str, Any] = {"springs": {}, "residual": 0.0}
    if A.shape[1] == 0:
        out["residual"] = float(np.max(np.abs(rhs))) if rhs.size else 0.0
        return out
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    z, *_ = np.linalg.lstsq(A / scale, rhs, rcond=None)
    K = z / scale
    out["residual"] = float(np.max(np.abs(A @ K - rhs))) if rhs.size else 0.0
    for j, i in enumerate(free):
        s = springs[i]
        rate = float(K[j] * s.pulley_ratio ** 2 / _count(s))
        tol = 1e-9 * max(1.0, abs(K[j]))
        if K[j] < 0 and Klo[j] <= 0:
            why = (f"the sign: {s.name} would need a negative rate {rate:.6g} N/m (a spring that pushes): "
                   f"its anchors (anchor_a on '{s.link_a}', anchor_b on '{s.link_b}') pull the wrong way; "
                   "move one across the joint it should hold, or let the method move it (anchor bounds)")
        elif K[j] < Klo[j] - tol:
            why = f"rate_min: {s.name} would need {rate:.6g} N/m, below rate_min = {getattr(s, 'rate_min', 0.0):.6g}"
        elif K[j] > Khi[j] + tol:
            why = f"rate_max: {s.name} would need {rate:.6g} N/m, above rate_max = {s.rate_max:.6g}"
        else:
            why = "nothing"
        out["springs"][s.name] = {"rate": rate, "equivalent_rate": float(K[j]), "stopped_by": why}
    return out


def _describe_rates(unconstrained: dict) -> str:
    return ", ".join(f"{n} {u['rate']:.6g} N/m" for n, u in unconstrained["springs"].items()) or "no free rate"
