"""`fit`: logs in, a physically consistent identified mechanism out, validated on held-out logs.

The steps (each documented in its module): read and check the logs (`mechbal.identify.logs`),
make them uniform, filter them and differentiate (`mechbal.identify.signal`), stack the
regressor of the segments' inertial parameters and the joints' friction
(`mechbal.identify.model`), reduce it to the base parameters (`mechbal.identify.base`), estimate
them by least squares and by weighted least squares (each joint's rows weighted by the inverse
of its residual's standard deviation, Gautier & Poignet 2001), with their standard deviations,
then fit the full parameters under physical consistency (`mechbal.identify.consistent`: an LMI
problem solved by the conic solver Clarabel), and compare the identified model, the
least-squares estimate, the CAD model and the CAD model with fitted friction on the validation
logs.

The goal the result reports (``ok``, ``limited_by``): the consistent fit solved (the conic
solver converged to its accuracy), every identified body physically consistent, and the
consistent model's RMS torque error on the validation logs (the held-out
ones; without them, the identification logs) within ``tolerance`` (default 1.2) times the
unconstrained least squares' (the price of consistency is small).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import scipy.linalg

from mechbal import _core
from mechbal.identify.base import BaseStructure, base_structure
from mechbal.identify.consistent import BodyConsistency, consistency, consistent_fit
from mechbal.identify.logs import Log, LogError, read_log
from mechbal.identify.model import Structure, parameters_to_body, structure_of
from mechbal.identify.signal import PreparedLog, prepare
from mechbal.mechanism import Mechanism

__all__ = ["fit", "Friction", "Validation", "IdentificationResult", "IdentifyError", "MODELS"]

#: the models a validation compares (keys of `Validation.rms_torque_error`)
MODELS = ("identified", "least_squares", "cad", "cad_friction")

#: relative size of a pivot of the column-scaled base regressor below which the logs are said not
#: to determine the base parameters that come after it
DATA_RANK_TOLERANCE = 1e-8


class IdentifyError(ValueError):
    """Logs that cannot identify the model (one line: which parameters, and why)."""


@dataclass(frozen=True)
class Friction:
    """Friction of one joint: tau_f = viscous v + coulomb sign(v) + offset [N m s/rad, N m, N m]
    (N s/m, N, N for a prismatic joint)."""

    viscous: float
    coulomb: float
    offset: float


@dataclass(frozen=True)
class Validation:
    """RMS torque error [N m or N] of each model (`MODELS`) per joint and over all joints (the
    RMS of every joint's error), against the measured (unfiltered) torques of ``logs``;
    ``held_out``: False when no validation log was given and these are the identification logs.
    ``trace``: the first log's time, measured torque and each model's prediction, for the plot."""

    logs: list[str]
    held_out: bool
    joint_names: list[str]
    rms_torque_error: dict[str, dict[str, float]]
    rms_torque_error_all: dict[str, float]
    trace: dict[str, np.ndarray] = field(repr=False, default_factory=dict)


@dataclass(frozen=True)
class IdentificationResult:
    """What `fit` found (module docstring). Parameters in SI units; the inertial ones per
    segment ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` about the link origin in
    the link frame."""

    mechanism: Mechanism
    structure: Structure = field(repr=False)
    base: BaseStructure = field(repr=False)
    #: the base parameters (weighted least squares unless ``weighted=False``), their standard
    #: deviations and relative standard deviations [%], and the ordinary least squares'
    base_values: np.ndarray
    base_std: np.ndarray
    base_relative_std_pct: np.ndarray
    base_least_squares: np.ndarray
    #: the consistent fit: inertial then friction parameters (`parameter_names`)
    parameters: np.ndarray
    parameter_names: list[str]
    friction: dict[str, Friction]
    cad_parameters: np.ndarray
    consistency: list[BodyConsistency]
    condition_number: float
    #: on the identification logs' filtered torques: RMS residual per joint of the consistent
    #: fit and of least squares
    residual_rms: dict[str, float]
    residual_rms_least_squares: dict[str, float]
    validation: Validation
    cutoff_hz: float
    samples: int
    data_notes: dict[str, list[str]]
    tolerance: float
    ok: bool
    limited_by: list[str]
    solver: dict[str, Any] = field(default_factory=dict)

    @property
    def base_names(self) -> list[str]:
        return list(self.base.names)

    def summary(self) -> dict[str, Any]:
        """The ``identify`` fields of summary.json (docs/summary.md)."""
        S = self.structure
        full = {}
        for i, name in enumerate(S.segment_names):
            pi = self.parameters[10 * i:10 * i + 10]
            m, c, Ic = parameters_to_body(pi)
            full[name] = {"mass": m, "com": c.tolist(),
                          "inertia": [Ic[0, 0], Ic[1, 1], Ic[2, 2], Ic[0, 1], Ic[0, 2], Ic[1, 2]],
                          "parameters": pi.tolist()}
        return {
            "goal": f"a physically consistent model whose RMS torque error on the validation logs is "
                    f"within {self.tolerance:g} x the unconstrained least squares'",
            "ok": self.ok, "limited_by": list(self.limited_by),
            "joint_names": list(S.joint_names), "segments": list(S.segment_names),
            "samples": self.samples, "cutoff_hz": self.cutoff_hz,
            "condition_number": self.condition_number,
            "base_parameters": {n: {"value": float(v), "std": float(s), "relative_std_pct": float(r),
                                    "least_squares": float(ls)}
                                for n, v, s, r, ls in zip(self.base.names, self.base_values, self.base_std,
                                                          self.base_relative_std_pct, self.base_least_squares)},
            "regrouping": dict(self.base.regrouping),
            "unidentifiable": list(self.base.unidentifiable),
            "full_parameters": full,
            "friction": {j: {"viscous": f.viscous, "coulomb": f.coulomb, "offset": f.offset}
                         for j, f in self.friction.items()},
            "consistency": {b.name: {"mass": b.mass, "principal_moments": list(b.principal_moments),
                                     "min_pseudo_inertia_eigenvalue": b.min_pseudo_inertia_eigenvalue,
                                     "consistent": b.consistent} for b in self.consistency},
            "residual_rms": dict(self.residual_rms),
            "residual_rms_least_squares": dict(self.residual_rms_least_squares),
            "validation": {"logs": list(self.validation.logs), "held_out": self.validation.held_out,
                           "rms_torque_error": self.validation.rms_torque_error["identified"],
                           "rms_torque_error_all": self.validation.rms_torque_error_all["identified"],
                           "models": {k: {"rms_torque_error": self.validation.rms_torque_error[k],
                                          "rms_torque_error_all": self.validation.rms_torque_error_all[k]}
                                      for k in MODELS}},
            "data": {k: list(v) for k, v in self.data_notes.items()},
            "solver": dict(self.solver),
        }


# ---- helpers ---------------------------------------------------------------------------------

def _as_log(item, joint_names: Sequence[str]) -> Log:
    log = item if isinstance(item, Log) else read_log(item)
    log = log.for_model(joint_names)
    q = log.q[np.all(np.isfinite(log.q), axis=1)]
    if q.shape[0] >= 2 and float(np.max(np.ptp(q, axis=0))) < 1e-6:
        raise LogError(f"log '{log.source}': a constant trajectory (no joint moves by more than 1e-6): "
                       "it excites nothing (play an excitation trajectory: mechbal excite)")
    return log


def _stack(structure: Structure, prepared: Sequence[PreparedLog], friction: bool, filtered: bool = True):
    """Regressor, torque and measured torque stacked over every segment's kept samples. With
    ``filtered``: the regressor's columns and the torque through the segment's filter (what the fit
    uses); otherwise the regressor of the filtered states against the measured, unfiltered torque
    (what a validation compares)."""
    Ws, ys, ms = [], [], []
    n = structure.dof
    for p in prepared:
        for s in p.segments:
            if filtered:
                W = structure.regressor(s.q, s.v, s.a, friction=friction)
                N = s.t.size
                Ws.append(s.filtered(W.reshape(N, n, -1)).reshape(-1, W.shape[1]))
                ys.append(s.tau[s.keep].reshape(-1))
            else:
                k = s.keep
                Ws.append(structure.regressor(s.q[k], s.v[k], s.a[k], friction=friction))
                ys.append(s.tau[k].reshape(-1))
            ms.append(s.tau_measured[s.keep].reshape(-1))
    return np.vstack(Ws), np.concatenate(ys), np.concatenate(ms)


def _rms_per_joint(err: np.ndarray, names: Sequence[str]) -> dict[str, float]:
    E = err.reshape(-1, len(names))
    return {n: float(np.sqrt(np.mean(E[:, j] ** 2))) for j, n in enumerate(names)}


def _rms_all(err: np.ndarray) -> float:
    return float(np.sqrt(np.mean(err ** 2)))


def _check_data_rank(Rb: np.ndarray, names: Sequence[str]) -> float:
    """IdentifyError naming the base parameters the logs do not determine; ``Rb``: the R factor
    (or any matrix with the same column space geometry, R^T R = W^T W) of the base regressor.
    Returns its condition number."""
    norms = np.linalg.norm(Rb, axis=0)
    dead = [names[int(i)] for i in np.flatnonzero(norms <= 1e-300)]
    if dead:
        raise IdentifyError(f"the logs do not determine {len(dead)} base parameter(s): {', '.join(dead)} "
                            "(their regressor columns are zero on these logs: the joints they belong to do not "
                            "move or the motion does not excite them)")
    _, R, piv = scipy.linalg.qr(Rb / norms, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    weak = np.flatnonzero(d < DATA_RANK_TOLERANCE * d[0])
    if weak.size:
        bad = [names[int(piv[i])] for i in weak]
        raise IdentifyError(f"the logs do not determine {len(bad)} base parameter(s): {', '.join(bad)} "
                            f"(rank-deficient regressor: their columns depend on the others to within "
                            f"{DATA_RANK_TOLERANCE:g}; excite the joints they belong to more, or add logs)")
    return float(np.linalg.cond(Rb))


# ---- the fit ---------------------------------------------------------------------------------

def fit(mechanism: Mechanism, logs: Sequence[str | Path | Log], *,
        validate: Sequence[str | Path | Log] = (), cutoff_hz: float | None = None,
        friction: bool = True, weighted: bool = True, consistent: bool = True,
        mass_bounds: tuple[float, float] | None = None, regularisation: float = 1e-4,
        tolerance: float = 1.2, decimate: int | None = None, gap_factor: float = 3.0,
        trim: int | None = None, max_iterations: int = 200) -> IdentificationResult:
    """Identify ``mechanism``'s inertial parameters (and ``friction``) from ``logs`` (paths or
    `Log` objects; module docstring), validate on ``validate`` (held-out logs; none: the
    identification logs, flagged ``held_out = False``).

    ``cutoff_hz``, ``decimate``, ``gap_factor``, ``trim``: the signal processing
    (`mechbal.identify.signal.prepare`; the cut-off of the first log applies to all).
    ``mass_bounds``: (low, high) factors bounding each segment's mass around its CAD value.
    ``regularisation``: weight of the pull towards the CAD values of what the logs leave free,
    relative to the weakest direction the logs determine.
    ``max_iterations``: the conic solver's limit (interior-point iterations; a fit that does not
    converge within it is reported, ``ok`` False).
    ``consistent=False`` skips the consistent fit (the identified mechanism and ``parameters``
    then carry the CAD inertias and no friction); it needs the ``identify`` extra (Clarabel:
    `mechbal.identify.consistent.MissingExtra`, an ImportError, without it). Raises `LogError` / `IdentifyError` (ValueErrors) with one
    line naming the log or the parameters."""
    structure = structure_of(mechanism)
    names = structure.joint_names
    if not logs:
        raise LogError("no identification log given")
    id_logs = [_as_log(x, names) for x in logs]
    val_logs = [_as_log(x, names) for x in validate]
    bs = base_structure(structure, friction=friction)
    r = bs.count
    for log in id_logs:
        if log.samples * structure.dof < r:
            raise LogError(f"log '{log.source}': fewer samples than parameters ({log.samples} samples x "
                           f"{structure.dof} joints = {log.samples * structure.dof} equations for {r} base parameters)")
    prepared: list[PreparedLog] = []
    for log in id_logs:
        p = prepare(log, cutoff_hz=cutoff_hz, decimate=decimate, gap_factor=gap_factor, trim=trim)
        cutoff_hz = p.cutoff_hz
        prepared.append(p)
    assert cutoff_hz is not None
    W, y, y_meas = _stack(structure, prepared, friction)
    if W.shape[0] < r:
        raise LogError(f"fewer samples than parameters after filtering: {W.shape[0]} equations for {r} base "
                       "parameters (longer logs, or a smaller trim / decimation)")
    Wb = W[:, bs.independent]
    Rb = np.asarray(np.linalg.qr(Wb, mode="r"))
    condition = _check_data_rank(Rb, bs.names)
    # the weakest direction the logs determine (column-scaled): the pull towards the CAD values is
    # ``regularisation`` times it, so that it only decides what the logs leave free
    weakest = float(np.linalg.svd(Rb / np.linalg.norm(Rb, axis=0), compute_uv=False)[-1] ** 2)
    n = structure.dof
    N = W.shape[0] // n
    # ordinary least squares, then weights per joint from its residual
    beta_ls, *_ = np.linalg.lstsq(Wb, y, rcond=None)
    res_ls = y - Wb @ beta_ls
    dof_per_joint = max(N - r / n, 1.0)
    sigma = np.sqrt(np.sum(res_ls.reshape(N, n) ** 2, axis=0) / dof_per_joint)
    sigma = np.maximum(sigma, 1e-12 * max(float(sigma.max()), 1e-300))
    w = np.tile(1.0 / sigma, N) if weighted else np.ones(N * n)
    Wbw = Wb * w[:, None]
    beta, *_ = np.linalg.lstsq(Wbw, y * w, rcond=None)
    rw = (y - Wb @ beta) * w
    s2 = float(rw @ rw) / max(N * n - r, 1)
    cov = s2 * np.linalg.pinv(Wbw.T @ Wbw)
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    rel = 100.0 * std / np.maximum(np.abs(beta), 1e-300)
    # the consistent fit over the full parameters, the same weights
    P = W.shape[1]
    Pi = structure.n_inertial
    Aug = np.hstack([W * w[:, None], (y * w)[:, None]])
    Raug = np.asarray(np.linalg.qr(Aug, mode="r"))
    R, z = Raug[:P, :P], Raug[:P, P]
    solver: dict[str, Any] = {}
    if consistent:
        x, report = consistent_fit(R, z, len(structure.segment_links), P - Pi, structure.cad,
                                   regularisation=regularisation * weakest, mass_bounds=mass_bounds,
                                   max_iterations=max_iterations,
                                   rest=float(abs(Raug[P, P])) if Raug.shape[0] > P else 0.0)
        solver = {"method": "LMI (pseudo-inertia >= 0), conic interior point (Clarabel)",
                  "converged": report.converged, "status": report.status, "iterations": report.iterations,
                  "max_iterations": int(max_iterations), "primal_residual": report.primal_residual,
                  "dual_residual": report.dual_residual, "gap": report.gap, "accuracy": report.accuracy,
                  "projection": report.projection, "solve_time_s": report.solve_time_s,
                  "regularisation": regularisation}
    else:
        x = np.concatenate([structure.cad, np.zeros(P - Pi)])
    pi = x[:Pi]
    fr = x[Pi:] if friction else np.zeros(3 * n)
    friction_map = {j: Friction(float(fr[3 * k]), float(fr[3 * k + 1]), float(fr[3 * k + 2]))
                    for k, j in enumerate(names)}
    checks = [consistency(name, pi[10 * i:10 * i + 10]) for i, name in enumerate(structure.segment_names)]
    identified = _identified_mechanism(structure, pi)
    res_c = y - W @ x
    limited_by = []
    if consistent and not report.converged:
        limited_by.append(f"the consistent fit's conic solver did not converge: status {report.status} after "
                          f"{report.iterations} iterations (max_iterations {int(max_iterations)}; relative primal "
                          f"residual {report.primal_residual:.3g}, dual {report.dual_residual:.3g}, gap "
                          f"{report.gap:.3g}, accuracy asked {report.accuracy:g})")
    bad = [c.name for c in checks if not c.consistent]
    if bad:
        limited_by.append(f"not physically consistent: {', '.join(bad)}")
    # validation: each model on the held-out logs (or the identification logs)
    held_out = bool(val_logs)
    vprep = [prepare(log, cutoff_hz=cutoff_hz, decimate=decimate, gap_factor=gap_factor, trim=trim)
             for log in val_logs] if held_out else prepared
    Wv, _, yv = _stack(structure, vprep, True, filtered=False)
    # CAD with friction: friction fitted to what the CAD inertias leave, on the identification logs
    Wf = W[:, Pi:] if friction else np.zeros((W.shape[0], 0))
    if friction:
        f_cad, *_ = np.linalg.lstsq(Wf, y - W[:, :Pi] @ structure.cad, rcond=None)
    x_ls = np.zeros(P)
    x_ls[bs.independent] = beta_ls
    Wvf = Wv if friction else Wv[:, :Pi]
    predictions = {
        "identified": Wvf @ x,
        "least_squares": Wvf @ x_ls,
        "cad": Wv[:, :Pi] @ structure.cad,
        "cad_friction": Wv[:, :Pi] @ structure.cad + (Wv[:, Pi:] @ f_cad if friction else 0.0),
    }
    rms = {k: _rms_per_joint(yv - p, names) for k, p in predictions.items()}
    rms_all = {k: _rms_all(yv - p) for k, p in predictions.items()}
    first = vprep[0].segments[0]
    m0 = first.samples * n
    trace = {"t": first.t[first.keep], "measured": first.tau_measured[first.keep],
             **{k: p[:m0].reshape(-1, n) for k, p in predictions.items()}}
    validation = Validation(logs=[p.source for p in vprep], held_out=held_out, joint_names=list(names),
                            rms_torque_error=rms, rms_torque_error_all=rms_all, trace=trace)
    rms_c, rms_ls = rms_all["identified"], rms_all["least_squares"]
    if rms_c > tolerance * rms_ls:
        where = "held-out" if held_out else "identification"
        limited_by.append(f"the consistent model's RMS torque error {rms_c:.6g} exceeds {tolerance:g} x least "
                          f"squares' {rms_ls:.6g} on the {where} logs")
    notes = {p.source: list(p.notes) for p in prepared}
    if held_out:
        notes.update({p.source: list(p.notes) for p in vprep})
    return IdentificationResult(
        mechanism=identified, structure=structure, base=bs, base_values=beta if weighted else beta_ls,
        base_std=std, base_relative_std_pct=rel, base_least_squares=beta_ls, parameters=x,
        parameter_names=structure.parameter_names if friction else structure.inertial_names,
        friction=friction_map, cad_parameters=structure.cad.copy(), consistency=checks,
        condition_number=condition, residual_rms=_rms_per_joint(res_c, names),
        residual_rms_least_squares=_rms_per_joint(res_ls, names), validation=validation,
        cutoff_hz=float(cutoff_hz), samples=int(N), data_notes=notes, tolerance=float(tolerance),
        ok=not limited_by, limited_by=limited_by, solver=solver)


def _identified_mechanism(structure: Structure, pi: np.ndarray) -> Mechanism:
    """The mechanism with the identified bodies: the base's bodies kept, one body per segment
    (named after it, on its link) with the identified parameters; names, frames, limits kept."""
    bodies = list(structure.base_bodies)
    for i, (link, name) in enumerate(zip(structure.segment_links, structure.segment_names)):
        m, c, Ic = parameters_to_body(pi[10 * i:10 * i + 10])
        bodies.append(_core.Body(name, link, float(m), c, Ic, "link"))
    mech = structure.mechanism
    return mech.with_bodies(bodies, replace=True, name=f"{mech.name}-identified")
