"""Runner for ``kind = "discs"``: Coutinho & Hess Coelho, "A new approach for designing dynamic
balanced serial mechanisms" -- static balancing, counter-rotating discs and decoupled control of
the planar 3R (``discs-3r``), the spatial 3R (``discs-spatial``), the SCARA (``scara``) and the
parallelogram 5R (``five-bar``).

For each: the balancing parameters (the discs' gear ratios and, for the spatial arm, the inertia
conditions sized by the general shaking-moment method, mechbal.balance.moment, on the case's
[balance] table and checked against the closed forms of mechbal.papers.discs; the static
balancing l_g of eqs 8, 18, 29), the mass-matrix metrics
before/after over random configurations, the peak gravity torque, the sensitivity table, the
joint torques on a rest-to-rest trajectory (unbalanced vs balanced), and the decoupled controller
(tau_i = k_i (q''_d + Kp e + Kd e')) against computed torque over the balanced model.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal.balance.result import DiscDesign

from mechbal import control
from mechbal import trajectory
from mechbal import progress, report
from mechbal.cases import register
from mechbal.config import ConfigError
from mechbal.schema import validate_case
from mechbal.export import write_bodies, write_summary
from mechbal.papers import discs as dz
from mechbal.papers.discs.five_bar import five_bar_design_mechanism, five_bar_initial_guess
from mechbal.papers.discs import _SPEC, parameters_from_config  # noqa: F401 (re-exported)

#: which corrections concern which mechanism
_CORRECTIONS = {"planar3r": (), "spatial3r": ("C1", "C2", "C3", "C4", "C5", "C6", "C7", "C8"),
                "scara": ("C9", "C10"), "fivebar": ("C11",)}


#: how far the general method's gear ratios, inertias and decoupled inertias k_i may be from the
#: closed forms (relative). Both are exact (the method solves linear conditions on the angular
#: momentum columns over sampled poses; the closed forms are algebra): measured ~1e-15. 1e-9 is
#: far above round-off and far below any design tolerance (the sensitivity table starts at 1 %).
DISC_AGREEMENT_RTOL = 1e-9
#: the quantities the general method sizes, per mechanism: name -> (slot of [balance], its key)
_SIZED = {"planar3r": {"beta": ("disc5", "ratio"), "gamma": ("disc7", "ratio")},
          "spatial3r": {"beta": ("disc5", "ratio"), "Jy2": ("link2_cross_bar", "Iyy"),
                        "Jy3": ("link3_shape", "Iyy")},
          "scara": {"beta": ("disc5", "ratio")},
          "fivebar": {}}


def general_discs(case, kind: str, closed: dict):
    """The discs by the general shaking-moment method (`mechbal.balance.moment`) on the
    statically balanced arm with the case's ``[balance]`` (``mechbal balance CASE --method
    moment``), next to the closed forms ``closed`` (``mechbal.papers.discs.BALANCE[kind]``).
    Returns (general values, closed-form values, largest relative difference, BalanceResult);
    ConfigError when they differ beyond `DISC_AGREEMENT_RTOL`.

    Serial arms: the chosen gear ratios (beta, gamma: eqs 14, 25, 35) and inertias (Jy2, Jy3:
    corrected eq 25) and the constant diagonal of the mass matrix (k_i: eqs 16, 27, 37). Five-bar
    (discs on the legs, the built-in table): the method proves full moment balance impossible
    (the leg discs act on the two rates only together) and what remains of the angular momentum
    per unit rate is k_1 + k_2 + the discs' inertias (docs/discs_derivation.md section 5)."""
    from mechbal.balance.run import case_from_config, run_method

    if getattr(case, "balance", None) is None or not case.balance.discs:
        raise ConfigError("balance.discs", "the discs runner sizes the discs by the general method: give "
                          "the [[balance.discs]] slots (see the built-in disc cases)", has_value=False)
    result = run_method(case_from_config(case), "moment")
    general, reference = {}, {}
    for name, (slot, key) in _SIZED[kind].items():
        plain = result.design[slot].to_dict() if slot in result.design else {}
        if key not in plain:
            raise ConfigError("balance", f"the discs runner compares {name} with the closed form: it needs the "
                              f"slot '{slot}' choosing '{key}' (see the built-in case {case.case.name!r})",
                              has_value=False)
        general[name] = float(plain[key])
        reference[name] = float(closed["inertia_conditions"][name] if name.startswith("Jy") else closed[name])
    if kind == "fivebar":
        cols = result.metrics["columns"]
        left = [c["peak_remaining"] for c in cols.values() if not c["cancelled"]]
        discs = sum(float(v.inertia) for v in result.design.values() if isinstance(v, DiscDesign))
        if len(left) != 1:
            raise ConfigError("balance.discs", "the five-bar check expects the leg discs of the built-in table "
                              f"(one actuated rate's angular momentum left; got {len(left)})", has_value=False)
        general["remaining_angular_momentum_per_unit_rate"] = float(left[0])
        reference["remaining_angular_momentum_per_unit_rate"] = float(sum(closed["k"])) + discs
    else:
        general["k"] = [float(x) for x in result.metrics["mass_matrix"]["diag_mean"]]
        reference["k"] = [float(x) for x in closed["k"]]
    diff = max(float(np.max(np.abs(np.subtract(general[k], reference[k])) / np.maximum(np.abs(reference[k]), 1e-300)))
               for k in general)
    if diff > DISC_AGREEMENT_RTOL:
        raise ConfigError("balance.discs", f"the general moment method ({general}) and the closed forms "
                          f"({reference}) differ by {diff:.3g} (relative) > {DISC_AGREEMENT_RTOL:g}: the "
                          "[[balance.discs]] positions, axes, fixed ratios and inertias must be the paper's "
                          "discs of [inertia]", has_value=False)
    return general, reference, diff, result


