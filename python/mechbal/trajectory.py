"""Desired motions: one interface, ``evaluate(t) -> Motion(q, v, a)``, for every kind of trajectory.

Every trajectory here has ``dof`` (number of coordinates), ``duration`` [s] (the motion runs over
``[0, duration]``; `Sampled` over the span of its samples) and ``evaluate(t)``:

* ``t`` a number: a `Motion` ``(q, v, a)``, each of shape ``(dof,)``;
* ``t`` an array of N times: each of shape ``(N, dof)`` (one call, no Python loop).

`Motion` is a named tuple: ``q, v, a = traj.evaluate(t)`` and ``traj.evaluate(t).v`` both work
(``.qd`` and ``.qdd``, the names of earlier releases, still work for one release and warn).

Positions are in rad (revolute) or m (prismatic), velocities in rad/s or m/s, accelerations in
rad/s^2 or m/s^2, times in s. Before its start and after its end a trajectory holds its first or
last point at rest (zero velocity and acceleration), as the C++ ``RestToRestTrajectory`` does.

* `quintic`: rest-to-rest, `s = 10 u^3 - 15 u^4 + 6 u^5` (the C++ `RestToRestTrajectory`);
* `minimum_energy_cubic`: rest-to-rest, `s = 3 u^2 - 2 u^3`, the law of least integral of
  squared acceleration (Arakelian, Le Baron & Mottu 2011, eq 13);
* `ConstantSpeed`: a steady motion from ``start`` at constant ``speed`` (a crank turning at so
  many rpm, the motion balancing textbooks quote);
* `ViaPoints`: a piecewise quintic through given points at given times;
* `Sampled`: a user's time series, interpolated by cubic splines.

All of them are accepted by `mechbal.simulate.closed_loop`; a `RestToRest` runs on the C++ path
directly, the others are sampled every `dt / 2` first.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

from typing import Any, NamedTuple, Protocol, Union, runtime_checkable

import numpy as np
import numpy.typing as npt

import mechbal._core as _core
from mechbal._deprecation import warn_renamed

__all__ = ["Trajectory", "Motion", "RestToRest", "quintic", "minimum_energy_cubic", "ConstantSpeed", "ViaPoints",
           "Sampled", "TimeLaw", "RestToRestTrajectory", "as_trajectory", "quintic_within_limits"]

TimeLaw = _core.TimeLaw
#: the C++ rest-to-rest law (quintic or minimum-energy cubic) that RestToRest wraps
RestToRestTrajectory = _core.RestToRestTrajectory
ArrayLike = npt.ArrayLike
Times = Union[float, npt.ArrayLike]
FloatArray = npt.NDArray[np.float64]


class Motion(NamedTuple):
    """A desired motion at one time or N times: positions ``q`` [rad or m], velocities ``v``
    [rad/s or m/s] and accelerations ``a`` [rad/s^2 or m/s^2], each ``(dof,)`` or ``(N, dof)``.
    A tuple, so ``q, v, a = trajectory.evaluate(t)`` works."""

    q: FloatArray
    v: FloatArray
    a: FloatArray

    @property
    def qd(self) -> FloatArray:
        """Deprecated name of `v`."""
        warn_renamed("qd", "v", "Motion")
        return self.v

    @property
    def qdd(self) -> FloatArray:
        """Deprecated name of `a`."""
        warn_renamed("qdd", "a", "Motion")
        return self.a


@runtime_checkable
class Trajectory(Protocol):
    """What every desired motion offers (see the module docstring)."""

    @property
    def dof(self) -> int:
        """Number of coordinates."""

    @property
    def duration(self) -> float:
        """Time span of the motion [s]."""

    def evaluate(self, t: Times) -> Motion:
        """`Motion` ``(q, v, a)`` at time(s) ``t`` [s]."""
        ...


def _times(t: Times) -> tuple[bool, np.ndarray]:
    a = np.asarray(t)
    if a.dtype.kind not in "iuf":
        raise TypeError(f"t must be real numbers (int or float), got dtype {a.dtype}")
    a = a.astype(float)
    if a.ndim > 1:
        raise ValueError(f"t must be a number or a 1-D array of times, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError("t must be finite")
    return a.ndim == 0, np.atleast_1d(a)


def _vector(name: str, value: ArrayLike) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be real numbers (int or float), got dtype {a.dtype}")
    a = np.array(a, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def _samples(times: ArrayLike, values: ArrayLike, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``times`` (K,) strictly increasing, K >= 2, and ``values`` (K, dof) (a 1-D array: one
    coordinate) named ``name`` in the ValueError, as ViaPoints and Sampled take them."""
    t = _vector("times", times)
    p = _vector(name, values)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"times must be a 1-D array of at least 2 times, got shape {t.shape}")
    if np.any(np.diff(t) <= 0):
        raise ValueError("times must be strictly increasing")
    if p.ndim == 1:
        p = p[:, None]
    if p.ndim != 2 or p.shape[0] != t.size:
        raise ValueError(f"{name} must have shape ({t.size}, dof), got {np.shape(values)}")
    return t, p


