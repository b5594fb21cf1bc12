"""The five-bar's closed form from Python with typed results: `FiveBarDynamics` (the C++
``mechbal::FiveBarDynamics``, the coupling-matrix method over a fixed 4x4 A°; Coutinho & Hess
Coelho, docs/discs_derivation.md section 5), its `FiveBarTerms` (M', v', g') and `FiveBarMotion`
(every joint's and the end effector's motion). The geometry is `mechbal.papers.discs.five_bar`'s.
The dict keys of the binding's results (earlier releases) still read for one release, with a
DeprecationWarning.

Layer: papers (docs/architecture.md). Imports nothing of its own paper package (the package
imports it).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, ClassVar

import numpy as np
import numpy.typing as npt

from mechbal import _core
from mechbal._deprecation import DeprecatedAttributes, renamed_kwargs
from mechbal.papers._closed_form import (FloatArray, StatusArray, TorqueBatch, closed_form_batch,
                                         single_status, status_or)

__all__ = ["FiveBarDynamics", "FiveBarTerms", "FiveBarMotion"]


class _StatusKeys(DeprecatedAttributes):
    """The statuses of the dicts of earlier releases: ``["status"]`` (the OR of every instant's
    flags), ``["status_per_instant"]`` and ``["ok"]`` (per instant)."""

    status: StatusArray

    def _dict_value(self, key: str, attribute: str) -> Any:
        if key == "status":
            return status_or(self.status)
        if key in ("status_per_instant", "ok"):
            return np.atleast_1d(getattr(self, attribute))
        return getattr(self, attribute)

    @property
    def ok(self) -> npt.NDArray[np.bool_]:
        """Boolean mask of the instants whose status is 0 (ok), as `mechbal.BatchArray.ok`."""
        return np.asarray(self.status == 0)


@dataclass(frozen=True)
class FiveBarTerms(_StatusKeys):
    """The five-bar's equation of motion in its actuated coordinates (theta1, theta2),
    ``tau = M'(q) a + v'(q, v) + g'(q)`` (Coutinho & Hess Coelho, coupling-matrix method;
    docs/discs_derivation.md section 5): ``mass_matrix`` M' (N, 2, 2) [kg m^2],
    ``coriolis_torque`` v' and ``gravity_torque`` g' (N, 2) [N m], the
    ``reciprocal_condition`` of the passive Jacobian A° (N,) and ``status`` (N,) per instant
    (a singular or unassembled pose: zeros and `mechbal.Status.singular`). One sample
    ((2,) q and v) gives (2, 2), (2,), (2,) and 0-d arrays.

    The dict of earlier releases is read for one release with a DeprecationWarning:
    ``result["mass"]``, ``["velocity"]``, ``["gravity"]``, ``["reciprocal_condition"]``,
    ``["ok"]``, ``["status_per_instant"]`` and ``["status"]`` (the OR of every instant's flags)."""

    mass_matrix: FloatArray
    coriolis_torque: FloatArray
    gravity_torque: FloatArray
    reciprocal_condition: FloatArray
    status: StatusArray

    _dict_keys: ClassVar[dict[str, str]] = {
        "mass": "mass_matrix", "velocity": "coriolis_torque", "gravity": "gravity_torque",
        "reciprocal_condition": "reciprocal_condition", "ok": "ok", "status": "status",
        "status_per_instant": "status"}


@dataclass(frozen=True)
class FiveBarMotion(_StatusKeys):
    """The five-bar's full motion from its actuated motion: ``q``, ``v``, ``a`` (N, 4) of every
    joint in the order (theta1, theta12, theta2, theta22) [rad, rad/s, rad/s^2], the end effector's
    ``end_effector`` (y, z) position [m], ``end_effector_velocity`` [m/s] and
    ``end_effector_acceleration`` [m/s^2] (N, 2), and ``status`` (N,) per instant (a failed
    instant: zeros and its flag). One sample gives (4,), (2,) and 0-d arrays.

    The dict of earlier releases is read for one release with a DeprecationWarning:
    ``result["angles"]``, ``["rates"]``, ``["accelerations"]``, ``["end_effector"]``,
    ``["end_effector_velocity"]``, ``["end_effector_acceleration"]``, ``["status_per_instant"]``
    and ``["status"]`` (the OR of every instant's flags)."""

    q: FloatArray
    v: FloatArray
    a: FloatArray
    end_effector: FloatArray
    end_effector_velocity: FloatArray
    end_effector_acceleration: FloatArray
    status: StatusArray

    _dict_keys: ClassVar[dict[str, str]] = {
        "angles": "q", "rates": "v", "accelerations": "a", "end_effector": "end_effector",
        "end_effector_velocity": "end_effector_velocity",
        "end_effector_acceleration": "end_effector_acceleration", "status": "status",
        "status_per_instant": "status"}


#: what a rejected single sample of the five-bar lacks
_FIVE_BAR_SAMPLE = ("q, v, a must be finite and the pose assembled away from a singularity of A° "
                    "(Status.singular)")


def _per_instant(where: str, call: Callable[..., Any], keys: tuple[str, ...],
                 **arrays: npt.ArrayLike) -> list[Any]:
    """``call`` at one sample (1-D arrays: each result without its first axis, ValueError when
    rejected) or N samples: the results of ``keys`` and the per-instant status, last."""
    single = np.ndim(next(iter(arrays.values()))) == 1
    r = call(*(np.atleast_2d(np.asarray(x, dtype=float)) for x in arrays.values()))
    status = np.asarray(r["status_per_instant"], dtype=np.uint32)
    values = [np.asarray(r[k]) for k in keys] + [status]
    if single:
        single_status(where, int(status[0]), _FIVE_BAR_SAMPLE)
        return [x[0, ...] for x in values]
    return values


class FiveBarDynamics(_core.FiveBarDynamics):
    """The planar 5R five-bar by the coupling-matrix method, evaluated per tick in C++ (a fixed
    4x4 A°; Coutinho & Hess Coelho, docs/discs_derivation.md section 5): the fast path of the
    general model (`five_bar_design_mechanism`) and a dynamics back end of
    `mechbal.control.ComputedTorque`.

    Args:
        parameters: ``FiveBarParameters`` (lengths, masses, centres of mass, inertias about x).
        singular_tolerance: reciprocal condition of A° below which a pose is singular (1e-6).

    Each method takes one sample ((2,) arrays: a result without the batch axis, ValueError on a
    rejected or singular sample) or N samples ((N, 2) arrays: every result with a per-instant
    ``status``), as `mechbal.Mechanism` does.
    """

    @renamed_kwargs(qd="v", qdd="a")
    def inverse_dynamics(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
                         a: npt.ArrayLike) -> FloatArray:
        """Actuated joint torques tau = M' a + v' + g' [N m], (2,) or (N, 2) (a
        `mechbal.BatchArray` with ``status``; a failed instant holds zeros). ``result["tau"]``,
        ``["status"]`` and ``["status_per_instant"]`` (the dict of earlier releases) still work for
        one release, with a DeprecationWarning."""
        return closed_form_batch("FiveBarDynamics.inverse_dynamics", super().inverse_dynamics,
                                 TorqueBatch, "tau", _FIVE_BAR_SAMPLE, q=q, v=v, a=a)

    @renamed_kwargs(qd="v")
    def evaluate(self, q: npt.ArrayLike, v: npt.ArrayLike) -> FiveBarTerms:  # type: ignore[override]
        """M'(q), v'(q, v), g'(q) at one sample or N samples: `FiveBarTerms`."""
        return FiveBarTerms(*_per_instant(
            "FiveBarDynamics.evaluate", super().evaluate,
            ("mass", "velocity", "gravity", "reciprocal_condition"), q=q, v=v))

    @renamed_kwargs(qd="v", qdd="a")
    def motion(self, q: npt.ArrayLike, v: npt.ArrayLike,  # type: ignore[override]
               a: npt.ArrayLike) -> FiveBarMotion:
        """Every joint's and the end effector's motion at one sample or N samples:
        `FiveBarMotion`."""
        return FiveBarMotion(*_per_instant(
            "FiveBarDynamics.motion", super().motion,
            ("angles", "rates", "accelerations", "end_effector", "end_effector_velocity",
             "end_effector_acceleration"), q=q, v=v, a=a))