def balanced_design(kind: str, p: dict, general: dict) -> dict:
    """The balanced design with what the general method sized (gear ratios, inertias) in place of
    the closed forms' values (the static balancing l_g stays that of eqs 8, 18, 29)."""
    d = dz.design(kind, p, True)
    d.update({k: v for k, v in general.items() if k in ("beta", "gamma", "Jy2", "Jy3")})
    return d


def _torques(kind, d, q, qd, qdd):
    M, v, g = dz.evaluate(kind, d, q, qd)
    return np.einsum("nij,nj->ni", M, qdd) + v + g


def _controller_check(kind, bal, k, cfg, q_des, qd_des, qdd_des, n):
    """DecoupledJointController (gains k) vs ComputedTorque over the balanced design ``bal``, on
    the trajectory with an offset actual state (so the PD terms act)."""
    kp, kd = np.array(cfg.kp, float), np.array(cfg.kd, float)
    k = np.asarray(k, float)
    dc = control.DecoupledJointController(k, kp, kd)
    rng = np.random.default_rng(0)
    q = q_des + rng.uniform(-0.05, 0.05, q_des.shape)
    qd = qd_des + rng.uniform(-0.1, 0.1, qd_des.shape)
    tau_dc = np.array([dc.step(*x)[0] for x in progress.track(
        zip(q, qd, q_des, qd_des, qdd_des), "decoupled control ticks", total=len(q))])
    if kind == "fivebar":
        ct = control.ComputedTorque(dz.fivebar_dynamics(bal), kp, kd)
        backend = "mechbal.ComputedTorque over FiveBarDynamics (C++, 4x4 A° per tick)"
    else:
        ct = control.ComputedTorque(control.MechanismDynamics(dz.disc_mechanism(kind, bal).model), kp, kd)
        backend = "mechbal.ComputedTorque over MechanismDynamics (the general model, discs as gear couplings)"
    steps = [ct.step(*x) for x in progress.track(
        zip(q, qd, q_des, qd_des, qdd_des), "computed torque ticks", total=len(q))]
    if any(s != control.Status.ok for _, s in steps):
        raise RuntimeError(f"computed torque failed on the trajectory: {[s for _, s in steps]}")
    tau_ct = np.array([t for t, _ in steps])
    dev = float(np.max(np.abs(tau_dc - tau_ct)) / np.max(np.abs(tau_ct)))
    return {"computed_torque_backend": backend, "max_rel_difference": dev,
            "ticks": int(len(q))}


