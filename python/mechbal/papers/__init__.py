"""The papers' mechanisms as data on the general model (:class:`mechbal.Mechanism`).

Each module builds, from the parameters a case runner reads, the mechanism the paper describes:
joints with their parents and placements, every link's bodies (links, counterweights, discs) and
gear couplings for geared discs. The papers' closed forms (``Arm2DofDynamics``,
``DiscArmDynamics``) stay as fast paths and are tested against these general models
(tests/python/test_papers.py).

* :mod:`mechbal.papers.arm2dof`: Arakelian, Le Baron & Mottu 2011, the 2-DOF arm with
  counterweights.
* :mod:`mechbal.papers.discs`: Coutinho & Hess Coelho, the planar 3R, spatial 3R and SCARA with
  counter-rotating discs (gear couplings).
* :mod:`mechbal.papers.rpsp`: Heydari & Enferadi, the 3(RPSP)-S robot: the closed-form inverse
  kinematics (eqs 1-13) and sizing (eqs 29-31) that check the ``rpsp`` case's general model.
"""
from mechbal.papers.arm2dof import arm2dof_mechanism
from mechbal.papers.discs import disc_arm_mechanism, disc_design_mechanism

__all__ = ["arm2dof_mechanism", "disc_arm_mechanism", "disc_design_mechanism"]
