"""What is identified on a mechanism: one rigid body per moving segment, and friction per joint.

A *segment* is a link moved by a joint that is not fixed, together with every link fixed to it;
its 10 inertial parameters ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` (the
regressors' order, `mechbal.mechanism.INERTIAL_PARAMETER_NAMES`; inertia about the link origin,
in the link frame) are the sum of its bodies' and are what the joint torques can tell. Bodies on
the base (and on links fixed to it) never move and are kept as they are. Each segment is named
after its link as a file names it (`mechbal.export.common.link_labels`: a URDF's link names).

Friction of coordinate j: ``tau_f = viscous v_j + coulomb sign(v_j) + offset`` [N m s/rad, N m,
N m] (N s/m, N, N for a prismatic joint).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechbal import _core
from mechbal.export.common import link_labels
from mechbal.mechanism import INERTIAL_PARAMETER_NAMES, Mechanism

__all__ = ["Structure", "structure_of", "body_parameters", "parameters_to_body",
           "FRICTION_NAMES"]

FRICTION_NAMES = ("viscous", "coulomb", "offset")


def body_parameters(mass: float, com, inertia) -> np.ndarray:
    """The 10 parameters of a body of ``mass`` [kg], centre of mass ``com`` [m] and inertia about
    it ``inertia`` (3, 3) [kg m^2], all in one frame: inertia moved to the frame's origin."""
    m, c, I = float(mass), np.asarray(com, float), np.asarray(inertia, float)
    Io = I + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])


def parameters_to_body(pi) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, com, inertia about the com) of 10 parameters (mass > 0; else com 0 and the
    inertia about the origin)."""
    pi = np.asarray(pi, float)
    m = float(pi[0])
    Io = np.array([[pi[4], pi[5], pi[7]], [pi[5], pi[6], pi[8]], [pi[7], pi[8], pi[9]]])
    if m <= 0.0:
        return m, np.zeros(3), Io
    c = pi[1:4] / m
    Ic = Io - m * (c @ c * np.eye(3) - np.outer(c, c))
    return m, c, 0.5 * (Ic + Ic.T)


def _transform_parameters(pi: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Parameters of a body given in frame B, expressed in frame A where T = A_T_B."""
    m, c, Ic = parameters_to_body(pi) if pi[0] > 0 else (0.0, np.zeros(3), None)
    R, p = T[:3, :3], T[:3, 3]
    if m > 0:
        return body_parameters(m, R @ c + p, R @ Ic @ R.T)
    _, _, Io = parameters_to_body(pi)
    return body_parameters(0.0, p, R @ Io @ R.T)


