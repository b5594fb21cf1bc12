"""The case layer: what a run is asked to do, from a case file or a URDF plus a design.

* `load_case`: the one reader of a case (a built-in case's name, a TOML case file, a URDF file)
  into one `LoadedCase`: its tables as read, the file, the validated case (`load`).
* `design.urdf_case` / `design.urdf_with_design`: a URDF and a ``--design`` file (its
  ``[trajectory]``, ``[control]`` and ``[balance]`` tables) as one complete case
  (`mechbal.Mechanism.to_toml` plus the design's tables), validated as a case file is, so that
  ``mechbal run``, ``mechbal verify`` and ``mechbal run --engine mujoco`` drive a URDF exactly as
  they drive a TOML case.
* `motion`: the mechanism's motion along the case's ``[trajectory]`` (`mechanism_motion`, the
  assembly at its start `start_assembly`, `motion_summary`) and the operational-space mode's path
  (`task_end_pose`: ``[trajectory] law = "line"``, the task frame's pose at ``start`` moved by
  ``displacement`` and turned by ``rotation``, the rest-to-rest laws its pose at ``end``;
  `frame_path`).
* `control_plan`: a reactionless ``[control]``'s commanded motion, checked before anything runs
  (`held_trajectory`, `check_task_space`, `feasibility_of`, `check_feasibility`).
* `writer`: the bodies files of a run's motions (`write_variant`, `drawing`).

Layer: the case, between the core and the methods (docs/architecture.md).
"""
from __future__ import annotations

from mechbal.case.load import LoadedCase, load_case
from mechbal.case.design import DESIGN_TABLES, urdf_case, urdf_with_design
from mechbal.case.motion import frame_path, mechanism_motion, motion_summary, start_assembly, task_end_pose
from mechbal.case.control_plan import check_feasibility, check_task_space, feasibility_of, held_trajectory
from mechbal.case.writer import drawing, write_variant

__all__ = ["LoadedCase", "load_case", "DESIGN_TABLES", "urdf_case", "urdf_with_design", "task_end_pose",
           "frame_path", "mechanism_motion", "motion_summary", "start_assembly", "check_feasibility",
           "check_task_space", "feasibility_of", "held_trajectory", "drawing", "write_variant"]