def _finite_motion(what: str, single: bool, q: FloatArray, v: FloatArray, a: FloatArray) -> Motion:
    """The motion, or ValueError when finite input overflowed into a non-finite value."""
    for name, x in (("q", q), ("v", v), ("a", a)):
        if not np.all(np.isfinite(x)):
            raise ValueError(f"{what}.evaluate: {name} is not finite (the points, velocities or "
                             "times overflow: values too large or times too close)")
    if single:
        return Motion(q[0], v[0], a[0])
    return Motion(q, v, a)


class _FromZero:
    """A motion that starts at t = 0: it ends at its duration."""

    @property
    def duration(self) -> float:
        """Motion time [s]."""
        raise NotImplementedError

    @property
    def end_time(self) -> float:
        """Time the motion ends [s] (= ``duration``: it starts at t = 0)."""
        return self.duration


class RestToRest(_FromZero):
    """Rest-to-rest motion from ``start`` to ``end`` in ``duration`` seconds along a time law
    (the C++ ``RestToRestTrajectory``; Arakelian, Le Baron & Mottu 2011, eqs 10-13):
    ``q(t) = start + (end - start) s(t / duration)``.

    Args:
        start: initial positions [rad or m], one per coordinate.
        end: final positions [rad or m], one per coordinate.
        duration: motion time [s], > 0.
        law: ``"quintic"`` (zero velocity and acceleration at both ends) or ``"cubic"``
            (minimum energy: least integral of squared acceleration; its acceleration jumps at
            both ends).
    """

    def __init__(self, start: ArrayLike, end: ArrayLike, duration: float,
                 law: str | _core.TimeLaw = "quintic"):
        if isinstance(law, str):
            if law not in ("quintic", "cubic"):
                raise ValueError(f"law must be 'quintic' or 'cubic', got '{law}'")
            time_law: _core.TimeLaw = getattr(_core.TimeLaw, law)
        else:
            time_law = law
        #: the C++ trajectory (what `mechbal.simulate.closed_loop` runs on)
        self.core = _core.RestToRestTrajectory(start, end, duration, time_law)

    @property
    def dof(self) -> int:
        """Number of coordinates."""
        return int(self.core.size)

    @property
    def duration(self) -> float:
        """Motion time [s]."""
        return float(self.core.duration)

    @property
    def law(self) -> str:
        """``"quintic"`` or ``"cubic"``."""
        return str(self.core.law.name)

    def evaluate(self, t: Times) -> Motion:
        """`Motion` ``(q, v, a)`` at ``t`` [s]: ``(dof,)`` each for a number, ``(N, dof)`` for N
        times."""
        single, ts = _times(t)
        q, v, a = self.core.evaluate_batch(ts)
        if single:
            return Motion(q[0], v[0], a[0])
        return Motion(q, v, a)

    def __repr__(self) -> str:
        return f"<RestToRest {self.law}, {self.dof} coordinates, {self.duration:g} s>"


def quintic(start: ArrayLike, end: ArrayLike, duration: float) -> RestToRest:
    """Quintic rest-to-rest motion (zero velocity and acceleration at both ends); positions
    [rad or m], duration [s]."""
    return RestToRest(start, end, duration, "quintic")


