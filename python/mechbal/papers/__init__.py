"""The papers' mechanisms as data on the general model (:class:`mechbal.Mechanism`).

Each module builds, from the parameters a case runner reads, the mechanism the paper describes:
joints with their parents and placements, every link's bodies (links, counterweights, discs), gear
couplings for geared discs and, for the closed linkages, loop closures between named frames with
the actuated joints named. The papers' closed forms (``Arm2DofDynamics``,
``FiveBarDynamics``, ``PaminsaModel``) stay as fast paths and are tested against these general
models (tests/python/test_papers.py, test_papers_loops.py). Each module also holds its paper's
balancing closed forms (PAMINSA's counterweights, the disc conditions, the 2-DOF RMS cubic; the
RPSP's eqs 29-31): the fast paths and regression tests of the general methods of
:mod:`mechbal.balance`, with which the papers' runners size (and which they check against these).

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

The papers' closed forms and per-paper evaluators, re-exported from the C++ core (fast paths of
the general model; SI units: m, kg, kg m^2, rad, s, N, N m):

* Arakelian, Le Baron & Mottu 2011: :class:`Arm2DofParameters`, :class:`Arm2DofCounterweights`,
  :class:`Arm2DofDynamics` (a forward-dynamics plant and an inverse-dynamics back end),
  :func:`pd_error_analytic` (eq 6).
* Briot & Arakelian 2009 (PAMINSA): :class:`PaminsaParameters`, :class:`PaminsaCounterweights`,
  :class:`PaminsaModel`, :func:`paminsa_kinematics`, :func:`paminsa_reactionless_run`,
  :func:`wrist_momentum_matrix`, :func:`wrist_momentum_bias` (its controller is
  :class:`mechbal.control.PaminsaController`).
* Coutinho & Hess Coelho: :class:`FiveBarParameters`, :class:`FiveBarDynamics` (the serial arms
  with discs are general mechanisms: :func:`disc_arm_mechanism`, evaluated by
  :class:`mechbal.control.MechanismDynamics`).
* The serial-chain evaluator the first case runners were written on (the general model,
  :class:`mechbal.Mechanism`, supersedes it): :class:`ChainModel`, :class:`JointSpec`,
  :func:`chain_kinematics` (every link's motion along a trajectory) and
  :func:`shaking_wrench` (the shaking force [N] and moment about O [N m] of any set of bodies
  from their masses, inertias and motion, eqs 1-4 of Briot & Arakelian 2009).
"""
from mechbal import _core
from mechbal.papers.arm2dof import arm2dof_mechanism
from mechbal.papers.discs import disc_arm_mechanism, disc_design_mechanism

Arm2DofParameters = _core.Arm2DofParameters
Arm2DofCounterweights = _core.Arm2DofCounterweights
Arm2DofDynamics = _core.Arm2DofDynamics
pd_error_analytic = _core.pd_error_analytic
PaminsaParameters = _core.PaminsaParameters
PaminsaCounterweights = _core.PaminsaCounterweights
PaminsaModel = _core.PaminsaModel
paminsa_kinematics = _core.paminsa_kinematics
paminsa_reactionless_run = _core.paminsa_reactionless_run
wrist_momentum_matrix = _core.wrist_momentum_matrix
wrist_momentum_bias = _core.wrist_momentum_bias
FiveBarParameters = _core.FiveBarParameters
FiveBarDynamics = _core.FiveBarDynamics
ChainModel = _core.ChainModel
JointSpec = _core.JointSpec
chain_kinematics = _core.chain_kinematics
shaking_wrench = _core.shaking_wrench

__all__ = [
    "arm2dof_mechanism", "disc_arm_mechanism", "disc_design_mechanism",
    "Arm2DofParameters", "Arm2DofCounterweights", "Arm2DofDynamics", "pd_error_analytic",
    "PaminsaParameters", "PaminsaCounterweights", "PaminsaModel", "paminsa_kinematics",
    "paminsa_reactionless_run", "wrist_momentum_matrix", "wrist_momentum_bias",
    "FiveBarParameters", "FiveBarDynamics",
    "ChainModel", "JointSpec", "chain_kinematics", "shaking_wrench",
]
