"""The papers: one package each, holding everything that exists to reproduce that paper.

Each package ``mechbal.papers.<paper>`` holds the paper's mechanism as data on the general model
(builders of `mechbal.Mechanism`, TOML cases in its ``cases/`` folder), its closed forms (fast
paths and regression checks of the general algorithms and methods), its case runner
(``runner.py``) and its ``mechbal balance`` adapter (``balance.py``). General code finds a paper
only through `mechbal.registry`, never by import, so deleting a paper's folder deletes the
paper and nothing else (tests/python/test_layers.py checks it).

* `mechbal.papers.arm2dof`: Arakelian, Le Baron & Mottu 2011, the 2-DOF arm with
  counterweights, computed torque and the RMS-optimal counterweights.
* `mechbal.papers.discs`: Coutinho & Hess Coelho, the planar 3R, spatial 3R and SCARA with
  counter-rotating discs (gear couplings), and the parallelogram 5R
  (`mechbal.papers.discs.five_bar`).
* `mechbal.papers.paminsa`: PAMINSA (Briot & Arakelian 2009): pantograph legs, guides,
  columns, platform, counterweights, vertical counter-mass and the reactionless wrist.
* `mechbal.papers.rpsp`: Heydari & Enferadi, the 3(RPSP)-S robot: inverse kinematics
  (eqs 1-13) and counterweights (eqs 29-31).
* `mechbal.papers.orthoglide`: Martini et al. 2015, the Orthoglide's closed forms (eq 1,
  eqs 2-19) and its spring balancing.

A paper's closed-form classes (``PaminsaModel``, ``Arm2DofDynamics``, ``FiveBarDynamics``, ...)
are attributes of its package; ``mechbal.papers.<Name>`` finds them in whichever paper has them.
`shaking_wrench` (the shaking wrench of a set of bodies given their motion, batched) is
here for the runners that write the bodies of a closed-form motion (the discs' five-bar).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from typing import Any

from mechbal import _core

shaking_wrench = _core.shaking_wrench

__all__ = ["shaking_wrench"]


def __getattr__(name: str) -> Any:
    # a paper's public name (mechbal.papers.PaminsaModel): found in whichever paper package has it
    from mechbal.registry import papers

    for module in papers().values():
        if name in getattr(module, "__all__", ()):
            return getattr(module, name)
    raise AttributeError(f"module 'mechbal.papers' has no attribute {name!r}")
