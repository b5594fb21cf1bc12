"""Comparison helpers shared by the tests that check mechbal against Pinocchio."""
from __future__ import annotations

import numpy as np

from mechbal import _core


def _rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    if a.size == 0 and b.size == 0:
        return 0.0
    return np.abs(a - b).max() / max(1.0, np.abs(b).max())


def _base_fixed_mass_moment(mech, q):
    """m c of the bodies that cannot move: on the base or on links welded to it by fixed joints
    (Pinocchio leaves them out of its centre of mass)."""
    motion = mech.body_motion(q)
    parents = mech.model.link_parents
    types = {j.name: j.type for j in mech.model.description.joints}
    names = mech.link_names

    def welded(link):
        while link != 0:
            if types[names[link]] != _core.JointType.fixed:
                return False
            link = parents[link]
        return True

    out = np.zeros(3)
    for b, body in enumerate(mech.bodies):
        if welded(mech.model.body_links[b]):
            out += body.mass * motion.com[b]
    return out
