"""Physically consistent inertial parameters: the log-Cholesky parameterisation.

A body's 10 parameters are physically consistent (a non-negative mass density over some region
can have them) exactly when its pseudo-inertia matrix

    J = [[Sigma, h], [h^T, m]],  Sigma = tr(I)/2 * 1 - I  (second moment, I about the origin)

is positive semi-definite (Wensing, Kim & Slotine 2017): positive mass, inertia positive
semi-definite and the triangle inequality of its principal moments all follow. Writing
``J = U U^T`` with ``U = e^alpha [[e^d1, s12, s13, t1], [0, e^d2, s23, t2], [0, 0, e^d3, t3],
[0, 0, 0, 1]]`` (Rucker & Wensing 2022, the log-Cholesky parameterisation) makes every real
theta = (alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3) a consistent body, and every consistent
body with J positive definite one theta: the constrained fit becomes an unconstrained nonlinear
least squares, solved by `scipy.optimize.least_squares` (trust region; the friction
coefficients bounded at zero: viscous and Coulomb friction dissipate). ``mass_bounds`` (relative
to the CAD mass) bound alpha, which bounds each mass around its CAD value.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["theta_to_parameters", "parameters_to_theta", "pseudo_inertia", "consistency",
           "BodyConsistency", "consistent_fit"]


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


def theta_to_parameters(theta):
    """pi (..., 10) of theta (..., 10) (real or complex: the complex step differentiates it)."""
    th = np.asarray(theta)
    e = np.exp
    a, d1, d2, d3, s12, s23, s13, t1, t2, t3 = np.moveaxis(th, -1, 0)
    z = np.zeros_like(a)
    one = np.ones_like(a)
    U = np.stack([np.stack([e(d1), s12, s13, t1], -1), np.stack([z, e(d2), s23, t2], -1),
                  np.stack([z, z, e(d3), t3], -1), np.stack([z, z, z, one], -1)], -2)
    U = U * e(a)[..., None, None]
    J = U @ np.swapaxes(U, -1, -2)
    m = J[..., 3, 3]
    h = J[..., :3, 3]
    Sigma = J[..., :3, :3]
    tr = np.trace(Sigma, axis1=-2, axis2=-1)
    Io = tr[..., None, None] * np.eye(3) - Sigma
    return np.stack([m, h[..., 0], h[..., 1], h[..., 2], Io[..., 0, 0], Io[..., 0, 1], Io[..., 1, 1],
                     Io[..., 0, 2], Io[..., 1, 2], Io[..., 2, 2]], -1)


def parameters_to_theta(pi, *, floor: float = 1e-9) -> np.ndarray:
    """theta of 10 parameters; a J that is not positive definite is first moved to the nearest
    one with eigenvalues at least ``floor`` times its largest (a CAD body with zero mass or a
    point mass, say)."""
    J = pseudo_inertia(pi)
    w, V = np.linalg.eigh(J)
    lo = floor * max(float(w.max()), 1e-12)
    if w.min() < lo:
        J = (V * np.maximum(w, lo)) @ V.T
    P = np.eye(4)[::-1]
    L = np.linalg.cholesky(P @ J @ P)
    U = P @ L @ P
    alpha = np.log(U[3, 3])
    U = U / U[3, 3]
    return np.array([alpha, np.log(U[0, 0]), np.log(U[1, 1]), np.log(U[2, 2]), U[0, 1], U[1, 2], U[0, 2],
                     U[0, 3], U[1, 3], U[2, 3]])


def parameters_jacobian(theta: np.ndarray, h: float = 1e-30) -> np.ndarray:
    """d pi / d theta (S, 10, 10) of theta (S, 10), by the complex step (exact to rounding)."""
    S = theta.shape[0]
    th = np.repeat(theta[:, None, :].astype(complex), 10, axis=1)
    th[:, np.arange(10), np.arange(10)] += 1j * h
    return np.swapaxes(theta_to_parameters(th).imag / h, 1, 2).reshape(S, 10, 10)


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


def consistent_fit(R: np.ndarray, z: np.ndarray, n_segments: int, n_friction: int, cad: np.ndarray, *,
                   regularisation: float = 1e-6, mass_bounds: tuple[float, float] | None = None,
                   x0_friction: np.ndarray | None = None, max_nfev: int = 2000):
    """Minimise ``|R x - z|^2 + regularisation * sum_k c_k^2 (pi_k - pi_cad_k)^2`` over consistent
    inertial parameters pi (S bodies) and friction x_f (viscous, Coulomb >= 0, offset free), x =
    [pi, x_f]. ``R`` (P, P), ``z`` (P,): the compressed weighted least squares (R of the QR
    decomposition of the weighted regressor); c_k: the norm of column k of R (so that the pull
    towards the CAD values only decides what the data leave free). Returns (x, scipy's result)."""
    from scipy.optimize import least_squares

    S = n_segments
    Pi = 10 * S
    c2 = np.sum(R[:, :Pi] ** 2, axis=0)
    c2 = c2 + 1e-6 * max(float(np.mean(c2)), 1e-300)
    reg = np.sqrt(regularisation * c2)
    theta0 = np.concatenate([parameters_to_theta(cad[10 * i:10 * i + 10]) for i in range(S)])
    f0 = np.zeros(n_friction) if x0_friction is None else np.asarray(x0_friction, float).copy()
    lo = np.full(Pi + n_friction, -np.inf)
    hi = np.full(Pi + n_friction, np.inf)
    lo[Pi::3] = 0.0          # viscous
    lo[Pi + 1::3] = 0.0      # Coulomb
    f0[0::3] = np.maximum(f0[0::3], 0.0)
    f0[1::3] = np.maximum(f0[1::3], 0.0)
    if mass_bounds is not None:
        for i in range(S):
            m = cad[10 * i]
            if m > 0:
                lo[10 * i] = 0.5 * np.log(m * mass_bounds[0]) if mass_bounds[0] > 0 else -np.inf
                hi[10 * i] = 0.5 * np.log(m * mass_bounds[1])
                theta0[10 * i] = np.clip(theta0[10 * i], lo[10 * i] + 1e-12, hi[10 * i] - 1e-12)
    y0 = np.concatenate([theta0, f0])
    y0 = np.clip(y0, np.where(np.isfinite(lo), lo + 1e-12, lo), hi)

    def unpack(y):
        th = y[:Pi].reshape(S, 10)
        return th, np.concatenate([theta_to_parameters(th).reshape(-1), y[Pi:]])

    def fun(y):
        _, x = unpack(y)
        return np.concatenate([R @ x - z, reg * (x[:Pi] - cad)])

    def jac(y):
        th, _ = unpack(y)
        D = parameters_jacobian(th)          # (S, 10 pi, 10 theta)
        dx = np.zeros((Pi + n_friction, Pi + n_friction))
        for i in range(S):
            dx[10 * i:10 * i + 10, 10 * i:10 * i + 10] = D[i]
        dx[Pi:, Pi:] = np.eye(n_friction)
        return np.vstack([R @ dx, reg[:, None] * dx[:Pi]])

    sol = least_squares(fun, y0, jac=jac, bounds=(lo, hi), method="trf", x_scale="jac",
                        max_nfev=max_nfev, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    _, x = unpack(sol.x)
    return x, sol
