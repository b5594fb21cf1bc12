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

is a convex semi-definite least squares (an LMI problem). It is solved as a conic program by
the interior-point solver Clarabel (Goulart & Chen 2024; the ``identify`` extra, imported lazily):
the objective as a second-order cone (minimise t with |[R; D^1/2] x - [z; D^1/2 pi_cad]| <= t,
the part of the residual no parameter changes included, so that the accuracy is relative to the
whole residual),
each body's J in a 4 x 4 positive semi-definite cone, the friction signs and mass bounds in the
non-negative cone. For the solver's sake the variables are scaled to a unit diagonal of the
normal matrix and each J by a congruence (J -> T J T, T = diag(a, a, a, b) from the CAD body's
size: the same cone). The solver stops at its relative accuracy (``1e-10``); its J's are then
within that accuracy of the cone, and the parameters returned are those of each J with its
eigenvalues raised to at least ``1e-12`` of its largest (consistent to rounding): how far that
moved the parameters is reported (`SolverReport.projection`). d_k is ``regularisation`` times the
squared norm of column k of R (plus a floor), a pull towards the CAD values that decides only what
the data leave free: `mechbal.identify.fit` scales it by the weakest direction the logs determine
(the smallest squared singular value of the column-scaled base regressor), so that it never
competes with the data.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["pseudo_inertia", "consistency", "BodyConsistency", "consistent_fit", "SolverReport",
           "MissingExtra", "clarabel_module"]

#: the solver's relative accuracy (Clarabel's ``tol_gap_abs``/``tol_gap_rel``/``tol_feas``)
ACCURACY = 1e-10

#: the floor of the pull towards the CAD values, relative to the mean squared column norm of R
#: (what gives the directions the data leave free a curvature the interior point can follow)
FLOOR = 1e-3

#: a solve Clarabel ends as ``AlmostSolved`` (slow progress near the end) counts as converged
#: when its relative primal and dual residuals and duality gap, measured here, are all below this
CERTIFIED = 1e-7


class MissingExtra(ImportError):
    """The ``identify`` extra (the Clarabel conic solver) is not installed."""


def clarabel_module():
    """The Clarabel module, or a `MissingExtra` naming the extra."""
    try:
        import clarabel
    except ImportError:
        raise MissingExtra("the physically consistent fit needs the 'identify' extra: pip install "
                           "'mechbal[identify]' (the Clarabel conic solver); or skip it: "
                           "fit(..., consistent=False)") from None
    return clarabel


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


#: the upper triangle of a 4 x 4 matrix column by column (Clarabel's PSDTriangleConeT order)
_TRIU = [(i, j) for j in range(4) for i in range(j + 1)]


def _svec_map() -> np.ndarray:
    """V (10, 16): svec(J) = V vec(J), the upper triangle column-major, off-diagonals times
    sqrt(2) (so that svec(A) . svec(B) = tr(A B))."""
    V = np.zeros((len(_TRIU), 16))
    for k, (i, j) in enumerate(_TRIU):
        V[k, 4 * i + j] = 1.0 if i == j else np.sqrt(2.0)
    return V


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
    """How the conic solve ended: Clarabel's ``status`` (``converged``: ``"Solved"``, or
    ``"AlmostSolved"`` with the residuals and gap below `CERTIFIED`), its
    ``iterations``, the relative primal and dual residuals and duality gap it reached, the
    ``accuracy`` asked, and ``projection``: the largest change of a parameter made by raising
    the J's eigenvalues to the cone, relative to the largest parameter of its body."""

    converged: bool
    status: str
    iterations: int
    primal_residual: float
    dual_residual: float
    gap: float
    accuracy: float
    projection: float
    solve_time_s: float


def _body_scale(pi_cad: np.ndarray) -> np.ndarray:
    """T = diag(a, a, a, b) making the CAD body's J of unit diagonal (1 when it has no mass)."""
    J = pseudo_inertia(pi_cad)
    m, s = J[3, 3], np.trace(J[:3, :3]) / 3.0
    a = 1.0 / np.sqrt(s) if s > 0 and np.isfinite(s) else 1.0
    b = 1.0 / np.sqrt(m) if m > 0 and np.isfinite(m) else 1.0
    return np.array([a, a, a, b])


