"""Runner for ``kind = "rpsp"``: the 3(RPSP)-S spherical parallel robot of Heydari & Enferadi,
balanced by an extra linkage per leg (``rpsp.toml``; the paper's closed forms are the checks in
`mechbal.papers.rpsp`).

Everything physical comes from the general model: the mechanism of ``[mechanism]`` (legs, extra
linkages, platform, loop closures) with the platform's spherical joint as the driven coordinates
(the loop solve is then the inverse kinematics: theta_i, l_i, b_i and the linkage angles from the
platform's orientation), its linear momentum regressor for the sizing, its shaking force for the
comparison. Variants:

* ``unbalanced``: the robot without the extra linkage and without counterweights (Fig. 3);
* ``balanced``: with the extra linkage and the counterweights sized by the general
  shaking-force method (`mechbal.balance.force.balance`: least squares of the linear
  momentum over the run's closed motion, one slot per counterweight body at its given point, only
  its mass unknown), checked against eqs 29-31 (`mechbal.papers.rpsp`);
* ``paper_masses``: with the extra linkage and the paper's printed masses (17.61 / 2.76 / 4.5 kg).

The survey stage follows the robot over the whole period of the paper's motion, reporting the
reciprocal condition of the loop solve, its statuses, the legs' lengths and the instants where the
extra linkage cannot be assembled (|A_iC_i| > |A_iD_i| + |D_iC_i|).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from mechbal import control
from mechbal import progress, report
from mechbal.cases import register
from mechbal.config import ConfigError
from mechbal.export import write_bodies, write_summary
from mechbal.mechanism import Mechanism
from mechbal.papers import rpsp as paper
from mechbal.schema import validate_case

#: an instant is near-singular where the loop solve's rcond is below this fraction of its median
#: over the survey (the inverse-kinematic conditioning varies smoothly; its dips are the legs
#: shortening towards l_i = 0, where theta_i is undefined)
NEAR_SINGULAR_FRACTION = 0.2
#: Newton tolerance of the loop solve [m]: 1e-14 keeps theta_i within 1e-12 rad of the closed form
#: even where a leg is 17 mm long (an angle error is a position error over l_i)
SOLVE_TOLERANCE = 1e-14
_SINGULAR = np.uint32(int(control.Status.singular))
#: how far the general method's masses may be from eqs 29-31 [kg]: both are exact (a full-rank,
#: zero-residual least squares over the solved run; algebra), ~1e-9 kg apart (the loop solve's
#: 1e-14 m tolerance through the regressor); 1e-6 kg on masses of 2.8-18 kg is a modelling
#: difference, not round-off
COUNTERWEIGHT_AGREEMENT_KG = 1e-6


# ---- the mechanism's variants, as specs ---------------------------------------------------------

def unbalanced_spec(spec, balancing):
    """The robot before balancing: ``spec`` without the extra linkage's joints (and everything on
    or below them: links, bodies, frames, the loops that use those frames) and without the
    counterweight bodies."""
    removed = set(balancing.extra_linkage)
    changed = True
    while changed:
        changed = False
        for j in spec.joints:
            if j.parent in removed and j.name not in removed:
                removed.add(j.name)
                changed = True
    links = set(removed)
    # a spherical joint's link is that of <name>_x; <name>_z, _y are its intermediate links
    cw = {n for key in ("m_P", "m_N", "m_F", "platform") for n in getattr(balancing, key)}
    frames = [f for f in spec.frames if f.link not in links]
    names = {f.name for f in frames}
    return dataclasses.replace(
        spec, joints=[j for j in spec.joints if j.name not in removed],
        bodies=[b for b in spec.bodies if b.link not in links and b.name not in cw],
        frames=frames, loops=[lp for lp in spec.loops if lp.frame_a in names and lp.frame_b in names])


def with_masses(spec, masses: dict):
    """``spec`` with the masses of the named bodies replaced [kg]."""
    return dataclasses.replace(spec, bodies=[dataclasses.replace(b, mass=float(masses[b.name]))
                                             if b.name in masses else b for b in spec.bodies])


def driven_by_platform(spec, platform: str):
    """``spec`` with the platform's spherical joint as the prescribed coordinates: the loop solve
    is then the robot's inverse kinematics."""
    return dataclasses.replace(spec, actuated=[f"{platform}_z", f"{platform}_y", f"{platform}_x"])