@dataclass(frozen=True)
class Structure:
    """The identification structure of a mechanism (module docstring)."""

    mechanism: Mechanism
    #: mechbal link of each segment, and its name (a file's link name)
    segment_links: tuple[str, ...]
    segment_names: tuple[str, ...]
    #: the mechanism with one unit body per segment (named after it): its regressor's columns
    #: are the segments' parameters
    regressor_mechanism: Mechanism
    #: the CAD parameters of every segment (10 S,), from the mechanism's bodies
    cad: np.ndarray
    #: bodies on the base, kept as they are
    base_bodies: tuple

    @property
    def dof(self) -> int:
        return self.mechanism.dof

    @property
    def joint_names(self) -> list[str]:
        return self.mechanism.joint_names

    @property
    def inertial_names(self) -> list[str]:
        return [f"{s}.{p}" for s in self.segment_names for p in INERTIAL_PARAMETER_NAMES]

    @property
    def friction_names(self) -> list[str]:
        return [f"{j}.{k}" for j in self.joint_names for k in FRICTION_NAMES]

    @property
    def parameter_names(self) -> list[str]:
        return self.inertial_names + self.friction_names

    @property
    def n_inertial(self) -> int:
        return 10 * len(self.segment_links)

    def regressor(self, q, v, a, sign_v=None, *, friction: bool = True) -> np.ndarray:
        """Stacked regressor (N dof, P), rows sample-major (sample k, joint j at k dof + j), of
        the inertial parameters and (``friction``) the friction parameters; ``sign_v``: the
        Coulomb column (default sign(v))."""
        q, v, a = (np.atleast_2d(np.asarray(x, float)) for x in (q, v, a))
        N, n = q.shape
        Y = np.asarray(self.regressor_mechanism.torque_regressor(q, v, a))
        if Y.ndim == 2:
            Y = Y[None]
        status = getattr(Y, "status", None)
        Y = np.asarray(Y)
        if status is not None and np.any(np.asarray(status) != 0):
            k = int(np.flatnonzero(np.asarray(status) != 0)[0])
            raise ValueError(f"the regressor was refused at sample {k} (status {int(np.asarray(status)[k])})")
        Y = Y.reshape(N * n, -1)
        if not friction:
            return Y
        s = np.sign(v) if sign_v is None else np.asarray(sign_v, float)
        F = np.zeros((N, n, n, 3))
        idx = np.arange(n)
        F[:, idx, idx, 0] = v
        F[:, idx, idx, 1] = s
        F[:, idx, idx, 2] = 1.0
        return np.hstack([Y, F.reshape(N * n, 3 * n)])


def structure_of(mech: Mechanism) -> Structure:
    """The segments of ``mech`` and their CAD parameters; ValueError for a closed mechanism
    (identification from joint torques needs a tree)."""
    if mech.is_closed:
        raise ValueError(f"identification needs a tree: {mech.name} has loop closures (identify the "
                         "open tree, then close it)")
    if mech.springs:
        raise ValueError(f"identification of a mechanism with springs is not supported: {mech.name} has "
                         f"{len(mech.springs)} (identify the robot without them)")
    d = mech.model.description
    root = d.root_name
    joint_of = {j.name: j for j in d.joints}
    # carrier segment of every link and the link's placement in it
    carrier: dict[str, tuple[str, np.ndarray]] = {root: (root, np.eye(4))}
    pending = list(d.joints)
    while pending:
        rest = []
        for j in pending:
            if j.parent not in carrier:
                rest.append(j)
                continue
            pc, pT = carrier[j.parent]
            if j.type == _core.JointType.fixed:
                carrier[j.name] = (pc, pT @ np.asarray(j.placement, float))
            else:
                carrier[j.name] = (j.name, np.eye(4))
        if len(rest) == len(pending):
            raise ValueError("the joints do not form a tree from the root")
        pending = rest
    labels = link_labels(mech)
    segments = [j.name for j in d.joints if j.type != _core.JointType.fixed]
    index = {s: i for i, s in enumerate(segments)}
    cad = np.zeros(10 * len(segments))
    base_bodies = []
    for b in d.bodies:
        seg, T = carrier[b.link]
        pi = body_parameters(b.mass, b.com, b.inertia)
        if seg == root:
            base_bodies.append(b)
            continue
        if not np.array_equal(T, np.eye(4)):
            pi = _transform_parameters(pi, T)
        cad[10 * index[seg]: 10 * index[seg] + 10] += pi
    names = tuple(labels[s] for s in segments)
    unit = [_core.Body(f"{n}", s, 1.0, np.zeros(3), 0.01 * np.eye(3)) for s, n in zip(segments, names)]
    desc = _core.MechanismDescription(list(d.joints), unit, list(d.frames), np.asarray(d.gravity, float),
                                      d.root_name, [], list(d.actuated), [])
    reg = Mechanism(_core.MechanismModel(desc), name=mech.name, source=mech.source,
                    link_frames=mech.link_frames)
    del joint_of
    return Structure(mechanism=mech, segment_links=tuple(segments), segment_names=names,
                     regressor_mechanism=reg, cad=cad, base_bodies=tuple(base_bodies))
