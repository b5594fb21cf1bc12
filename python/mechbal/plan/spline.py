"""Clamped quintic B-splines of the actuated joints with exact boundary conditions.

Each actuated joint follows ``q(t) = sum_k p_k B_k(t)`` on ``[0, duration]``: a clamped B-spline
of degree 5 on uniform knots (every quintic polynomial is one of them, so the quintic law is a
point of the search space: the warm start). The first and last three control points are fixed by
the boundary position, velocity and acceleration at each end; the others are free:
``p = F z + G r`` with ``z`` the free points and ``r = [q0, v0, a0, q1, v1, a1]``.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline

DEGREE = 5


@dataclass(frozen=True)
class SplineBasis:
    """Basis of a clamped B-spline of `DEGREE` with ``count`` control points over ``[0, duration]``
    and its boundary map (see the module docstring)."""

    duration: float
    count: int
    knots: np.ndarray
    free_map: np.ndarray       # F: (count, count - 2 held)
    boundary_map: np.ndarray   # G: (count, 2 held)
    held: int = 2

    @classmethod
    def make(cls, duration: float, count: int, held: int = 2) -> "SplineBasis":
        """``held``: derivatives fixed at each end, 2 (position and velocity) or 3 (and
        acceleration)."""
        if held not in (2, 3):
            raise ValueError(f"held must be 2 or 3, got {held}")
        if count < DEGREE + 2 or count < 2 * held + 1:
            raise ValueError(f"control_points must be >= {max(DEGREE + 2, 2 * held + 1)}, got {count}")
        inner = np.linspace(0.0, duration, count - DEGREE + 1)
        knots = np.concatenate([[0.0] * DEGREE, inner, [duration] * DEGREE])
        ends = np.array([0.0, duration])
        rows = np.concatenate([_basis(knots, count, ends[:1], nu) for nu in range(held)]
                              + [_basis(knots, count, ends[1:], nu) for nu in range(held)])
        fixed = np.concatenate([np.arange(held), np.arange(count - held, count)])
        free = np.setdiff1d(np.arange(count), fixed)
        E = rows[:, fixed]
        F = np.zeros((count, free.size))
        G = np.zeros((count, 2 * held))
        F[free, np.arange(free.size)] = 1.0
        F[fixed] = -np.linalg.solve(E, rows[:, free])
        G[fixed] = np.linalg.inv(E)
        return cls(float(duration), int(count), knots, F, G, held)

    @property
    def free_count(self) -> int:
        return self.count - 2 * self.held

    def matrices(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(B0, B1, B2): the basis and its first two time derivatives at ``t`` (N, count)."""
        t = np.clip(np.asarray(t, float), 0.0, self.duration)
        return tuple(_basis(self.knots, self.count, t, nu) for nu in range(3))  # type: ignore[return-value]

    def control_points(self, z: np.ndarray, boundary: np.ndarray) -> np.ndarray:
        """Control points (count, na) from free points ``z`` (count - 2 held, na) and ``boundary``
        (2 held, na), ``r`` of the module docstring."""
        return self.free_map @ z + self.boundary_map @ boundary

    def fit(self, t: np.ndarray, q: np.ndarray, boundary: np.ndarray) -> np.ndarray:
        """Free points (count - 2 held, na) whose spline is nearest ``q`` (N, na) at ``t`` (least
        squares), with the boundary conditions held exactly."""
        B0 = self.matrices(t)[0]
        A = B0 @ self.free_map
        rhs = q - B0 @ self.boundary_map @ boundary
        return np.linalg.lstsq(A, rhs, rcond=None)[0]


def _basis(knots: np.ndarray, count: int, t: np.ndarray, nu: int) -> np.ndarray:
    spline = BSpline(knots, np.eye(count), DEGREE, extrapolate=False)
    out = spline(t, nu)
    return np.nan_to_num(np.asarray(out, float))


class SplineTrajectory:
    """The planned motion of the actuated joints: a `mechbal.trajectory.Trajectory` (``dof``,
    ``duration``, ``evaluate(t)``, ``evaluate_batch(t)``), held at its end points outside
    ``[0, duration]`` at rest, as every trajectory of `mechbal.trajectory` is."""

    law = "min_shaking"

    def __init__(self, basis: SplineBasis, points: np.ndarray):
        self.basis = basis
        #: control points (count, na)
        self.points = np.asarray(points, float)
        self._spline = BSpline(basis.knots, self.points, DEGREE, extrapolate=False)
        self._d1 = self._spline.derivative(1)
        self._d2 = self._spline.derivative(2)

    @property
    def dof(self) -> int:
        return int(self.points.shape[1])

    @property
    def duration(self) -> float:
        return self.basis.duration

    def evaluate_batch(self, t):
        from mechbal.trajectory import Motion

        t = np.atleast_1d(np.asarray(t, float))
        tc = np.clip(t, 0.0, self.duration)
        q = np.asarray(self._spline(tc))
        v = np.asarray(self._d1(tc))
        a = np.asarray(self._d2(tc))
        outside = ((t < 0.0) | (t > self.duration))[:, None]
        v = np.where(outside, 0.0, v)
        a = np.where(outside, 0.0, a)
        return Motion(q, v, a)

    def evaluate(self, t):
        from mechbal.trajectory import Motion

        single = np.ndim(t) == 0
        m = self.evaluate_batch(t)
        return Motion(m.q[0], m.v[0], m.a[0]) if single else m

    def __repr__(self) -> str:
        return f"<SplineTrajectory min_shaking, {self.dof} coordinates, {self.duration:g} s>"