# ---- motion ---------------------------------------------------------------------------------------

def platform_motion(motion, t):
    """(phi, phi', phi'') (N, 3) ordered z, y, x: the paper's motion of ``[motion]``."""
    return paper.paper_motion(t, motion.roll_amplitude, motion.yaw_amplitude, motion.period,
                              motion.yaw_factor)


def solve(mech: Mechanism, motion, t, guess: dict):
    """The general loop solve along the paper's motion (the platform's joint prescribed)."""
    phi, dphi, ddphi = platform_motion(motion, t)
    order = {f"{motion.platform}_z": 0, f"{motion.platform}_y": 1, f"{motion.platform}_x": 2}
    cols = [order[n] for n in mech.actuated_names]
    q0 = np.array([guess[n] for n in mech.joint_names], float)
    return mech.closed_motion(phi[:, cols], dphi[:, cols], ddphi[:, cols], q_guess=q0,
                              tolerance=SOLVE_TOLERANCE)


def motor_rcond(spec, driven: Mechanism, q) -> np.ndarray:
    """Reciprocal condition of the loop solve with the motors (the spec's own ``actuated``
    joints) as inputs, at the configurations ``q`` of the platform-driven mechanism ``driven``:
    the direct-kinematic (parallel) singularities, where locked motors do not hold the platform."""
    motor = Mechanism.from_spec(spec)
    idx = [driven.joint_names.index(n) for n in motor.joint_names]
    act = [motor.joint_names.index(n) for n in motor.actuated_names]
    out = np.zeros(len(q))
    for k, qk in enumerate(q[:, idx]):
        out[k] = float(motor.closed_motion(qk[act], q_guess=qk, tolerance=SOLVE_TOLERANCE).rcond)
    return out


def local_minima(t, x, count=5) -> list[dict]:
    """The ``count`` lowest interior local minima of ``x`` (with the ends), as {t, value}."""
    k = [i for i in range(len(x)) if (i == 0 or x[i] <= x[i - 1]) and (i == len(x) - 1 or x[i] <= x[i + 1])]
    k = sorted(k, key=lambda i: x[i])[:count]
    return [{"t": float(t[i]), "value": float(x[i])} for i in sorted(k)]


def coordinates(mech: Mechanism, q, prefix: str) -> np.ndarray:
    """Columns ``prefix_1``, ``prefix_2``, ``prefix_3`` of (N, dof) ``q``."""
    names = mech.joint_names
    return q[:, [names.index(f"{prefix}_{i}") for i in (1, 2, 3)]]


def intervals(t, mask) -> list[list[float]]:
    """[start, end] times of the runs of True in ``mask``."""
    out, start = [], None
    for k, m in enumerate(mask):
        if m and start is None:
            start = k
        if not m and start is not None:
            out.append([float(t[start]), float(t[k - 1])])
            start = None
    if start is not None:
        out.append([float(t[start]), float(t[-1])])
    return out


def ik_agreement(mech: Mechanism, m, geometry, motion, t) -> dict:
    """The general solve against the paper's closed-form inverse kinematics (eqs 1-13) and the
    closure of eq 2 recomputed from the solved coordinates."""
    phi, dphi, ddphi = platform_motion(motion, t)
    cf = paper.inverse_kinematics(geometry, phi, dphi, ddphi)
    ok = (m.status & ~_SINGULAR) == 0
    ok &= ~np.any(cf["degenerate"], axis=1)
    out = {"instants_compared": int(np.sum(ok))}
    for name, key in (("theta", "theta"), ("l", "l"), ("b", "b")):
        pos = coordinates(mech, m.q, name)[ok]
        vel = coordinates(mech, m.v, name)[ok]
        acc = coordinates(mech, m.a, name)[ok]
        d = pos - cf[key][ok]
        if name == "theta":
            d = np.angle(np.exp(1j * d))
        out[f"max_abs_error_{name}"] = float(np.max(np.abs(d), initial=0.0))
        out[f"max_abs_error_{name}_dot"] = float(np.max(np.abs(vel - cf[key + "_dot"][ok]), initial=0.0))
        out[f"max_abs_error_{name}_ddot"] = float(np.max(np.abs(acc - cf[key + "_ddot"][ok]), initial=0.0))
        out[f"max_abs_{name}_ddot"] = float(np.max(np.abs(cf[key + "_ddot"][ok]), initial=0.0))
    # eq 2 with the solved theta_i, l_i, b_i: |h + b_i R v_i - a u_i - l_i e_i|
    th, l, b = (coordinates(mech, m.q, n)[ok] for n in ("theta", "l", "b"))
    res = 0.0
    for s, (p, thk, lk, bk) in enumerate(zip(phi[ok], th, l, b)):
        R = paper.platform_rotation(p)
        for i in range(3):
            u = np.array([np.cos(geometry.lam[i]), np.sin(geometry.lam[i]), 0.0])
            v = R @ np.array([np.cos(geometry.alpha[i]), np.sin(geometry.alpha[i]), 0.0])
            e = np.cos(thk[i]) * np.array([0.0, 0.0, 1.0]) + np.sin(thk[i]) * np.cross(u, [0.0, 0.0, 1.0])
            r = np.array([0.0, 0.0, geometry.h]) + bk[i] * v - geometry.a[i] * u - lk[i] * e
            res = max(res, float(np.max(np.abs(r))))
    out["max_eq2_residual"] = res
    out["max_loop_residual"] = float(np.max(m.residual[ok], initial=0.0))
    out["closed_form_degenerate_instants"] = int(np.sum(np.any(cf["degenerate"], axis=1)))
    return out