def minimum_energy_cubic(start: ArrayLike, end: ArrayLike, duration: float) -> RestToRest:
    """Minimum-energy cubic rest-to-rest motion ``s = 3 u^2 - 2 u^3`` (Arakelian, Le Baron &
    Mottu 2011, eq 13): least integral of squared acceleration between two rests; positions
    [rad or m], duration [s]."""
    return RestToRest(start, end, duration, "cubic")


class ConstantSpeed(_FromZero):
    """Steady motion at constant speed: ``q(t) = start + speed t``, ``qd = speed``, ``qdd = 0``
    for ``0 <= t <= duration`` (a crank turning at so many rpm). Outside ``[0, duration]`` it holds
    its first or last point at rest, as every trajectory here does.

    Args:
        start: initial positions [rad or m], one per coordinate.
        speed: speeds [rad/s or m/s], one per coordinate (a number: the same for every one).
        duration: motion time [s], > 0.
    """

    law = "constant_speed"

    def __init__(self, start: ArrayLike, speed: ArrayLike, duration: float):
        q0 = _vector("start", start).reshape(-1)
        w = _vector("speed", speed).reshape(-1)
        if w.size == 1 and q0.size > 1:
            w = np.full(q0.size, float(w[0]))
        if w.shape != q0.shape:
            raise ValueError(f"speed must have {q0.size} values (one per coordinate), got {w.size}")
        if isinstance(duration, bool) or not isinstance(duration, (int, float, np.integer, np.floating)) \
                or not np.isfinite(duration) or duration <= 0:
            raise ValueError(f"duration must be a finite number of seconds > 0, got {duration!r}")
        self.start, self.speed, self._duration = q0, w, float(duration)
        if not np.all(np.isfinite(q0 + w * self._duration)):
            raise ValueError("ConstantSpeed: start + speed * duration overflows")

    @classmethod
    def from_rpm(cls, start: ArrayLike, rpm: ArrayLike, *, duration: float | None = None,
                 revolutions: float | None = None) -> "ConstantSpeed":
        """From revolutions per minute, over ``duration`` [s] or ``revolutions`` turns of the
        fastest coordinate (exactly one of them)."""
        w = _vector("rpm", rpm) * (2.0 * np.pi / 60.0)
        if (duration is None) == (revolutions is None):
            raise ValueError("give duration or revolutions (exactly one)")
        if revolutions is None:
            assert duration is not None   # exactly one of them (checked above)
            return cls(start, w, float(duration))
        top = float(np.max(np.abs(w)))
        if top == 0.0 or not revolutions > 0:
            raise ValueError("revolutions needs a non-zero rpm and revolutions > 0")
        return cls(start, w, float(revolutions) * 2.0 * np.pi / top)

    @property
    def dof(self) -> int:
        """Number of coordinates."""
        return int(self.start.size)

    @property
    def duration(self) -> float:
        """Motion time [s]."""
        return self._duration

    @property
    def end(self) -> np.ndarray:
        """Positions at the end [rad or m]."""
        return self.start + self.speed * self._duration

    def evaluate(self, t: Times) -> Motion:
        """``(q, qd, qdd)`` at ``t`` [s]: ``(dof,)`` each for a number, ``(N, dof)`` for N times."""
        single, ts = _times(t)
        tc = np.clip(ts, 0.0, self._duration)[:, None]
        inside = ((ts >= 0.0) & (ts <= self._duration))[:, None]
        q = self.start + self.speed * tc
        qd = np.where(inside, self.speed, 0.0)
        qdd = np.zeros_like(q)
        return _finite_motion("ConstantSpeed", single, q, qd, qdd)

    def evaluate_batch(self, t: ArrayLike) -> Motion:
        """``(q, qd, qdd)`` (N, dof) at N times (the interface of the C++ trajectories)."""
        return self.evaluate(np.atleast_1d(np.asarray(t, float)))

    def __repr__(self) -> str:
        return f"<ConstantSpeed {self.dof} coordinates at {self.speed.tolist()} rad/s, {self.duration:g} s>"


