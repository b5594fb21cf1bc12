"""The planar 5R five-bar of the discs case (Coutinho & Hess Coelho, "A new approach for designing
dynamic balanced serial mechanisms": the 5R named in the abstract; model and balancing in
docs/discs_derivation.md section 5) on the general mechanism model, as a tree of two legs and one
loop closure.

Geometry (as ``mechbal.FiveBarDynamics`` and ``mechbal.papers.discs.fivebar_model``): the vertical
y-z plane, every joint axis along x, z up, gravity (0, 0, -g). Leg i is a 2R arm:

* ``theta1`` / ``theta2``: proximal link i about x at A_1 = 0 / A_2 = (0, d, 0); the joint angle is
  the link's absolute angle from +y (its frame Rx(theta_i): y along the link);
* ``theta12`` / ``theta22``: distal link i about x at the elbow B_i = A_i + a_i e(theta_i), angle
  relative to the proximal link (the paper's theta_i2);
* bodies ``proximal1/2``, ``distal1/2`` at (0, c, 0) of their link frames with the central inertias
  of the case (``inertia.proximal1`` ...: [Jx, Jy, Jz] in the link frame, x = joint axis), and
  ``end_effector``: the point mass m_P at the tip of distal link 1 (where both distal links meet);
* the loop ``tip``: a ``planar_point`` closure between the distal tips (frames ``tip1`` on
  ``theta12`` and ``tip2`` on ``theta22`` at (0, b_i, 0), z axes along the joint axes x): the two
  in-plane equations of the paper's constraint rows v_P - J_tip,i qd_leg,i = 0, integrated;
* actuated ``theta1``, ``theta2``; passive ``theta12``, ``theta22``.

The five-bar has no counter-rotating discs: its balancing is leg-wise static balancing (the
balanced centres of mass of ``mechbal.papers.discs.balance_fivebar``).

The closed form (`FiveBarDynamics`, the C++ per-tick evaluator with typed results, in
`mechbal.papers.discs.five_bar_dynamics`: its torques as an array like
`mechbal.Mechanism.inverse_dynamics`, `FiveBarTerms` M', v', g' and `FiveBarMotion`, the
passive motion from the coupling projection) equals this general model to 1e-10 along the case's trajectory
(tests/python/test_papers_loops.py); the ``discs`` runner writes the five-bar's bodies files and
shaking wrench from this model, its loop solved along the trajectory; ``python/mechbal/papers/discs/cases/five-bar-linkage.toml`` is
`five_bar_case_toml` of the shipped ``five-bar`` case (balanced), run by ``mechbal run``.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import numpy as np

from mechbal import _core
from mechbal.mechanism import Mechanism
from mechbal.papers.discs.five_bar_dynamics import FiveBarDynamics, FiveBarMotion, FiveBarTerms

__all__ = ["FiveBarDynamics", "FiveBarTerms", "FiveBarMotion", "five_bar_mechanism",
           "five_bar_design_mechanism", "five_bar_initial_guess", "five_bar_case_toml"]


_EX = np.array([1.0, 0.0, 0.0])
#: a frame whose z axis is the link frame's x (the joint axis): columns (y, z, x)
_PLANE_FRAME = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _T(y: float = 0.0, R: np.ndarray | None = None) -> np.ndarray:
    T = np.eye(4)
    T[1, 3] = float(y)
    if R is not None:
        T[:3, :3] = R
    return T


def five_bar_design_mechanism(d: Mapping[str, Any], *, name: str = "five-bar",
                              gravity: float = 9.81) -> Mechanism:
    """A five-bar design (``mechbal.papers.discs.design("fivebar", p, balanced)``: lengths a_i, b_i,
    d, masses mp_i, md_i, mP, centres of mass cp_i, cd_i, inertias ``inertia_p1`` ...) as a closed
    `mechbal.Mechanism` (module docstring)."""
    R = _core.JointType.revolute
    joints, bodies = [], []
    for i in (1, 2):
        prox, dist = f"theta{i}", f"theta{i}2"
        joints.append(_core.Joint(prox, R, "base", _T(d["d"] if i == 2 else 0.0), _EX))
        joints.append(_core.Joint(dist, R, prox, _T(d[f"a{i}"]), _EX))
        bodies.append(_core.Body(f"proximal{i}", prox, float(d[f"mp{i}"]),
                                 np.array([0.0, d[f"cp{i}"], 0.0]), np.diag(d[f"inertia_p{i}"]), "link"))
        bodies.append(_core.Body(f"distal{i}", dist, float(d[f"md{i}"]),
                                 np.array([0.0, d[f"cd{i}"], 0.0]), np.diag(d[f"inertia_d{i}"]), "link"))
    bodies.append(_core.Body("end_effector", "theta12", float(d["mP"]), np.array([0.0, d["b1"], 0.0]),
                             np.zeros((3, 3)), "payload"))
    frames = [_core.Frame("tip1", "theta12", _T(d["b1"], _PLANE_FRAME)),
              _core.Frame("tip2", "theta22", _T(d["b2"], _PLANE_FRAME))]
    loops = [_core.LoopConstraint("tip", _core.LoopType.planar_point, "tip1", "tip2")]
    return Mechanism.from_description(joints, bodies, frames, (0.0, 0.0, -float(gravity)), name=name,
                                      loops=loops, actuated=["theta1", "theta2"])


def five_bar_initial_guess(mech: Mechanism, d: Mapping[str, Any], q_actuated) -> np.ndarray:
    """Every coordinate at actuated angles (theta1, theta2), in the assembly mode of the closed form
    (``mechbal.papers.discs.fivebar_positions``: nearest the parallelogram point)."""
    from mechbal.papers.discs import fivebar_positions

    th1, th2 = map(float, q_actuated)
    B1, B2, P = fivebar_positions(d, th1, th2)
    values = {"theta1": th1, "theta2": th2,
              "theta12": np.arctan2((P - B1)[2], (P - B1)[1]) - th1,
              "theta22": np.arctan2((P - B2)[2], (P - B2)[1]) - th2}
    return np.array([values[n] for n in mech.joint_names])


def _case(case_config):
    from mechbal.config import read_case

    return read_case(case_config) if isinstance(case_config, (str, Path)) else case_config


def five_bar_mechanism(case_config: Mapping[str, Any] | str | Path = "five-bar",
                       balanced: bool = True) -> Mechanism:
    """The five-bar of a ``discs`` case with ``case.mechanism = "fivebar"`` (a case name, path or
    loaded TOML dict), balanced (leg-wise static balancing) or the case's ``[unbalanced]``
    baseline, from the runner's parameters (``mechbal.papers.discs.parameters_from_config``)."""
    from mechbal.papers.discs import parameters_from_config
    from mechbal.papers import discs as dz

    config = _case(case_config)
    p = parameters_from_config("fivebar", config)
    variant = "balanced" if balanced else "unbalanced"
    return five_bar_design_mechanism(dz.design("fivebar", p, balanced),
                                     name=f"{config['case']['name']} ({variant})")


