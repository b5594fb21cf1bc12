"""Files that carry mechbal's results and models to other tools.

* `mechbal.export.bodies`: ``bodies_<variant>.npz`` (every body's motion and mechbal's
  shaking wrench, enough to recompute it) and the strict-JSON ``summary.json`` of every run;
  re-exported here (``from mechbal.export import write_bodies, write_summary, ...``).
* `mechbal.export.mjcf`: a MuJoCo model (MJCF) of any mechanism: tree, gears, loops,
  springs, every body with its own inertia (`mechbal.Mechanism.to_mjcf`).
* `mechbal.export.urdf`: URDF of a mechanism URDF can describe (a tree without springs),
  link names, frames and every body's inertia kept (`mechbal.Mechanism.to_urdf`).
* `mechbal.export.mujoco`: the exported model in MuJoCo (optional extra ``mechbal[mujoco]``):
  inverse dynamics and base reaction on mechbal's motion, forward simulation.

Layer: core (docs/architecture.md): files of the core's objects, below ``Mechanism.to_mjcf`` and
``simulate.closed_loop(engine="mujoco")``; nothing here imports a method or a paper.
"""
from __future__ import annotations

from mechbal.export.bodies import (  # noqa: F401  (the public names of the former module)
    BODY_FIELDS, _derivative, _jsonable, momenta_by_finite_differences, read_bodies,
    shaking_wrench_by_finite_differences, to_json, write_bodies, write_summary)
from mechbal.export.common import ExportError  # noqa: F401

__all__ = ["BODY_FIELDS", "write_bodies", "read_bodies", "momenta_by_finite_differences",
           "shaking_wrench_by_finite_differences", "to_json", "write_summary", "ExportError",
           "mjcf_text", "urdf_text"]


def mjcf_text(mech, name=None, **kw) -> str:
    """MJCF of ``mech`` (`mechbal.export.mjcf.mjcf_text`)."""
    from mechbal.export.mjcf import mjcf_text as f

    return f(mech, name, **kw)


def urdf_text(mech, name=None) -> str:
    """URDF of ``mech`` (`mechbal.export.urdf.urdf_text`)."""
    from mechbal.export.urdf import urdf_text as f

    return f(mech, name)
