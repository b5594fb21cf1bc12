"""The serial arms of Coutinho & Hess Coelho ("A new approach for designing dynamic balanced serial
mechanisms") on the general mechanism model: links as bodies, each counter-rotating disc as a link
on its own revolute joint whose angle is a **gear coupling** of a joint of the arm.

How the paper's discs map to gear couplings. A disc d rides on an axle fixed to its carrier link
and turns relative to the carrier by ``ratio * theta_j`` (theta_j the relative angle of joint j):
a gear fixed to the next link (ratio 1: the disc turns with that link) or a gear train (ratio beta
or gamma, negative: counter-rotating). On the general model that is a revolute joint whose parent
is the carrier link, placed on the axle, with ``mimic_joint = joint j, mimic_ratio = ratio``. The
disc's absolute angular velocity is then the carrier's plus ``ratio * theta_j'`` about the axle,
exactly the paper's constraint rows (eqs 10-11, 20-21, 31-32), and the model's projection of the
joint forces (tau = G^T tau_joint) is the paper's coupling-matrix projection M' = C^T M# C.

Mechanisms (SI units, z up, gravity (0, 0, -9.81); link frames x = joint axis for the horizontal
joints, y along the link; ``mechbal.sizing.discs`` for the parameters and the corrections):

* ``planar3r`` (Sec. 3.1, eqs 7-16): joints x at 0, (0, l1, 0), (0, l2, 0). Discs 4, 5 on link 1
  on the joint-2 axle (omega4 = theta1' + theta2', omega5 = theta1' + beta theta2'), discs 6, 7 on
  link 2 on the joint-3 axle (omega6 = theta1' + theta2' + theta3', omega7 = ... + gamma theta3').
* ``spatial3r`` (Sec. 3.2, eqs 17-27 corrected): joint 1 about z, joints 2, 3 about x at
  (0, l1, 0) and (0, l2, 0). Discs 4, 5 on link 2 on the joint-3 axle (ratios 1 and beta).
* ``scara`` (Sec. 3.3, eqs 28-37, general l2): joints 1, 2 about x, joint 3 prismatic along x at
  (0, l2, 0) of link 2; discs 4, 5 on link 1 on the joint-2 axle (ratios 1 and beta).

As in the case files (and ``mechbal.DiscArmDynamics``), a disc's mass is included in its carrier
link's mass and centre of mass, so the disc body carries only its central inertia
diag(J_x, J_y, J_z) (disc frame, x = spin axis) and mass 0: where its axle sits then changes no
force, torque or momentum, only the disc's reported pose. The unbalanced designs have no discs.

The planar 5R five-bar is a closed loop: it needs loop-closure constraints, which the general
model does not have yet; it stays on ``mechbal.FiveBarDynamics``.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import numpy as np

from mechbal import _core
from mechbal.mechanism import Mechanism

__all__ = ["disc_arm_mechanism", "disc_design_mechanism", "SERIAL_ARMS"]

#: the disc arms that are serial (trees with gear couplings) and so plain data on the model
SERIAL_ARMS = ("planar3r", "spatial3r", "scara")

_EX, _EZ = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])


def _along_link(length: float) -> np.ndarray:
    """Placement translated by ``length`` along the link (y)."""
    T = np.eye(4)
    T[1, 3] = length
    return T


def _principal(d: Mapping[str, Any], i: int) -> np.ndarray:
    return np.diag([float(d[f"Jx{i}"]), float(d[f"Jy{i}"]), float(d[f"Jz{i}"])])


def disc_design_mechanism(kind: str, design: Mapping[str, Any], *, name: str | None = None) -> Mechanism:
    """A design of ``mechbal.sizing.discs.design`` (balanced, unbalanced or perturbed as built) as
    a :class:`mechbal.Mechanism` (module docstring for frames and disc couplings).

    Joints ``joint1..3`` (the coordinates, in order) and, with ``design['discs']``, the geared
    ``disc4..7`` joints; bodies ``link1..3`` and ``disc4..7`` in that order (the order of the
    runner's ``bodies_*.npz``)."""
    if kind not in SERIAL_ARMS:
        raise ValueError(f"mechanism: {kind!r} is not a serial disc arm (one of {', '.join(SERIAL_ARMS)}); "
                         "the five-bar is a closed loop and stays on mechbal.FiveBarDynamics")
    d = design
    R, P = _core.JointType.revolute, _core.JointType.prismatic
    l1, l2 = float(d["l1"]), float(d["l2"])
    y = lambda L: np.array([0.0, float(L), 0.0])  # noqa: E731
    if kind == "planar3r":   # eqs 7-9: three parallel horizontal axes
        axes, types = (_EX, _EX, _EX), (R, R, R)
        coms = (y(d["lg1"]), y(d["lg2"]), y(d["lg3"]))
        # (disc, carrier link, driving joint, axle placement on the carrier, ratio): eqs 10-12
        discs = [(4, "joint1", "joint2", l1, 1.0), (5, "joint1", "joint2", l1, d["beta"]),
                 (6, "joint2", "joint3", l2, 1.0), (7, "joint2", "joint3", l2, d["gamma"])]
    elif kind == "spatial3r":  # eqs 17-19: vertical joint 1, link 1's CoM on its axis
        axes, types = (_EZ, _EX, _EX), (R, R, R)
        coms = (np.zeros(3), y(d["lg2"]), y(d["lg3"]))
        discs = [(4, "joint2", "joint3", l2, 1.0), (5, "joint2", "joint3", l2, d["beta"])]  # eqs 20-23
    else:                    # scara, eqs 28-30: RRP, link 3's CoM on the prismatic axis
        axes, types = (_EX, _EX, _EX), (R, R, P)
        coms = (y(d["lg1"]), y(d["lg2"]), np.zeros(3))
        discs = [(4, "joint1", "joint2", l1, 1.0), (5, "joint1", "joint2", l1, d["beta"])]  # eqs 31-33
    placements = (np.eye(4), _along_link(l1), _along_link(l2))
    joints, bodies = [], []
    parent = "base"
    for i in range(3):
        jn = f"joint{i + 1}"
        joints.append(_core.Joint(jn, types[i], parent, placements[i], axes[i]))
        bodies.append(_core.Body(f"link{i + 1}", jn, float(d[f"m{i + 1}"]), coms[i],
                                 _principal(d, i + 1), "link"))
        parent = jn
    if d.get("discs", True):
        for k, carrier, master, axle, ratio in discs:
            dn = f"disc{k}"
            joints.append(_core.Joint(dn, R, carrier, _along_link(axle), _EX, mimic_joint=master,
                                      mimic_ratio=float(ratio), mimic_offset=0.0))
            bodies.append(_core.Body(dn, dn, 0.0, np.zeros(3), _principal(d, k), "disc"))
    return Mechanism.from_description(joints, bodies, (), gravity=(0.0, 0.0, -9.81),
                                      name=name or kind)


def disc_arm_mechanism(case_config: Mapping[str, Any] | str | Path, balanced: bool = True) -> Mechanism:
    """The arm of a disc case (``discs-3r``, ``discs-spatial``, ``scara``: a case name, path or
    the loaded TOML dict) as a :class:`mechbal.Mechanism`, built from the runner's parameters
    (``mechbal.cases.discs.parameters_from_config``).

    ``balanced=True``: static balancing (eqs 8, 18, 29 generalised), the discs with the gear
    ratios of eqs 14, 25, 35 and, for the spatial arm, the corrected inertia conditions of eq 25:
    the mass matrix is then diagonal and constant (k_i of eqs 16, 27, 37) and the gravity torque
    zero. ``balanced=False``: the case's ``[unbalanced]`` baseline, no discs."""
    from mechbal.cases.discs import parameters_from_config
    from mechbal.config import load_case, require, string
    from mechbal.sizing import discs as dz

    config = load_case(case_config) if isinstance(case_config, (str, Path)) else case_config
    kind = string(require(require(config, "case", ""), "mechanism", "case"), "case.mechanism",
                  dz.MECHANISMS)
    if kind not in SERIAL_ARMS:
        raise ValueError(f"case.mechanism: {kind!r} is a closed loop (five-bar): not a serial disc "
                         "arm; use mechbal.FiveBarDynamics")
    p = parameters_from_config(kind, config)
    variant = "balanced" if balanced else "unbalanced"
    return disc_design_mechanism(kind, dz.design(kind, p, balanced),
                                 name=f"{config['case']['name']} ({variant})")
