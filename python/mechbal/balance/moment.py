"""Shaking-moment balancing by counter-rotating discs, for any force-balanced mechanism (issue 11,
method 3): Coutinho & Hess Coelho, "A new approach for designing dynamic balanced serial
mechanisms" (eqs 10-14, 20-25, 31-35; corrected in docs/discs_derivation.md), generalised.

**Condition.** The shaking moment is the rate of the angular momentum about O; it vanishes for
all motions when ``H_O(q, v) = A_H(q) v = 0`` for every configuration q of the workspace and every
velocity v, i.e. when every column ``A_H(q) e_k`` (the angular momentum of a unit rate of
coordinate k, all others still) is zero. For a closed mechanism the velocities are v = C(q) v#
and the columns are those of the actuated rates. The condition needs the mechanism to be
force-balanced first (method ``force``): where the linear momentum of a unit rate is not zero,
its moment depends on the reference point and no disc can cancel it.

**Discs** (`DiscSlot`). A disc rides on an axle fixed to a
carrier link and turns relative to it by ``ratio * q_j'`` (a gear train to coordinate j: a gear
coupling on the general model). Its mass is part of the carrier's (as in the paper), so it adds
only its inertia: axial ``J_a`` about the axle, transverse ``J_t`` (thin disc: J_a / 2). Its
angular momentum is ``R I R^T w_carrier + ratio J_a q_j' a`` -- linear in the unknowns
``(J_a, J_t)`` and ``h = ratio * J_a`` jointly, so the condition is a linear least-squares problem
in the disc inertias, the "geared inertias" h (hence the ratios) and any central inertia of an
existing body left free (`InertiaSlot`: the spatial arm's
corrected conditions J_y2 = J_z2 + m3 l2^2 (1 + m3/m2), J_y3 = J_z3 are of this kind). The rows
come from the angular rows of the momentum regressor (`mechbal.Mechanism.momentum_regressor`)
of the mechanism with the discs rigid on their carriers and geared at ratio 1.

**When full balance is impossible.** The columns (coordinate k, axis x/y/z) that the slots can
cancel together are found (largest consistent set, greedily removing the group whose removal
leaves the least residual); those are cancelled exactly (the paper's conditions: for the planar
3R the columns of joints 2 and 3 give its beta and gamma, eq 14) and each remaining one is
explained: not force-balanced, no slot acts on it, a bound (a negative inertia) would be needed,
or it varies over the workspace in a way constant-ratio discs cannot follow (the general
five-bar, docs/discs_derivation.md section 5). Where what remains of a column is constant in the
frame of a link (the base for joint 1 of the planar 3R: ``k1 theta1'`` about x), the result says
which disc would cancel it: one on that link, geared to that coordinate, with ratio x inertia
= -remainder.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, Mapping, Sequence

import numpy as np

from mechbal import _core
from mechbal.balance.result import BalanceResult, DiscSlot, InertiaSlot
from mechbal.mechanism import Mechanism

__all__ = ["balance", "with_discs", "angular_momentum_columns", "design_from_table"]

_COMPONENTS = "xyz"
_INERTIA_INDEX = {"Ixx": 4, "Iyy": 6, "Izz": 9}   # in [m, mc, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]
_INERTIA_PAIR = {"Ixx": (0, 0), "Iyy": (1, 1), "Izz": (2, 2)}


def _pi_inertia(axis: np.ndarray, axial: float, transverse: float) -> np.ndarray:
    """10 inertial parameters of a massless axisymmetric disc (its frame at the axle)."""
    a = axis / np.linalg.norm(axis)
    I = transverse * (np.eye(3) - np.outer(a, a)) + axial * np.outer(a, a)
    return np.array([0, 0, 0, 0, I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]], float)


def _placement(position) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = np.asarray(position, float)
    return T


def with_discs(mechanism: Mechanism, discs: Sequence[DiscSlot], inertias: Mapping[str, Mapping[str, float]] = {},
               *, rigid: bool = False, unit_ratio: bool = False, unit_inertia: bool = False,
               name: str | None = None) -> Mechanism:
    """A copy of ``mechanism`` with each disc as a link on a revolute joint (named after the
    slot) on its carrier, geared to its coordinate (``mimic``: q_disc = ratio q_j), and a massless
    body of its inertia; ``inertias[body][component]`` replaces central principal inertias of
    existing bodies (link axes). ``rigid``: the discs on fixed joints (turning with the carrier);
    ``unit_ratio``/``unit_inertia``: evaluation models for the regressors (ratio 1, inertia 1)."""
    d = mechanism.model.description
    coords = set(mechanism.joint_names)
    links = set(mechanism.link_names)
    joints = list(d.joints)
    bodies = []
    for b in d.bodies:
        if b.name in inertias:
            I = np.array(b.inertia, float)
            for comp, value in inertias[b.name].items():
                i, j = _INERTIA_PAIR[comp]
                I[i, j] = value
            b = _core.Body(b.name, b.link, b.mass, np.asarray(b.com), I, b.kind)
        bodies.append(b)
    for s in discs:
        if s.carrier not in links:
            from mechbal.schema import did_you_mean
            raise ValueError(f"discs.{s.name}.carrier: no link named '{s.carrier}'{did_you_mean(s.carrier, sorted(links))}")
        if s.joint not in coords:
            from mechbal.schema import did_you_mean
            raise ValueError(f"discs.{s.name}.joint: '{s.joint}' is not a coordinate of the mechanism"
                             f"{did_you_mean(s.joint, sorted(coords))}")
        axis = np.asarray(s.axis, float)
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.linalg.norm(axis) == 0:
            raise ValueError(f"discs.{s.name}.axis: must be a nonzero 3-vector (got {s.axis})")
        ratio = 1.0 if unit_ratio else s.ratio
        if rigid or ratio == 0.0:
            joints.append(_core.Joint(s.name, _core.JointType.fixed, s.carrier, _placement(s.position), axis))
        else:
            joints.append(_core.Joint(s.name, _core.JointType.revolute, s.carrier, _placement(s.position), axis,
                                      mimic_joint=s.joint, mimic_ratio=float(ratio), mimic_offset=0.0))
        Ja = 1.0 if unit_inertia else float(s.inertia)
        Jt = Ja if unit_inertia else _transverse(s, Ja)
        a = axis / np.linalg.norm(axis)
        I = Jt * (np.eye(3) - np.outer(a, a)) + Ja * np.outer(a, a)
        bodies.append(_core.Body(s.name, s.name, 0.0, np.zeros(3), I, "disc"))
    return Mechanism.from_description(joints, bodies, d.frames, d.gravity, root_name=d.root_name,
                                      name=name or mechanism.name, loops=d.loops, actuated=d.actuated,
                                      springs=d.springs)


def _transverse(s: DiscSlot, axial: float) -> float:
    return 0.5 * axial if s.transverse_inertia is None else float(s.transverse_inertia)


def _motions(mechanism: Mechanism, samples: np.ndarray, q_guess=None):
    """(q (N, dof), basis velocities V (N, nb, dof), names of the nb independent rates)."""
    if mechanism.is_closed:
        na = len(mechanism.model.actuated_coordinates)
        if samples.shape[1] != na:
            raise ValueError(f"samples: a closed mechanism is sampled by its {na} actuated positions (N, {na}), "
                             f"got {samples.shape}")
        m = mechanism.closed_motion(samples, q_guess=q_guess)
        bad = np.asarray(m.status).astype(np.int64) & ~int(_core.Status.singular)
        if np.any(bad):
            raise ValueError(f"samples[{int(np.flatnonzero(bad)[0])}]: the loops cannot be solved there")
        V = np.zeros((len(samples), na, mechanism.dof))
        for k in range(na):
            e = np.zeros_like(samples)
            e[:, k] = 1.0
            V[:, k] = mechanism.closed_motion(samples, e, q_guess=q_guess).v
        return np.asarray(m.q), V, mechanism.actuated_names
    if samples.shape[1] != mechanism.dof:
        raise ValueError(f"samples: must have shape (N, {mechanism.dof}), got {samples.shape}")
    V = np.broadcast_to(np.eye(mechanism.dof), (len(samples), mechanism.dof, mechanism.dof)).copy()
    return samples, V, mechanism.joint_names


def angular_momentum_columns(mechanism: Mechanism, samples, *, q_guess=None) -> tuple[np.ndarray, np.ndarray]:
    """(linear, angular) momentum of a unit rate of each independent coordinate (actuated ones
    for a closed mechanism), all others still: two (N, nb, 3) arrays [kg m/s, kg m^2/s]."""
    q, V, _ = _motions(mechanism, np.atleast_2d(np.asarray(samples, float)), q_guess)
    N, nb, dof = V.shape
    mom = mechanism.momentum(np.repeat(q, nb, axis=0), V.reshape(N * nb, dof))
    return mom.linear_momentum.reshape(N, nb, 3), mom.angular_momentum.reshape(N, nb, 3)


#: workspace poses of ``mechbal balance --method moment`` unless ``balance.samples`` says otherwise
DEFAULT_SAMPLES = 200


def design_from_table(table, mechanism: Mechanism):
    """(design, samples, options) of a validated ``[balance]`` table for `balance` (what
    ``mechbal balance --method moment`` runs): the `DiscSlot` of ``[[balance.discs]]`` and
    `InertiaSlot` of ``[[balance.inertias]]``, checked against the mechanism
    (`ConfigError` naming ``balance.discs[i].carrier`` ...); ``samples``:
    ``balance.samples`` (default 200) uniform random poses in the box ``balance.lower`` ..
    ``balance.upper`` (default the joint limits, else +-pi / +-0.5 m: ``common.sample_box``), of
    the actuated joints of a closed mechanism (whose box must be given: where its loops
    assemble), visited along a nearest-neighbour path so that each loop solve starts near the
    last; ``options``: ``seed`` and ``check_motions``."""
    from mechbal.balance import common
    from mechbal.errors import ConfigError
    from mechbal.schema import did_you_mean

    if table is None or not (table.discs or table.inertias):
        raise ConfigError("balance.discs", "no disc or inertia slots: add [[balance.discs]] (name, carrier, "
                                           "joint, axis, position, ratio or inertia) or [[balance.inertias]]",
                          has_value=False)
    links = list(mechanism.link_names)
    coords = list(mechanism.joint_names)
    taken = set(links) | set(mechanism.body_names)
    discs = []
    for i, c in enumerate(table.discs):
        f = f"balance.discs[{i}]"
        if c.name in taken:
            raise ConfigError(f"{f}.name", "is already a link or body of the mechanism", c.name)
        if c.carrier not in links:
            raise ConfigError(f"{f}.carrier", f"no link named so{did_you_mean(c.carrier, links)}", c.carrier)
        if c.joint not in coords:
            raise ConfigError(f"{f}.joint", f"is not a coordinate of the mechanism{did_you_mean(c.joint, coords)}",
                              c.joint)
        discs.append(DiscSlot(c.name, c.carrier, c.joint, axis=tuple(c.axis), position=tuple(c.position),
                              ratio=c.ratio, inertia=c.inertia, transverse_inertia=c.transverse_inertia,
                              inertia_min=c.inertia_min,
                              inertia_max=math.inf if c.inertia_max is None else c.inertia_max,
                              ratio_min=-math.inf if c.ratio_min is None else c.ratio_min,
                              ratio_max=math.inf if c.ratio_max is None else c.ratio_max))
    bodies = list(mechanism.body_names)
    inertias = []
    for i, c in enumerate(table.inertias):
        if c.body not in bodies:
            raise ConfigError(f"balance.inertias[{i}].body", f"no body named so{did_you_mean(c.body, bodies)}", c.body)
        inertias.append(InertiaSlot(c.name, c.body, tuple(c.components), c.minimum))
    closed = mechanism.is_closed
    width = len(mechanism.actuated_names) if closed else mechanism.dof
    for key in ("lower", "upper"):
        v = getattr(table, key)
        if v is not None and len(v) != width:
            what = "actuated joint" if closed else "coordinate"
            raise ConfigError(f"balance.{key}", f"must have {width} values (one per {what})", list(v))
        if closed and v is None:
            raise ConfigError(f"balance.{key}", f"a closed mechanism is sampled by its actuated joints "
                                                f"({', '.join(mechanism.actuated_names)}) in a box where its loops "
                                                "assemble: give balance.lower and balance.upper", has_value=False)
    try:
        lo, hi = common.sample_box(mechanism, table.lower, table.upper, "actuated" if closed else "independent")
    except ValueError as exc:
        raise ConfigError("balance.upper", str(exc).split(": ", 1)[-1], has_value=False) from None
    n = DEFAULT_SAMPLES if table.samples is None else int(table.samples)
    samples = lo + (hi - lo) * np.random.default_rng(table.seed).random((n, len(lo)))
    if closed:
        samples = samples[common._nearest_neighbour_order(samples)]
    options: dict[str, Any] = {"seed": int(table.seed)}
    if table.check_motions is not None:
        options["check_motions"] = int(table.check_motions)
    return discs + inertias, samples, options


def _as_design(design):
    if isinstance(design, (DiscSlot, InertiaSlot)):
        design = [design]
    if isinstance(design, Mapping):
        design = list(design.get("discs", [])) + list(design.get("inertias", []))
    design = list(design)
    discs = [d for d in design if isinstance(d, DiscSlot)]
    inertias = [d for d in design if isinstance(d, InertiaSlot)]
    other = [d for d in design if not isinstance(d, (DiscSlot, InertiaSlot))]
    if other:
        raise TypeError(f"design: moment balancing takes DiscSlot and InertiaSlot objects, got {type(other[0]).__name__}")
    names = [d.name for d in design]
    if len(set(names)) != len(names):
        raise ValueError(f"design: slot names must be unique (got {names})")
    if not design:
        raise ValueError("design: no disc or inertia slots")
    return discs, inertias


def balance(mechanism: Mechanism, design, samples, *, q_guess=None, tolerance: float = 1e-9,
            check_motions: int = 1000, seed: int = 0, **options) -> BalanceResult:
    """Disc inertias, gear ratios and free body inertias that cancel the angular momentum
    (hence the shaking moment) for all motions over the workspace ``samples`` (configurations
    (N, dof); actuated positions (N, na) for a closed mechanism).

    ``design``: `DiscSlot` and
    `InertiaSlot` objects (or ``{"discs": [...], "inertias": [...]}``).

    Returns a `BalanceResult`: ``design[disc] = {"inertia", "transverse_inertia",
    "ratio", "geared_inertia" (ratio x inertia), "carrier", "joint", "axis"}``,
    ``design[inertia slot] = {component: value}``; ``residual`` the peak |H_O| [kg m^2/s] of the
    balanced mechanism over ``check_motions`` random velocities (U(-1, 1) rad/s or m/s) at the
    samples, ``residual_before`` the same for the mechanism as given; ``metrics["columns"]`` per
    independent rate and axis whether it is cancelled, and why not; ``metrics["mass_matrix"]``
    the paper's criteria (largest off-diagonal / smallest diagonal, variation of the diagonal);
    ``balanced`` the mechanism with the discs (gear couplings) and inertias."""
    from scipy.optimize import lsq_linear

    if options:
        raise TypeError(f"balance() got unexpected options: {', '.join(sorted(options))}")
    discs, islots = _as_design(design)
    samples = np.atleast_2d(np.asarray(samples, float))
    bodies = {b.name: b for b in mechanism.bodies}
    for s in islots:
        if s.body not in bodies:
            from mechbal.schema import did_you_mean
            raise ValueError(f"inertias.{s.name}.body: no body named '{s.body}'{did_you_mean(s.body, sorted(bodies))}")
        for c in s.components:
            if c not in _INERTIA_INDEX:
                raise ValueError(f"inertias.{s.name}.components: {c!r} is not one of Ixx, Iyy, Izz")
    for s in discs:
        if s.inertia is not None and not (s.inertia >= 0 and math.isfinite(s.inertia)):
            raise ValueError(f"discs.{s.name}.inertia: must be >= 0 (got {s.inertia})")

    # evaluation models: discs rigid on their carriers (ratio 0) and geared at ratio 1
    rigid = with_discs(mechanism, discs, rigid=True, unit_inertia=True)
    geared = with_discs(mechanism, discs, unit_ratio=True, unit_inertia=True)
    q, V, rate_names = _motions(mechanism, samples, q_guess)
    N, nb, dof = V.shape
    Q = np.repeat(q, nb, axis=0)
    Vf = V.reshape(N * nb, dof)
    Y1 = geared.momentum_regressor(Q, Vf)          # (N nb, 6, 10 B')
    Y0 = rigid.momentum_regressor(Q, Vf)
    nB = len(mechanism.bodies)
    pi = mechanism.inertial_parameters()
    # the fixed part: every existing body, with the free central inertias removed
    pi_fixed = pi.copy()
    columns, names_x, kinds = [], [], []
    for s in islots:
        bi = mechanism.body_names.index(s.body)
        for c in s.components:
            k = 10 * bi + _INERTIA_INDEX[c]
            i, j = _INERTIA_PAIR[c]
            pi_fixed[k] -= float(np.asarray(bodies[s.body].inertia)[i, j])
            columns.append(Y1[:, :, k])
            names_x.append((s.name, c))
            kinds.append(("body", s.minimum, math.inf))
    known = np.einsum("rcp,p->rc", Y1[:, :, :10 * nB], pi_fixed)
    for di, s in enumerate(discs):
        sl = slice(10 * (nB + di), 10 * (nB + di + 1))
        a = np.asarray(s.axis, float)
        Y0d, dY = Y0[:, :, sl], Y1[:, :, sl] - Y0[:, :, sl]
        spin = dY @ _pi_inertia(a, 1.0, 1.0)             # (rows, 6): q_j' a  per unit geared inertia
        tau = 0.5 if s.transverse_inertia is None else None
        if s.inertia is not None:
            Ja = float(s.inertia)
            known = known + Y0d @ _pi_inertia(a, Ja, _transverse(s, Ja))
            if s.ratio is not None:
                known = known + s.ratio * Ja * spin
            else:
                columns.append(spin)
                names_x.append((s.name, "geared_inertia"))
                kinds.append(("geared", -math.inf, math.inf))
        else:
            if tau is not None:
                col = Y0d @ _pi_inertia(a, 1.0, tau)
            else:
                col = Y0d @ _pi_inertia(a, 1.0, 0.0)
                known = known + Y0d @ _pi_inertia(a, 0.0, float(s.transverse_inertia))
            if s.ratio is not None:
                col = col + s.ratio * spin
            else:
                columns.append(spin)
                names_x.append((s.name, "geared_inertia"))
                kinds.append(("geared", -math.inf, math.inf))
            columns.append(col)
            names_x.append((s.name, "inertia"))
            kinds.append(("inertia", float(s.inertia_min), float(s.inertia_max)))

    lin = known[:, :3].reshape(N, nb, 3)     # linear momentum of the fixed part (discs add none)
    b_all = -known[:, 3:].reshape(N, nb, 3)  # angular rows: A x = b
    u = len(columns)
    A_all = (np.stack(columns, axis=-1)[:, 3:, :].reshape(N, nb, 3, u) if u else np.zeros((N, nb, 3, 0)))
    lo = np.array([k[1] for k in kinds]) if u else np.zeros(0)
    hi = np.array([k[2] for k in kinds]) if u else np.zeros(0)
    scale_H = float(np.max(np.abs(b_all))) if b_all.size else 0.0
    col_scale = np.linalg.norm(A_all.reshape(-1, u), axis=0) if u else np.zeros(0)
    col_scale[col_scale == 0] = 1.0
    tol = tolerance * max(scale_H, 1e-300) * math.sqrt(N)

    groups = [(k, c) for k in range(nb) for c in range(3)]

    def system(gs):
        if not gs:
            return np.zeros((0, u)), np.zeros(0)
        A = np.concatenate([A_all[:, k, c, :] for k, c in gs], axis=0)
        b = np.concatenate([b_all[:, k, c] for k, c in gs], axis=0)
        return A, b

    def solve(gs, bounded=True):
        A, b = system(gs)
        if u == 0:
            return np.zeros(0), float(np.linalg.norm(b))
        As = A / col_scale
        z, *_ = np.linalg.lstsq(As, b, rcond=None)
        x = z / col_scale
        if bounded and not (np.all(x >= lo - 1e-12 * np.maximum(1, np.abs(x))) and np.all(x <= hi)):
            r = lsq_linear(As, b, bounds=(lo * col_scale, np.where(np.isinf(hi), np.inf, hi * col_scale)),
                           method="bvls", tol=1e-15)
            x = r.x / col_scale
        return x, float(np.linalg.norm(A @ x - b))

    acts = {g: bool(u and np.max(np.abs(A_all[:, g[0], g[1], :]) / col_scale) > 1e-12) for g in groups}
    need = {g: float(np.max(np.abs(b_all[:, g[0], g[1]]))) > tolerance * max(scale_H, 1e-300) for g in groups}
    active = [g for g in groups if acts[g]]
    dropped = [g for g in groups if not acts[g] and need[g]]
    x, res = solve(active)
    while active and res > tol:
        trials = []
        for g in active:
            rest = [h for h in active if h != g]
            trials.append((solve(rest)[1], -float(np.max(np.abs(b_all[:, g[0], g[1]]))), g))
        trials.sort(key=lambda t: (t[0], t[1]))
        g = trials[0][2]
        active.remove(g)
        dropped.append(g)
        x, res = solve(active)
    # lexicographic: exact on the kept columns, then least on the dropped ones in their null space
    if u:
        A_k, b_k = system(active)
        A_d, b_d = system(dropped)
        if A_k.shape[0]:
            Uk, sk, Vt = np.linalg.svd(A_k / col_scale, full_matrices=True)
            rank_k = int(np.sum(sk > 1e-10 * (sk[0] if sk.size else 1)))
            Nz = Vt[rank_k:].T
        else:
            rank_k, Nz = 0, np.eye(u)
        if Nz.shape[1] and A_d.shape[0]:
            z0 = x * col_scale
            # the cutoff is relative to the scaled system, not to this projection: where the
            # dropped columns do not see the null space of the kept ones (the projection is
            # round-off), nothing moves (a relative cutoff would solve the round-off)
            Md = (A_d / col_scale) @ Nz
            ref = max(float(sk[0]) if A_k.shape[0] and sk.size else 0.0, float(np.linalg.norm(A_d / col_scale, 2)))
            Ud, sd, Vdt = np.linalg.svd(Md, full_matrices=False)
            keep = sd > 1e-10 * ref
            dz = Vdt[keep].T @ ((Ud[:, keep].T @ (b_d - A_d @ x)) / sd[keep])
            x_try = (z0 + Nz @ dz) / col_scale
            if np.all(x_try >= lo - 1e-12 * np.maximum(1, np.abs(x_try))) and np.all(x_try <= hi):
                x = x_try
        A_full, _ = system(groups)
        rank = int(np.linalg.matrix_rank(A_full / col_scale, tol=1e-10)) if A_full.size else 0
    else:
        rank = 0

    # the sized design
    values = {nx: float(v) for nx, v in zip(names_x, x)}
    design_out: dict[str, dict[str, Any]] = {}
    limited: list[str] = []
    sized_discs = []
    for s in discs:
        Ja = values.get((s.name, "inertia"), s.inertia)
        h = values.get((s.name, "geared_inertia"), None)
        ratio = s.ratio
        if ratio is None:
            if Ja is None or Ja <= 1e-300:
                limited.append(f"impossible: {s.name} needs a geared inertia {h:.6g} kg m^2 with zero inertia "
                               "(infinite ratio): fix its inertia or bound it away from 0")
                ratio = 0.0
            else:
                ratio = h / Ja
        sized = dataclasses.replace(s, inertia=float(Ja), ratio=float(ratio))
        sized_discs.append(sized)
        design_out[s.name] = {"inertia": float(Ja), "transverse_inertia": _transverse(sized, float(Ja)),
                              "ratio": float(ratio), "geared_inertia": float(ratio * Ja), "carrier": s.carrier,
                              "joint": s.joint, "axis": list(map(float, s.axis)),
                              "position": list(map(float, s.position))}
        if s.ratio is None and not (s.ratio_min <= ratio <= s.ratio_max):
            limited.append(f"bound: {s.name}.ratio {ratio:.6g} outside [{s.ratio_min}, {s.ratio_max}]")
    new_inertias: dict[str, dict[str, float]] = {}
    for s in islots:
        design_out[s.name] = {"body": s.body}
        for c in s.components:
            v = values[(s.name, c)]
            design_out[s.name][c] = v
            new_inertias.setdefault(s.body, {})[c] = v
    balanced = with_discs(mechanism, sized_discs, new_inertias, name=f"{mechanism.name} (moment-balanced)")

    # per column: cancelled, or why not
    link_rot = mechanism.body_motion(q).link_rotation        # (N, L, 3, 3)
    parents = mechanism.model.link_parents
    lnames = mechanism.link_names
    x_res = (np.einsum("nkcu,u->nkc", A_all, x) - b_all) if u else -b_all   # remaining H (N, nb, 3)
    Hscale = max(scale_H, 1e-300)
    column_report = {}
    for k, rname in enumerate(rate_names):
        P = lin[:, k]
        rem = x_res[:, k]
        entry = {"cancelled": bool(np.max(np.abs(rem)) <= tolerance * Hscale),
                 "peak_remaining": float(np.max(np.linalg.norm(rem, axis=1)))}
        if not entry["cancelled"]:
            axes = [_COMPONENTS[c] for c in range(3) if (k, c) in dropped]
            norm = np.linalg.norm(rem, axis=1)
            if not any(acts[(k, c)] for c in range(3) if (k, c) in dropped):
                reason = f"no slot acts on the angular momentum of {rname} (about {', '.join(axes) or 'xyz'})"
            else:
                unb = solve(active + [(k, c) for c in range(3) if (k, c) in dropped], bounded=False)[1]
                if unb <= tol:
                    reason = f"cancelling {rname} needs a slot outside its bounds (e.g. a negative inertia)"
                elif np.max(norm) - np.min(norm) <= 1e-7 * Hscale:
                    done = [n for j, n in enumerate(rate_names) if j != k and
                            all((j, c) not in dropped for c in range(3)) and any(acts[(j, c)] for c in range(3))]
                    reason = (f"the slots cannot cancel the angular momentum of {rname}: {norm.max():.6g} kg m^2/s "
                              "per unit rate remains at every sample (no slot supplies a constant geared "
                              f"inertia for {rname}" + (f" that cancelling {', '.join(done)} leaves free: the slots "
                                                         f"act on both only together" if done else "") + ")")
                else:
                    reason = (f"the angular momentum of {rname} varies over the workspace in a way these slots "
                              f"(constant inertias and ratios) cannot follow: what remains of a unit rate ranges "
                              f"{norm.min():.4g}..{norm.max():.4g} kg m^2/s over the sample")
            if np.max(np.abs(P)) > 1e-9 * max(1.0, mechanism.total_mass):
                reason += (f"; and a unit rate of {rname} has linear momentum (up to "
                           f"{np.max(np.linalg.norm(P, axis=1)):.3g} kg m/s): the mechanism is not force-balanced "
                           "for it, so the shaking moment about other points than O keeps a part no disc "
                           "cancels (balance the shaking force first: method 'force')")
                entry["force_balanced"] = False
            # is what remains constant in the frame of the coordinate's link or an ancestor?
            suggestion = None
            li = mechanism.model.link_index(rname)
            chain = []
            while li >= 0:
                li = parents[li]
                if li >= 0:
                    chain.append(li)
            for L in chain:
                local = np.einsum("nji,nj->ni", link_rot[:, L], rem)
                if np.max(np.abs(local - local.mean(0))) <= 1e-7 * Hscale:
                    h = local.mean(0)
                    suggestion = (f"what remains is constant in the frame of '{lnames[L]}': a disc on "
                                  f"'{lnames[L]}' about axis {np.round(h / np.linalg.norm(h), 12).tolist()}, geared "
                                  f"to {rname} with ratio x inertia = {-np.linalg.norm(h):.6g} kg m^2, cancels it")
                    entry["constant_remainder"] = {"link": lnames[L], "vector": h.tolist()}
                    break
            entry["why"] = reason
            if suggestion:
                entry["add"] = suggestion
            limited.append(f"impossible: {reason}" + (f"; {suggestion}" if suggestion else ""))
        column_report[rname] = entry

    # evidence on the balanced mechanism itself (C++ momentum, not the regressor)
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, N, check_motions)
    coeff = rng.uniform(-1, 1, (check_motions, nb))
    qc = q[idx]
    vc = np.einsum("nk,nkd->nd", coeff, V[idx])
    H_before = mechanism.momentum(qc, vc).angular_momentum
    H_after = balanced.momentum(qc, vc).angular_momentum
    metrics = {"columns": column_report,
               "angular_momentum_before": {"peak": float(np.max(np.linalg.norm(H_before, axis=1))),
                                           "rms": float(np.sqrt(np.mean(np.sum(H_before ** 2, axis=1))))},
               "angular_momentum_after": {"peak": float(np.max(np.linalg.norm(H_after, axis=1))),
                                          "rms": float(np.sqrt(np.mean(np.sum(H_after ** 2, axis=1))))},
               "check_motions": int(check_motions), "samples": int(N)}
    metrics["mass_matrix"] = _mass_matrix_metrics(balanced, q if not mechanism.is_closed else samples, q_guess)
    return BalanceResult(method="moment", design=design_out, residual=metrics["angular_momentum_after"]["peak"],
                         residual_before=metrics["angular_momentum_before"]["peak"],
                         residual_units="kg m^2/s (peak |H_O| over random unit-scale motions)",
                         rank=rank if u else None, unknowns=u, limited_by=limited, metrics=metrics,
                         balanced=balanced)


def _mass_matrix_metrics(mech: Mechanism, samples, q_guess) -> dict[str, Any]:
    """The paper's criteria on the balanced mechanism: max over samples of the largest
    off-diagonal |M_ij| over the smallest M_ii, and max over i of (max - min)/mean of M_ii."""
    if mech.is_closed:
        M, _ = mech.reduced_mass_matrix(samples, q_guess=q_guess)
    else:
        M = mech.mass_matrix(samples)
    M = np.atleast_3d(M) if M.ndim == 2 else M
    n = M.shape[1]
    diag = np.einsum("nii->ni", M)
    off = np.abs(M - np.einsum("ni,ij->nij", diag, np.eye(n)))
    return {"offdiag_ratio": float(np.max(off.max(axis=(1, 2)) / diag.min(axis=1))),
            "diag_variation": float(np.max((diag.max(0) - diag.min(0)) / np.abs(diag.mean(0)))),
            "diag_mean": diag.mean(0).tolist()}