def counterweight_slots(mech: Mechanism, spec, names: list[str]):
    """The design variables of the general method: one `mechbal.balance.CounterweightSlot`
    per named counterweight body of ``spec``, on its link at its centre of mass (a fixed position,
    in the frame the link is described in: only the mass is unknown, within [0, inf)), with its
    inertia; and ``mech`` without those bodies (the robot the slots are added to)."""
    from mechbal.balance import CounterweightSlot

    bodies = {b.name: b for b in spec.bodies}
    slots = []
    for name in names:
        b = bodies[name]
        T = mech.user_frame(b.link)
        R = T[:3, :3]
        slots.append(CounterweightSlot(name, b.link, position=tuple(R.T @ (np.asarray(b.com, float) - T[:3, 3])),
                                       inertia=R.T @ np.asarray(b.inertia, float) @ R))
    return slots, mech.with_bodies([b for b in mech.bodies if b.name not in set(names)], replace=True)


def size_counterweights(mech: Mechanism, spec, names: list[str], platform, dplatform, q_guess=None):
    """The general shaking-force method (`mechbal.balance.force.balance`): the masses of the
    ``names`` counterweight bodies (at their given points, bounded below by 0) that make the linear
    momentum zero over the samples (the platform's joint coordinates ``platform`` and rates
    ``dplatform``, (N, 3) in ``mech.actuated_names`` order: the loop solve gives the rest).
    Returns (masses by name, BalanceResult). A mass the condition makes zero (the platform
    counterweight) is held at its bound 0, not left at -1e-13."""
    from mechbal.balance import force

    slots, bare = counterweight_slots(mech, spec, names)
    result = force.balance(bare, slots, (platform, dplatform), q_guess=q_guess)
    return {n: float(result.design[n]["mass"]) for n in names}, result


def _bodies_file(path, mech, t, motion, F, M, **extra):
    write_bodies(path, t=t, names=mech.body_names, mass=np.array([b.mass for b in mech.bodies], float),
                 inertia_body=np.array([b.inertia for b in mech.bodies], float).reshape(-1, 3, 3),
                 com=motion.com, rotation=motion.rotation, shaking_force=F, shaking_moment=M, **extra)


def _reduction(before, after, floor):
    """100 (1 - |after| / |before|) [%], or None where |before| <= ``floor`` (a force that is zero
    by symmetry, as F_y at t = 0, has no reduction)."""
    if not abs(before) > floor:
        return None
    return float(100.0 * (1.0 - abs(after) / abs(before)))


def _mean(values):
    v = [x for x in values if x is not None]
    return float(np.mean(v)) if v else None