class _OverTimes:
    """A motion defined over sample times ``self._t``: its duration and end."""

    _t: np.ndarray

    @property
    def duration(self) -> float:
        """``times[-1] - times[0]`` [s]."""
        return float(self._t[-1] - self._t[0])

    @property
    def end_time(self) -> float:
        """``times[-1]`` [s]: when the motion ends."""
        return float(self._t[-1])


class ViaPoints(_OverTimes):
    """Piecewise quintic through ``points`` at ``times``: continuous position, velocity and
    acceleration; at rest at the first and last point.

    Args:
        times: (K,) strictly increasing times [s], K >= 2; the motion starts at ``times[0]``.
        points: (K, dof) positions [rad or m].
        velocities: optional (K, dof) velocities at the points [rad/s or m/s]. By default the
            first and last are zero and an interior one is the mean of the slopes of its two
            segments, or zero where the motion turns back (the slopes differ in sign), so the path
            does not overshoot a via point.
        accelerations: optional (K, dof) accelerations at the points [rad/s^2 or m/s^2];
            default zero at every point.

    ``duration`` is ``times[-1] - times[0]`` and ``evaluate(t)`` takes absolute times.
    """

    def __init__(self, times: ArrayLike, points: ArrayLike, velocities: ArrayLike | None = None,
                 accelerations: ArrayLike | None = None):
        t, p = _samples(times, points, "points")
        h = np.diff(t)[:, None]
        if velocities is None:
            with np.errstate(all="ignore"):  # an overflow is reported below
                slope = np.diff(p, axis=0) / h
                v = np.zeros_like(p)
                inner = 0.5 * (slope[:-1] + slope[1:])
                v[1:-1] = np.where(slope[:-1] * slope[1:] > 0, inner, 0.0)
        else:
            v = _vector("velocities", velocities).reshape(p.shape)
        a = np.zeros_like(p) if accelerations is None else _vector("accelerations",
                                                                   accelerations).reshape(p.shape)
        # quintic coefficients per segment in u = (t - t_i) / h, x(u) = sum c_k u^k
        with np.errstate(all="ignore"):  # an overflow is reported below, not as a RuntimeWarning
            p0, p1, v0, v1, a0, a1 = p[:-1], p[1:], v[:-1] * h, v[1:] * h, a[:-1] * h**2, a[1:] * h**2
            c0, c1, c2 = p0, v0, 0.5 * a0
            d = p1 - p0 - v0 - 0.5 * a0
            # c3, c4, c5 from position, velocity and acceleration at u = 1
            A = np.array([[1.0, 1.0, 1.0], [3.0, 4.0, 5.0], [6.0, 12.0, 20.0]])
            rhs = np.stack([d, v1 - v0 - a0, a1 - a0], axis=-1)  # (K-1, dof, 3)
            c3, c4, c5 = np.moveaxis(rhs @ np.linalg.inv(A).T, -1, 0)
        if not all(np.all(np.isfinite(c)) for c in (c0, c1, c2, c3, c4, c5)):
            raise ValueError("ViaPoints: the points, velocities or accelerations overflow over the "
                             "given times (values too large or times too close)")
        self._t = t
        self._h = h[:, 0]
        self._c = np.stack([c0, c1, c2, c3, c4, c5], axis=0)  # (6, K-1, dof)
        self._points = p

    @property
    def dof(self) -> int:
        """Number of coordinates."""
        return int(self._points.shape[1])

    def evaluate(self, t: Times) -> Motion:
        """`Motion` ``(q, v, a)`` at absolute times ``t`` [s]; held at rest outside ``times``."""
        single, ts = _times(t)
        i = np.clip(np.searchsorted(self._t, ts, side="right") - 1, 0, len(self._h) - 1)
        h = self._h[i][:, None]
        with np.errstate(all="ignore"):  # an overflow is reported below, not as a RuntimeWarning
            u = np.clip((ts - self._t[i]) / self._h[i], 0.0, 1.0)[:, None]
            c = self._c[:, i, :]  # (6, N, dof)
            q = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))))
            v = (c[1] + u * (2 * c[2] + u * (3 * c[3] + u * (4 * c[4] + u * 5 * c[5])))) / h
            a = (2 * c[2] + u * (6 * c[3] + u * (12 * c[4] + u * 20 * c[5]))) / h**2
        outside = ((ts < self._t[0]) | (ts > self._t[-1]))[:, None]
        v = np.where(outside, 0.0, v)
        a = np.where(outside, 0.0, a)
        return _finite_motion("ViaPoints", single, q, v, a)


