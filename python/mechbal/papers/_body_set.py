"""The deprecated ``mechbal.shaking_wrench`` / ``mechbal.papers.shaking_wrench``: the shaking wrench
of a set of bodies given their motion, kept one release for the scripts that call it.

mechbal computes the shaking wrench of a mechanism on its model (`mechbal.Mechanism.shaking_wrench`,
the C++ ``algorithm/shaking_wrench``); the poses stored in a bodies file are checked by
`mechbal.export.shaking_wrench_by_finite_differences`. This numpy sum keeps the old function's
arguments, checks, statuses and result for one release, and warns.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from mechbal import _core

_DEPRECATION = ("mechbal.shaking_wrench (the shaking wrench of a set of bodies given their motion) is "
                "deprecated and will be removed in the next release: use Mechanism.shaking_wrench(q, v, a) "
                "(the general model) or, for the poses of a bodies file, "
                "mechbal.export.shaking_wrench_by_finite_differences")


def _real(value: Any, name: str) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype == object or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)
                                 or a.dtype == bool):
        raise TypeError(f"{name} must be an array of real numbers (int or float), got {a.dtype}")
    return a.astype(float)


def _shape(a: np.ndarray, name: str, shape: tuple[int, ...]) -> None:
    if a.ndim != len(shape) or any(s >= 0 and n != s for n, s in zip(a.shape, shape)):
        want = ", ".join("*" if s < 0 else str(s) for s in shape) + ("," if len(shape) == 1 else "")
        got = ", ".join(map(str, a.shape)) + ("," if a.ndim == 1 else "")
        raise ValueError(f"{name} must have shape ({want}), got ({got})")


def shaking_wrench(mass, inertia_body, com, com_velocity, com_acceleration, rotation, angular_velocity,
                   angular_acceleration) -> dict[str, Any]:
    """Deprecated: use `mechbal.Mechanism.shaking_wrench` (the general model) or
    `mechbal.export.shaking_wrench_by_finite_differences` (the poses of a bodies file).

    Shaking force and moment about O of B bodies over N instants (Briot & Arakelian 2009,
    eqs 1-4). mass (B,), inertia_body (B,3,3) about each centre of mass in the body frame; com,
    com_velocity, com_acceleration, angular_velocity, angular_acceleration (N,B,3) and rotation
    (N,B,3,3) body->base, all in the base frame. Returns a dict of (N,3) arrays: force (dP/dt),
    moment (dH_O/dt), linear_momentum, angular_momentum; status_per_instant (N,) and their OR,
    status. Instants with non-finite input (non_finite_input) or an overflowing wrench
    (out_of_range) give zeros."""
    warnings.warn(_DEPRECATION, DeprecationWarning, stacklevel=2)
    c = _real(com, "com")
    _shape(c, "com", (-1, -1, 3))
    N, B = c.shape[:2]
    m = _real(mass, "mass")
    _shape(m, "mass", (-1,))
    J = _real(inertia_body, "inertia_body")
    _shape(J, "inertia_body", (m.shape[0], 3, 3))
    for j in range(m.shape[0]):
        _core.validate_rigid_body(float(m[j]), J[j], f"bodies[{j}]")
    if m.shape[0] != B:
        raise ValueError(f"com has {B} bodies but mass has {m.shape[0]}")
    arrays = {"com": c}
    for name, value, shape in (("com_velocity", com_velocity, (N, B, 3)),
                               ("com_acceleration", com_acceleration, (N, B, 3)),
                               ("rotation", rotation, (N, B, 3, 3)),
                               ("angular_velocity", angular_velocity, (N, B, 3)),
                               ("angular_acceleration", angular_acceleration, (N, B, 3))):
        arrays[name] = _real(value, name)
        _shape(arrays[name], name, shape)
    v, a, R = arrays["com_velocity"], arrays["com_acceleration"], arrays["rotation"]
    w, al = arrays["angular_velocity"], arrays["angular_acceleration"]
    with np.errstate(all="ignore"):
        I = np.einsum("nbij,bjk,nblk->nbil", R, J, R)  # inertia in the base frame, R J R^T
        Iw = np.einsum("nbij,nbj->nbi", I, w)
        out = {"force": np.einsum("b,nbi->ni", m, a),
               "moment": (np.einsum("b,nbi->ni", m, np.cross(c, a)) + np.einsum("nbij,nbj->ni", I, al)
                          + np.cross(w, Iw).sum(axis=1)),
               "linear_momentum": np.einsum("b,nbi->ni", m, v),
               "angular_momentum": np.einsum("b,nbi->ni", m, np.cross(c, v)) + Iw.sum(axis=1)}
    finite_input = np.ones(N, bool)
    for x in arrays.values():
        finite_input &= np.isfinite(x.reshape(N, -1)).all(axis=1)
    finite_output = np.all([np.isfinite(x).all(axis=1) for x in out.values()], axis=0)
    status = np.where(~finite_input, int(_core.Status.non_finite_input),
                      np.where(~finite_output, int(_core.Status.out_of_range), int(_core.Status.ok))).astype(np.uint32)
    for x in out.values():
        x[status != 0] = 0.0
    result: dict[str, Any] = dict(out)
    result["status"] = _core.Status(int(np.bitwise_or.reduce(status, initial=0)))
    result["status_per_instant"] = status
    return result
