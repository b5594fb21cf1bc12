"""Runner for ``kind = "paminsa"``: Briot & Arakelian 2009, PAMINSA unbalanced, force-balanced and
fully balanced (counterweights + vertical counter-mass + reactionless wrist), over the paper's cycle.

Writes bodies_{unbalanced,force_balanced,balanced}.npz (+ bodies_balanced_{euler,rk4}.npz, whose
shaking_force/shaking_moment are the wrench of the stored poses and shaking_*_commanded the
controller's ideal one: see `pose_wrench`),
shaking_wrench.png (the paper's Fig. 4), wrist_angles.png (Fig. 5), wrist_condition.png and
summary.json, and prints a table.

The "+35 % in M_z after force balancing" (paper, Sec. III): once F = 0 the shaking moment is the
same about every point, but the unbalanced moment is not (M_Q = M_O - OQ x F, with F_y up to
~27 N). About O of the reconstructed layout M_z drops; about the base centre (centroid of the B_i)
it rises by ~38 %, the paper's pattern: the heavy counterweights at A_i, moving opposite to the
platform at the far ends of the legs, form a z-couple that force balancing does not remove.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal import progress, report
from mechbal.cases import register
from mechbal.config import ConfigError
from mechbal.schema import validate_case
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences, write_bodies, write_summary
from mechbal.papers import paminsa as paper
from mechbal.papers.paminsa import parameters_from_config  # noqa: F401 (re-exported)

def wrist_config_from_config(config, integrator: str | None = None):
    from mechbal.papers.paminsa.controller import ReactionlessWristConfig, WristIntegrator

    w = validate_case(config, warn=False).wrist
    try:
        return ReactionlessWristConfig(
            rate_hz=w.rate_hz, integrator=getattr(WristIntegrator, integrator or w.integrator),
            max_rate=w.max_rate, max_condition=w.max_condition, damping=w.damping)
    except ValueError as exc:
        raise ConfigError("wrist", str(exc), w.model_dump()) from None


def trajectory_from_config(config):
    from mechbal.trajectory import RestToRestTrajectory, TimeLaw

    tr = validate_case(config, warn=False).trajectory
    return RestToRestTrajectory(np.array(tr.start, float), np.array(tr.end, float), tr.duration,
                                getattr(TimeLaw, tr.law))


#: how far the general method's counterweights may be from the closed form's [kg]. Both are exact
#: (the method solves a rank-4, zero-residual least squares over solved closed motions; the closed
#: form is algebra): they agree to ~1e-12 kg. A disagreement beyond 1 mg on masses of 0.4-10 kg is
#: a different mechanism, not round-off: slot positions that no longer follow [geometry].
COUNTERWEIGHT_AGREEMENT_KG = 1e-6


def general_counterweights(config):
    """PAMINSA's counterweights by the general shaking-force method (`mechbal.balance.force`)
    on the case's mechanism (`mechbal.papers.paminsa.paminsa_mechanism`, unbalanced) with the
    slots of its ``[balance]`` table, as ``mechbal balance paminsa --method force`` runs it.
    Returns (`mechbal.papers.paminsa.CounterweightSet`, the method's BalanceResult)."""
    from mechbal.balance.run import case_from_config, run_method

    case = validate_case(config, warn=False)
    if getattr(case, "balance", None) is None or not case.balance.counterweights:
        raise ConfigError("balance.counterweights", "the paminsa runner sizes its counterweights by the general "
                          "method: give the [[balance.counterweights]] slots (leg<i>.CP1_atA, leg<i>.CP2_atF, "
                          "leg<i>.CP3_atL, vertical_counter_mass; see cases/paminsa.toml)", has_value=False)
    result = run_method(case_from_config(case), "force")
    try:
        cw = paper.counterweights_from_design(result.design, "general_method (mechbal.balance.force, [balance] slots)")
    except KeyError as exc:
        raise ConfigError("balance.counterweights", exc.args[0], has_value=False) from None
    return cw, result


def check_against_closed_form(general, closed, result, tolerance: float = COUNTERWEIGHT_AGREEMENT_KG) -> float:
    """The largest |general - closed form| [kg] over every counterweight; ConfigError when the
    method is not exact or the two differ by more than ``tolerance``."""
    diff = max(float(np.max(np.abs(np.subtract(getattr(general, k), getattr(closed, k)))))
               for k in ("cp1", "cp2", "cp3", "vertical"))
    if not result.exact or diff > tolerance:
        why = ("; the method is limited by: " + "; ".join(result.limited_by)) if not result.exact else ""
        raise ConfigError("balance.counterweights",
                          f"the general force method's counterweights (CP1 {general.cp1[0]:.6g}, CP2 {general.cp2[0]:.6g}, "
                          f"CP3 {general.cp3[0]:.6g}, vertical {general.vertical:.6g} kg) differ from the closed form's "
                          f"(eqs 11, 14-16: {closed.cp1[0]:.6g}, {closed.cp2[0]:.6g}, {closed.cp3[0]:.6g}, "
                          f"{closed.vertical:.6g} kg) by {diff:.3g} kg > {tolerance:g} kg{why}. The slots' positions "
                          "must follow [geometry]: A at -length_AE on link 3, F at length_DF / k on link 2, L at "
                          "cp3_ratio * length_MS5 on the guide", has_value=False)
    return diff


def half_step_samples(traj, rate_hz: float):
    """Platform motion on the half-step grid t_j = j dt/2 (what an RK4 tick needs) and the tick times."""
    dt = 1.0 / rate_hz
    steps = int(round(traj.duration / dt))
    th = np.arange(2 * steps + 1) * (dt / 2)
    P, Pd, Pdd = traj.evaluate_batch(th)
    return th[::2], P, Pd, Pdd


def _kept(model):
    """Bodies worth exporting: those with mass or rotational inertia (drops absent counterweights)."""
    m, J = np.asarray(model.masses), np.asarray(model.inertia_body)
    return np.nonzero((m > 0) | (np.abs(J).reshape(len(m), -1).max(axis=1) > 0))[0]


def _export(path, t, model, run, **extra):
    keep = _kept(model)
    names = [model.body_names[i] for i in keep]
    return write_bodies(path, t=t, names=names, mass=np.asarray(model.masses)[keep],
                        inertia_body=np.asarray(model.inertia_body)[keep],
                        com=run["com"][:, keep], rotation=run["rotation"][:, keep],
                        shaking_force=run["shaking_force"], shaking_moment=run["shaking_moment"], **extra)


def pose_wrench(model, t, P, Pd, Pdd, wrist_angles):
    """Shaking wrench (and kinematics) of the motion through the stored poses: the platform on
    its planned trajectory and the wrist along the quintic spline (C4, not-a-knot) through the
    wrist angles the controller produced at the ticks.

    The controller's own moment (``paminsa_reactionless_run``'s ``shaking_moment``) is that of
    the *commanded* rates and feed-forward accelerations, zero to rounding at every tick; the
    stored angles are those rates integrated (Euler or RK4), whose motion does not have zero
    moment (Euler: 0.24 N m, 0.9 % of the unbalanced peak). A file must hold the wrench of the
    poses it stores (docs/architecture.md, Data flow: the output), so this is what ``bodies_balanced*.npz`` calls
    ``shaking_moment``; central differences of the stored poses agree with it to ~4e-5 N m (their
    own truncation error at 1 kHz)."""
    from scipy.interpolate import make_interp_spline

    from mechbal.papers.paminsa import paminsa_kinematics

    spline = make_interp_spline(t, wrist_angles, k=5)
    return paminsa_kinematics(model, P, Pd, Pdd, wrist_angles, spline(t, 1), spline(t, 2))


def moment_about(M, F, point):
    """M_Q = M_O - OQ x F."""
    return M - np.cross(np.asarray(point, float)[None, :], F)


@register("paminsa", stages=5)
def run(config, out: Path) -> dict:
    from mechbal.papers.paminsa import PaminsaModel, paminsa_kinematics, paminsa_reactionless_run

    config = validate_case(config, warn=False)
    params = parameters_from_config(config)
    cycle = trajectory_from_config(config)
    q0 = np.array(config.wrist.initial_angles, float)
    primary = config.wrist.integrator
    use = config.counterweights.use

    progress.stage("sizing counterweights (general force method, checked by the closed form)")
    # ---- counterweights: the general method, checked by the closed forms; the printed equations
    general, result = general_counterweights(config)
    closed = paper.closed_form_counterweights(params)
    difference = check_against_closed_form(general, closed, result)
    printed = paper.printed_counterweights(params)
    reported = paper.reported_counterweights(params, closed.vertical)
    chosen = {"general_method": general, "closed_form": closed, "paper_reported": reported}[use]

    model_unbal = PaminsaModel(params)
    model_bal = PaminsaModel(chosen.apply(params))
    model_reported = PaminsaModel(reported.apply(params))

    # ---- motion
    progress.stage("kinematics and reactionless wrist (Euler, RK4)")
    cfg = {name: wrist_config_from_config(config, name) for name in ("euler", "rk4")}
    rate = cfg[primary].rate_hz
    t, Ph, Pdh, Pddh = half_step_samples(cycle, rate)
    P, Pd, Pdd = Ph[::2], Pdh[::2], Pddh[::2]
    still = np.tile(q0, (len(t), 1))
    zero = np.zeros_like(P)
    unbal = paminsa_kinematics(model_unbal, P, Pd, Pdd, still, zero, zero)
    fbal = paminsa_kinematics(model_bal, P, Pd, Pdd, still, zero, zero)
    rep = paminsa_kinematics(model_reported, P, Pd, Pdd, still, zero, zero)
    bal = {name: paminsa_reactionless_run(model_bal, c, q0, Ph, Pdh, Pddh) for name, c in cfg.items()}

    # ---- export
    progress.stage("bodies files (wrench of the stored poses)")
    _export(out / "bodies_unbalanced.npz", t, model_unbal, unbal, P=P, Pd=Pd, Pdd=Pdd)
    _export(out / "bodies_force_balanced.npz", t, model_bal, fbal, P=P, Pd=Pd, Pdd=Pdd)
    posed = {}
    for name, r in bal.items():
        # the wrench of the stored poses, not the controller's commanded (ideal) one
        posed[name] = pose_wrench(model_bal, t, P, Pd, Pdd, r["wrist_angles"])
        extra = dict(P=P, wrist_angles=r["wrist_angles"], wrist_rates=r["wrist_rates"],
                     wrist_accelerations=r["wrist_accelerations"], condition=r["condition"], D=r["D"],
                     shaking_force_commanded=r["shaking_force"],
                     shaking_moment_commanded=r["shaking_moment"])
        stored = dict(r, shaking_force=posed[name]["shaking_force"],
                      shaking_moment=posed[name]["shaking_moment"])
        _export(out / f"bodies_balanced_{name}.npz", t, model_bal, stored, **extra)
        if name == primary:
            _export(out / "bodies_balanced.npz", t, model_bal, stored, integrator=np.array(name), **extra)

    progress.stage("checks from the exported poses, plots")
    # ---- the balanced moment recomputed from the exported poses alone (central differences)
    inner = slice(2, -2)
    F_unbal, M_unbal = unbal["shaking_force"], unbal["shaking_moment"]
    peak_F_norm = float(np.linalg.norm(F_unbal, axis=1).max())
    peak_M_norm = float(np.linalg.norm(M_unbal, axis=1).max())
    fd = {}
    for name in ("euler", "rk4"):
        F_fd, M_fd = shaking_wrench_by_finite_differences(read_bodies(out / f"bodies_balanced_{name}.npz"))
        fd[name] = (report.peak_abs(F_fd[inner]), report.peak_abs(M_fd[inner]))
    F_fb_fd, _ = shaking_wrench_by_finite_differences(read_bodies(out / "bodies_force_balanced.npz"))

    # ---- the +35 % z-moment
    base_centre = np.append(np.asarray(model_unbal.slider_lines).mean(axis=0), params.z_A)
    M_fb = fbal["shaking_moment"]
    ratio_O = float(np.abs(M_fb[:, 2]).max() / np.abs(M_unbal[:, 2]).max())
    Mu_c = moment_about(M_unbal, F_unbal, base_centre)
    Mf_c = moment_about(M_fb, fbal["shaking_force"], base_centre)
    ratio_c = float(np.abs(Mf_c[:, 2]).max() / np.abs(Mu_c[:, 2]).max())

    # ---- plots (Fig. 4, Fig. 5, cond N)
    title = config.case.title or "PAMINSA"
    report.plot_wrench(out / "shaking_wrench.png", t,
                       {"unbalanced": (F_unbal, M_unbal), "force-balanced": (fbal["shaking_force"], M_fb),
                        f"fully balanced ({primary})": (bal[primary]["shaking_force"], bal[primary]["shaking_moment"])},
                       title=title + " (moments about O)",
                       caption="Shaking force and moment about O over the paper's cycle (cf. "
                               "Briot & Arakelian 2009, Fig. 4): unbalanced; force-balanced by "
                               "the counterweights and vertical counter-mass (force ~0, moment "
                               "remains); fully balanced, the reactionless wrist also cancelling "
                               "the moment (the controller's moment, zero at every tick; the "
                               "moment of the stored poses is in the bodies files).")
    report.plot_series(out / "wrist_angles.png", t, {n: r["wrist_angles"] for n, r in bal.items()},
                       ["phi", "theta", "psi"], "angle [rad]", title="reactionless wrist angles (z-x-z)",
                       caption="Wrist angles commanded by the reactionless wrist at 1 kHz with "
                               "explicit Euler (eq 26) and RK4 (cf. Fig. 5); the two integrators "
                               "coincide to the eye (RK4 dashed over Euler).")
    report.plot_series(out / "wrist_condition.png", t, {n: r["condition"] for n, r in bal.items()},
                       ["cond(N)"], "condition number [-]", title="condition number of N along the run",
                       caption="Condition number of the wrist momentum matrix N (eq 23, corrected) "
                               "along the run; the wrist is far from its z-x-z singularity.")

    # ---- summary
    progress.stage("summary")
    rates = {n: report.peak_abs(r["wrist_rates"]) for n, r in bal.items()}
    cond = bal[primary]["condition"]
    m_reported = np.linalg.norm(rep["shaking_force"], axis=1).max()
    summary = {
        "case": config.case.name,
        "kind": "paminsa",
        "paper": "Briot & Arakelian 2009, AIM, PAMINSA complete shaking force and moment balancing",
        "duration": float(cycle.duration),
        "samples": int(len(t)),
        "tick_rate_hz": float(rate),
        "integrator": primary,
        "integrators_run": ["euler", "rk4"],
        "wrist_initial_angles": q0,
        "counterweights_used": use,
        "counterweight_masses": {"cp1": chosen.cp1, "cp2": chosen.cp2, "cp3": chosen.cp3,
                              "vertical": chosen.vertical, "source": chosen.source},
        "counterweights": {
            "general_method": general.as_dict(), "closed_form": closed.as_dict(),
            "max_abs_difference": difference, "tolerance": COUNTERWEIGHT_AGREEMENT_KG, "unit": "kg",
            "method": {"name": "force", "slots": "[balance] of the case (tied legs, fixed positions)",
                       "samples": result.metrics["samples"], "unknowns": result.unknowns, "rank": result.rank,
                       "singular_value_ratio": result.metrics["singular_value_ratio"],
                       "residual": result.residual, "residual_before": result.residual_before,
                       "residual_units": result.residual_units, "exact": result.exact}},
        "counterweight_masses_paper_printed_eqs": printed.as_dict(),
        "paper_counterweight_masses": dict(paper.REPORTED_COUNTERWEIGHTS_KG, vertical=None),
        "peak_shaking_force": {"unbalanced": report.peak_abs(F_unbal),
                                 "force_balanced": report.peak_abs(fbal["shaking_force"]),
                                 "balanced": fd[primary][0],
                                 "paper_reported_masses": report.peak_abs(rep["shaking_force"])},
        "peak_shaking_moment": {"unbalanced": report.peak_abs(M_unbal),
                                   "force_balanced": report.peak_abs(M_fb),
                                   "balanced": fd[primary][1],
                                   "balanced_stored_poses": report.peak_abs(posed[primary]["shaking_moment"][inner]),
                                   "balanced_commanded": report.peak_abs(bal[primary]["shaking_moment"])},
        "moment_reference": ("about O; 'balanced' recomputed from the exported poses by central "
                             "differences; 'balanced_stored_poses' is the bodies files' "
                             "shaking_moment (the wrench of the stored poses, wrist on a quintic "
                             "spline through the stored angles); 'balanced_commanded' is the "
                             "controller's ideal moment (the files' shaking_moment_commanded)"),
        "peak_shaking_force_norm_unbalanced": peak_F_norm,
        "peak_shaking_moment_norm_unbalanced": peak_M_norm,
        "balanced_moment_residual_percent_of_unbalanced_peak": {
            n: 100.0 * fd[n][1] / peak_M_norm for n in ("euler", "rk4")},
        "force_balanced_force_residual_relative": {
            "closed_form": report.peak_abs(fbal["shaking_force"]) / peak_F_norm,
            "from_poses": report.peak_abs(F_fb_fd[inner]) / peak_F_norm},
        "balanced_residual_explanation": (
            "Explicit Euler (eq 26) makes the central-difference wrist rate the mean of two "
            "commanded rates, leaving H_n - H_target ~ (dt/2) dD/dt and a residual moment "
            "~ (dt/2) d2D/dt2 that scales with dt; RK4 is O(dt^2) in this check. The closed-form "
            "moment at each tick (rates and feed-forward accelerations) is zero to rounding."),
        "peak_wrist_rate": rates[primary],
        "peak_wrist_rate_by_integrator": rates,
        "wrist_angle_excursion": np.ptp(bal[primary]["wrist_angles"], axis=0),
        "condition_number_range": [float(cond.min()), float(cond.max())],
        "wrist_status_or": int(np.bitwise_or.reduce(bal[primary]["status_per_instant"])),
        "z_moment_ratio_force_balanced_over_unbalanced": {
            "about_O": ratio_O, "about_base_centre": ratio_c, "base_centre": base_centre,
            "paper": 1.35,
            "explanation": ("Once force-balanced, M is the same about every point; the unbalanced "
                            "M_z is not (M_Q = M_O - OQ x F). About the base centre (centroid of "
                            "the B_i) M_z rises as in the paper: the heavy CP1 counterweights at "
                            "the A_i move opposite to the platform at the legs' far ends and form "
                            "a z-couple that force balancing does not remove. About O of the "
                            "reconstructed layout it drops.")},
        "discrepancies": [
            {"quantity": "m_CP1 [kg]", "paper": 4.49, "ours": closed.cp1[0],
             "reason": "eq 14 (correct as printed) and the general force method give 2.7915; 4.49 not reproducible under any "
                       "misprint tried"},
            {"quantity": "m_CP2 [kg]", "paper": 1.69, "ours": closed.cp2[0],
             "reason": "1.69 = eq 15 with its -2 m8 term dropped (%.4f); with m8 it is 1.3865"
                       % printed.notes["cp2_without_m8_term"]},
            {"quantity": "m_CP3 [kg]", "paper": 0.436, "ours": closed.cp3[0], "reason": "agrees (eq 16, r = -1)"},
            {"quantity": "vertical counter-mass [kg]", "paper": printed.vertical, "ours": closed.vertical,
             "reason": "eqs 6/11 omit link 8 (at F, moving vertically): + 2 m8/(2k) per leg"},
            {"quantity": "peak |F| with the paper's reported masses [N]", "paper": 0.0,
             "ours": float(m_reported),
             "reason": "4.49/1.69/0.436 do not force-balance the reconstructed leg"},
            {"quantity": "M_z force-balanced / unbalanced", "paper": 1.35, "ours": ratio_c,
             "reason": "about the base centre; about O it is %.2f (reference-point dependence while F != 0)" % ratio_O},
            {"quantity": "wrist start orientation", "paper": "(0, 0, 0)", "ours": list(map(float, q0)),
             "reason": "(0,0,0) is a z-x-z singularity (theta = 0, det N ~ sin theta): cond N infinite"},
            {"quantity": "eq 23 (N)", "paper": "printed matrix",
             "ours": "[(I1+I2+I3) e_z | (I2+I3) x1 | I3 z2]",
             "reason": "printed form omits I2, I3 from the phi column, adds a rotation to an inertia"},
            {"quantity": "k", "paper": "B_iF_i / D_iF_i", "ours": "D_iF_i / B_iF_i",
             "reason": "the printed ratio would make BF = 1.26 m"},
        ],
        "files": ["bodies_unbalanced.npz", "bodies_force_balanced.npz", "bodies_balanced.npz",
                  "bodies_balanced_euler.npz", "bodies_balanced_rk4.npz", "shaking_wrench.png",
                  "wrist_angles.png", "wrist_condition.png", "summary.json"],
    }
    write_summary(out / "summary.json", summary)

    rows = [["peak F [N], unbalanced", *report.peak_abs(F_unbal)],
            ["peak F [N], force-balanced", *report.peak_abs(fbal["shaking_force"])]]
    rows += [[f"peak F [N], balanced {n} (from poses)", *fd[n][0]] for n in ("euler", "rk4")]
    rows += [["peak M_O [N m], unbalanced", *report.peak_abs(M_unbal)],
             ["peak M_O [N m], force-balanced", *report.peak_abs(M_fb)]]
    rows += [[f"peak M_O [N m], balanced {n} (from poses)", *fd[n][1]] for n in ("euler", "rk4")]
    rows += [[f"residual M [% of |M_unbal|], {n}", *(100 * fd[n][1] / peak_M_norm)] for n in ("euler", "rk4")]
    rows += [[f"peak wrist rate [rad/s], {n}", *rates[n]] for n in ("euler", "rk4")]
    print(report.table(rows, ["PAMINSA (Briot & Arakelian 2009)", "x", "y", "z"]))
    six = lambda *xs: [f"{x:.6g}" for x in xs]  # noqa: E731  (4 digits would show 1.3865 as 1.386 / 1.387)
    print(report.table(
        [["CP1 at A_i", *six(general.cp1[0], closed.cp1[0], printed.cp1[0]), 4.49],
         ["CP2 at F_i", *six(general.cp2[0], closed.cp2[0], printed.cp2[0]), 1.69],
         ["CP3 at L_i", *six(general.cp3[0], closed.cp3[0], printed.cp3[0]), 0.436],
         ["vertical counter-mass", *six(general.vertical, closed.vertical, printed.vertical), "-"]],
        ["counterweight [kg]", "general method", "closed form", "printed eqs", "paper reported"]))
    print(f"general method (mechbal.balance.force) vs closed form: largest difference {difference:.2g} kg; "
          f"the variants use the {use.replace('_', ' ')} masses")
    print(f"cond(N) along the run: [{cond.min():.3g}, {cond.max():.3g}];  "
          f"M_z force-balanced/unbalanced: {ratio_O:.2f} about O, {ratio_c:.2f} about the base centre "
          f"(paper: +35 %)")
    return summary
