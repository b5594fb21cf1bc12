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

from mechbal import control
from mechbal import papers
from mechbal import trajectory
from mechbal import progress, report
from mechbal.cases import register
from mechbal.config import ConfigError
from mechbal.schema import validate_case
from mechbal.export import write_bodies, write_summary
from mechbal.papers import discs as dz
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
        if slot not in result.design or key not in result.design[slot]:
            raise ConfigError("balance", f"the discs runner compares {name} with the closed form: it needs the "
                              f"slot '{slot}' choosing '{key}' (see the built-in case {case.case.name!r})",
                              has_value=False)
        general[name] = float(result.design[slot][key])
        reference[name] = float(closed["inertia_conditions"][name] if name.startswith("Jy") else closed[name])
    if kind == "fivebar":
        cols = result.metrics["columns"]
        left = [c["peak_remaining"] for c in cols.values() if not c["cancelled"]]
        discs = sum(float(v["inertia"]) for v in result.design.values() if "inertia" in v and "ratio" in v)
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
    """Every body of a design along (q, qd, qdd) (N, n): names, mass (B,), inertia_body (B,3,3)
    and the motion arrays (N, B, ...) of mechbal.shaking_wrench.

    Serial arms: the links from the general model's body motion (the arm alone,
    `mechbal.papers.discs.arm_mechanism`); each disc spins at ratio * q[joint]
    about its axis through the carrier's frame origin (rotation R_c Rot(axis, ratio q_j),
    omega = omega_c + ratio q_j' a, alpha = alpha_c + ratio q_j'' a + omega_c x ratio q_j' a).
    As in the model, a disc's mass is lumped into its carrier link (the link masses of the case
    include the discs), so a disc body has mass 0 and its own central inertia.
    Five-bar: proximal/distal links and the end-effector point mass, with the passive angles,
    rates and accelerations from the C++ FiveBarDynamics.motion (p = C p#, p' = C p#'' + cbar)."""
    N = len(q)
    if kind == "fivebar":
        m = dz.fivebar_dynamics(d).motion(q, qd, qdd)
        if m["status"] != control.Status.ok:
            raise RuntimeError(f"five-bar trajectory hits a singular pose ({m['status']})")
        th, w, al = m["angles"], m["rates"], m["accelerations"]
        names, mass, inertia = [], [], []
        com, vel, acc, rot, omg, alp = ([] for _ in range(6))
        e = lambda t: np.stack([np.zeros_like(t), np.cos(t), np.sin(t)], -1)  # noqa: E731
        nv = lambda t: np.stack([np.zeros_like(t), -np.sin(t), np.cos(t)], -1)  # noqa: E731

        def Rx(t):
            R = np.zeros((len(t), 3, 3))
            R[:, 0, 0] = 1.0
            R[:, 1, 1] = R[:, 2, 2] = np.cos(t)
            R[:, 2, 1], R[:, 1, 2] = np.sin(t), -np.sin(t)
            return R

        def point(base, L, t, td, tdd):  # base + L e(t) and its derivatives
            return (base[0] + L * e(t), base[1] + L * td[:, None] * nv(t),
                    base[2] + L * (tdd[:, None] * nv(t) - td[:, None] ** 2 * e(t)))

        ax = np.array([1.0, 0.0, 0.0])
        for i, leg in ((1, 0), (2, 1)):
            A = (np.tile([0.0, d["d"] if i == 2 else 0.0, 0.0], (N, 1)), np.zeros((N, 3)),
                 np.zeros((N, 3)))
            t1, t1d, t1dd = th[:, 2 * leg], w[:, 2 * leg], al[:, 2 * leg]
            phi = t1 + th[:, 2 * leg + 1]
            phid, phidd = t1d + w[:, 2 * leg + 1], t1dd + al[:, 2 * leg + 1]
            B = point(A, d[f"a{i}"], t1, t1d, t1dd)
            for name, base, L, t, td, tdd, key, mk in (
                    (f"proximal{i}", A, d[f"cp{i}"], t1, t1d, t1dd, f"p{i}", f"mp{i}"),
                    (f"distal{i}", B, d[f"cd{i}"], phi, phid, phidd, f"d{i}", f"md{i}")):
                G = point(base, L, t, td, tdd)
                names.append(name)
                mass.append(d[mk])
                inertia.append(np.diag(d[f"inertia_{key}"]))
                com.append(G[0]), vel.append(G[1]), acc.append(G[2]), rot.append(Rx(t))
                omg.append(td[:, None] * ax), alp.append(tdd[:, None] * ax)
        names.append("end_effector")
        mass.append(d["mP"])
        inertia.append(np.zeros((3, 3)))
        z = np.zeros((N, 1))
        com.append(np.hstack([z, m["end_effector"]]))
        vel.append(np.hstack([z, m["end_effector_velocity"]]))
        acc.append(np.hstack([z, m["end_effector_acceleration"]]))
        rot.append(np.tile(np.eye(3), (N, 1, 1)))
        omg.append(np.zeros((N, 3))), alp.append(np.zeros((N, 3)))
        stack = lambda xs: np.stack(xs, 1)  # noqa: E731
        return dict(names=names, mass=np.array(mass), inertia_body=np.array(inertia),
                    com=stack(com), com_velocity=stack(vel), com_acceleration=stack(acc),
                    rotation=stack(rot), angular_velocity=stack(omg),
                    angular_acceleration=stack(alp))

    joints, links, discs = dz.serial_structure(kind, d)
    m = dz.arm_mechanism(joints, links).body_motion(q, qd, qdd)
    if np.any(np.asarray(m.status) != 0):
        raise RuntimeError(f"arm kinematics failed: {np.asarray(m.status).max()}")
    # link c's frame is the model's link c + 1 (link 0 is the base)
    kin = dict(com=m.com, com_velocity=m.com_velocity, com_acceleration=m.com_acceleration,
               rotation=m.rotation, angular_velocity=m.angular_velocity,
               angular_acceleration=m.angular_acceleration)
    names = [f"link{i + 1}" for i in range(len(links))]
    mass = [b.mass for b in links]
    inertia = [np.asarray(b.inertia, float) for b in links]
    out = {k: [kin[k][:, i] for i in range(len(links))]
           for k in ("com", "com_velocity", "com_acceleration", "rotation", "angular_velocity",
                     "angular_acceleration")}
    for k, ds in enumerate(discs):
        c = ds.carrier
        Rc, o = m.link_rotation[:, c + 1], m.link_position[:, c + 1]
        axis = np.asarray(ds.axis, float) / np.linalg.norm(ds.axis)
        a = Rc @ axis
        ang = ds.ratio * q[:, ds.joint]
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        Rrel = (np.eye(3) + np.sin(ang)[:, None, None] * K
                + (1 - np.cos(ang))[:, None, None] * (K @ K))
        wc, alc = kin["angular_velocity"][:, c], kin["angular_acceleration"][:, c]
        spin = ds.ratio * qd[:, ds.joint, None] * a
        r = o - kin["com"][:, c]  # carrier CoM -> disc centre
        names.append(f"disc{k + 4}")
        mass.append(0.0)
        inertia.append(np.diag(ds.inertia))
        out["com"].append(o)
        out["com_velocity"].append(kin["com_velocity"][:, c] + np.cross(wc, r))
        out["com_acceleration"].append(kin["com_acceleration"][:, c] + np.cross(alc, r)
                                       + np.cross(wc, np.cross(wc, r)))
        out["rotation"].append(Rc @ Rrel)
        out["angular_velocity"].append(wc + spin)
        out["angular_acceleration"].append(alc + ds.ratio * qdd[:, ds.joint, None] * a
                                           + np.cross(wc, spin))
    return dict(names=names, mass=np.array(mass), inertia_body=np.array(inertia),
                **{k: np.stack(v, 1) for k, v in out.items()})


def _write_bodies(path, t, b, q, qd, qdd):
    """bodies_<variant>.npz (mechbal.export schema) with mechbal.shaking_wrench of the bodies."""
    w = papers.shaking_wrench(b["mass"], b["inertia_body"], b["com"], b["com_velocity"],
                             b["com_acceleration"], b["rotation"], b["angular_velocity"],
                             b["angular_acceleration"])
    if w["status"] != control.Status.ok:
        raise RuntimeError(f"shaking wrench failed: {w['status']}")
    write_bodies(path, t=t, names=b["names"], mass=b["mass"], inertia_body=b["inertia_body"],
                 com=b["com"], rotation=b["rotation"], shaking_force=w["force"],
                 shaking_moment=w["moment"], q=q, qd=qd, qdd=qdd)
    return w["force"], w["moment"]


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
                             "design": {k: {kk: v[kk] for kk in ("carrier", "joint", "ratio", "inertia", "Iyy")
                                            if kk in v} for k, v in sized.design.items()}},
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