def _disc_bodies(kind, d, q, qd, qdd):
    """Every body of a design along the actuated motion (q, qd, qdd) (N, n), on the general model:
    names, mass (B,), inertia_body (B,3,3), the bodies' motion (N, B, ...: com, com_velocity,
    com_acceleration, rotation, angular_velocity, angular_acceleration) and the shaking wrench of
    that motion (shaking_force, shaking_moment (N, 3), `mechbal.Mechanism.shaking_wrench`).

    Serial arms: `mechbal.papers.discs.disc_mechanism` (each disc a joint geared to its driving
    joint, on its axle; as in the case files, a disc's mass is lumped into its carrier link, so a
    disc body has mass 0 and its own central inertia). Five-bar:
    `mechbal.papers.discs.five_bar.five_bar_design_mechanism`, its loop solved along the actuated
    motion from the closed form's assembly (`five_bar_initial_guess`); the closed form
    FiveBarDynamics equals it to 1e-10 (tests/python/test_papers_loops.py)."""
    if kind == "fivebar":
        mech = five_bar_design_mechanism(d)
        solved = mech.closed_motion(q, qd, qdd, q_guess=five_bar_initial_guess(mech, d, q[0]))
        if np.any(np.asarray(solved.status) != 0):
            raise RuntimeError("five-bar trajectory: the loop solve fails or hits a singular pose "
                               f"({control.Status(int(np.bitwise_or.reduce(solved.status)))})")
        q, qd, qdd = solved.q, solved.v, solved.a
    else:
        mech = dz.disc_mechanism(kind, d)
    motion = mech.body_motion(q, qd, qdd)
    wrench = mech.shaking_wrench(q, qd, qdd)
    if np.any(np.asarray(motion.status) != 0) or np.any(np.asarray(wrench.status) != 0):
        raise RuntimeError(f"{kind} kinematics failed: {np.max(motion.status)}, {np.max(wrench.status)}")
    bodies = mech.model.bodies
    return dict(names=mech.body_names, mass=np.array([b.mass for b in bodies]),
                inertia_body=np.array([np.asarray(b.inertia, float) for b in bodies]),
                **{k: np.asarray(getattr(motion, k)) for k in (
                    "com", "com_velocity", "com_acceleration", "rotation", "angular_velocity",
                    "angular_acceleration")},
                shaking_force=np.asarray(wrench.shaking_force), shaking_moment=np.asarray(wrench.shaking_moment))


def _write_bodies(path, t, b, q, qd, qdd):
    """bodies_<variant>.npz (mechbal.export schema): the bodies' poses and the shaking wrench of
    that motion (`_disc_bodies`)."""
    write_bodies(path, t=t, names=b["names"], mass=b["mass"], inertia_body=b["inertia_body"],
                 com=b["com"], rotation=b["rotation"], shaking_force=b["shaking_force"],
                 shaking_moment=b["shaking_moment"], q=q, qd=qd, qdd=qdd)
    return b["shaking_force"], b["shaking_moment"]


