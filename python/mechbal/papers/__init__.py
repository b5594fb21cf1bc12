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

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from mechbal import _core
from mechbal._deprecation import DeprecatedAttributes
from mechbal.mechanism import ShakingWrench

__all__ = ["shaking_wrench", "BodiesShakingWrench"]


@dataclass(frozen=True)
class BodiesShakingWrench(DeprecatedAttributes, ShakingWrench):
    """The `mechbal.ShakingWrench` of a set of bodies (`shaking_wrench`): ``shaking_force`` [N],
    ``shaking_moment`` about O [N m], ``linear_momentum`` [kg m/s], ``angular_momentum`` about O
    [kg m^2/s], each (N, 3), and ``status`` (N,). The dict of earlier releases (``["force"]``,
    ``["moment"]``, ``["status"]`` the OR of the instants' flags, ``["status_per_instant"]``)
    is read for one release with a DeprecationWarning."""

    _dict_keys: ClassVar[dict[str, str]] = {
        "force": "shaking_force", "moment": "shaking_moment", "linear_momentum": "linear_momentum",
        "angular_momentum": "angular_momentum", "status": "status",
        "status_per_instant": "status"}

    def _dict_value(self, key: str, attribute: str) -> Any:
        if key == "status":
            return int(np.bitwise_or.reduce(np.atleast_1d(self.status)))
        return getattr(self, attribute)


def shaking_wrench(mass: npt.ArrayLike, inertia_body: npt.ArrayLike, com: npt.ArrayLike,
                   com_velocity: npt.ArrayLike, com_acceleration: npt.ArrayLike,
                   rotation: npt.ArrayLike, angular_velocity: npt.ArrayLike,
                   angular_acceleration: npt.ArrayLike) -> BodiesShakingWrench:
    """Shaking force and moment about O of B bodies over N instants (Briot & Arakelian 2009,
    eqs 1-4) from their motion: ``mass`` (B,) [kg], ``inertia_body`` (B, 3, 3) [kg m^2] about
    each centre of mass in body axes, ``com`` [m], ``com_velocity`` [m/s], ``com_acceleration``
    [m/s^2] (N, B, 3), ``rotation`` (N, B, 3, 3) body to O, ``angular_velocity`` [rad/s] and
    ``angular_acceleration`` [rad/s^2] (N, B, 3) in O: a `BodiesShakingWrench` (N, 3) each."""
    r = _core.shaking_wrench(mass, inertia_body, com, com_velocity, com_acceleration, rotation,
                             angular_velocity, angular_acceleration)
    return BodiesShakingWrench(shaking_force=np.asarray(r["force"]),
                               shaking_moment=np.asarray(r["moment"]),
                               linear_momentum=np.asarray(r["linear_momentum"]),
                               angular_momentum=np.asarray(r["angular_momentum"]),
                               status=np.asarray(r["status_per_instant"]))


def __getattr__(name: str) -> Any:
    # a paper's public name (mechbal.papers.PaminsaModel): found in whichever paper package has it
    from mechbal.registry import papers

    for module in papers().values():
        if name in getattr(module, "__all__", ()):
            return getattr(module, name)
    raise AttributeError(f"module 'mechbal.papers' has no attribute {name!r}")