class Sampled(_OverTimes):
    """A user's sampled motion (measured or planned elsewhere), interpolated by a cubic spline
    (``scipy.interpolate.CubicSpline``) per coordinate: q(t) the spline, v and a its first
    and second derivatives.

    Args:
        times: (K,) strictly increasing sample times [s], K >= 2.
        positions: (K, dof) samples [rad or m].
        bc_type: the spline's end conditions (scipy's ``bc_type``): ``"clamped"`` (default: zero
            velocity at both ends, a motion between rests), ``"natural"`` (zero acceleration) or
            ``"not-a-knot"``.

    ``duration`` is ``times[-1] - times[0]``; ``evaluate(t)`` takes absolute times and holds the
    first or last sample at rest outside them.
    """

    def __init__(self, times: ArrayLike, positions: ArrayLike, bc_type: str = "clamped"):
        from scipy.interpolate import CubicSpline

        t, p = _samples(times, positions, "positions")
        self._t = t
        overflow = False
        with np.errstate(all="ignore"):  # an overflow is reported here, not as a RuntimeWarning
            try:
                self._spline = CubicSpline(t, p, axis=0, bc_type=bc_type)
            except ValueError as exc:  # scipy's own check of its slopes
                if "finite" not in str(exc):
                    raise
                overflow = True
        if overflow or not np.all(np.isfinite(self._spline.c)):
            raise ValueError("Sampled: the positions overflow over the given times (values too large "
                             "or times too close)")
        self._d1 = self._spline.derivative(1)
        self._d2 = self._spline.derivative(2)
        self._dof = p.shape[1]

    @property
    def dof(self) -> int:
        """Number of coordinates."""
        return int(self._dof)

    def evaluate(self, t: Times) -> Motion:
        """`Motion` ``(q, v, a)`` at absolute times ``t`` [s]; held at rest outside the
        samples."""
        single, ts = _times(t)
        tc = np.clip(ts, self._t[0], self._t[-1])
        outside = ((ts < self._t[0]) | (ts > self._t[-1]))[:, None]
        with np.errstate(all="ignore"):  # an overflow is reported below, not as a RuntimeWarning
            q = self._spline(tc)
            v = np.where(outside, 0.0, self._d1(tc))
            a = np.where(outside, 0.0, self._d2(tc))
        return _finite_motion("Sampled", single, q, v, a)


def as_trajectory(obj: object) -> Trajectory:
    """A `Trajectory` from a trajectory object or a C++ ``RestToRestTrajectory``."""
    if isinstance(obj, _core.RestToRestTrajectory):
        r = RestToRest.__new__(RestToRest)
        r.core = obj
        return r
    if not isinstance(obj, Trajectory):
        raise TypeError(f"trajectory must have dof, duration and evaluate(t) (see "
                        f"mechbal.trajectory), got {type(obj).__name__}")
    return obj



#: peak |velocity| and |acceleration| of the quintic rest-to-rest law, in units of
#: |end - start| / duration and |end - start| / duration^2
QUINTIC_PEAK_VELOCITY = 15.0 / 8.0
QUINTIC_PEAK_ACCELERATION = 10.0 / np.sqrt(3.0)


def _limit_list(x: np.ndarray) -> list[float | None]:
    return [float(v) if np.isfinite(v) else None for v in x]


