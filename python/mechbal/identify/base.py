"""Base parameters: the combinations of the standard parameters that joint torques determine.

Numerical QR decomposition (Gautier 1990; the approach of SymPyBotics and FIGAROH) of the
regressor stacked over random states of the mechanism (positions within the joint limits,
velocities and accelerations of unit scale), its columns scaled to unit norm and taken in a
preferred order (segment by segment from the base; in each, the rotational inertia first, the
mass last): a column whose diagonal entry of R is below sqrt(``tolerance``) of the largest lies
in the span of the columns before it (the pivoting is by that order, not by size). The others
are the base parameters' leading columns, and the dependent ones regroup onto them,
``beta = pi_b + K pi_d`` with ``R_b K = R_d``. Columns that are zero at every state (a
parameter no joint torque depends on) regroup onto nothing. Which parameters are identifiable is
a property of the mechanism's structure, not of a log; whether a given log determines them is
checked on its own regressor (`mechbal.identify.fitting`).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from mechbal.identify.model import Structure

__all__ = ["BaseStructure", "base_structure", "random_states"]

#: order of a body's parameters (indices into INERTIAL_PARAMETER_NAMES) in the sequential QR:
#: izz, ixx, ixy, ixz, iyz, mcx, mcy, iyy, mcz, m
_PREFERENCE = (9, 4, 5, 7, 8, 1, 2, 6, 3, 0)


@dataclass(frozen=True)
class BaseStructure:
    """The base parameters of a structure's parameter vector x (inertial then friction).

    ``independent``: indices of x whose columns are the base columns (one per base parameter),
    ``dependent``: the others, ``K`` (r, len(dependent)): beta = x[independent] + K x[dependent].
    ``names``: one name per base parameter (its leading parameter's), ``regrouping``: the
    expression of each base parameter that regroups others (``'l2.izz + 0.09 l3.m + ...'``),
    ``unidentifiable``: parameters no torque depends on."""

    independent: np.ndarray
    dependent: np.ndarray
    K: np.ndarray
    names: list[str]
    regrouping: dict[str, str]
    unidentifiable: list[str]

    @property
    def count(self) -> int:
        return int(self.independent.size)

    def project(self, x: np.ndarray) -> np.ndarray:
        """beta of a full parameter vector x."""
        x = np.asarray(x, float)
        return x[self.independent] + self.K @ x[self.dependent]

    def matrix(self, n: int) -> np.ndarray:
        """(r, n) matrix B with beta = B x."""
        B = np.zeros((self.count, n))
        B[np.arange(self.count), self.independent] = 1.0
        B[:, self.dependent] = self.K
        return B


def random_states(structure: Structure, count: int, rng: np.random.Generator):
    """(q, v, a) at ``count`` random states: q uniform within the limits (+-pi where there is none),
    v and a standard normal."""
    joints = {j.name: j for j in structure.mechanism.model.description.joints}
    lo = np.array([joints[n].lower if np.isfinite(joints[n].lower) else -np.pi for n in structure.joint_names])
    hi = np.array([joints[n].upper if np.isfinite(joints[n].upper) else np.pi for n in structure.joint_names])
    n = structure.dof
    q = lo + (hi - lo) * rng.random((count, n))
    return q, rng.normal(size=(count, n)), rng.normal(size=(count, n))


def _term(coef: float, name: str) -> str:
    return f"{coef:+.6g} {name}".replace("+", "+ ", 1).replace("-", "- ", 1)


def base_structure(structure: Structure, *, friction: bool = True, samples: int | None = None,
                   seed: int = 0, tolerance: float = 1e-10) -> BaseStructure:
    """The base parameters of ``structure`` (module docstring)."""
    names = structure.parameter_names if friction else structure.inertial_names
    P = len(names)
    count = samples or max(50, int(np.ceil(4 * P / max(structure.dof, 1))))
    rng = np.random.default_rng(seed)
    q, v, a = random_states(structure, count, rng)
    W = structure.regressor(q, v, a, friction=friction)
    norms = np.linalg.norm(W, axis=0)
    zero = norms <= 1e-12 * max(float(norms.max()), 1e-300)
    cols = np.flatnonzero(~zero)
    # columns in a preferred order (per segment from the base: rotational inertia, first moments,
    # then the mass), so that a dependent parameter regroups onto those before it: a link's
    # mass and iyy onto its own inertia and its parent's, as in the closed-form rules
    rank_in_body = {p: k for k, p in enumerate(_PREFERENCE)}
    key = [(i // 10, rank_in_body[i % 10]) if i < structure.n_inertial else (10 ** 6, i) for i in cols]
    cols = cols[sorted(range(cols.size), key=lambda k: key[k])]
    Wn = W[:, cols] / norms[cols]
    R = np.asarray(np.linalg.qr(Wn, mode="r"))
    d = np.abs(np.diag(R))
    lead = d > tolerance ** 0.5 * max(float(d.max()), 1e-300)
    ind_n, dep_n = np.flatnonzero(lead), np.flatnonzero(~lead)
    r = ind_n.size
    if dep_n.size:
        K_n = np.linalg.lstsq(R[:, ind_n], R[:, dep_n], rcond=None)[0]
    else:
        K_n = np.zeros((r, 0))
    # back to unscaled parameters: beta_i = x_i + sum_j K_ij x_j, with the columns' scales
    K = K_n * norms[cols[dep_n]][None, :] / norms[cols[ind_n]][:, None]
    K[np.abs(K) < 1e-9 * max(1.0, float(np.abs(K).max(initial=0.0)))] = 0.0
    # keep the base parameters in the order of the standard parameters
    order = np.argsort(cols[ind_n])
    independent = cols[ind_n][order]
    K = K[order]
    dependent = cols[dep_n]
    base_names = [names[i] for i in independent]
    regrouping = {}
    for i, name in enumerate(base_names):
        terms = [_term(K[i, k], names[dependent[k]]) for k in np.flatnonzero(K[i])]
        if terms:
            regrouping[name] = name + " " + " ".join(terms)
    unidentifiable = [names[i] for i in np.flatnonzero(zero)]
    return BaseStructure(independent=independent, dependent=dependent, K=K, names=base_names,
                         regrouping=regrouping, unidentifiable=unidentifiable)
