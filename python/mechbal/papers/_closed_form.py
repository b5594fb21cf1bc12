"""What the papers' closed-form dynamics classes share (``Arm2DofDynamics``, ``FiveBarDynamics``):
one sample or N samples in, the array of `mechbal.Mechanism` out (a `mechbal.BatchArray` with
its per-instant ``status`` for N samples, a ValueError on a rejected single sample), and the
dict keys of earlier releases read for one release with a DeprecationWarning
(mechbal/_deprecation.py).

Layer: papers (docs/architecture.md): shared by the paper packages, which import nothing of each
other.
"""
from __future__ import annotations

import warnings
from typing import Any, Callable

import numpy as np
import numpy.typing as npt

from mechbal.mechanism import BatchArray

FloatArray = npt.NDArray[np.float64]
StatusArray = npt.NDArray[np.uint32]


def status_or(status: npt.ArrayLike) -> int:
    """The OR of every instant's status (the scalar ``"status"`` of the dicts of earlier releases)."""
    return int(np.bitwise_or.reduce(np.atleast_1d(np.asarray(status, dtype=np.uint32))))


class LegacyKeysBatch(BatchArray):
    """A batch result that also answers the dict keys of earlier releases for one release, with a
    DeprecationWarning: ``[_key]`` (``"tau"``, ``"qdd"``: the array itself), ``["status"]`` (the
    OR of the statuses) and ``["status_per_instant"]`` (``.status``)."""

    _key: str = ""

    def __getitem__(self, key: Any) -> Any:
        if isinstance(key, str):
            if key == self._key:
                warnings.warn(f"result[{key!r}] is deprecated: the result is the array itself "
                              "(its per-instant status in .status)", DeprecationWarning, stacklevel=2)
                return np.asarray(self)
            if key == "status":
                warnings.warn("result['status'] is deprecated: use result.status (per instant)",
                              DeprecationWarning, stacklevel=2)
                return status_or(self.status)
            if key == "status_per_instant":
                warnings.warn("result['status_per_instant'] is deprecated: use result.status",
                              DeprecationWarning, stacklevel=2)
                return np.atleast_1d(self.status)
            raise KeyError(key)
        return super().__getitem__(key)


class TorqueBatch(LegacyKeysBatch):
    """Joint torques (N, dof) [N m or N] with ``status`` (N,); ``["tau"]`` reads the array."""

    _key = "tau"


class AccelerationBatch(LegacyKeysBatch):
    """Joint accelerations (N, dof) with ``status`` (N,); ``["qdd"]`` reads the array."""

    _key = "qdd"


#: what a rejected single sample lacks (the message's end)
FINITE_SAMPLE = "the arguments must be finite and give finite results"


def single_status(where: str, status: int, requirement: str = FINITE_SAMPLE) -> None:
    """ValueError when a single sample was rejected (its status is not 0)."""
    if status != 0:
        raise ValueError(f"{where}: input rejected (status {int(status)}); {requirement}")


def closed_form_batch(where: str, call: Callable[..., Any], cls: type[LegacyKeysBatch], out_key: str,
                      requirement: str = FINITE_SAMPLE, **arrays: npt.ArrayLike) -> FloatArray:
    """``call`` (a binding over (N, dof) arrays that returns a dict with ``out_key`` and the
    statuses; it checks the shapes) at one sample (the first array 1-D) or N samples: the (dof,)
    result (ValueError when rejected) or an (N, dof) ``cls`` with the per-instant ``status``."""
    single = np.ndim(next(iter(arrays.values()))) == 1
    batch = [np.atleast_2d(np.asarray(x, dtype=float)) for x in arrays.values()]
    r = call(*batch)
    values = np.asarray(r[out_key])
    status = np.asarray(r["status_per_instant"] if "status_per_instant" in r else r["status"])
    status = np.broadcast_to(status, values.shape[:1]).astype(np.uint32)
    if single:
        single_status(where, int(status[0]), requirement)
        return values[0]
    return cls(values, status)
