"""Runner for ``kind = "discs"``: Coutinho & Hess Coelho, "A new approach for designing dynamic
balanced serial mechanisms" -- static balancing, counter-rotating discs and decoupled control of
the planar 3R (``discs-3r``), the spatial 3R (``discs-spatial``), the SCARA (``scara``) and the
parallelogram 5R (``five-bar``).

For each: the balancing parameters (closed forms, mechbal.sizing.discs), the mass-matrix metrics
before/after over random configurations, the peak gravity torque, the sensitivity table, the
joint torques on a rest-to-rest trajectory (unbalanced vs balanced), and the decoupled controller
(tau_i = k_i (q''_d + Kp e + Kd e')) against computed torque over the balanced model.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal import _core, report
from mechbal.cases import register
from mechbal.config import ConfigError, inertia, integer, number, require, string, vector
from mechbal.export import write_summary
from mechbal.sizing import discs as dz

_SPEC = {
    "planar3r": dict(params=("l1", "l2", "m1", "m2", "m3"),
                     bodies=("link1", "link2", "link3", "disc4", "disc5", "disc6", "disc7"),
                     unbalanced=("lg1", "lg2", "lg3"), n=3),
    "spatial3r": dict(params=("l1", "l2", "m1", "m2", "m3"),
                      bodies=("link1", "link2", "link3", "disc4", "disc5"),
                      unbalanced=("lg2", "lg3"), n=3),
    "scara": dict(params=("l1", "l2", "m1", "m2", "m3"),
                  bodies=("link1", "link2", "link3", "disc4", "disc5"),
                  unbalanced=("lg1", "lg2"), n=3),
    "fivebar": dict(params=("a1", "a2", "b1", "b2", "d", "mp1", "mp2", "md1", "md2", "mP",
                            "mP1_share"),
                    bodies=("proximal1", "proximal2", "distal1", "distal2"),
                    unbalanced=("cp1", "cp2", "cd1", "cd2"), n=2),
}
_FIVEBAR_KEYS = {"proximal1": "p1", "proximal2": "p2", "distal1": "d1", "distal2": "d2"}
#: which corrections concern which mechanism
_CORRECTIONS = {"planar3r": (), "spatial3r": ("C1", "C2", "C3", "C4", "C5", "C6", "C7", "C8"),
                "scara": ("C9", "C10"), "fivebar": ("C11",)}


def _principal(I: np.ndarray, field: str) -> np.ndarray:
    if np.max(np.abs(I - np.diag(np.diag(I)))) > 0.0:
        raise ConfigError(field, "must be principal (give [Jx, Jy, Jz] in the link frame)",
                          I.tolist())
    return np.diag(I).copy()


def parameters_from_config(kind: str, config: dict) -> dict:
    """Flat parameter dict (the names of docs/discs_derivation.md) from a case file; every value
    checked, errors name the field."""
    spec = _SPEC[kind]
    pt, it = require(config, "parameters", ""), require(config, "inertia", "")
    ut = require(config, "unbalanced", "")
    p = {}
    for k in spec["params"]:
        if k in ("d", "mP1_share"):
            p[k] = number(require(pt, k, "parameters"), f"parameters.{k}", minimum=0.0)
        else:
            p[k] = number(require(pt, k, "parameters"), f"parameters.{k}", positive=True)
    if kind == "fivebar" and p["mP1_share"] > p["mP"]:
        raise ConfigError("parameters.mP1_share", f"must be <= mP = {p['mP']}", p["mP1_share"])
    for b in spec["bodies"]:
        J = _principal(inertia(require(it, b, "inertia"), f"inertia.{b}"), f"inertia.{b}")
        if kind == "fivebar":
            key = _FIVEBAR_KEYS[b]
            p[f"J{key}"] = J[0]
            p[f"inertia_{key}"] = J
        else:
            i = b[-1]
            p[f"Jx{i}"], p[f"Jy{i}"], p[f"Jz{i}"] = J
    for k in spec["unbalanced"]:
        p[f"{k}_unbal"] = number(require(ut, k, "unbalanced"), f"unbalanced.{k}")
    for b in ("link1", "link2", "link3"):
        if b in ut and kind != "fivebar":
            J = _principal(inertia(ut[b], f"unbalanced.{b}"), f"unbalanced.{b}")
            i = b[-1]
            p[f"Jx{i}_unbal"], p[f"Jy{i}_unbal"], p[f"Jz{i}_unbal"] = J
    if kind == "spatial3r":  # the inertia conditions of eq 25 must give a physical body
        ic = dz.balance_spatial3r(p)["inertia_conditions"]
        for i in (2, 3):
            J = [p[f"Jx{i}"], ic[f"Jy{i}"], p[f"Jz{i}"]]
            inertia(J, f"inertia.link{i} with the eq 25 condition Jy{i} = {ic[f'Jy{i}']:.6g}")
    return p


def _torques(kind, d, q, qd, qdd):
    M, v, g = dz.evaluate(kind, d, q, qd)
    return np.einsum("nij,nj->ni", M, qdd) + v + g


def _controller_check(kind, p, cfg, q_des, qd_des, qdd_des, n):
    """DecoupledJointController vs ComputedTorque over the balanced model, on the trajectory with
    an offset actual state (so the PD terms act)."""
    kp = vector(require(cfg, "kp", "controller"), "controller.kp", n)
    kd = vector(require(cfg, "kd", "controller"), "controller.kd", n)
    k = np.asarray(dz.BALANCE[kind](p)["k"])
    dc = _core.DecoupledJointController(k, kp, kd)
    rng = np.random.default_rng(0)
    q = q_des + rng.uniform(-0.05, 0.05, q_des.shape)
    qd = qd_des + rng.uniform(-0.1, 0.1, qd_des.shape)
    tau_dc = np.array([dc.step(*x)[0] for x in zip(q, qd, q_des, qd_des, qdd_des)])
    bal = dz.design(kind, p, True)
    if kind == "fivebar":  # computed torque tau = M v_cmd + v + g on the Python coupled model
        v_cmd = qdd_des + kp * (q_des - q) + kd * (qd_des - qd)
        tau_ct = _torques(kind, bal, q, qd, v_cmd)
        backend = "mechbal.coupling (5R, Python)"
    else:
        ct = _core.ComputedTorque(dz.disc_arm_dynamics(kind, bal), kp, kd)
        tau_ct = np.array([ct.step(*x)[0] for x in zip(q, qd, q_des, qd_des, qdd_des)])
        backend = "mechbal.ComputedTorque over DiscArmDynamics"
    dev = float(np.max(np.abs(tau_dc - tau_ct)) / np.max(np.abs(tau_ct)))
    return {"computed_torque_backend": backend, "max_rel_difference": dev}


@register("discs")
def run(config: dict, out: Path) -> dict:
    kind = string(require(config["case"], "mechanism", "case"), "case.mechanism", dz.MECHANISMS)
    n = _SPEC[kind]["n"]
    p = parameters_from_config(kind, config)
    bal = dz.BALANCE[kind](p)
    if kind == "fivebar" and not dz.is_parallelogram(p):
        raise ConfigError("parameters", "a general 5R cannot be made constant-diagonal (C11): "
                          "use the parallelogram d = 0, b1 = a2, b2 = a1",
                          {k: p[k] for k in ("d", "a1", "a2", "b1", "b2")})

    st = require(config, "sampling", "", {})
    N = integer(require(st, "configurations", "sampling", 1000), "sampling.configurations", minimum=10)
    seed = integer(require(st, "seed", "sampling", 0), "sampling.seed", minimum=0)
    q, qd = dz.sample_states(kind, N, np.random.default_rng(seed))
    before = dz.metrics(*dz.evaluate(kind, dz.design(kind, p, False), q, qd))
    after = dz.metrics(*dz.evaluate(kind, dz.design(kind, p, True), q, qd), bal["k"])

    sens_cfg = require(config, "sensitivity", "", {})
    params = require(sens_cfg, "parameters", "sensitivity", [])
    if not isinstance(params, list) or not all(isinstance(x, str) for x in params):
        raise ConfigError("sensitivity.parameters", "must be a list of names", params)
    errors = vector(require(sens_cfg, "errors_pct", "sensitivity", [1.0, 5.0, 10.0]),
                    "sensitivity.errors_pct") / 100.0
    Ns = min(N, 200)
    try:
        sens = dz.sensitivity(kind, p, params, errors, q[:Ns], qd[:Ns])
    except KeyError as exc:
        raise ConfigError("sensitivity.parameters", "unknown parameter", exc.args[0]) from None

    tt = require(config, "trajectory", "")
    start = vector(require(tt, "start", "trajectory"), "trajectory.start", n)
    end = vector(require(tt, "end", "trajectory"), "trajectory.end", n)
    T = number(require(tt, "duration", "trajectory"), "trajectory.duration", positive=True)
    Nt = integer(require(tt, "samples", "trajectory", 301), "trajectory.samples", minimum=3)
    t = np.linspace(0.0, T, Nt)
    qt, qdt, qddt = _core.RestToRestTrajectory(start, end, T, _core.TimeLaw.quintic).evaluate_batch(t)
    tau_u = _torques(kind, dz.design(kind, p, False), qt, qdt, qddt)
    tau_b = _torques(kind, dz.design(kind, p, True), qt, qdt, qddt)
    tau_k = qddt * np.asarray(bal["k"])
    labels = [f"joint {j + 1}" for j in range(n)]
    if kind == "scara":
        labels[2] = "joint 3 (force [N])"
    report.plot_series(out / "joint_torques.png", t,
                       {"unbalanced": tau_u, "balanced": tau_b, "k_i q''_i": tau_k},
                       labels, "torque [N m]",
                       title=f"{config['case']['name']}: joint torques, unbalanced vs balanced")
    control = _controller_check(kind, p, require(config, "controller", ""), qt, qdt, qddt, n)

    balancing = {"l_g": bal["lg"], "k": bal["k"]}
    if "beta" in bal:
        balancing["beta"] = bal["beta"]
    if "gamma" in bal:
        balancing["gamma"] = bal["gamma"]
    if "inertia_conditions" in bal:
        balancing["inertia_conditions"] = bal["inertia_conditions"]
    if "K_cross" in bal:
        balancing["K_cross"] = bal["K_cross"]
    summary = {
        "case": config["case"]["name"], "kind": "discs", "mechanism": kind,
        "source": "Coutinho & Hess Coelho, A new approach for designing dynamic balanced serial "
                  "mechanisms (derivation: docs/discs_derivation.md)",
        "balancing": balancing,
        **{k: v for k, v in balancing.items()},
        "configurations": N, "seed": seed,
        "offdiag_ratio_before": before["offdiag_ratio"],
        "offdiag_ratio_after": after["offdiag_ratio"],
        "coupling_coefficient_before": before["coupling"],
        "coupling_coefficient_after": after["coupling"],
        "diag_variation_before": before["diag_variation"],
        "diag_variation_after": after["diag_variation"],
        "diag_vs_k_after": after["diag_vs_k"],
        "peak_gravity_torque_Nm": {"before": before["peak_gravity_torque_Nm"],
                                   "after": after["peak_gravity_torque_Nm"]},
        "peak_velocity_terms_Nm": {"before": before["peak_velocity_terms"],
                                   "after": after["peak_velocity_terms"]},
        "trajectory_peak_torque_Nm": {"unbalanced": report.peak_abs(tau_u),
                                      "balanced": report.peak_abs(tau_b)},
        "trajectory_balanced_vs_k_qdd_max_abs": float(np.max(np.abs(tau_b - tau_k))),
        "decoupled_control": control,
        "sensitivity": sens,
        "corrections": [c for c in dz.CORRECTIONS if c["id"] in _CORRECTIONS[kind]],
        "files": ["joint_torques.png"],
    }
    if kind == "planar3r":
        summary["corrections_note"] = "eqs 7-16 checked: correct as printed"
    write_summary(out / "summary.json", summary)

    print(report.table([[kind, before["offdiag_ratio"], after["offdiag_ratio"],
                         before["diag_variation"], after["diag_variation"],
                         before["peak_gravity_torque_Nm"], after["peak_gravity_torque_Nm"]]],
                       ["mechanism", "offdiag before", "after", "diag var before", "after",
                        "gravity before [N m]", "after"]))
    print(report.table([[k, v] for k, v in balancing.items()], ["balancing", "value"]))
    print(report.table([[r["parameter"], r["error_pct"], r["offdiag_ratio"], r["coupling"],
                         r["diag_variation"], r["gravity_peak_over_unbalanced"],
                         r["velocity_peak_over_unbalanced"]] for r in sens],
                       ["parameter", "error %", "offdiag ratio", "coupling", "diag spread",
                        "gravity/unbal", "velocity/unbal"]))
    return summary
