"""``mechbal balance`` on an ``orthoglide`` case: the Orthoglide 5-axis (Martini et al. 2015) as
the runner builds it (`mechbal.papers.orthoglide.runner.Orthoglide`: the case's ``[mechanism]`` without its springs,
the ``[[springs]]`` anchors as named frames, the ``[roles]`` initial guess as assembly mode).
Without a ``[balance]`` table, ``--method springs`` sizes the ``[[springs]]`` slots (zero free
length; a ``rate`` given there stays fixed) exactly as the runner does
(`sizing`): static balance C^T (G + K) = 0 at the
sliders' positions (eq 1) of the ``[workspace]`` grid, loops closed to the runner's
``CLOSURE_TOLERANCE``; the rates are then eqs 18-19 (2.510052 / 11.130577 N/mm). The
trajectory is a rest-to-rest quintic move of the three actuated sliders from the positions of
the workspace cube's corner C - edge/2 (1, 1, 1) to those of the opposite corner C + edge/2
(1, 1, 1) in 2 s, 201 samples (the platform moves near the cube's diagonal). ``balanced.toml``
is the case itself (kind ``orthoglide``) with the sized rates as ``rate`` of its ``[[springs]]``
(``mechbal run`` puts them on the model as fixed rates); a design the kind cannot carry
(``--design`` springs that are not the case's ``[[springs]]`` with zero free length, one spring,
no pulley, their anchors) is written as a kind ``mechanism`` case instead (the mechanism with
its springs as ``[[mechanism.springs]]`` and the trajectory).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Any

import copy

import numpy as np

from mechbal.balance.run import BalanceCase, design_trajectory, register_case
from mechbal.papers import orthoglide as paper
from mechbal.papers.orthoglide import runner


def orthoglide_written_back(bc, result) -> dict | None:
    """The case itself with the sized rates as ``[[springs]]`` ``rate`` (the TOML data), or None
    when the sized springs are not the case's (module docstring)."""
    data = copy.deepcopy(bc.raw)
    data.pop("balance", None)
    by_name = {s["name"]: s for s in data.get("springs", [])}
    slots = {s.name: s for s in (bc.default_design or {}).get("springs", ([],))[0]}
    sized = [sp for sp in result.balanced.springs if sp.name not in set(bc.mechanism.spring_names)]
    if not sized or {sp.name for sp in sized} != set(by_name):
        return None
    for sp in sized:
        slot = slots.get(sp.name)
        if (slot is None or sp.free_length != 0.0 or sp.preload != 0.0 or sp.count != 1 or sp.pulley_ratio != 1.0
                or sp.link_a != slot.link_a or sp.link_b != slot.link_b
                or not np.allclose(sp.anchor_a, slot.anchor_a, rtol=0, atol=1e-15)
                or not np.allclose(sp.anchor_b, slot.anchor_b, rtol=0, atol=1e-15)):
            return None
        by_name[sp.name]["rate"] = float(sp.rate)
    return data


@register_case("orthoglide", written_back=orthoglide_written_back)
def orthoglide_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of an ``orthoglide`` case (module docstring)."""
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    o = runner.Orthoglide(cfg)
    mech = o.mech
    mech.name = f"{name} (without its springs)"
    ws = cfg.workspace
    grid = runner.workspace_grid(ws.center, ws.edge, ws.grid)
    slots, rho, options = o.sizing(grid)
    corners = np.asarray(ws.center, float) + np.outer([-1.0, 1.0], np.full(3, ws.edge / 2))
    ends = o.rho(corners)
    default = {"law": "quintic", "start": ends[0].tolist(), "end": ends[1].tolist(), "duration": 2.0,
               "samples": 201}
    t, motion, tt, guess = design_trajectory(mech, design_cfg, default, o.q_guess)
    t1 = paper.PAPER_TABLE1["theoretical"]
    notes = {
        "trajectory": ("rest-to-rest quintic of the actuated sliders (rho_x, rho_y, rho_z) between their positions "
                       "(eq 1) at the workspace cube's corners C - edge/2 (1, 1, 1) and C + edge/2 (1, 1, 1)"
                       if design_cfg is None or design_cfg.trajectory is None else "the --design file's [trajectory]"),
        "sizing_samples": (f"the runner's: the sliders' positions of the {ws.grid}^3 workspace grid (centre "
                           f"{list(ws.center)} m, edge {ws.edge} m), closure tolerance {runner.CLOSURE_TOLERANCE:g} m"
                           if table is None else "the [balance] table's"),
        "paper_spring_rates_N_per_mm": {"K_D": t1["K_D_N_per_mm"], "K_P": t1["K_P_N_per_mm"]},
        "roles": {"K_D": cfg.roles.distal_spring, "K_P": cfg.roles.proximal_spring},
    }
    return BalanceCase(name, title, mech, table, t, motion, tt, guess, raw, "orthoglide", [],
                       default_design={"springs": (slots, rho, options)}, notes=notes)
