"""The 2-DOF arm of Arakelian, Le Baron & Mottu 2011 ("Torque minimisation of the 2-DOF serial
manipulators based on minimum energy consideration and optimum mass redistribution",
Mechatronics 21:310-314, Fig. 1) on the general mechanism model.

Geometry (as ``mechbal/arm2dof.hpp``): the arm moves in the vertical x-z plane of the base frame
(z up, gravity (0, 0, -g)). Joint ``shoulder`` at A (the origin), joint ``elbow`` at B = (l1, 0, 0)
of the shoulder link's frame; both axes along -y, so that a positive angle lifts +x towards +z:
theta1 is link 1's angle from +x, theta2 link 2's angle relative to link 1 (the paper's
convention). Each link's frame has x along the link (A -> B for link 1).

Bodies (one per physical part, not lumped):

* ``link1`` on ``shoulder``: mass m1, centre of mass S1 at (l_S1, 0, 0), inertia I_S1 about S1
  (eq 16: I_A = I_S1 + m1 l_S1^2 about A);
* ``link2`` on ``elbow``: mass m2, S2 at (l_S2, 0, 0), inertia I_S2 about S2 (eqs 18-19);
* ``counterweight1`` on ``shoulder``: point mass m_CW1 on the extension of link 1 beyond A, at
  (-r_CW1, 0, 0) (eqs 23-31);
* ``counterweight2`` on ``elbow``: point mass m_CW2 beyond B, at (-r_CW2, 0, 0).

Link inertias are slender-rod tensors diag(0, I, I) about the centre of mass (link frame); the
planar motion about y only sees I. Frames: ``B`` (the elbow axis point on link 1).

The general model's inverse dynamics, mass matrix and gravity torque equal the corrected closed
form of eqs 14-31 (``mechbal.Arm2DofDynamics``, the fast path) to 1e-12 relative along the
paper's trajectories (tests/python/test_papers.py).
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from mechbal import _core
from mechbal.mechanism import Mechanism

__all__ = ["arm2dof_mechanism"]

_ARM_KEYS = ("m1", "m2", "l1", "l_s1", "l_s2", "i_s1", "i_s2", "g")
_CW_KEYS = ("m_cw1", "m_cw2", "r_cw1", "r_cw2")


def _values(source: Any, keys: tuple[str, ...], what: str, defaults: Mapping[str, float] = {}) -> dict:
    out = {}
    for k in keys:
        if isinstance(source, Mapping):
            value = source.get(k, defaults.get(k))
        else:
            value = getattr(source, k, defaults.get(k))
        if value is None:
            raise ValueError(f"{what}.{k}: is required")
        value = float(value)
        if not np.isfinite(value):
            raise ValueError(f"{what}.{k}: must be finite (got {value})")
        out[k] = value
    return out


def _point(x: float) -> np.ndarray:
    return np.array([x, 0.0, 0.0])


def arm2dof_mechanism(arm, counterweights=None, *, name: str = "arm2dof") -> Mechanism:
    """The arm of Fig. 1 as a :class:`mechbal.Mechanism` (module docstring for the frames).

    ``arm``: a ``mechbal.Arm2DofParameters`` or a mapping with its fields (the case file's
    ``[arm]`` table: m1, m2, l1, l_s1, l_s2, i_s1, i_s2, g; g defaults to 9.81).
    ``counterweights``: ``None`` for the bare arm (eqs 14-22), or a
    ``mechbal._core.Arm2DofCounterweights`` or a mapping with m_cw1, m_cw2, r_cw1, r_cw2 (eqs
    23-31; a radius is the signed distance beyond the joint, negative puts the mass on the link
    side). Counterweights are separate point-mass bodies of kind ``"counterweight"`` on their links.

    Raises ValueError naming the field on a missing or non-finite value; the model itself refuses
    negative masses or inertias.
    """
    a = _values(arm, _ARM_KEYS, "arm", {"g": 9.81})
    if a["l1"] <= 0.0:
        raise ValueError(f"arm.l1: must be > 0 (got {a['l1']})")
    elbow = np.eye(4)
    elbow[:3, 3] = _point(a["l1"])
    axis = np.array([0.0, -1.0, 0.0])  # a positive angle lifts +x towards +z
    joints = [_core.Joint("shoulder", _core.JointType.revolute, "base", np.eye(4), axis),
              _core.Joint("elbow", _core.JointType.revolute, "shoulder", elbow, axis)]
    rod = lambda inertia: np.diag([0.0, inertia, inertia])  # noqa: E731
    bodies = [_core.Body("link1", "shoulder", a["m1"], _point(a["l_s1"]), rod(a["i_s1"]), "link"),
              _core.Body("link2", "elbow", a["m2"], _point(a["l_s2"]), rod(a["i_s2"]), "link")]
    if counterweights is not None:
        c = _values(counterweights, _CW_KEYS, "counterweights")
        bodies += [_core.Body("counterweight1", "shoulder", c["m_cw1"], _point(-c["r_cw1"]),
                              np.zeros((3, 3)), "counterweight"),
                   _core.Body("counterweight2", "elbow", c["m_cw2"], _point(-c["r_cw2"]),
                              np.zeros((3, 3)), "counterweight")]
    frames = [_core.Frame("B", "shoulder", elbow)]
    return Mechanism.from_description(joints, bodies, frames, gravity=(0.0, 0.0, -a["g"]), name=name)