@register("discs", stages=5)
def run(config, out: Path) -> dict:
    case = validate_case(config, warn=False)
    kind = case.case.mechanism
    n = _SPEC[kind]["n"]
    p = parameters_from_config(kind, case)
    bal = dz.BALANCE[kind](p)
    if kind == "fivebar" and not dz.is_parallelogram(p):  # the schema checks it too
        raise ConfigError("parameters", "a general 5R cannot be made constant-diagonal (C11): "
                          "use the parallelogram d = 0, b1 = a2, b2 = a1",
                          {k: p[k] for k in ("d", "a1", "a2", "b1", "b2")})
    params = list(case.sensitivity.parameters)
    known = dz.design(kind, p, True)
    for i, name in enumerate(params):
        if name not in known:
            from mechbal.schema import did_you_mean

            raise ConfigError(f"sensitivity.parameters[{i}]", "unknown parameter"
                              + did_you_mean(name, sorted(k for k, v in known.items()
                                                          if np.ndim(v) == 0)), name)
    errors = np.array(case.sensitivity.errors_pct, float) / 100.0

    progress.stage("discs by the general moment method, checked by the closed forms")
    general, reference, difference, sized = general_discs(case, kind, bal)
    d_bal = balanced_design(kind, p, general)
    if "k" in general:
        bal = dict(bal, k=general["k"], **{k: general[k] for k in ("beta", "gamma") if k in general})
        if "Jy2" in general:
            bal["inertia_conditions"] = dict(bal["inertia_conditions"], Jy2=general["Jy2"], Jy3=general["Jy3"])

    N, seed = case.sampling.configurations, case.sampling.seed
    progress.stage("mass matrix over sampled configurations")
    q, qd = dz.sample_states(kind, N, np.random.default_rng(seed))
    before = dz.metrics(*dz.evaluate(kind, dz.design(kind, p, False), q, qd))
    after = dz.metrics(*dz.evaluate(kind, d_bal, q, qd), bal["k"])

    Ns = min(N, 200)
    progress.stage("sensitivity to parameter errors")
    sens = dz.sensitivity(kind, p, params, errors, q[:Ns], qd[:Ns])

    tt = case.trajectory
    start, end = np.array(tt.start, float), np.array(tt.end, float)
    T, Nt = tt.duration, tt.samples
    t = np.linspace(0.0, T, Nt)
    qt, qdt, qddt = trajectory.RestToRestTrajectory(start, end, T, trajectory.TimeLaw.quintic).evaluate_batch(t)
    progress.stage("trajectory torques, decoupled and computed-torque control")
    tau_u = _torques(kind, dz.design(kind, p, False), qt, qdt, qddt)
    tau_b = _torques(kind, d_bal, qt, qdt, qddt)
    tau_k = qddt * np.asarray(bal["k"])
    labels = [f"joint {j + 1}" for j in range(n)]
    if kind == "scara":
        labels[2] = "joint 3 (force [N])"
    report.plot_series(out / "joint_torques.png", t,
                       {"unbalanced": tau_u, "balanced": tau_b, "k_i q''_i": tau_k},
                       labels, ["force [N]" if "force" in lab else "torque [N m]" for lab in labels],
                       title=f"{case.case.name}: joint torques, unbalanced vs balanced",
                       caption="Joint torques along the rest-to-rest trajectory: unbalanced arm, "
                               "arm balanced by counterweights and counter-rotating discs, and "
                               "the decoupled model k_i q''_i, which the balanced torque equals "
                               "(dashed over solid).")
    control = _controller_check(kind, d_bal, bal["k"], case.controller, qt, qdt, qddt, n)

    # ---- every link and disc as a body along the trajectory: the shaking wrench ----
    progress.stage("bodies files (shaking wrench)")
    wrench = {}
    for variant, d in (("unbalanced", dz.design(kind, p, False)), ("balanced", d_bal)):
        b = _disc_bodies(kind, d, qt, qdt, qddt)
        F, Mo = _write_bodies(out / f"bodies_{variant}.npz", t, b, qt, qdt, qddt)
        wrench[variant] = {"bodies": b["names"],
                           "peak_shaking_force": float(np.max(np.linalg.norm(F, axis=1))),
                           "peak_shaking_moment": float(np.max(np.linalg.norm(Mo, axis=1)))}

    balancing = {"l_g": bal["lg"], "k": bal["k"]}
    if "beta" in bal:
        balancing["beta"] = bal["beta"]
    if "gamma" in bal:
        balancing["gamma"] = bal["gamma"]
    if "inertia_conditions" in bal:
        balancing["inertia_conditions"] = bal["inertia_conditions"]
    if "K_cross" in bal:
        balancing["K_cross"] = bal["K_cross"]
    progress.stage("summary")
    summary = {
        "case": case.case.name, "kind": "discs", "mechanism": kind,
        "source": "Coutinho & Hess Coelho, A new approach for designing dynamic balanced serial "
                  "mechanisms (derivation: docs/discs_derivation.md)",
        "balancing": balancing,
        "discs": {"general_method": general, "closed_form": reference, "max_rel_difference": difference,
                  "tolerance_rel": DISC_AGREEMENT_RTOL,
                  "method": {"name": "moment", "exact": sized.exact, "limited_by": sized.limited_by,
                             "design": {k: {kk: x for kk, x in v.to_dict().items()
                                            if kk in ("carrier", "joint", "ratio", "inertia", "Iyy")}
                                        for k, v in sized.design.items()}},
                  "sized_by_the_general_method": sorted(k for k in general if k in ("beta", "gamma", "Jy2", "Jy3")),
                  "closed_form_source": "Coutinho & Hess Coelho eqs 14, 16, 25, 27, 35, 37 corrected "
                                        "(mechbal.papers.discs.BALANCE)"},
        **{k: v for k, v in balancing.items()},
        "configurations": N, "seed": seed,
        "offdiag_ratio_before": before["offdiag_ratio"],
        "offdiag_ratio_after": after["offdiag_ratio"],
        "coupling_coefficient_before": before["coupling"],
        "coupling_coefficient_after": after["coupling"],
        "diag_variation_before": before["diag_variation"],
        "diag_variation_after": after["diag_variation"],
        "diag_vs_k_after": after["diag_vs_k"],
        "peak_gravity_torque": {"before": before["peak_gravity_torque"],
                                   "after": after["peak_gravity_torque"]},
        "peak_velocity_terms": {"before": before["peak_velocity_terms"],
                                   "after": after["peak_velocity_terms"]},
        "peak_joint_torque": {"unbalanced": report.peak_abs(tau_u),
                                      "balanced": report.peak_abs(tau_b)},
        "trajectory_balanced_vs_k_qdd_max_abs": float(np.max(np.abs(tau_b - tau_k))),
        "decoupled_control": control,
        "shaking_wrench_on_trajectory": {
            **wrench,
            "note": "peaks of |F| and |M_O| (inertial: dP/dt, dH_O/dt about the base origin) over "
                    "the rest-to-rest trajectory. Dynamic balancing in this paper makes the mass "
                    "matrix diagonal and constant, not the shaking wrench zero: static balancing "
                    "fixes the total centre of mass (zero shaking force when all masses move in "
                    "the balanced planes), while the shaking moment about the first joint axis "
                    "is k_1 q1'' (the reaction of the first actuator), which the discs do not "
                    "cancel. Disc masses are lumped into their carrier links (mass 0 disc "
                    "bodies with their own inertia)."},
        "sensitivity": sens,
        "corrections": [c for c in dz.CORRECTIONS if c["id"] in _CORRECTIONS[kind]],
        "files": ["joint_torques.png", "bodies_unbalanced.npz", "bodies_balanced.npz"],
    }
    if kind == "planar3r":
        summary["corrections_note"] = "eqs 7-16 checked: correct as printed"
    write_summary(out / "summary.json", summary)

    print(report.table([[kind, before["offdiag_ratio"], after["offdiag_ratio"],
                         before["diag_variation"], after["diag_variation"],
                         before["peak_gravity_torque"], after["peak_gravity_torque"]]],
                       ["mechanism", "offdiag before", "after", "diag var before", "after",
                        "gravity before [N m]", "after"]))
    print(report.table([[k, v] for k, v in balancing.items()], ["balancing", "value"]))
    print(report.table([[v, wrench[v]["peak_shaking_force"], wrench[v]["peak_shaking_moment"]]
                        for v in ("unbalanced", "balanced")],
                       ["variant", "peak |shaking force| [N]", "peak |shaking moment| [N m]"]))
    print(report.table([[r["parameter"], r["error_pct"], r["offdiag_ratio"], r["coupling"],
                         r["diag_variation"], r["gravity_peak_over_unbalanced"],
                         r["velocity_peak_over_unbalanced"]] for r in sens],
                       ["parameter", "error %", "offdiag ratio", "coupling", "diag spread",
                        "gravity/unbal", "velocity/unbal"]))
    return summary
