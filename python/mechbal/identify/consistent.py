"""Physically consistent inertial parameters: a convex fit under linear matrix inequalities.

A body's 10 parameters are physically consistent (a non-negative mass density over some region
can have them) exactly when its pseudo-inertia matrix

    J = [[Sigma, h], [h^T, m]],  Sigma = tr(I)/2 * 1 - I  (second moment, I about the origin)

is positive semi-definite (Wensing, Kim & Slotine 2017): positive mass, inertia positive
semi-definite and the triangle inequality of its principal moments all follow. J is linear in
the parameters, so the fit

    minimise |R x - z|^2 + sum_k d_k (pi_k - pi_cad_k)^2
    subject to J_b(pi) >= 0 for every body b, viscous >= 0, Coulomb >= 0
               (and, if asked, each mass within bounds around its CAD value)

is a convex semi-definite least squares (an LMI problem). It is solved here without an extra
dependency by ADMM (Boyd et al. 2011, the splitting of the OSQP / SCS conic solvers: a linear
solve with a factorised matrix, then a projection onto the cone -- eigenvalues of each 4 x 4 J
clipped at zero --, variables scaled to a unit diagonal, the penalty adapted to balance the
primal and dual residuals). The parameters returned are those of the projected J's: consistent
to rounding. d_k is ``regularisation`` times the squared norm of column k of R (plus a floor), a
pull towards the CAD values that decides only what the data leave free: `mechbal.identify.fit`
scales it by the weakest direction the logs determine (the smallest squared singular value of
the column-scaled base regressor), so that it never competes with the data.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["pseudo_inertia", "consistency", "BodyConsistency", "consistent_fit"]


def pseudo_inertia(pi) -> np.ndarray:
    """J (4, 4) of 10 parameters (module docstring)."""
    pi = np.asarray(pi, float)
    m, h = pi[0], pi[1:4]
    Io = np.array([[pi[4], pi[5], pi[7]], [pi[5], pi[6], pi[8]], [pi[7], pi[8], pi[9]]])
    Sigma = 0.5 * np.trace(Io) * np.eye(3) - Io
    J = np.zeros((4, 4))
    J[:3, :3] = Sigma
    J[:3, 3] = J[3, :3] = h
    J[3, 3] = m
    return J


def _pseudo_inertia_map() -> np.ndarray:
    """E (16, 10): vec(J) = E pi."""
    return np.column_stack([pseudo_inertia(np.eye(10)[k]).reshape(-1) for k in range(10)])


@dataclass(frozen=True)
class BodyConsistency:
    """Whether one identified body is physically consistent: mass [kg], principal moments about
    the centre of mass [kg m^2], the smallest eigenvalue of the pseudo-inertia J (>= 0 for a
    consistent body) and the verdict (mass > 0, moments >= 0, each at most the sum of the others;
    within ``1e-12`` times the largest moment)."""

    name: str
    mass: float
    principal_moments: tuple[float, float, float]
    min_pseudo_inertia_eigenvalue: float
    consistent: bool


def consistency(name: str, pi) -> BodyConsistency:
    from mechbal.identify.model import parameters_to_body

    m, _, Ic = parameters_to_body(pi)
    lam = np.sort(np.linalg.eigvalsh(0.5 * (Ic + Ic.T)))
    tol = 1e-12 * max(float(np.abs(lam).max()), 1e-300)
    ok = bool(m > 0.0 and lam[0] >= -tol and lam[2] <= lam[0] + lam[1] + tol)
    jmin = float(np.linalg.eigvalsh(pseudo_inertia(pi)).min())
    return BodyConsistency(name=name, mass=float(m), principal_moments=tuple(float(x) for x in lam),  # type: ignore[arg-type]
                           min_pseudo_inertia_eigenvalue=jmin, consistent=ok)


@dataclass(frozen=True)
class SolverReport:
    """How the ADMM iterations ended: ``converged`` (primal and dual residuals below
    ``tolerance``), ``iterations``, the final relative residuals."""

    converged: bool
    iterations: int
    primal_residual: float
    dual_residual: float
    tolerance: float


def consistent_fit(R: np.ndarray, z: np.ndarray, n_segments: int, n_friction: int, cad: np.ndarray, *,
                   regularisation: float = 1e-6, mass_bounds: tuple[float, float] | None = None,
                   tolerance: float = 1e-6, max_iterations: int = 20000) -> tuple[np.ndarray, SolverReport]:
    """The fit of the module docstring: ``R`` (P, P), ``z`` (P,) the compressed weighted least
    squares (R of the QR decomposition of the weighted regressor), x = [pi (10 S), friction
    (viscous, Coulomb, offset per joint)]; ``mass_bounds`` (low, high): factors of each body's CAD
    mass (bodies with a CAD mass only). Returns (x, `SolverReport`)."""
    S = int(n_segments)
    Pi = 10 * S
    P = R.shape[1]
    c2 = np.sum(R[:, :Pi] ** 2, axis=0)
    c2 = c2 + 1e-6 * max(float(np.mean(c2)), 1e-300)
    d = np.zeros(P)
    d[:Pi] = regularisation * c2
    x_ref = np.zeros(P)
    x_ref[:Pi] = cad
    # constraint rows: vec(J) of every body (cone), then boxes (friction >= 0, masses)
    E = _pseudo_inertia_map()
    box_rows, lo, hi = [], [], []
    for k in range(n_friction // 3):
        for c in (0, 1):
            row = np.zeros(P)
            row[Pi + 3 * k + c] = 1.0
            box_rows.append(row)
            lo.append(0.0)
            hi.append(np.inf)
    if mass_bounds is not None:
        for b in range(S):
            m = cad[10 * b]
            if m > 0:
                row = np.zeros(P)
                row[10 * b] = 1.0
                box_rows.append(row)
                lo.append(m * mass_bounds[0])
                hi.append(m * mass_bounds[1])
    M = np.zeros((16 * S + len(box_rows), P))
    M[:16 * S, :Pi] = np.kron(np.eye(S), E)
    if box_rows:
        M[16 * S:] = np.array(box_rows)
    lo_a, hi_a = np.array(lo), np.array(hi)
    H0 = R.T @ R + np.diag(d)
    sc = 1.0 / np.sqrt(np.maximum(np.diag(H0), 1e-300))   # x = sc * y: H with a unit diagonal
    H = H0 * np.outer(sc, sc)
    g = sc * (R.T @ z + d * x_ref)
    Ms = M * sc[None, :]
    MtM = Ms.T @ Ms
    rho = 1.0

    def project(v):
        out = v.copy()
        J = v[:16 * S].reshape(S, 4, 4)
        J = 0.5 * (J + np.swapaxes(J, 1, 2))
        w, V = np.linalg.eigh(J)
        out[:16 * S] = ((V * np.maximum(w, 0.0)[:, None, :]) @ np.swapaxes(V, 1, 2)).reshape(-1)
        out[16 * S:] = np.clip(v[16 * S:], lo_a, hi_a)
        return out

    # the system is small (P x P): its inverse, refreshed when the penalty changes
    Kinv = np.linalg.inv(H + rho * MtM)
    y = Kinv @ g
    g_norm = float(np.linalg.norm(g))
    Zc = project(Ms @ y)
    U = np.zeros_like(Zc)
    r_rel = s_rel = np.inf
    it = 0
    for it in range(1, int(max_iterations) + 1):
        y = Kinv @ (g + rho * Ms.T @ (Zc - U))
        My = Ms @ y
        Z_old = Zc
        Zc = project(My + U)
        U += My - Zc
        r = float(np.linalg.norm(My - Zc))
        s = float(rho * np.linalg.norm(Ms.T @ (Zc - Z_old)))
        r_rel = r / max(float(np.linalg.norm(My)), float(np.linalg.norm(Zc)), 1e-300)
        s_rel = s / max(float(rho * np.linalg.norm(Ms.T @ U)), g_norm, 1e-300)
        if r_rel < tolerance and s_rel < tolerance:
            break
        if it % 50 == 0:      # residual balancing (Boyd et al. 2011, section 3.4.1)
            if r > 10.0 * s:
                rho, U = 2.0 * rho, U / 2.0
            elif s > 10.0 * r:
                rho, U = rho / 2.0, U * 2.0
            else:
                continue
            Kinv = np.linalg.inv(H + rho * MtM)
    x = sc * y
    # the consistent parameters: those of the projected J's (E is injective), each J's eigenvalues
    # at least 1e-12 of its largest (so that rounding cannot make a body inconsistent), and the
    # friction boxes clipped. (Mass bounds are met to the solver's tolerance: changing a mass
    # alone would break its body's consistency.)
    J = Zc[:16 * S].reshape(S, 4, 4)
    w, V = np.linalg.eigh(0.5 * (J + np.swapaxes(J, 1, 2)))
    w = np.maximum(w, 1e-12 * np.max(np.abs(w), axis=1, keepdims=True))
    J = (V * w[:, None, :]) @ np.swapaxes(V, 1, 2)
    pi = np.linalg.lstsq(np.kron(np.eye(S), E), J.reshape(-1), rcond=None)[0]
    xf = x[Pi:].copy()
    xf[0::3] = np.maximum(xf[0::3], 0.0)
    xf[1::3] = np.maximum(xf[1::3], 0.0)
    report = SolverReport(converged=bool(r_rel < tolerance and s_rel < tolerance), iterations=it,
                          primal_residual=float(r_rel), dual_residual=float(s_rel), tolerance=float(tolerance))
    return np.concatenate([pi, xf]), report