@register("rpsp", stages=5)
def run(config, out: Path) -> dict:
    case = validate_case(config, warn=False)
    bal, mo, pp = case.balancing, case.motion, case.paper
    geometry = paper.RpspGeometry(a=(pp.a,) * 3, h=pp.h, lam=tuple(pp.lambda_i), alpha=tuple(pp.alpha_i))
    spec_full = case.spec
    spec_unbal = unbalanced_spec(spec_full, bal)
    if len(mo.initial_guess) != len(spec_full.independent_joints):
        raise ConfigError("motion.initial_guess", "must have one value per joint coordinate", list(mo.initial_guess))
    guess = dict(zip(spec_full.independent_joints, mo.initial_guess))
    groups = {"m_P": bal.m_P, "m_N": bal.m_N, "m_F": bal.m_F, "platform": bal.platform}
    slots = [n for names in groups.values() for n in names]
    name = case.case.name

    progress.stage("loop solve along the paper's motion")
    t = np.linspace(0.0, mo.duration, mo.samples)
    mech_unbal = Mechanism.from_spec(driven_by_platform(spec_unbal, mo.platform), name=f"{name}_unbalanced")
    mech_paper = Mechanism.from_spec(driven_by_platform(spec_full, mo.platform), name=f"{name}_paper_masses")
    m_unbal = solve(mech_unbal, mo, t, guess)
    m_full = solve(mech_paper, mo, t, guess)
    for what, m in (("robot", m_unbal), ("robot with the extra linkage", m_full)):
        bad = (m.status & ~_SINGULAR) != 0
        if np.any(bad):
            k = int(np.argmax(bad))
            raise ConfigError("motion.duration", f"the {what} cannot be assembled at t = {t[k]:.4g} s "
                                                 f"(closure residual {m.residual[k]:.3g} m); shorten the "
                                                 "run or check [motion.initial_guess]", mo.duration)

    progress.stage("sizing the counterweights (eqs 29-31 and the general method)")
    phi, dphi, _ = platform_motion(mo, t)
    order = {f"{mo.platform}_z": 0, f"{mo.platform}_y": 1, f"{mo.platform}_x": 2}
    cols = [order[n] for n in mech_paper.actuated_names]
    q0 = np.array([guess[n] for n in mech_paper.joint_names], float)
    masses, sized = size_counterweights(mech_paper, spec_full, slots, phi[:, cols], dphi[:, cols], q_guess=q0)
    if sized.metrics["dropped_samples"]:
        raise ConfigError("motion.duration", f"{sized.metrics['dropped_samples']} samples of the run cannot be "
                          "assembled for the sizing", mo.duration)
    eqs = paper.counterweights_eqs_29_31(pp.m_E, pp.m_Q, pp.m_H, pp.m_K, pp.r_H, pp.r_K, pp.r_P, pp.r_N,
                                         pp.r_Q, pp.r_F)
    per_group = {k: [masses[n] for n in names] for k, names in groups.items()}
    counterweights = {k: float(np.mean(per_group[k])) for k in ("m_P", "m_N", "m_F")}
    closed_form = {k: float(eqs[k]) for k in ("m_P", "m_N", "m_F")}
    max_difference = max(abs(m - closed_form[k]) for k in closed_form for m in per_group[k])
    if not sized.exact or max_difference > COUNTERWEIGHT_AGREEMENT_KG:
        raise ConfigError("balancing", f"the general force method's counterweights {per_group} differ from eqs "
                          f"29-31 ({closed_form}) by {max_difference:.3g} kg > {COUNTERWEIGHT_AGREEMENT_KG:g} kg"
                          + ("" if sized.exact else "; limited by: " + "; ".join(sized.limited_by))
                          + ": the [paper] masses and radii and the [mechanism] bodies describe different robots",
                          has_value=False)
    mech_bal = Mechanism.from_spec(driven_by_platform(with_masses(spec_full, masses), mo.platform),
                                   name=f"{name}_balanced")
    coeff_paper = paper.balance_coefficients(pp.counterweights_kg.m_P, pp.counterweights_kg.m_N,
                                             pp.counterweights_kg.m_F, pp.m_E, pp.m_Q, pp.m_H, pp.m_K,
                                             pp.r_H, pp.r_K, pp.r_P, pp.r_N, pp.r_Q, pp.r_F)

    progress.stage("shaking force, platform, tables")
    F, M, motions = {}, {}, {}
    for key, mech, m in (("unbalanced", mech_unbal, m_unbal), ("balanced", mech_bal, m_full),
                         ("paper_masses", mech_paper, m_full)):
        sw = mech.shaking_wrench(m.q, m.v, m.a)
        motions[key] = mech.body_motion(m.q, m.v, m.a)
        if np.any(sw.status != 0) or np.any(motions[key].status != 0):
            raise ConfigError("motion", f"{key}: non-finite shaking wrench along the run", has_value=False)
        F[key], M[key] = sw.shaking_force, sw.shaking_moment
    plat = [mech_bal.body_names.index(n) for n in ["platform", *bal.platform] if n in mech_bal.body_names]
    mass_b = np.array([b.mass for b in mech_bal.bodies])
    F_platform = np.einsum("b,nbi->ni", mass_b[plat], motions["balanced"].com_acceleration[:, plat])
    # the paper's instants (exactly, not interpolated)
    tt = np.asarray(pp.table_times, float)
    tab = {}
    for key, mech, spec in (("unbalanced", mech_unbal, None), ("balanced", mech_bal, None),
                            ("paper_masses", mech_paper, None)):
        mt = solve(mech, mo, tt, guess)
        tab[key] = mech.shaking_wrench(mt.q, mt.v, mt.a).shaking_force
    peak = {k: report.peak_abs(F[k]) for k in F}
    rms = {k: np.sqrt(np.mean(F[k] ** 2, axis=0)) for k in F}
    table_rows = {}
    axes = "xyz"
    floor = 1e-9 * np.max(peak["unbalanced"])
    for ax in range(3):
        table_rows[axes[ax]] = [
            {"t": float(tt[k]), "unbalanced": float(tab["unbalanced"][k, ax]),
             "balanced": float(tab["balanced"][k, ax]),
             "reduction_pct": _reduction(tab["unbalanced"][k, ax], tab["balanced"][k, ax], floor),
             "paper_masses": float(tab["paper_masses"][k, ax]),
             "paper_masses_reduction_pct": _reduction(tab["unbalanced"][k, ax], tab["paper_masses"][k, ax], floor)}
            for k in range(len(tt))]
    mean_red = [_mean([r["reduction_pct"] for r in table_rows[a]]) for a in axes]
    mean_red_paper_masses = [_mean([r["paper_masses_reduction_pct"] for r in table_rows[a]]) for a in axes]
    agreement = ik_agreement(mech_paper, m_full, geometry, mo, t)

    progress.stage("survey of the whole period")
    ts = np.linspace(0.0, mo.survey_duration, mo.survey_samples)
    s_unbal = solve(mech_unbal, mo, ts, guess)
    s_full = solve(mech_paper, mo, ts, guess)
    phi_s, dphi_s, ddphi_s = platform_motion(mo, ts)
    cf = paper.inverse_kinematics(geometry, phi_s, dphi_s, ddphi_s)
    reach = pp.AD + pp.DC
    unreachable = np.any(cf["l"] > reach, axis=1)
    failed = (s_full.status & ~_SINGULAR) != 0
    l_min = np.min(cf["l"], axis=0)
    k_rc = int(np.argmin(s_unbal.rcond))
    near = NEAR_SINGULAR_FRACTION * float(np.median(s_unbal.rcond))
    rc_motor = motor_rcond(spec_unbal, mech_unbal, s_unbal.q)
    survey = {
        "duration": float(mo.survey_duration), "samples": int(mo.survey_samples),
        "robot": {
            "min_rcond": float(s_unbal.rcond[k_rc]), "t_min_rcond": float(ts[k_rc]),
            "shortest_leg_at_min_rcond": int(np.argmin(cf["l"][k_rc]) + 1),
            "rcond_local_minima": local_minima(ts, s_unbal.rcond),
            "near_singular_rcond": near,
            "near_singular_rule": f"rcond < {NEAR_SINGULAR_FRACTION} x its median over the survey",
            "near_singular_intervals": intervals(ts, s_unbal.rcond < near),
            "motors_actuated": {
                "what": "rcond of the loop solve with the motors theta_i as inputs (direct kinematics) at "
                        "the same configurations: its zeros are parallel singularities",
                "min_rcond": float(np.min(rc_motor)), "t_min_rcond": float(ts[np.argmin(rc_motor)]),
                "rcond_at_start": float(rc_motor[0]),
                "rcond_local_minima": local_minima(ts, rc_motor),
            },
            "singular_instants": int(np.sum((s_unbal.status & _SINGULAR) != 0)),
            "failed_instants": int(np.sum((s_unbal.status & ~_SINGULAR) != 0)),
            "max_loop_residual": float(np.max(s_unbal.residual)),
            "min_leg_length": l_min.tolist(),
            "t_min_leg_length": [float(ts[k]) for k in np.argmin(cf["l"], axis=0)],
            "max_leg_length": np.max(cf["l"], axis=0).tolist(),
            "min_abs_eq8_denominator": float(np.min(np.abs(cf["denominator"]))),
            "closed_form_degenerate_instants": int(np.sum(np.any(cf["degenerate"], axis=1))),
            "ik_agreement": ik_agreement(mech_unbal, s_unbal, geometry, mo, ts),
        },
        "with_extra_linkage": {
            "linkage_reach": reach,
            "unreachable_intervals": intervals(ts, unreachable),
            "failed_intervals": intervals(ts, failed),
            "failed_instants": int(np.sum(failed)),
            "singular_instants": int(np.sum((s_full.status & _SINGULAR) != 0)),
            "min_rcond_where_solved": float(np.min(s_full.rcond[~failed], initial=np.inf)),
        },
        # where the loops were solved (a failed instant is NaN by design, counted above)
        "nan_free": bool(all(np.all(np.isfinite(x[(m.status & ~_SINGULAR) == 0])) for m in (s_unbal, s_full)
                             for x in (m.q, m.v, m.a, m.rcond, m.residual))),
    }

    progress.stage("files and summary")
    for key, mech, m in (("unbalanced", mech_unbal, m_unbal), ("balanced", mech_bal, m_full)):
        _bodies_file(out / f"bodies_{key}.npz", mech, t, motions[key], F[key], M[key], q=m.q, qd=m.v,
                     qdd=m.a, rcond=m.rcond, status=m.status)
    files = ["bodies_unbalanced.npz", "bodies_balanced.npz"]
    for ax in range(3):
        f = f"shaking_force_{axes[ax]}.png"
        report.plot_series(out / f, t, {"before balancing": F["unbalanced"][:, ax:ax + 1],
                                        "after balancing (sized)": F["balanced"][:, ax:ax + 1],
                                        "after balancing (paper's masses)": F["paper_masses"][:, ax:ax + 1]},
                           [f"{axes[ax]} axis"], "shaking force [N]",
                           title=f"{name}: shaking force along {axes[ax]} (Fig. {5 + ax})",
                           caption="Shaking force on the base (inertial, no gravity) along the paper's motion: "
                                   "the robot without the extra linkage, with it and the counterweights sized "
                                   "here (zero to round-off), and with the paper's printed masses.")
        files.append(f)
    report.plot_series(out / "survey.png", ts,
                       {"survey": np.column_stack([cf["l"], s_unbal.rcond, rc_motor])},
                       ["leg 1 length l_1", "leg 2 length l_2", "leg 3 length l_3",
                        "rcond, platform driven (inverse kinematics)", "rcond, motors driven (direct kinematics)"],
                       ["length [m]", "length [m]", "length [m]", "rcond (dimensionless)", "rcond (dimensionless)"],
                       title=f"{name}: conditioning over the whole period",
                       caption=f"Leg lengths (eq 9) and the reciprocal condition of the loop solve of the robot "
                               f"(without the extra linkage) with the platform or the motors as inputs. The "
                               f"extra linkage reaches {reach:g} m: legs 2 and 3 go beyond it.")
    files.append("survey.png")
    cons = paper.table_consistency()
    discrepancies = _discrepancies(eqs, pp, counterweights, coeff_paper, cons, survey, table_rows, tt)
    summary = {
        "case": name, "kind": "rpsp", "paper": "Heydari & Enferadi, 3(RPSP)-S balancing by extra linkage",
        "variants": ["unbalanced", "balanced", "paper_masses"],
        "duration": float(mo.duration), "samples": int(mo.samples),
        "counterweight_masses": counterweights,
        "counterweight_masses_per_leg": per_group,
        "counterweight_masses_eqs_29_31": eqs,
        "paper_counterweight_masses": pp.counterweights_kg.model_dump(),
        "platform_counterweight_mass": per_group["platform"],
        "general_method": {"method": "mechbal.balance.force: least squares of the linear momentum over the "
                                     "run's closed motion, one slot per counterweight body at its given point "
                                     "(only the mass unknown, >= 0)",
                           "unknowns": sized.unknowns, "rank": sized.rank, "exact": sized.exact,
                           "singular_value_ratio": sized.metrics["singular_value_ratio"],
                           "limited_by": sized.limited_by, "samples": sized.metrics["samples"],
                           "residual_momentum": sized.residual, "momentum_before": sized.residual_before,
                           "residual_units": sized.residual_units},
        "counterweights": {"general_method": counterweights, "closed_form": closed_form,
                           "max_abs_difference": max_difference, "tolerance": COUNTERWEIGHT_AGREEMENT_KG,
                           "unit": "kg", "closed_form_source": "Heydari & Enferadi eqs 29-31"},
        "eq28_coefficients_with_paper_masses": list(coeff_paper),
        "peak_shaking_force": {k: peak[k] for k in peak},
        "rms_shaking_force": {k: rms[k] for k in rms},
        "balanced_over_unbalanced_peak": (peak["balanced"] / peak["unbalanced"]).tolist(),
        "peak_platform_shaking_force": report.peak_abs(F_platform),
        "mean_reduction_pct": mean_red,
        "mean_reduction_pct_paper_masses": mean_red_paper_masses,
        "rms_reduction_pct": (100.0 * (1.0 - rms["balanced"] / rms["unbalanced"])).tolist(),
        "rms_reduction_pct_paper_masses": (100.0 * (1.0 - rms["paper_masses"] / rms["unbalanced"])).tolist(),
        "paper_mean_reduction_pct": list(pp.mean_reduction_pct),
        "mean_reduction_note": "mean over the paper's instants of 100 (1 - |balanced| / |unbalanced|), as the "
                               "paper's tables; an instant where the unbalanced force is zero (y at t = 0, by "
                               "symmetry) has no reduction (null) and is left out of the mean",
        "tables": table_rows,
        "paper_tables": cons,
        "total_mass": {"unbalanced": mech_unbal.total_mass, "balanced": mech_bal.total_mass,
                          "paper_masses": mech_paper.total_mass},
        "added_mass": mech_bal.total_mass - mech_unbal.total_mass,
        "loops": {"min_rcond": float(np.min(m_full.rcond)), "t_min_rcond": float(t[np.argmin(m_full.rcond)]),
                  "singular_instants": int(np.sum((m_full.status & _SINGULAR) != 0)),
                  "max_closure_residual": float(np.max(m_full.residual))},
        "ik_agreement": agreement,
        "survey": survey,
        "discrepancies": discrepancies,
        "files": files + ["summary.json"],
    }
    write_summary(out / "summary.json", summary)
    print(report.table([["m_P", counterweights["m_P"], eqs["m_P"], pp.counterweights_kg.m_P],
                        ["m_N", counterweights["m_N"], eqs["m_N"], pp.counterweights_kg.m_N],
                        ["m_F", counterweights["m_F"], eqs["m_F"], pp.counterweights_kg.m_F]],
                       ["counterweight [kg]", "general method", "eqs 29-31", "paper"]))
    print(report.table([["unbalanced", *peak["unbalanced"]], ["balanced", *peak["balanced"]],
                        ["paper's masses", *peak["paper_masses"]]], ["peak shaking force [N]", "x", "y", "z"]))
    return summary


