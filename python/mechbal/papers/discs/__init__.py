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
joints, y along the link; the closed forms below for the parameters and the corrections):

* ``planar3r`` (Sec. 3.1, eqs 7-16): joints x at 0, (0, l1, 0), (0, l2, 0). Discs 4, 5 on link 1
  on the joint-2 axle (omega4 = theta1' + theta2', omega5 = theta1' + beta theta2'), discs 6, 7 on
  link 2 on the joint-3 axle (omega6 = theta1' + theta2' + theta3', omega7 = ... + gamma theta3').
* ``spatial3r`` (Sec. 3.2, eqs 17-27 corrected): joint 1 about z, joints 2, 3 about x at
  (0, l1, 0) and (0, l2, 0). Discs 4, 5 on link 2 on the joint-3 axle (ratios 1 and beta).
* ``scara`` (Sec. 3.3, eqs 28-37, general l2): joints 1, 2 about x, joint 3 prismatic along x at
  (0, l2, 0) of link 2; discs 4, 5 on link 1 on the joint-2 axle (ratios 1 and beta).

As in the case files, a disc's mass is included in its carrier
link's mass and centre of mass, so the disc body carries only its central inertia
diag(J_x, J_y, J_z) (disc frame, x = spin axis) and mass 0: where its axle sits then changes no
force, torque or momentum, only the disc's reported pose. The unbalanced designs have no discs.

The planar 5R five-bar is a closed loop: `mechbal.papers.discs.five_bar` (its per-tick fast path
is ``mechbal.FiveBarDynamics``).

**The paper's closed forms** (derivation and every correction: docs/discs_derivation.md): the
fast path of the disc cases and the regression test of the general shaking-moment method
(`mechbal.balance.moment`), with which the ``discs`` runner sizes the discs' gear ratios and
the inertia conditions and which it checks against `BALANCE`.

Procedure (the paper's order matters): static balancing first (centre-of-mass positions l_g that
cancel gravity, eqs 8, 18, 29) makes the arm's mass matrix constant (planar) or free of
translational coupling (spatial); then the gear ratios of the discs (beta, gamma: eqs 14, 25, 35)
and, for the spatial arm, the inertia conditions of eq 25 make it diagonal and constant, so that
tau_i = k_i q''_i (eqs 15-16, 26-27, 36-37).

Mechanisms (SI units, z up, gravity (0, 0, -9.81); link frames x = joint axis, y along the link):

* ``planar3r``: 3R in the vertical y-z plane, joint axes x, discs 4, 5 on link 1 (turning with
  link 2 and at beta * theta2'), discs 6, 7 on link 2 (with link 3 and at gamma * theta3').
