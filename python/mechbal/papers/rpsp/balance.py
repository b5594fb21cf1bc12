"""``mechbal balance`` on an ``rpsp`` case (Heydari & Enferadi): the 3(RPSP)-S robot with its
extra linkage and without the counterweight bodies of ``[balancing]``, driven by the platform's
spherical joint (the loop solve is then its inverse kinematics); the default design variables
(without a ``[balance]`` table) are those bodies as fixed-position slots (their centres of mass:
only the masses are unknown); the trajectory is the paper's platform motion of ``[motion]`` over
``duration``. ``balanced.toml`` is the case itself with the sized masses (``mechbal run`` runs it).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from mechbal.balance.run import BalanceCase, register_case
from mechbal.errors import ConfigError
from mechbal.mechanism import Mechanism
from mechbal.papers.rpsp import runner


@register_case("rpsp")
def rpsp_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of an ``rpsp`` case (module docstring)."""
    if design_cfg is not None and design_cfg.trajectory is not None:
        raise ConfigError("trajectory", "the rpsp case moves its platform by the paper's law ([motion]); "
                                        "a --design file gives only [balance]", has_value=False)
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    mo, bal = cfg.motion, cfg.balancing
    names = [n for key in ("m_P", "m_N", "m_F", "platform") for n in getattr(bal, key)]
    full = Mechanism.from_spec(runner.driven_by_platform(cfg.spec, mo.platform), name=name)
    slots, bare = runner.counterweight_slots(full, cfg.spec, names)
    bare.name = f"{name} (without its counterweights)"
    if len(mo.initial_guess) != len(cfg.spec.independent_joints):
        raise ConfigError("motion.initial_guess", "must have one value per joint coordinate", list(mo.initial_guess))
    by_name = dict(zip(cfg.spec.independent_joints, mo.initial_guess))
    guess = np.array([by_name[n] for n in bare.joint_names], float)
    t = np.linspace(0.0, mo.duration, mo.samples)
    phi, dphi, ddphi = runner.platform_motion(mo, t)
    order = {f"{mo.platform}_z": 0, f"{mo.platform}_y": 1, f"{mo.platform}_x": 2}
    cols = [order[n] for n in bare.actuated_names]
    motion = (phi[:, cols], dphi[:, cols], ddphi[:, cols])
    # the sample box of static / force: the range the motion sweeps
    tt = {"law": "paper: phi_x = A sin(2 pi t / T), phi_y = 0, phi_z = B sin(f pi t / T)",
          "start": motion[0].min(axis=0).tolist(), "end": motion[0].max(axis=0).tolist(),
          "duration": mo.duration, "samples": mo.samples, "initial_guess": guess.tolist()}
    return BalanceCase(name, title, bare, table, t, motion, tt, guess, raw, "rpsp", slots)