def _discrepancies(eqs, pp, cw, coeff_paper, cons, survey, rows, tt) -> list[str]:
    out = []
    pc = pp.counterweights_kg
    if abs(eqs["m_N"] - pc.m_N) > 5e-3 or abs(eqs["m_P"] - pc.m_P) > 5e-3:
        out.append(
            f"Counterweights: eqs 29-31 with the printed parameters give m_N = {eqs['m_N']:.4g} kg and "
            f"m_P = {eqs['m_P']:.4g} kg (the general method: {cw['m_N']:.4g} / {cw['m_P']:.4g} kg), not the "
            f"printed {pc.m_N} / {pc.m_P} kg; m_F = {eqs['m_F']:.4g} kg agrees. The printed m_P follows from "
            f"the printed m_N through the exact balance condition (eq 28's d_D coefficient with eq 30 not "
            f"substituted: m_P = -(m_H r_H + m_K (1 - r_K) + m_N (1 - r_N)) / r_P), so the error is in m_N "
            f"= -(m_K r_K + m_Q) / r_N = {eqs['m_N']:.4g} kg. With the printed masses the coefficients of "
            f"eq 28 are ({coeff_paper[0]:.3g}, {coeff_paper[1]:.3g}, {coeff_paper[2]:.3g}) kg instead of 0: "
            "a residual shaking force of 0.09 kg times the accelerations of D_i and C_i - D_i.")
    for ax, v in cons.items():
        bad = [r for r in v["rows"] if not r["consistent"]]
        for r in bad:
            out.append(f"Table {'xyz'.index(ax) + 1} ({ax}), t = {r['t']}: the printed reduction "
                       f"{r['printed_pct']} % does not follow from the printed forces {r['before']} / "
                       f"{r['after']} N ({r['recomputed_pct']:.4f} %).")
    out.append("Tables 1-3: the readings that reconcile the cells: x, t = 0.102: 98.5147 % (printed 98.0147); "
               "y, t = 0: after = 5.0244 N (printed 0.0244, gives 81.52 %); y, t = 0.1: before = -56.5087 N "
               "(printed -56.05087, gives 80.96 %); y, t = 0.102: 76.455 % (printed 76.405); z, t = 0.052: "
               "99.6953 % (printed 99.7953); z, t = 0.1: before = -235.936 N (printed -225.936, gives "
               "99.316 %). Table 1's last 'before' prints 18956 for 1.8956 N; the fourth instant prints "
               "0.102 s in every table (0.152 by the 0.05 s spacing).")
    out.append(f"Mean reductions: the printed percentage columns average "
               f"{cons['x']['mean_printed_pct']:.2f} / {cons['y']['mean_printed_pct']:.2f} / "
               f"{cons['z']['mean_printed_pct']:.2f} %; the text rounds them to 98 / 79 / 99.4 % (z's mean "
               "is 99.50 %, 99.48 % with the corrected cells).")
    out.append("The tables' forces (60-225 N within 0.2 s, changing sign between 0.052 s and 0.1 s) cannot "
               "come from the printed motion (T = 2 pi s: the platform turns at about 1 rad/s and the "
               "lumped masses' accelerations are below 1 m/s^2 at these instants); the ADAMS model's time "
               "scale or motion must differ, so the tables' values are compared in ratio only. Here at "
               f"t = {tt[0]:g} s the unbalanced force is ({rows['x'][0]['unbalanced']:.3g}, "
               f"{rows['y'][0]['unbalanced']:.3g}, {rows['z'][0]['unbalanced']:.3g}) N.")
    w = survey["with_extra_linkage"]
    if w["unreachable_intervals"]:
        out.append(f"The extra linkage (|A_iD_i| + |D_iC_i| = {w['linkage_reach']:g} m) cannot follow the "
                   f"printed motion over the whole period: the legs reach "
                   f"{max(survey['robot']['max_leg_length']):.3f} m and the linkage cannot be assembled for t in "
                   + ", ".join(f"[{a:.3f}, {b:.3f}]" for a, b in w["unreachable_intervals"])
                   + " s; the comparison runs over the first "
                   "assemblable span.")
    r = survey["robot"]
    out.append(f"Near-singularity: leg {r['shortest_leg_at_min_rcond']} shortens to "
               f"{min(r['min_leg_length']) * 1000:.1f} mm at t = {r['t_min_rcond']:.3f} s (rcond "
               f"{r['min_rcond']:.3g}); eq 10 divides by l_i, eq 13 by u_ix (written here without it).")
    rr = [r["paper_masses_reduction_pct"] for r in rows["x"]]
    out.append("Balance: with the sized counterweights the lumped-mass model is balanced to round-off "
               "(reduction 100 % on every axis). The paper's printed masses alone leave a residual of 0.09 kg "
               "times the accelerations of D_i and C_i - D_i, which here still reduces the force by "
               f"{min(x for x in rr if x is not None):.1f}-{max(x for x in rr if x is not None):.1f} % in x at "
               "the paper's instants and more in y and z, not 98 / 79 / 99.4 %: the paper's residual comes "
               "from its ADAMS multibody model (link inertias and distributed masses, the platform's sliders, "
               "whatever else differs from the lumped model of eq 14), not from eqs 29-31; see "
               "docs/rpsp_derivation.md.")
    out.append("Parallel singularity: the home pose R = I (every leg vertical, where the paper's motion starts) "
               "is a singularity of the motor-driven robot: locked motors let the platform roll and pitch to "
               "first order (rcond of the direct kinematics "
               f"{survey['robot']['motors_actuated']['rcond_at_start']:.2g}); the paper drives the motors "
               "with theta_i(t) from the inverse kinematics, which is well conditioned there.")
    return out