def consistent_fit(R: np.ndarray, z: np.ndarray, n_segments: int, n_friction: int, cad: np.ndarray, *,
                   regularisation: float = 1e-6, mass_bounds: tuple[float, float] | None = None,
                   max_iterations: int = 200, rest: float = 0.0) -> tuple[np.ndarray, SolverReport]:
    """The fit of the module docstring: ``R`` (P, P), ``z`` (P,) the compressed weighted least
    squares (R of the QR decomposition of the weighted regressor), x = [pi (10 S), friction
    (viscous, Coulomb, offset per joint)]; ``mass_bounds`` (low, high): factors of each body's CAD
    mass (bodies with a CAD mass only); ``max_iterations``: the solver's (interior-point
    iterations); ``rest``: the part of the residual's norm no parameter changes (the last diagonal
    element of the QR of [W, y]), so that the solver's relative accuracy is relative to the whole
    residual, not to its excess over the unconstrained optimum. Returns (x, `SolverReport`); x is consistent whatever the solver's status, which
    the caller judges (`SolverReport.converged`). Raises `MissingExtra` without Clarabel."""
    import scipy.sparse as sp

    clarabel = clarabel_module()
    S = int(n_segments)
    Pi = 10 * S
    P = R.shape[1]
    if mass_bounds is not None and not (0.0 <= mass_bounds[0] <= mass_bounds[1]):
        raise ValueError(f"mass_bounds: {mass_bounds!r} is not (low, high) with 0 <= low <= high")
    c2 = np.sum(R[:, :Pi] ** 2, axis=0)
    c2 = c2 + FLOOR * max(float(np.mean(c2)), 1e-300)
    d = np.zeros(P)
    d[:Pi] = regularisation * c2
    x_ref = np.zeros(P)
    x_ref[:Pi] = cad
    # the objective's factor: |A x - c|^2 = |R x - z|^2 + sum d (x - x_ref)^2, A (P, P) triangular
    A_obj = np.vstack([R, np.diag(np.sqrt(d))])
    c_obj = np.concatenate([z, np.sqrt(d) * x_ref])
    Q, A_obj = np.linalg.qr(A_obj)
    c_full = c_obj
    c_obj = Q.T @ c_obj
    # what no x changes: the residual orthogonal to A's columns and ``rest`` (the cone's last entry)
    fixed = float(np.sqrt(max(float(c_full @ c_full - c_obj @ c_obj), 0.0) + float(rest) ** 2))
    # variables scaled to a unit diagonal of A^T A: x = sc * y; the solver's are [y, t]
    sc = 1.0 / np.maximum(np.linalg.norm(A_obj, axis=0), 1e-300)
    obj_scale = fixed if fixed > 0.0 else max(float(np.linalg.norm(c_obj)), 1e-300)
    n_var = P + 1
    rows_A: list[np.ndarray] = []
    rows_b: list[np.ndarray] = []
    cones = []
    # second-order cone: (t, A x - c, fixed), all divided by the fixed part (t of order one)
    blk = np.zeros((P + 2, n_var))
    blk[0, P] = -1.0
    blk[1:P + 1, :P] = -(A_obj * sc[None, :]) / obj_scale
    rows_A.append(blk)
    rows_b.append(np.concatenate([[0.0], -c_obj / obj_scale, [fixed / obj_scale]]))
    cones.append(clarabel.SecondOrderConeT(P + 2))
    # non-negative cone: friction signs and mass bounds
    nn_A, nn_b = [], []
    for k in range(n_friction // 3):
        for c in (0, 1):
            row = np.zeros(n_var)
            row[Pi + 3 * k + c] = -sc[Pi + 3 * k + c]
            nn_A.append(row)
            nn_b.append(0.0)
    if mass_bounds is not None:
        for bdy in range(S):
            m = cad[10 * bdy]
            if m > 0:
                for sign, bound in ((1.0, m * mass_bounds[1]), (-1.0, -m * mass_bounds[0])):
                    row = np.zeros(n_var)
                    row[10 * bdy] = sign * sc[10 * bdy] / max(m, 1e-300)
                    nn_A.append(row)
                    nn_b.append(bound / max(m, 1e-300))
    if nn_A:
        rows_A.append(np.array(nn_A))
        rows_b.append(np.array(nn_b))
        cones.append(clarabel.NonnegativeConeT(len(nn_A)))
    # a 4 x 4 positive semi-definite cone per body: svec(T J(pi) T)
    E, V = _pseudo_inertia_map(), _svec_map()
    scales = []
    for bdy in range(S):
        T = _body_scale(cad[10 * bdy:10 * bdy + 10])
        scales.append(T)
        TT = np.kron(T, T)          # vec(T J T) = (T kron T) vec(J), T diagonal
        blk = np.zeros((10, n_var))
        blk[:, 10 * bdy:10 * bdy + 10] = -(V @ (TT[:, None] * E)) * sc[None, 10 * bdy:10 * bdy + 10]
        rows_A.append(blk)
        rows_b.append(np.zeros(10))
        cones.append(clarabel.PSDTriangleConeT(4))
    A = sp.csc_matrix(np.vstack(rows_A))
    b = np.concatenate(rows_b)
    q = np.zeros(n_var)
    q[P] = 1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = int(max_iterations)
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = ACCURACY
    solver = clarabel.DefaultSolver(sp.csc_matrix((n_var, n_var)), q, A, b, cones, settings)
    sol = solver.solve()
    y = np.asarray(sol.x, float)[:P]
    if not np.all(np.isfinite(y)):
        y = np.nan_to_num(y, nan=0.0, posinf=0.0, neginf=0.0)
    x = sc * y
    # the consistent parameters: each (scaled) J's eigenvalues at least 1e-12 of its largest, so
    # that rounding cannot make a body inconsistent; the friction signs clipped
    pi = x[:Pi].copy()
    projection = 0.0
    for bdy, T in enumerate(scales):
        p = x[10 * bdy:10 * bdy + 10]
        Js = T[:, None] * pseudo_inertia(p) * T[None, :]
        w, U = np.linalg.eigh(0.5 * (Js + Js.T))
        floor = 1e-12 * max(float(np.max(np.abs(w))), 1e-300)
        if w[0] < floor:
            Js = (U * np.maximum(w, floor)[None, :]) @ U.T
            J = Js / np.outer(T, T)
            p_new = np.linalg.lstsq(E, J.reshape(-1), rcond=None)[0]
            projection = max(projection, float(np.max(np.abs(p_new - p)) / max(float(np.max(np.abs(p))), 1e-300)))
            pi[10 * bdy:10 * bdy + 10] = p_new
    xf = x[Pi:].copy()
    xf[0::3] = np.maximum(xf[0::3], 0.0)
    xf[1::3] = np.maximum(xf[1::3], 0.0)
    status = str(sol.status).split(".")[-1]
    r_p = float(getattr(sol, "r_prim", np.nan))
    r_d = float(getattr(sol, "r_dual", np.nan))
    certified = status == "AlmostSolved" and max(r_p, r_d, _gap(sol)) <= CERTIFIED
    report = SolverReport(converged=status == "Solved" or bool(certified), status=status, iterations=int(sol.iterations),
                          primal_residual=float(getattr(sol, "r_prim", np.nan)),
                          dual_residual=float(getattr(sol, "r_dual", np.nan)),
                          gap=_gap(sol), accuracy=ACCURACY, projection=projection,
                          solve_time_s=float(getattr(sol, "solve_time", np.nan)))
    return np.concatenate([pi, xf]), report


def _gap(sol) -> float:
    p, dual = float(sol.obj_val), float(getattr(sol, "obj_val_dual", np.nan))
    return abs(p - dual) / max(1.0, abs(p), abs(dual))
