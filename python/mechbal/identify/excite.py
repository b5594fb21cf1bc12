"""Excitation trajectories: finite Fourier series that make the base regressor well conditioned.

Each joint follows (Swevers et al. 1997)

    q_j(t) = q0_j + sum_k a_jk / (w k) sin(w k t) - b_jk / (w k) cos(w k t),   w = 2 pi / T,

k = 1..K harmonics of the period T (the duration). The coefficients are tied so that the motion
starts and ends at rest (v(0) = sum_k a_jk = 0, a(0) = w sum_k k b_jk = 0): a robot can play it
from its start pose, once or looped. The free coefficients minimise the condition number of the
base regressor (inertial and friction parameters, `mechbal.identify.base`) stacked over
``samples`` instants of the period (SLSQP, `scipy.optimize.minimize`), within the limits, which
are enforced through bounds that hold at every instant, not only at the samples:

    |q_j - q0_j| <= sum_k |c_jk| / (w k),  |v_j| <= sum_k |c_jk|,  |a_j| <= sum_k w k |c_jk|,

with |c_jk| = sqrt(a_jk^2 + b_jk^2): each within the joint's position range (minus ``margin``),
velocity limit and acceleration limit. Limits come from the model (URDF position and velocity
limits) or the caller (``max_velocity``, ``max_acceleration``: a URDF declares no acceleration
limit, so one must be given); a joint with neither is refused, never given a made-up limit.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mechbal.identify.base import base_structure
from mechbal.identify.model import structure_of
from mechbal.mechanism import Mechanism

__all__ = ["Excitation", "excite", "fourier_motion"]


@dataclass(frozen=True)
class Excitation:
    """An excitation trajectory: its Fourier coefficients ``a``, ``b`` (dof, K) and ``q0`` (dof,),
    the period ``duration`` [s], the condition number of the base regressor over it (and of the
    initial guess), and the limits it keeps."""

    joint_names: list[str]
    duration: float
    a: np.ndarray
    b: np.ndarray
    q0: np.ndarray
    condition_number: float
    initial_condition_number: float
    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    max_acceleration: np.ndarray
    iterations: int

    @property
    def harmonics(self) -> int:
        return int(self.a.shape[1])

    def motion(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, v, a (N, dof) at the times t (N,)."""
        return fourier_motion(self.a, self.b, self.q0, self.duration, t)

    def sample(self, rate_hz: float = 1000.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(t, q, v, a) over one period at ``rate_hz``, both ends included."""
        n = int(round(self.duration * rate_hz)) + 1
        t = np.linspace(0.0, self.duration, n)
        return (t, *self.motion(t))

    def to_csv(self, path: str | Path, rate_hz: float = 1000.0) -> Path:
        """Write ``t, q_<joint>..., v_<joint>..., a_<joint>...`` at ``rate_hz`` (a file a robot
        controller can play)."""
        t, q, v, a = self.sample(rate_hz)
        cols = (["t"] + [f"q_{j}" for j in self.joint_names] + [f"v_{j}" for j in self.joint_names]
                + [f"a_{j}" for j in self.joint_names])
        path = Path(path)
        np.savetxt(path, np.hstack([t[:, None], q, v, a]), delimiter=",", header=",".join(cols),
                   comments="", fmt="%.17g")
        return path


def fourier_motion(a, b, q0, duration: float, t):
    """q, v, a (N, dof) of the Fourier series (module docstring) at the times t."""
    a, b, q0 = np.asarray(a, float), np.asarray(b, float), np.asarray(q0, float)
    t = np.asarray(t, float).reshape(-1)
    w = 2.0 * np.pi / float(duration)
    k = np.arange(1, a.shape[1] + 1)
    wk = w * k                                   # (K,)
    s, c = np.sin(np.outer(t, wk)), np.cos(np.outer(t, wk))   # (N, K)
    q = q0 + s @ (a / wk).T - c @ (b / wk).T
    v = c @ a.T + s @ b.T
    acc = -s @ (a * wk).T + c @ (b * wk).T
    return q, v, acc


def _unpack(z: np.ndarray, n: int, K: int):
    """Free variables -> (a, b, q0) with v(0) = a(0) = 0."""
    fa = z[: n * (K - 1)].reshape(n, K - 1)
    fb = z[n * (K - 1): 2 * n * (K - 1)].reshape(n, K - 1)
    q0 = z[2 * n * (K - 1):]
    a = np.hstack([fa, -fa.sum(axis=1, keepdims=True)])
    k = np.arange(2, K + 1)
    b1 = -(fb * k).sum(axis=1, keepdims=True)
    b = np.hstack([b1, fb])
    return a, b, q0


def _limits(mech: Mechanism, max_velocity, max_acceleration, margin: float):
    joints = {j.name: j for j in mech.model.description.joints}
    names = mech.joint_names
    n = len(names)
    lower = np.array([joints[j].lower for j in names], float) + margin
    upper = np.array([joints[j].upper for j in names], float) - margin
    for j, lo, hi in zip(names, lower, upper):
        if np.isfinite(lo) and np.isfinite(hi) and hi <= lo:
            raise ValueError(f"joint '{j}': its position range is narrower than twice the margin {margin:g}")

    def per_joint(value, own, what):
        out = np.array(own, float)
        if value is not None:
            v = np.broadcast_to(np.asarray(value, float), (n,))
            if np.any(~np.isfinite(v)) or np.any(v <= 0):
                raise ValueError(f"{what}: must be positive and finite (got {value!r})")
            out = np.minimum(out, v) if np.all(np.isfinite(out)) else np.where(np.isfinite(out), np.minimum(out, v), v)
        missing = [j for j, x in zip(names, out) if not np.isfinite(x) or x <= 0]
        if missing:
            flag = "--max-" + what.split("_")[1]
            raise ValueError(f"{what}: joint '{missing[0]}' declares none (give {what}, on the command line "
                             f"{flag})")
        return out

    vmax = per_joint(max_velocity, [joints[j].velocity_limit if joints[j].velocity_limit > 0 else np.inf
                                    for j in names], "max_velocity")
    amax = per_joint(max_acceleration, [np.inf] * n, "max_acceleration")
    return lower, upper, vmax, amax


def excite(mechanism: Mechanism, duration: float, harmonics: int = 5, *, max_velocity=None,
           max_acceleration=None, margin: float = 0.05, samples: int | None = None, seed: int = 0,
           max_iterations: int = 100, friction: bool = True) -> Excitation:
    """An excitation trajectory for ``mechanism`` (module docstring): period ``duration`` [s],
    ``harmonics`` K >= 2, within the joints' position range shrunk by ``margin`` [rad or m] at
    each end and the velocity and acceleration limits (model's, or the given ones if lower: a
    number for every joint or one per joint). ValueError naming the limit that is missing."""
    duration = float(duration)
    if not np.isfinite(duration) or duration <= 0:
        raise ValueError(f"duration: must be positive (got {duration!r})")
    K = int(harmonics)
    if K < 2:
        raise ValueError(f"harmonics: at least 2 (one harmonic cannot start and end at rest), got {harmonics!r}")
    structure = structure_of(mechanism)
    n = structure.dof
    lower, upper, vmax, amax = _limits(mechanism, max_velocity, max_acceleration, margin)
    bs = base_structure(structure, friction=friction)
    M = samples or max(100, int(np.ceil(3 * bs.count / n)))
    t = np.linspace(0.0, duration, M, endpoint=False)
    w = 2.0 * np.pi / duration
    wk = w * np.arange(1, K + 1)
    centre = np.where(np.isfinite(lower) & np.isfinite(upper), 0.5 * (lower + upper), 0.0)
    half = np.where(np.isfinite(lower) & np.isfinite(upper), 0.5 * (upper - lower), np.inf)

    def amplitudes(z):
        a, b, q0 = _unpack(z, n, K)
        c = np.sqrt(a ** 2 + b ** 2 + 1e-18)
        return a, b, q0, c

    def constraints(z):
        a, b, q0, c = amplitudes(z)
        g = [vmax - c.sum(axis=1), amax - (c * wk).sum(axis=1)]
        pos = (c / wk).sum(axis=1)
        finite = np.isfinite(half)
        g.append(np.where(finite, np.nan_to_num(upper - q0 - pos, posinf=1.0), 1.0))
        g.append(np.where(finite, np.nan_to_num(q0 - pos - lower, posinf=1.0), 1.0))
        return np.concatenate(g)

    def objective(z):
        a, b, q0 = _unpack(z, n, K)
        q, v, acc = fourier_motion(a, b, q0, duration, t)
        W = structure.regressor(q, v, acc, friction=friction)[:, bs.independent]
        lam = np.linalg.eigvalsh(W.T @ W)     # cond(W)^2 = cond(W^T W): cheaper than an SVD
        return float(0.5 * np.log(lam[-1] / max(lam[0], lam[-1] * 1e-300)))

    rng = np.random.default_rng(seed)
    z0 = np.concatenate([rng.normal(size=2 * n * (K - 1)), centre])
    # scale the initial amplitudes into the limits (half of what they allow)
    a, b, q0, c = amplitudes(z0)
    ratio = np.min(np.stack([vmax / c.sum(axis=1), amax / (c * wk).sum(axis=1),
                             np.where(np.isfinite(half), half / (c / wk).sum(axis=1), np.inf)]), axis=0)
    scale = 0.5 * ratio
    z0[: 2 * n * (K - 1)] = (z0[: 2 * n * (K - 1)].reshape(2, n, K - 1) * scale[None, :, None]).reshape(-1)
    cond0 = float(np.exp(objective(z0)))
    from scipy.optimize import minimize

    sol = minimize(objective, z0, method="SLSQP", constraints=[{"type": "ineq", "fun": constraints}],
                   options={"maxiter": int(max_iterations), "ftol": 1e-6})
    z = np.array(sol.x, float)
    for _ in range(60):   # SLSQP may end a hair outside a limit: shrink the amplitudes into them
        if np.all(constraints(z) >= 0.0):
            break
        z[: 2 * n * (K - 1)] *= 0.99
    if not np.all(constraints(z) >= 0.0) or objective(z) > objective(z0):
        z = z0
    a, b, q0 = _unpack(z, n, K)
    return Excitation(joint_names=list(structure.joint_names), duration=duration, a=a, b=b, q0=q0,
                      condition_number=float(np.exp(objective(z))), initial_condition_number=cond0,
                      lower=lower, upper=upper, max_velocity=vmax, max_acceleration=amax,
                      iterations=int(getattr(sol, "nit", 0)))
