"""Sweep parameters: what a path names in a mechanism, its nominal value, its distribution, and how
a whole matrix of values is turned into models (rebuilt) or inertial parameters (batched).

A path names one number of a `mechbal.spec.MechanismSpec` (the data the general model is
built from, whatever the source: TOML, URDF, code), or a design variable:

==========================================  ==========================================================
``bodies.<body>.mass``                      kg
``bodies.<body>.com[i]``                    m, centre of mass in the link frame (i = 0, 1, 2)
``bodies.<body>.inertia[k]``                kg m^2 about the centre of mass, link axes: k = 0..5 is
                                            [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (the TOML order);
``bodies.<body>.inertia[i][j]``             or one entry of the 3x3 matrix (its mirror follows)
``joints.<joint>.placement.xyz[i]``         m, joint frame in the parent link's frame at q = 0
``joints.<joint>.placement.rpy[i]``         rad, roll-pitch-yaw of that placement
``joints.<joint>.axis[i]``                  axis in the joint frame (normalised after the change)
``gravity[i]``                              m/s^2, in O
``design.<name>``                           a design variable: not in the mechanism, handed to the
                                            callable metrics (e.g. a spring rate of a balancing
                                            method); needs a ``nominal``
==========================================  ==========================================================

A joint's link body is named after the joint (``bodies.elbow.mass`` is the elbow link's mass).
The link frame is the frame right after the joint's motion: for a joint given by ``origin`` in a
TOML file it is the frame the file uses; for a standard-DH joint the spec has already moved the
file's values into it (see `mechbal.spec`).

**Body parameters are batched**: a body's mass, centre of mass and inertia enter the inertial
parameters pi linearly or as a cheap closed form (pi = [m, m c, I_c + m (c.c 1 - c c^T)]), and
every metric of the sweep is Y(q) pi with a regressor Y that does not depend on them: one regressor
evaluation, then a matrix product over thousands of parameter sets. **Joint and gravity parameters
are geometric**: the model is rebuilt for each set that changes one.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from mechbal.errors import ConfigError

#: [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] -> matrix entry
_INERTIA_FLAT = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]

_BODY = re.compile(r"^bodies\.(?P<name>.+)\.(?P<attr>mass|com\[(?P<c>[0-2])\]|"
                   r"inertia\[(?P<k>[0-5])\](?:\[(?P<j>[0-2])\])?)$")
_JOINT = re.compile(r"^joints\.(?P<name>.+)\.(?P<attr>placement\.(?P<part>xyz|rpy)\[(?P<i>[0-2])\]|"
                    r"axis\[(?P<a>[0-2])\])$")
_GRAVITY = re.compile(r"^gravity\[(?P<i>[0-2])\]$")
_DESIGN = re.compile(r"^design\.(?P<name>[A-Za-z_][A-Za-z0-9_.-]*)$")

PATH_FORMS = ("bodies.<body>.mass", "bodies.<body>.com[i]", "bodies.<body>.inertia[k]",
              "bodies.<body>.inertia[i][j]", "joints.<joint>.placement.xyz[i]",
              "joints.<joint>.placement.rpy[i]", "joints.<joint>.axis[i]", "gravity[i]",
              "design.<name>")


@dataclass(frozen=True)
class Target:
    """What a path resolves to: ``kind`` body | joint | gravity | design, the ``name`` of the body,
    joint or design variable, and the entry: ``attr`` (mass, com, inertia, xyz, rpy, axis,
    gravity), ``index`` (a component, or an (i, j) pair of the inertia matrix)."""

    kind: str
    name: str
    attr: str
    index: Any = None

    @property
    def batched(self) -> bool:
        """True when the value enters the inertial parameters only (no model rebuild)."""
        return self.kind in ("body", "design")


def parse_path(path: str, field: str = "path") -> Target:
    """The `Target` of a parameter path (ConfigError listing the forms otherwise)."""
    if not isinstance(path, str):
        raise ConfigError(field, "must be a string", path)
    m = _BODY.match(path)
    if m:
        if m["attr"] == "mass":
            return Target("body", m["name"], "mass")
        if m["c"] is not None:
            return Target("body", m["name"], "com", int(m["c"]))
        k, j = int(m["k"]), m["j"]
        if j is not None:
            if k > 2:
                raise ConfigError(field, "inertia[i][j] takes i, j in 0..2", path)
            return Target("body", m["name"], "inertia", (k, int(j)))
        return Target("body", m["name"], "inertia", _INERTIA_FLAT[k])
    m = _JOINT.match(path)
    if m:
        if m["part"] is not None:
            return Target("joint", m["name"], m["part"], int(m["i"]))
        return Target("joint", m["name"], "axis", int(m["a"]))
    m = _GRAVITY.match(path)
    if m:
        return Target("gravity", "gravity", "gravity", int(m["i"]))
    m = _DESIGN.match(path)
    if m:
        return Target("design", m["name"], "design")
    head = path.split(".", 1)[0].split("[", 1)[0]
    from mechbal.schema import did_you_mean

    hint = did_you_mean(head, ["bodies", "joints", "gravity", "design"]) if head else ""
    hint = hint if "did you" in hint else ""
    raise ConfigError(field, f"not a parameter path{hint}: use one of {', '.join(PATH_FORMS)}", path)


def rpy_of(R: np.ndarray) -> np.ndarray:
    """Roll-pitch-yaw of a rotation R = Rz(yaw) Ry(pitch) Rx(roll) (inverse of
    `mechbal.spec.rotation_rpy`)."""
    yaw = math.atan2(R[1, 0], R[0, 0])
    pitch = math.atan2(-R[2, 0], math.hypot(R[2, 1], R[2, 2]))
    roll = math.atan2(R[2, 1], R[2, 2])
    return np.array([roll, pitch, yaw])


def nominal_value(spec, target: Target, field: str = "path") -> float:
    """The value a path has in ``spec`` (ConfigError naming the nearest body or joint if unknown)."""
    from mechbal.schema import did_you_mean

    if target.kind == "body":
        bodies = {b.name: b for b in spec.bodies}
        if target.name not in bodies:
            raise ConfigError(field, f"no body named {target.name!r}{did_you_mean(target.name, list(bodies))}",
                              has_value=False)
        b = bodies[target.name]
        if target.attr == "mass":
            return float(b.mass)
        if target.attr == "com":
            return float(b.com[target.index])
        return float(b.inertia[target.index])
    if target.kind == "joint":
        joints = {j.name: j for j in spec.joints}
        if target.name not in joints:
            raise ConfigError(field, f"no joint named {target.name!r}{did_you_mean(target.name, list(joints))}",
                              has_value=False)
        j = joints[target.name]
        if target.attr == "xyz":
            return float(j.placement[target.index, 3])
        if target.attr == "rpy":
            return float(rpy_of(np.asarray(j.placement)[:3, :3])[target.index])
        if j.type == "fixed":
            raise ConfigError(field, f"joint {target.name!r} is fixed: it has no axis", has_value=False)
        return float(j.axis[target.index])
    if target.kind == "gravity":
        return float(spec.gravity[target.index])
    raise ConfigError(field, "a design variable needs a nominal value", has_value=False)


def apply_values(spec, targets: Sequence[Target], values: Sequence[float], nominal: Sequence[float]):
    """A copy of ``spec`` with every non-design target that differs from its nominal value set to
    its value (a parameter at its nominal value leaves the spec's own number untouched)."""
    from mechbal.spec import rotation_rpy

    bodies = {b.name: dict(mass=b.mass, com=np.array(b.com, float), inertia=np.array(b.inertia, float))
              for b in spec.bodies}
    joints: dict[str, dict] = {}
    gravity = np.array(spec.gravity, float)
    changed_bodies, rpy_changes = set(), {}
    for t, v, n in zip(targets, values, nominal):
        if t.kind == "design" or v == n:
            continue
        v = float(v)
        if t.kind == "body":
            b = bodies[t.name]
            changed_bodies.add(t.name)
            if t.attr == "mass":
                b["mass"] = v
            elif t.attr == "com":
                b["com"][t.index] = v
            else:
                i, j = t.index
                b["inertia"][i, j] = b["inertia"][j, i] = v
        elif t.kind == "gravity":
            gravity[t.index] = v
        else:
            j = spec.joint(t.name)
            d = joints.setdefault(t.name, dict(placement=np.array(j.placement, float),
                                               axis=np.array(j.axis, float)))
            if t.attr == "xyz":
                d["placement"][t.index, 3] = v
            elif t.attr == "rpy":
                rpy_changes.setdefault(t.name, rpy_of(np.asarray(j.placement)[:3, :3]))[t.index] = v
            else:
                d["axis"][t.index] = v
    for name, rpy in rpy_changes.items():
        joints[name]["placement"][:3, :3] = rotation_rpy(rpy)
    new_joints = []
    for j in spec.joints:
        if j.name in joints:
            d = joints[j.name]
            axis = d["axis"]
            norm = float(np.linalg.norm(axis))
            axis = axis / norm if norm > 0 else axis  # a zero axis is refused by the model
            j = dataclasses.replace(j, placement=d["placement"], axis=axis)
        new_joints.append(j)
    new_bodies = [dataclasses.replace(b, **bodies[b.name]) if b.name in changed_bodies else b
                  for b in spec.bodies]
    return dataclasses.replace(spec, joints=new_joints, bodies=new_bodies, gravity=gravity)


# ---- inertial parameters of many parameter sets at once ----------------------------------------

def inertial_parameters(mass: np.ndarray, com: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """pi (S, 10) = [m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about the link origin, from masses (S,),
    centres of mass (S, 3) and inertias about the centre of mass (S, 3, 3), all in the link frame
    (the convention of `mechbal.Mechanism.inertial_parameters` and the regressors)."""
    cc = np.einsum("si,si->s", com, com)
    Io = inertia + mass[:, None, None] * (cc[:, None, None] * np.eye(3) - com[:, :, None] * com[:, None, :])
    return np.column_stack([mass, mass[:, None] * com, Io[:, 0, 0], Io[:, 0, 1], Io[:, 1, 1],
                            Io[:, 0, 2], Io[:, 1, 2], Io[:, 2, 2]])


def physical_status(mass: np.ndarray, inertia: np.ndarray | None) -> np.ndarray:
    """(S,) bool: masses >= 0 and inertias symmetric positive semi-definite that satisfy the
    triangle inequality (the checks of the C++ ``validate_rigid_body``)."""
    ok = np.isfinite(mass) & (mass >= 0)
    if inertia is not None:
        scale = np.maximum(1.0, np.max(np.abs(inertia), axis=(1, 2)))
        p = np.linalg.eigvalsh(inertia)
        tol = 1e-12 * scale
        ok &= np.all(np.isfinite(inertia), axis=(1, 2)) & (p[:, 0] >= -tol) & (p[:, 2] <= p[:, 0] + p[:, 1] + tol)
    return ok


__all__ = ["PATH_FORMS", "Target", "apply_values", "inertial_parameters", "nominal_value", "parse_path",
           "physical_status", "rpy_of"]
