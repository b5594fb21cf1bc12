"""The tests' independent reference for the shaking wrench of bodies whose motion a closed form
gives: a plain numpy sum over the bodies (Briot & Arakelian 2009, eqs 1-4), each inertia formed
in the base frame (I = R J R^T), with none of mechbal's C++ in it. The general model's
`Mechanism.shaking_wrench` and the papers' closed forms are compared against it; test_cli_export.py
checks it against finite differences of its own momenta."""
from __future__ import annotations

import numpy as np


def body_set_wrench(mass, inertia_body, com, com_velocity, com_acceleration, rotation, angular_velocity,
                    angular_acceleration) -> dict[str, np.ndarray]:
    """Momenta about O and their rates of B bodies over N instants: mass (B,), inertia_body
    (B,3,3) about each centre of mass in the body frame, com / com_velocity / com_acceleration /
    angular_velocity / angular_acceleration (N,B,3), rotation (N,B,3,3) body -> base. Returns
    (N,3) arrays ``linear_momentum`` (sum m v), ``angular_momentum`` (sum m c x v + I w),
    ``force`` (sum m a) and ``moment`` (sum m c x a + I alpha + w x I w)."""
    m, J = np.asarray(mass, float), np.asarray(inertia_body, float)
    c, v, a = (np.asarray(x, float) for x in (com, com_velocity, com_acceleration))
    R, w, al = (np.asarray(x, float) for x in (rotation, angular_velocity, angular_acceleration))
    I = R @ J[None] @ np.swapaxes(R, -1, -2)
    Iw = (I @ w[..., None])[..., 0]
    Ial = (I @ al[..., None])[..., 0]
    mb = m[None, :, None]
    return {"linear_momentum": (mb * v).sum(axis=1),
            "angular_momentum": (mb * np.cross(c, v) + Iw).sum(axis=1),
            "force": (mb * a).sum(axis=1),
            "moment": (mb * np.cross(c, a) + Ial + np.cross(w, Iw)).sum(axis=1)}