def quintic_within_limits(mech: Any, start: ArrayLike, end: ArrayLike, duration: float, *,
                          samples: int = 101, max_doublings: int = 10) -> tuple[float, dict[str, Any]]:
    """``(duration, report)`` of a quintic rest-to-rest move of an open mechanism from ``start``
    to ``end`` that respects the joints' limits where the model has them (URDF <limit>):

    * positions: ``start`` and ``end`` are clipped into [lower, upper] (a quintic stays between
      them);
    * velocities: the duration is at least ``15/8 |end - start| / velocity_limit`` per joint;
    * efforts: the duration is doubled (at most ``max_doublings`` times) while the inverse-dynamics
      torque of some joint exceeds its effort limit at a sample where the static torque alone is
      within it (slower moves need less inertial torque; the static torque does not change).

    ``report`` (echoed in summary.json as ``default_motion``) holds the limits, the peaks reached,
    the duration, and ``respected`` (False when an effort limit is exceeded by the static torque
    alone, or after the doublings)."""
    lower = np.asarray(mech.model.lower_limits, float)
    upper = np.asarray(mech.model.upper_limits, float)
    vmax = np.asarray(mech.model.velocity_limits, float)
    emax = np.asarray(mech.model.effort_limits, float)
    q0 = np.clip(np.asarray(start, float), lower, upper)
    q1 = np.clip(np.asarray(end, float), lower, upper)
    step = np.abs(q1 - q0)
    need = np.where(np.isfinite(vmax) & (vmax > 0), QUINTIC_PEAK_VELOCITY * step / np.where(vmax > 0, vmax, 1.0), 0.0)
    T = max(float(duration), float(np.max(need, initial=0.0)))
    reason = "the requested duration" if T == float(duration) else "the velocity limits"
    respected = True
    tau = static = None
    for _ in range(max_doublings + 1):
        q, v, a = quintic(q0, q1, T).evaluate(np.linspace(0.0, T, samples))
        tau = np.atleast_2d(mech.inverse_dynamics(q, v, a))
        over = np.abs(tau) > emax
        if not np.any(over):
            break
        static = np.atleast_2d(mech.static_torque(q))
        if np.any(over & (np.abs(static) > emax)):   # the static torque alone exceeds it
            respected = False
            break
        T, reason = 2.0 * T, "the effort limits"
    else:
        respected = False
    q, v, a = quintic(q0, q1, T).evaluate(np.linspace(0.0, T, samples))
    tau = np.atleast_2d(mech.inverse_dynamics(q, v, a))
    report = {
        "law": "quintic", "duration": T, "duration_set_by": reason,
        "start": q0.tolist(), "end": q1.tolist(),
        "position_limits": [_limit_list(lower), _limit_list(upper)],
        "velocity_limit": _limit_list(vmax), "peak_velocity": np.max(np.abs(v), axis=0).tolist(),
        "effort_limit": _limit_list(emax), "peak_torque": np.max(np.abs(tau), axis=0).tolist(),
        "respected": bool(respected and np.all(np.abs(tau) <= emax * (1 + 1e-9))
                          and np.all(np.max(np.abs(v), axis=0) <= vmax * (1 + 1e-9))),
    }
    return T, report


#: largest default motion of one joint (`default_motion`): revolute [rad], prismatic [m]
DEFAULT_MAX_STEP = {_core.JointType.revolute: 0.5, _core.JointType.prismatic: 0.1}


def default_motion(mech: Any) -> tuple[np.ndarray, np.ndarray]:
    """(start, end) of the default motion of an open mechanism (``mechbal run robot.urdf``,
    `mechbal.Mechanism.to_toml`): every joint starts at 0 (clipped into its limits) and moves
    towards its upper limit by half the room left, at most 0.5 rad (revolute) or 0.1 m
    (prismatic); a joint with no room above moves towards its lower limit the same way; an
    unlimited (continuous) joint moves by 0.5 rad."""
    lower = np.asarray(mech.model.lower_limits, float)
    upper = np.asarray(mech.model.upper_limits, float)
    types = {j.name: j.type for j in mech.model.description.joints}
    step = np.array([DEFAULT_MAX_STEP[types[n]] for n in mech.joint_names])
    start = np.clip(np.zeros(mech.dof), lower, upper)
    room_up, room_down = upper - start, start - lower
    up = np.minimum(step, 0.5 * room_up)
    down = np.minimum(step, 0.5 * room_down)
    end = np.where(room_up >= room_down, start + up, start - down)
    return start, end
