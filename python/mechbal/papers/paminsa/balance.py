"""``mechbal balance`` on a ``paminsa`` case (Briot & Arakelian 2009): the mechanism of
`mechbal.papers.paminsa.paminsa_mechanism` built from the case's ``[geometry]``, ``[masses]``,
``[inertias]``, unbalanced and without the zero-mass placeholder counterweights (so the ``[balance]``
slots may carry the paper's names ``leg1.CP1_atA`` ...); the trajectory rest-to-rest in the actuated
joints between the actuator positions of the case's start and end platform positions, wrist still
at its initial angles (as ``paminsa-linkage.toml``), 501 samples, the closed form's assembly as
initial guess. A ``--design FILE`` replaces the ``[balance]`` table (and its ``[trajectory]``, in
actuated joints, the case's trajectory).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from mechbal.balance.run import BalanceCase, design_trajectory, register_case
from mechbal.papers.paminsa import paminsa_actuated_motion, paminsa_initial_guess, paminsa_mechanism
from mechbal.papers.paminsa import parameters_from_config


@register_case("paminsa")
def paminsa_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of a ``paminsa`` case (module docstring)."""
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    params = parameters_from_config(cfg)
    full = paminsa_mechanism(params, False, name=f"{name} (unbalanced)")
    # the case file has no counterweights: drop their zero-mass placeholders, keep everything else
    keep = [b for b in full.bodies if not (b.kind == "counterweight" and b.mass == 0.0)]
    mech = full.with_bodies(keep, replace=True)
    tr = cfg.trajectory
    wrist = np.asarray(cfg.wrist.initial_angles, float)
    ends = np.array([tr.start, tr.end], float)
    qa, _, _ = paminsa_actuated_motion(mech, params, ends, np.zeros((2, 3)), np.zeros((2, 3)), np.tile(wrist, (2, 1)))
    guess = paminsa_initial_guess(mech, params, ends[0], wrist)
    default = {"law": tr.law, "start": qa[0].tolist(), "end": qa[1].tolist(), "duration": tr.duration,
               "samples": 501}
    t, motion, tt, guess = design_trajectory(mech, design_cfg, default, guess)
    return BalanceCase(name, title, mech, table, t, motion, tt, guess, raw, "paminsa", [])
