"""``mechbal balance`` on a ``discs`` case (Coutinho & Hess Coelho: ``discs-3r``, ``discs-spatial``,
``scara``, ``five-bar``): the statically balanced arm of
`mechbal.papers.discs.disc_design_mechanism` without discs, its links' inertias as the case
gives them (``[inertia]``: the spatial arm's J_y2, J_y3 are then what the moment method's inertia
slots choose); ``five-bar``: the leg-wise statically balanced parallelogram 5R of
`mechbal.papers.discs.five_bar.five_bar_design_mechanism`. The trajectory is the case's
quintic; a ``--design FILE`` replaces the ``[balance]`` table (and its ``[trajectory]``).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Any

from mechbal.balance.run import BalanceCase, design_trajectory, register_case
from mechbal.papers import discs as dz
from mechbal.papers.discs import disc_design_mechanism
from mechbal.papers.discs.five_bar import five_bar_design_mechanism, five_bar_initial_guess
from mechbal.papers.discs import parameters_from_config


@register_case("discs")
def discs_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of a ``discs`` case (module docstring)."""
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    kind = cfg.case.mechanism
    p = parameters_from_config(kind, cfg)
    d = dict(dz.design(kind, p, True))
    tr = cfg.trajectory
    default = {"law": "quintic", "start": list(tr.start), "end": list(tr.end), "duration": tr.duration,
               "samples": tr.samples}
    if kind == "fivebar":
        mech = five_bar_design_mechanism(d, name=f"{name} (statically balanced)")
        start = (design_cfg.trajectory.start if design_cfg is not None and design_cfg.trajectory is not None
                 else tr.start)
        guess = five_bar_initial_guess(mech, d, start)
    else:
        d["discs"] = False
        for i in (1, 2, 3):   # the links' inertias as the case gives them (the method may choose some)
            for axis in "xyz":
                d[f"J{axis}{i}"] = p[f"J{axis}{i}"]
        mech = disc_design_mechanism(kind, d, name=f"{name} (statically balanced, no discs)")
        guess = None
    t, motion, tt, guess = design_trajectory(mech, design_cfg, default, guess)
    return BalanceCase(name, title, mech, table, t, motion, tt, guess, raw, "discs", [])
