"""The case layer: what a run is asked to do, from a case file or a URDF plus a design.

* `design.urdf_case` / `design.urdf_with_design`: a URDF and a ``--design`` file (its
  ``[trajectory]``, ``[control]`` and ``[balance]`` tables) as one complete case
  (`mechbal.Mechanism.to_toml` plus the design's tables), validated as a case file is, so that
  ``mechbal run``, ``mechbal verify`` and ``mechbal run --engine mujoco`` drive a URDF exactly as
  they drive a TOML case.
* `motion.task_end_pose`: the end pose of the operational-space mode's path (``[trajectory]
  law = "line"``: the task frame's pose at ``start`` moved by ``displacement`` and turned by
  ``rotation``; the rest-to-rest laws: its pose at ``end``).

Layer: the case, between the core and the methods (docs/architecture.md).
"""
from __future__ import annotations

from mechbal.case.design import DESIGN_TABLES, urdf_case, urdf_with_design
from mechbal.case.motion import task_end_pose

__all__ = ["DESIGN_TABLES", "urdf_case", "urdf_with_design", "task_end_pose"]
