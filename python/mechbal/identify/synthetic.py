"""Synthetic logs: what a robot with a known model would record, for checking an identification.

`simulate_log` plays a motion (an `Excitation` or arrays t, q, v, a) on a mechanism, computes
the joint efforts by inverse dynamics plus friction, and adds Gaussian measurement noise to q, v
and tau. The identification never sees the model, only the log.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from mechbal.identify.excite import Excitation
from mechbal.identify.fitting import Friction
from mechbal.identify.logs import Log
from mechbal.mechanism import Mechanism

__all__ = ["simulate_log"]


def simulate_log(mechanism: Mechanism, motion: Excitation | tuple, *, rate_hz: float = 1000.0,
                 friction: Mapping[str, Friction] | None = None, noise_q: float = 0.0,
                 noise_v: float = 0.0, noise_tau: float = 0.0, seed: int = 0, with_v: bool = True,
                 source: str = "synthetic") -> Log:
    """A `Log` of ``motion`` on ``mechanism`` (module docstring): ``motion`` an `Excitation`
    (sampled at ``rate_hz`` over one period) or a tuple (t, q, v, a); ``friction``: per joint
    name; noise: standard deviations [rad, rad/s, N m] (m, m/s, N for prismatic joints)."""
    if isinstance(motion, Excitation):
        t, q, v, a = motion.sample(rate_hz)
    else:
        t, q, v, a = (np.asarray(x, float) for x in motion)
    tau = np.asarray(mechanism.inverse_dynamics(q, v, a), float)
    if friction:
        for j, name in enumerate(mechanism.joint_names):
            f = friction.get(name)
            if f is not None:
                tau[:, j] += f.viscous * v[:, j] + f.coulomb * np.sign(v[:, j]) + f.offset
    rng = np.random.default_rng(seed)
    return Log(t=t, q=q + noise_q * rng.normal(size=q.shape),
               v=(v + noise_v * rng.normal(size=v.shape)) if with_v else None,
               tau=tau + noise_tau * rng.normal(size=tau.shape), joint_names=tuple(mechanism.joint_names),
               source=source)
