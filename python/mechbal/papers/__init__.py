"""The papers: one package each, holding everything that exists to reproduce that paper.

Each package ``mechbal.papers.<paper>`` holds the paper's mechanism as data on the general model
(builders of `mechbal.Mechanism`, TOML cases in its ``cases/`` folder), its closed forms (fast
paths and regression checks of the general algorithms and methods), its case runner
(``runner.py``) and its ``mechbal balance`` adapter (``balance.py``). General code finds a paper
only through `mechbal.registry`, never by import: this package finds its papers in its own
folder (`discover`, `submodules`) and the root package registers it with the registry, so
deleting a paper's folder deletes the paper and nothing else (tests/python/test_layers.py checks
it).

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
`shaking_wrench` (the shaking wrench of a set of bodies given their motion) is deprecated and
warns: the shaking wrench is `mechbal.Mechanism.shaking_wrench` on the general model, and the
poses of a bodies file are checked by `mechbal.export.shaking_wrench_by_finite_differences`.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import importlib
import importlib.util
from pathlib import Path
from types import ModuleType
from typing import Any

from mechbal.papers._body_set import shaking_wrench  # deprecated, one release

__all__ = ["shaking_wrench", "discover", "submodules"]

_HERE = Path(__file__).resolve().parent


def _names() -> list[str]:
    return sorted(p.name for p in _HERE.iterdir()
                  if p.is_dir() and not p.name.startswith(("_", ".")) and (p / "__init__.py").is_file())


def discover() -> dict[str, ModuleType]:
    """Every paper package of this folder, imported (importing one registers its case kinds):
    ``{name: module}``."""
    return {name: importlib.import_module(f"{__name__}.{name}") for name in _names()}


def submodules(submodule: str) -> list[ModuleType]:
    """The module ``submodule`` (``runner``, ``balance``) of every paper that has one, imported."""
    out = []
    for name in _names():
        full = f"{__name__}.{name}.{submodule}"
        if importlib.util.find_spec(full) is not None:
            out.append(importlib.import_module(full))
    return out


def __getattr__(name: str) -> Any:
    # a paper's public name (mechbal.papers.PaminsaModel): found in whichever paper package has it
    from mechbal.registry import papers

    for module in papers().values():
        if name in getattr(module, "__all__", ()):
            return getattr(module, name)
    raise AttributeError(f"module 'mechbal.papers' has no attribute {name!r}")
