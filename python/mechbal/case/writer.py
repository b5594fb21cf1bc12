"""The files of a case's run: `write_variant` (``bodies_<variant>.npz`` of a motion, with the
shaking wrench of its stored poses) and `drawing` (what a picture of the mechanism needs beside
the bodies). The case file itself is written by `mechbal.export.toml` (`toml_text`,
`mechanism_table`: core, `mechbal.Mechanism.to_toml` uses it).

Layer: the case (docs/architecture.md)."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mechbal.errors import ConfigError
from mechbal.export import write_bodies

if TYPE_CHECKING:
    from mechbal.mechanism import Mechanism


def drawing(mech: Mechanism, motion) -> dict:
    """What a picture of the mechanism needs beside the bodies (`mechbal.animation`): every
    link frame's origin and parent, and every named frame's origin with its link."""
    links = list(mech.link_names)
    by_name = {f.name: f.link for f in mech.model.description.frames}
    frame_link = [links.index(by_name[n]) if by_name.get(n) in links else -1 for n in mech.frame_names]
    return dict(link_position=motion.link_position, link_parent=np.array(mech.model.link_parents, int),
                frame_position=motion.frame_placement[..., :3, 3], frame_link=np.array(frame_link, int))


def write_variant(mech: Mechanism, out: Path, variant: str, t, q, v, a):
    """bodies_<variant>.npz of the motion (q, v, a) (every coordinate) with the wrench of those
    poses; returns (F, M)."""
    sw = mech.shaking_wrench(q, v, a)
    motion = mech.body_motion(q, v, a)
    if np.any(sw.status != 0) or np.any(motion.status != 0):
        raise ConfigError("trajectory", f"the {variant} motion has non-finite results",
                          has_value=False)
    bodies = mech.bodies
    write_bodies(out / f"bodies_{variant}.npz", t=t, names=mech.body_names,
                 mass=np.array([b.mass for b in bodies], float),
                 inertia_body=np.array([b.inertia for b in bodies], float).reshape(-1, 3, 3),
                 com=motion.com, rotation=motion.rotation, shaking_force=sw.shaking_force,
                 shaking_moment=sw.shaking_moment, q=q, qd=v, qdd=a, **drawing(mech, motion))
    return sw.shaking_force, sw.shaking_moment