* ``spatial3r``: joint 1 vertical, joints 2, 3 horizontal, radial shoulder offset l1; discs 4, 5
  on link 2 about the joint-3 axis (with link 3 and at beta * theta3').
* ``scara``: RRP with horizontal revolute axes (wall-mounted; the printed gravity terms of eq 28
  require it), prismatic joint 3 along x at distance l2 from joint 2; discs 4, 5 on link 1.
* ``fivebar``: planar 5R, balanced leg-wise; only the parallelogram variant (d = 0, b1 = a2,
  b2 = a1) can be made constant-diagonal (no disc set can do it for a general 5R:
  docs/discs_derivation.md section 5).

Link masses include the discs they carry (disc mass at its centre on the carrier); a disc
subsystem carries only its central inertia.

Corrections to the printed equations (CORRECTIONS below, each proved by tests/python/test_discs.py):

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from mechbal import _core
from mechbal._deprecation import renamed_kwargs
from mechbal.papers.discs import coupling as cp
from mechbal.papers.discs.five_bar_dynamics import FiveBarDynamics, FiveBarMotion, FiveBarTerms
from mechbal.config import ConfigError, inertia
from mechbal.mechanism import Mechanism
from mechbal.schema import inertia_matrix, validate_case

# the closed forms of the C++ core (cpp/src/papers/five_bar/): fast paths of the general model
# (FiveBarDynamics: its typed Python face in five_bar_dynamics.py)
FiveBarParameters = _core.FiveBarParameters

__all__ = ["FiveBarParameters", "FiveBarDynamics", "FiveBarTerms", "FiveBarMotion", "parameters_from_config",
           "disc_arm_mechanism", "disc_design_mechanism", "SERIAL_ARMS", "BALANCE", "CORRECTIONS", "MECHANISMS",
           "design", "disc_mechanism", "evaluate", "metrics", "sensitivity", "fivebar_model", "fivebar_positions",
           "fivebar_dynamics", "is_parallelogram", "sample_states"]

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
    """A design of `design` (balanced, unbalanced or perturbed as built) as
    a `mechbal.Mechanism` (module docstring for frames and disc couplings).

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
    the loaded TOML dict) as a `mechbal.Mechanism`, built from the runner's parameters
    (`parameters_from_config`).

    ``balanced=True``: static balancing (eqs 8, 18, 29 generalised), the discs with the gear
    ratios of eqs 14, 25, 35 and, for the spatial arm, the corrected inertia conditions of eq 25:
    the mass matrix is then diagonal and constant (k_i of eqs 16, 27, 37) and the gravity torque
    zero. ``balanced=False``: the case's ``[unbalanced]`` baseline, no discs."""
    from mechbal.config import read_case, require, string

    config = read_case(case_config) if isinstance(case_config, (str, Path)) else case_config
    kind = string(require(require(config, "case", ""), "mechanism", "case"), "case.mechanism",
                  MECHANISMS)
    if kind not in SERIAL_ARMS:
        raise ValueError(f"case.mechanism: {kind!r} is a closed loop (five-bar): not a serial disc "
                         "arm; use mechbal.FiveBarDynamics")
    p = parameters_from_config(kind, config)
    variant = "balanced" if balanced else "unbalanced"
    return disc_design_mechanism(kind, design(kind, p, balanced),
                                 name=f"{config['case']['name']} ({variant})")


G = 9.81
EX, EY, EZ = np.eye(3)

#: the paper's printed equations that are wrong, and what is right (docs/discs_derivation.md §7)
CORRECTIONS = [
    {"id": "C1", "eq": "19", "printed": "D22 = J_x2 + J_x3 + m2 l2^2 + l2^2 m3^2/m2",
     "correct": "D22 = J_x2 + J_x3 + m3 l2^2 + l2^2 m3^2/m2"},
    {"id": "C2", "eq": "19, 25",
     "printed": "D211 puts mu = m3 l2^2 (1 + m3/m2) on the s(2th2+2th3) term; conditions "
                "J_y2 = J_z2, J_y3 = J_z3 + mu",
     "correct": "mu belongs to the s(2th2) term; conditions J_y2 = J_z2 + mu, J_y3 = J_z3 (the "
                "printed ones leave D'11 varying)"},
    {"id": "C3", "eq": "24", "printed": "arguments th2+th2, beta th2+th2, 2 beta th2+2th3 "
                                        "(theta_2 repeated where theta_3 is meant)",
     "correct": "th2+th3, th2+beta th3, 2th2+2beta th3"},
    {"id": "C4", "eq": "24",
     "printed": "D'112, D'113 add 1/4(...), D'113 without beta, D'211 = D211, D'311 = D311",
     "correct": "add 1/2(...), disc-5 term of D'113 multiplied by beta, D'211 = -D'112, "
                "D'311 = -D'113 (disc terms included)"},
    {"id": "C5", "eq": "20", "printed": "spatial disc model v_i = 0",
     "correct": "v_i = omega_i x J_i omega_i (Euler); v = 0 gives the wrong Coriolis terms of "
                "eq 24 (explains C4); harmless for planar discs and after balancing"},
    {"id": "C6", "eq": "26", "printed": "f3 = k3 d3'' (a prismatic third joint)",
     "correct": "tau3 = k3 theta3'' (the spatial arm is 3R)"},
    {"id": "C7", "eq": "27", "printed": "k1 ... + l1^2 m3^2/m2", "correct": "k1 ... + l2^2 m3^2/m2"},
    {"id": "C8", "eq": "27", "printed": "k2 ... + l1^2 m3^2/m2 (l1 where l2 is meant)",
     "correct": "k2 ... + l2^2 m3^2/m2"},
    {"id": "C9", "eq": "28-30, 35, 37",
     "printed": "SCARA terms without m3 l2; l_g2 = 0",
     "correct": "valid only with the prismatic axis through joint 2 (l2 = 0); in general "
                "l_g2 = -l2 m3/m2 and beta, k gain mu_s = m3 l2^2 (1 + m3/m2)"},
    {"id": "C10", "eq": "28", "printed": "'SCARA' with gravity torques on theta1, theta2",
     "correct": "the revolute axes are horizontal (wall-mounted); a vertical-axis SCARA has "
                "D1 = D2 = 0 and D3 = m3 g, which mass redistribution cannot remove"},
    {"id": "C11", "eq": "abstract", "printed": "planar 5R balanced by the method",
     "correct": "a general 5R cannot be made constant-diagonal by discs; the parallelogram 5R "
                "can (leg-wise static balancing also zeroes its coupling K)"},
]

MECHANISMS = ("planar3r", "spatial3r", "scara", "fivebar")


# ---------------------------------------------------------------------------------------------
# Closed forms (corrected)
# ---------------------------------------------------------------------------------------------
def balance_planar3r(p: dict) -> dict:
    """eq 8 (static), eq 14 (beta, gamma), eq 16 (k_i; correct as printed)."""
    l1, l2, m1, m2, m3 = p["l1"], p["l2"], p["m1"], p["m2"], p["m3"]
    X = p["Jx2"] + p["Jx3"] + p["Jx4"] + p["Jx6"] + p["Jx7"] + m3 * l2 ** 2 + m3 ** 2 * l2 ** 2 / m2
    return dict(
        lg=[-l1 * (m2 + m3) / m1, -l2 * m3 / m2, 0.0],
        beta=-X / p["Jx5"],
        gamma=-(p["Jx3"] + p["Jx6"]) / p["Jx7"],
        k=[sum(p[f"Jx{i}"] for i in range(1, 8)) + m2 * l1 ** 2 + m3 * (l1 ** 2 + l2 ** 2)
           + l1 ** 2 * (m2 + m3) ** 2 / m1 + l2 ** 2 * m3 ** 2 / m2,
           X * (X + p["Jx5"]) / p["Jx5"],
           (p["Jx3"] + p["Jx6"]) * (p["Jx3"] + p["Jx6"] + p["Jx7"]) / p["Jx7"]])


def balance_spatial3r(p: dict) -> dict:
    """eq 18 (static), eq 25 corrected (beta and the inertia conditions, C2), eq 27 corrected
    (k1, k2 with l2 where l1 is printed, C7, C8; tau3 = k3 theta3'', C6)."""
    l1, l2, m2, m3 = p["l1"], p["l2"], p["m2"], p["m3"]
    mu = m3 * l2 ** 2 * (1.0 + m3 / m2)
    return dict(
        lg=[0.0, -l2 * m3 / m2, 0.0],
        beta=-(p["Jx3"] + p["Jx4"]) / p["Jx5"],
        inertia_conditions={"Jy2": float(p["Jz2"] + mu), "Jy3": float(p["Jz3"]),
                            "Jy4": float(p["Jz4"]), "Jy5": float(p["Jz5"]), "mu": float(mu)},
        k=[p["Jz1"] + p["Jz2"] + p["Jz3"] + p["Jz4"] + p["Jz5"] + m2 * l1 ** 2
           + m3 * (l1 ** 2 + l2 ** 2) + l2 ** 2 * m3 ** 2 / m2,
           p["Jx2"] + p["Jx3"] + p["Jx4"] + p["Jx5"] + m3 * l2 ** 2 + l2 ** 2 * m3 ** 2 / m2,
           (p["Jx3"] + p["Jx4"]) * (p["Jx3"] + p["Jx4"] + p["Jx5"]) / p["Jx5"]])


def balance_scara(p: dict) -> dict:
    """eq 29 generalised (prismatic axis at l2 from joint 2; the paper's equations are l2 = 0,
    C9), eq 35 (beta), eq 37 (k_i, k3 = m3)."""
    l1, l2, m1, m2, m3 = p["l1"], p["l2"], p["m1"], p["m2"], p["m3"]
    mu_s = m3 * l2 ** 2 * (1.0 + m3 / m2)
    Y = p["Jx2"] + p["Jx3"] + p["Jx4"] + mu_s
    return dict(
        lg=[-l1 * (m2 + m3) / m1, -l2 * m3 / m2, 0.0],
        beta=-Y / p["Jx5"],
        k=[sum(p[f"Jx{i}"] for i in range(1, 6)) + (m2 + m3) * l1 ** 2
           + l1 ** 2 * (m2 + m3) ** 2 / m1 + mu_s,
           Y * (Y + p["Jx5"]) / p["Jx5"],
           m3])


def balance_fivebar(p: dict) -> dict:
    """Leg-wise static balancing (eq 8 applied to each leg carrying its share of the end
    effector); for the parallelogram 5R it also zeroes the coupling K (docs §5)."""
    mP1 = p["mP1_share"]
    mP2 = p["mP"] - mP1
    cd1 = -mP1 * p["b1"] / p["md1"]
    cd2 = -mP2 * p["b2"] / p["md2"]
    cp1 = -p["a1"] * (p["md1"] + mP1) / p["mp1"]
    cp2 = -p["a2"] * (p["md2"] + mP2) / p["mp2"]
    k1 = p["Jp1"] + p["mp1"] * cp1 ** 2 + (p["md1"] + p["mP"]) * p["a1"] ** 2 + p["Jd2"] + p["md2"] * cd2 ** 2
    k2 = p["Jp2"] + p["mp2"] * cp2 ** 2 + (p["md2"] + p["mP"]) * p["a2"] ** 2 + p["Jd1"] + p["md1"] * cd1 ** 2
    K = p["a1"] * p["md1"] * cd1 + p["a2"] * p["md2"] * cd2 + p["mP"] * p["a1"] * p["a2"]
    return dict(lg={"cp1": cp1, "cp2": cp2, "cd1": cd1, "cd2": cd2}, k=[k1, k2], K_cross=K)


BALANCE: dict[str, Callable[[dict], dict]] = dict(
    planar3r=balance_planar3r, spatial3r=balance_spatial3r, scara=balance_scara,
    fivebar=balance_fivebar)


def is_parallelogram(p: dict, tol: float = 1e-12) -> bool:
    return abs(p["d"]) < tol and abs(p["b1"] - p["a2"]) < tol and abs(p["b2"] - p["a1"]) < tol


# ---------------------------------------------------------------------------------------------
# Designs: the values actually built (balanced, unbalanced, or perturbed as-built)
# ---------------------------------------------------------------------------------------------
def design(kind: str, p: dict, balanced: bool = True) -> dict:
    """A design dict: the parameters plus lg*, beta/gamma and a 'discs' flag. The balanced design
    computes its balancing values from ``p``; the unbalanced one uses ``*_unbal`` values and no
    discs."""
    d = dict(p)
    if kind == "fivebar":
        if balanced:
            d.update(balance_fivebar(p)["lg"])
        else:
            d.update(cp1=p.get("cp1_unbal", p["a1"] / 2), cp2=p.get("cp2_unbal", p["a2"] / 2),
                     cd1=p.get("cd1_unbal", p["b1"] / 2), cd2=p.get("cd2_unbal", p["b2"] / 2))
        return d
    if balanced:
        b = BALANCE[kind](p)
        d.update(lg1=b["lg"][0], lg2=b["lg"][1], lg3=b["lg"][2], beta=b["beta"],
                 gamma=b.get("gamma", 0.0), discs=True)
        if kind == "spatial3r":
            d.update(Jy2=b["inertia_conditions"]["Jy2"], Jy3=b["inertia_conditions"]["Jy3"])
    else:
        d.update(lg1=p.get("lg1_unbal", 0.0), lg2=p["lg2_unbal"], lg3=p.get("lg3_unbal", 0.0),
                 beta=0.0, gamma=0.0, discs=False)
        for k in ("Jx", "Jy", "Jz"):
            for i in (1, 2, 3):
                if f"{k}{i}_unbal" in p:
                    d[f"{k}{i}"] = p[f"{k}{i}_unbal"]
    return d


def _J(d, i):
    return np.array([d[f"Jx{i}"], d[f"Jy{i}"], d[f"Jz{i}"]])


def serial_structure(kind: str, d: dict):
    """(joints, links, discs) of a serial mechanism (mechbal.papers.discs.coupling types)."""
    y = lambda L: np.array([0.0, L, 0.0])  # noqa: E731
    if kind == "planar3r":
        joints = [cp.Joint("R", EX, y(0)), cp.Joint("R", EX, y(d["l1"])), cp.Joint("R", EX, y(d["l2"]))]
        links = [cp.Link(d[f"m{i}"], y(d[f"lg{i}"]), np.diag(_J(d, i))) for i in (1, 2, 3)]
        discs = [cp.Disc(0, 1, EX, 1.0, _J(d, 4)), cp.Disc(0, 1, EX, d["beta"], _J(d, 5)),
                 cp.Disc(1, 2, EX, 1.0, _J(d, 6)), cp.Disc(1, 2, EX, d["gamma"], _J(d, 7))]
    elif kind == "spatial3r":
        joints = [cp.Joint("R", EZ, y(0)), cp.Joint("R", EX, y(d["l1"])), cp.Joint("R", EX, y(d["l2"]))]
        links = [cp.Link(d["m1"], np.zeros(3), np.diag(_J(d, 1))),  # CoM on axis 1
                 cp.Link(d["m2"], y(d["lg2"]), np.diag(_J(d, 2))),
                 cp.Link(d["m3"], y(d["lg3"]), np.diag(_J(d, 3)))]
        discs = [cp.Disc(1, 2, EX, 1.0, _J(d, 4)), cp.Disc(1, 2, EX, d["beta"], _J(d, 5))]
    elif kind == "scara":
        joints = [cp.Joint("R", EX, y(0)), cp.Joint("R", EX, y(d["l1"])), cp.Joint("P", EX, y(d["l2"]))]
        links = [cp.Link(d["m1"], y(d["lg1"]), np.diag(_J(d, 1))),
                 cp.Link(d["m2"], y(d["lg2"]), np.diag(_J(d, 2))),
                 cp.Link(d["m3"], np.zeros(3), np.diag(_J(d, 3)))]
        discs = [cp.Disc(0, 1, EX, 1.0, _J(d, 4)), cp.Disc(0, 1, EX, d["beta"], _J(d, 5))]
    else:
        raise ValueError(f"not a serial mechanism: {kind!r}")
    return joints, links, (discs if d.get("discs", True) else [])


def arm_mechanism(joints, links) -> Mechanism:
    """The arm links alone (no discs) on the general model: joint i + 1 ``joint<i+1>`` carries body
    ``link<i+1>``, one after the other (for the bodies' motion, KDL and Pinocchio)."""
    jts, bodies, parent = [], [], "base"
    for i, (j, b) in enumerate(zip(joints, links)):
        T = np.eye(4)
        T[:3, 3] = j.offset
        jt = _core.JointType.revolute if j.type == "R" else _core.JointType.prismatic
        name = f"joint{i + 1}"
        jts.append(_core.Joint(name, jt, parent, T, np.asarray(j.axis, float)))
        bodies.append(_core.Body(f"link{i + 1}", name, float(b.mass), np.asarray(b.com, float),
                                 np.asarray(b.inertia, float)))
        parent = name
    return Mechanism.from_description(jts, bodies, name="arm")


def disc_mechanism(kind: str, d: dict):
    """A serial design on the general model: mechbal.Mechanism with each disc a gear-coupled
    joint (`disc_design_mechanism`). What `evaluate` and the runner use."""
    return disc_design_mechanism(kind, d)


# ---------------------------------------------------------------------------------------------
# Planar 5R: two legs (serial 2R arms, own models) + end-effector point mass, loop closure
# ---------------------------------------------------------------------------------------------
def _e(t):
    return np.array([0.0, np.cos(t), np.sin(t)])


def fivebar_positions(d: dict, th1: float, th2: float):
    """Elbows B1, B2 and end effector P for actuated (th1, th2), in the assembly mode nearest
    the parallelogram point B1 + (B2 - A2) (exact for the parallelogram)."""
    A2 = np.array([0.0, d["d"], 0.0])
    B1, B2 = d["a1"] * _e(th1), A2 + d["a2"] * _e(th2)
    D = B2 - B1
    L = np.linalg.norm(D)
    x = (d["b1"] ** 2 - d["b2"] ** 2 + L ** 2) / (2 * L)
    h = np.sqrt(max(d["b1"] ** 2 - x ** 2, 0.0))
    u = D / L
    nrm = np.array([0.0, -u[2], u[1]])
    ref = B1 + (B2 - A2)
    P = min((B1 + x * u + s * h * nrm for s in (1.0, -1.0)), key=lambda c: np.linalg.norm(c - ref))
    return B1, B2, P


@renamed_kwargs(qd="v")
def fivebar_model(d: dict, q, v) -> cp.CoupledModel:
    """M', v', g' of the 5R in (theta11, theta21) by the coupling method: subsystems leg 1
    (theta11, theta12), leg 2 (theta21, theta22), point mass P (v_Py, v_Pz); constraints
    v_P - J_tip,i qd_leg,i = 0 (4 rows), so A° (4x4) is not the identity."""
    qd = v
    th1, th2 = q
    B1, B2, P = fivebar_positions(d, th1, th2)
    phi1 = np.arctan2(*(P - B1)[[2, 1]])
    phi2 = np.arctan2(*(P - B2)[[2, 1]])
    qs = [np.array([th1, phi1 - th1]), np.array([th2, phi2 - th2])]
    legs = []
    for i, base in ((1, np.zeros(3)), (2, np.array([0.0, d["d"], 0.0]))):
        joints = [cp.Joint("R", EX, np.zeros(3)), cp.Joint("R", EX, np.array([0.0, d[f"a{i}"], 0.0]))]
        links = [cp.Link(d[f"mp{i}"], np.array([0.0, d[f"cp{i}"], 0.0]), np.diag(d[f"inertia_p{i}"])),
                 cp.Link(d[f"md{i}"], np.array([0.0, d[f"cd{i}"], 0.0]), np.diag(d[f"inertia_d{i}"]))]
        legs.append((joints, links, base, d[f"b{i}"]))

    def tip_jacobian(k):
        joints, _, base, b = legs[k]
        kin = cp.chain_kinematics(joints, qs[k], np.zeros(2), base)
        tip = kin[1].p + kin[1].R @ np.array([0.0, b, 0.0])
        return cp.point_jacobian(kin, 1, tip)[0][1:]

    def leg(k, qdl):
        joints, links, base, b = legs[k]
        model, kin = cp.arm_model(joints, links, qs[k], qdl, base)
        tip = kin[1].p + kin[1].R @ np.array([0.0, b, 0.0])
        sub = cp.Subsystem(model.mass, model.velocity, model.gravity)
        return sub, cp.point_bias(kin, 1, tip)[1:]

    A = np.zeros((4, 6))
    A[0:2, 0:2], A[0:2, 4:6] = -tip_jacobian(0), np.eye(2)
    A[2:4, 2:4], A[2:4, 4:6] = -tip_jacobian(1), np.eye(2)
    indep = [0, 2]
    full = cp.coupling_matrix(A, indep) @ np.asarray(qd, float)   # passive rates first (from C)
    s1, b1 = leg(0, full[0:2])
    s2, b2 = leg(1, full[2:4])
    sP = cp.Subsystem(d["mP"] * np.eye(2), np.zeros(2), np.array([0.0, d["mP"] * G]))
    return cp.couple([s1, s2, sP], A, indep, -np.concatenate([b1, b2]), qd)


def fivebar_dynamics(d: dict) -> FiveBarDynamics:
    """The C++ per-tick evaluator (`FiveBarDynamics`) of a five-bar design; in-plane
    inertias are the x components of ``inertia_*`` (as in ``fivebar_model``)."""
    keys = ("a1", "a2", "b1", "b2", "d", "mp1", "mp2", "md1", "md2", "mP", "cp1", "cp2", "cd1", "cd2")
    fp = _core.FiveBarParameters(**{k: float(d[k]) for k in keys},
                                 **{f"J{k}": float(d[f"inertia_{k}"][0]) for k in ("p1", "p2", "d1", "d2")},
                                 gravity=G)
    return FiveBarDynamics(fp)


# ---------------------------------------------------------------------------------------------
# Evaluation over samples, metrics, sensitivity
# ---------------------------------------------------------------------------------------------
def sample_states(kind: str, n: int, rng: np.random.Generator):
    """Random configurations (angles U(-pi, pi), prismatic U(-0.2, 0.2) m; 5R with
    |theta2 - theta1| in [0.25, pi - 0.25], away from the parallelogram's flat bifurcations) and
    velocities U(-2, 2)."""
    if kind == "fivebar":
        t1 = rng.uniform(-np.pi, np.pi, n)
        t2 = t1 + rng.choice([-1.0, 1.0], n) * rng.uniform(0.25, np.pi - 0.25, n)
        q = np.stack([t1, t2], 1)
        return q, rng.uniform(-2, 2, (n, 2))
    q = rng.uniform(-np.pi, np.pi, (n, 3))
    if kind == "scara":
        q[:, 2] = rng.uniform(-0.2, 0.2, n)
    return q, rng.uniform(-2, 2, (n, 3))


@renamed_kwargs(qd="v")
def evaluate(kind: str, d: dict, q: np.ndarray, v: np.ndarray):
    """(M (N, n, n), v (N, n), g (N, n)) of design d at N states, in C++: the general model for
    the serial arms (`disc_mechanism`: CRBA mass matrix, v = bias - gravity torque),
    FiveBarDynamics for the 5R (a closed loop; ``fivebar_model`` is its Python reference). A
    singular five-bar state raises ValueError."""
    qd = v
    q, qd = np.asarray(q, float), np.asarray(qd, float)
    if kind == "fivebar":
        r = fivebar_dynamics(d).evaluate(q, qd)
        if not np.all(r.ok):
            bad = np.flatnonzero(~r.ok)
            raise ValueError(f"five-bar singular or not assembled at {len(bad)} states, first "
                             f"q = {q[bad[0]].tolist()}")
        return r.mass_matrix, r.coriolis_torque, r.gravity_torque
    mech = disc_mechanism(kind, d)
    M, g = mech.mass_matrix(q), mech.gravity_torque(q)
    return M, mech.bias_torque(q, qd) - g, g


def metrics(M, v, g, k=None) -> dict:
    """offdiag_ratio: max over samples of (largest |M_ij|, i != j) / (smallest M_ii);
    coupling: max |M_ij| / sqrt(M_ii M_jj); diag_variation: max_i (max - min)/mean of M_ii over the
    samples; velocity/gravity peaks: max |v_i|, max |g_i|."""
    n = M.shape[1]
    diag = np.einsum("nii->ni", M)
    off = np.abs(M - np.einsum("ni,ij->nij", diag, np.eye(n)))
    out = dict(
        offdiag_ratio=float(np.max(off.max(axis=(1, 2)) / diag.min(axis=1))),
        coupling=float(np.max(off / np.sqrt(np.einsum("ni,nj->nij", diag, diag)))),
        diag_variation=float(np.max((diag.max(0) - diag.min(0)) / diag.mean(0))),
        diag_mean=diag.mean(0),
        peak_velocity_terms=float(np.max(np.abs(v))),
        peak_gravity_torque=float(np.max(np.abs(g))))
    if k is not None:
        out["diag_vs_k"] = float(np.max(np.abs(diag - np.asarray(k)) / np.asarray(k)))
    return out


def perturbed_design(kind: str, p: dict, parameter: str, error: float) -> dict:
    """As built: balancing values computed for the nominal ``p``, then one quantity off by the
    relative ``error``: a gear ratio (beta, gamma), a mass (the balancing l_g stay those of the
    nominal masses) or a built inertia value (e.g. Jy2 of the spatial link 2)."""
    d = design(kind, p, True)
    if parameter not in d:
        raise KeyError(f"sensitivity.parameters: unknown parameter {parameter!r}")
    d[parameter] = d[parameter] * (1.0 + error)
    if kind == "fivebar" and parameter.startswith(("Jp", "Jd")):
        key = ("inertia_p" if parameter[1] == "p" else "inertia_d") + parameter[2]
        d[key] = d[key] * (1.0 + error)
    return d


@renamed_kwargs(qd="v")
def sensitivity(kind: str, p: dict, parameters, errors, q, v) -> list[dict]:
    """How far the balanced mass matrix leaves diagonal/constant (and gravity/velocity terms
    leave zero) when one quantity is off by each relative error."""
    qd = v
    M0, v0, g0 = evaluate(kind, design(kind, p, False), q, qd)
    vmax, gmax = np.max(np.abs(v0)), np.max(np.abs(g0))
    k = np.asarray(BALANCE[kind](p)["k"])
    rows = []
    for name in parameters:
        for e in errors:
            M, v, g = evaluate(kind, perturbed_design(kind, p, name, e), q, qd)
            m = metrics(M, v, g, k)
            rows.append(dict(parameter=name, error_pct=100.0 * e,
                             offdiag_ratio=m["offdiag_ratio"], coupling=m["coupling"],
                             diag_variation=m["diag_variation"], diag_shift_vs_k=m["diag_vs_k"],
                             gravity_peak_over_unbalanced=m["peak_gravity_torque"] / gmax,
                             velocity_peak_over_unbalanced=m["peak_velocity_terms"] / vmax))
    return rows


__doc__ += "\n".join(f"  {c['id']} (eq {c['eq']}): printed {c['printed']}; correct: {c['correct']}."
                     for c in CORRECTIONS)

# ---- a case's parameters (the runner, the balance adapter and the case-file generators) ----
_SPEC = {
    "planar3r": dict(params=("l1", "l2", "m1", "m2", "m3"),
                     bodies=("link1", "link2", "link3", "disc4", "disc5", "disc6", "disc7"),
                     unbalanced=("lg1", "lg2", "lg3"), n=3),
    "spatial3r": dict(params=("l1", "l2", "m1", "m2", "m3"),
                      bodies=("link1", "link2", "link3", "disc4", "disc5"),
                      unbalanced=("lg2", "lg3"), n=3),
    "scara": dict(params=("l1", "l2", "m1", "m2", "m3"),
                  bodies=("link1", "link2", "link3", "disc4", "disc5"),
                  unbalanced=("lg1", "lg2"), n=3),
    "fivebar": dict(params=("a1", "a2", "b1", "b2", "d", "mp1", "mp2", "md1", "md2", "mP",
                            "mP1_share"),
                    bodies=("proximal1", "proximal2", "distal1", "distal2"),
                    unbalanced=("cp1", "cp2", "cd1", "cd2"), n=2),
}
_FIVEBAR_KEYS = {"proximal1": "p1", "proximal2": "p2", "distal1": "d1", "distal2": "d2"}
def _principal_moments(I: np.ndarray, field: str) -> np.ndarray:
    if np.max(np.abs(I - np.diag(np.diag(I)))) > 0.0:
        raise ConfigError(field, "must be principal (give [Jx, Jy, Jz] in the link frame)",
                          I.tolist())
    return np.diag(I).copy()


def parameters_from_config(kind: str, config) -> dict:
    """Flat parameter dict (the names of docs/discs_derivation.md) from a case (validated, or a
    dict validated here); errors name the field."""
    case = validate_case(config, warn=False)
    if case.case.mechanism != kind:
        raise ConfigError("case.mechanism", f"must be {kind!r} here", case.case.mechanism)
    spec = _SPEC[kind]
    pt, it, ut = case.parameters, case.inertia, case.unbalanced
    p = {k: getattr(pt, k) for k in spec["params"]}
    for b in spec["bodies"]:
        J = _principal_moments(inertia_matrix(getattr(it, b)), f"inertia.{b}")
        if kind == "fivebar":
            key = _FIVEBAR_KEYS[b]
            p[f"J{key}"] = J[0]
            p[f"inertia_{key}"] = J
        else:
            i = b[-1]
            p[f"Jx{i}"], p[f"Jy{i}"], p[f"Jz{i}"] = J
    for k in spec["unbalanced"]:
        p[f"{k}_unbal"] = getattr(ut, k)
    for b in ("link1", "link2", "link3"):
        if kind != "fivebar" and getattr(ut, b) is not None:
            J = _principal_moments(inertia_matrix(getattr(ut, b)), f"unbalanced.{b}")
            i = b[-1]
            p[f"Jx{i}_unbal"], p[f"Jy{i}_unbal"], p[f"Jz{i}_unbal"] = J
    if kind == "spatial3r":  # the inertia conditions of eq 25 must give a physical body
        ic = balance_spatial3r(p)["inertia_conditions"]
        for i in (2, 3):
            J = [p[f"Jx{i}"], ic[f"Jy{i}"], p[f"Jz{i}"]]
            inertia(J, f"inertia.link{i} with the eq 25 condition Jy{i} = {ic[f'Jy{i}']:.6g}")
    return p


# importing the schema registers this paper's case kind (mechbal.registry imports this package)
from mechbal.papers.discs import schema as _schema  # noqa: E402,F401
