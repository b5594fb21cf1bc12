"""``mechbal balance`` on the ``arm2dof`` case (Arakelian, Le Baron & Mottu 2011): its arm as a
mechanism with links ``shoulder`` and ``elbow``, x along each link; the counterweights of
``[counterweights]`` on the link extensions unless ``[balance]`` gives others; the minimum-energy
cubic law of its ``[trajectory]``.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from mechbal.balance.result import CounterweightSlot
from mechbal.balance.run import BalanceCase, _trajectory_motion, register_case
from mechbal.papers.arm2dof import arm2dof_mechanism


@register_case("arm2dof")
def arm2dof_case(cfg, raw, table, design_cfg) -> BalanceCase:
    """The BalanceCase of the ``arm2dof`` case (module docstring)."""
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    mech = arm2dof_mechanism(cfg.arm.model_dump(), name=name)
    cw = cfg.counterweights
    slots = [CounterweightSlot("counterweight1", "shoulder", cw.m_cw1, cw.m_cw1, direction=(-1.0, 0.0, 0.0)),
             CounterweightSlot("counterweight2", "elbow", cw.m_cw2, cw.m_cw2, direction=(-1.0, 0.0, 0.0))]
    tr = cfg.trajectory
    t, motion, tt = _trajectory_motion(mech, {"start": tr.start, "end": tr.end, "duration": tr.duration,
                                              "samples": tr.samples}, law="cubic")
    return BalanceCase(name, title, mech, table, t, motion, tt, None, raw, "arm2dof", slots)
