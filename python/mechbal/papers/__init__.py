"""The papers' mechanisms as data on the general model (:class:`mechbal.Mechanism`).

Each module builds, from the parameters a case runner reads, the mechanism the paper describes:
joints with their parents and placements, every link's bodies (links, counterweights, discs), gear
couplings for geared discs and, for the closed linkages, loop closures between named frames with
the actuated joints named. The papers' closed forms (``Arm2DofDynamics``, ``DiscArmDynamics``,
``FiveBarDynamics``, ``PaminsaModel``) stay as fast paths and are tested against these general
models (tests/python/test_papers.py, test_papers_loops.py).

* :mod:`mechbal.papers.arm2dof`: Arakelian, Le Baron & Mottu 2011, the 2-DOF arm with
  counterweights.
* :mod:`mechbal.papers.discs`: Coutinho & Hess Coelho, the planar 3R, spatial 3R and SCARA with
  counter-rotating discs (gear couplings).
* :mod:`mechbal.papers.five_bar`: the parallelogram 5R of the discs case (Coutinho & Hess Coelho).
* :mod:`mechbal.papers.paminsa`: PAMINSA (Briot & Arakelian 2009): pantograph legs, guides,
  columns, platform, counterweights, vertical counter-mass and wrist.
* :mod:`mechbal.papers.rpsp`: Heydari & Enferadi, the 3(RPSP)-S robot: the closed-form inverse
  kinematics (eqs 1-13) and sizing (eqs 29-31) that check the ``rpsp`` case's general model.
* :mod:`mechbal.papers.orthoglide`: Martini et al. 2015, the Orthoglide's closed forms (eq 1,
  eqs 2-19) that check the ``orthoglide`` case's general model.
"""
from mechbal.papers.arm2dof import arm2dof_mechanism
from mechbal.papers.discs import disc_arm_mechanism, disc_design_mechanism

__all__ = ["arm2dof_mechanism", "disc_arm_mechanism", "disc_design_mechanism"]