def five_bar_case_toml(case_config: Mapping[str, Any] | str | Path = "five-bar",
                       balanced: bool = True) -> str:
    """The ``kind = "mechanism"`` case file of a five-bar case's mechanism with the case's
    trajectory (rest-to-rest in (theta1, theta2)) and the closed form's assembly as the initial
    guess: what ``python/mechbal/papers/discs/cases/five-bar-linkage.toml`` holds for the shipped case."""
    from mechbal.papers.discs import parameters_from_config
    from mechbal.papers._toml import case_toml
    from mechbal.papers import discs as dz

    config = _case(case_config)
    p = parameters_from_config("fivebar", config)
    d = dz.design("fivebar", p, balanced)
    mech = five_bar_design_mechanism(d)
    tr = config["trajectory"]
    variant = "balanced by leg-wise static balancing" if balanced else "unbalanced baseline"
    header = f"""\
The parallelogram 5R five-bar of the `{config['case']['name']}` case, {variant}, as data on
the general model: two 2R legs in the vertical y-z plane (joint axes x, z up, gravity -z) closed by
one planar point loop at the end effector. Coutinho & Hess Coelho (the 5R of the abstract; design
and balancing in docs/discs_derivation.md section 5). Generated by
mechbal.papers.discs.five_bar.five_bar_case_toml("{config['case']['name']}"); the closed form
FiveBarDynamics equals it to 1e-10 (tests/python/test_papers_loops.py). Do not edit by hand:
regenerate. Units SI, angles rad; theta_i from +y, theta_i2 relative to the proximal link."""
    traj = {"law": "quintic", "start": tr["start"], "end": tr["end"], "duration": tr["duration"],
            "samples": tr["samples"], "initial_guess": five_bar_initial_guess(mech, d, tr["start"])}
    comments = {"theta1": "actuated: proximal link 1, angle from +y", "theta2": "actuated: proximal link 2",
                "theta12": "passive: distal link 1, relative angle", "theta22": "passive: distal link 2",
                "end_effector": "point mass where the distal links meet",
                "tip": "the distal tips coincide in the y-z plane",
                "trajectory.initial_guess": "theta1, theta12, theta2, theta22: the closed form's assembly"}
    return case_toml(mech, name="five-bar-linkage", title=f"Five-bar linkage ({variant}) on the general "
                     "model, quintic motion of both actuators", header=header, trajectory=traj,
                     comments=comments)
