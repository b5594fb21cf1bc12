"""The general mechanism model from Python: :class:`Mechanism`.

A :class:`Mechanism` wraps the C++ ``MechanismModel`` (a tree of revolute, prismatic and fixed
joints, any number of named bodies on each link, gear couplings, named frames and gravity; see
``cpp/include/mechbal/model.hpp`` for the frame conventions) and exposes every algorithm over it.

Every method takes either one sample (1-D arrays of ``dof`` values) or a batch ((N, dof) arrays),
evaluated in one C++ call. One sample returns plain arrays and raises :class:`ValueError` when the
input is rejected (wrong size, non-finite, overflow); a batch returns arrays with a leading N axis
and a per-instant ``status`` array (0 = ok; see :class:`mechbal.Status`): rejected instants are
zeros, never garbage.

Units: SI throughout (m, kg, kg m^2, rad, N, N m); world quantities in the base frame O; moments
and angular momenta about O's origin.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from mechbal import _core

__all__ = ["Mechanism", "ShakingWrench", "BaseReaction", "Momentum", "BodyMotion"]


@dataclass(frozen=True)
class ShakingWrench:
    """Momenta about O and their rates: the shaking force [N] and moment [N m] (Briot &
    Arakelian 2009, eqs 1-4). Shapes (3,) for one sample, (N, 3) for a batch."""

    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    linear_momentum: np.ndarray
    angular_momentum: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class BaseReaction:
    """Wrench the base exerts on the mechanism, gravity included: force [N], moment about O [N m]."""

    base_reaction_force: np.ndarray
    base_reaction_moment: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class Momentum:
    """Linear momentum [kg m/s] and angular momentum about O [kg m^2/s]."""

    linear_momentum: np.ndarray
    angular_momentum: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class BodyMotion:
    """Every body's motion in O: ``com`` (.., B, 3), ``rotation`` (.., B, 3, 3) body (= link axes)
    to O, ``com_velocity``, ``com_acceleration``, ``angular_velocity``, ``angular_acceleration``
    (.., B, 3); link frames ``link_rotation`` (.., L, 3, 3), ``link_position`` (.., L, 3); named
    frames ``frame_placement`` (.., F, 4, 4)."""

    com: np.ndarray
    rotation: np.ndarray
    com_velocity: np.ndarray
    com_acceleration: np.ndarray
    angular_velocity: np.ndarray
    angular_acceleration: np.ndarray
    link_rotation: np.ndarray
    link_position: np.ndarray
    frame_placement: np.ndarray
    status: np.ndarray


def _status_text(code: int) -> str:
    names = [s.name for s in _core.Status.__members__.values() if int(s) and int(code) & int(s)]
    return " | ".join(names) or "ok"


class Mechanism:
    """A mechanism: the general model plus every algorithm over it (see the module docstring).

    Build one with :meth:`from_urdf`, :meth:`from_toml` or :meth:`from_description`.
    """

    def __init__(self, model: "_core.MechanismModel", *, name: str = "mechanism",
                 source: str | None = None):
        if not isinstance(model, _core.MechanismModel):
            raise TypeError(f"model must be a mechbal._core.MechanismModel, got {type(model).__name__}")
        self.model = model
        self.name = name
        self.source = source

    # ---- construction ------------------------------------------------------------------------
    @classmethod
    def from_description(cls, joints: Sequence["_core.Joint"], bodies: Sequence["_core.Body"] = (),
                         frames: Sequence["_core.Frame"] = (), gravity=(0.0, 0.0, -9.81),
                         root_name: str = "base", name: str = "mechanism") -> "Mechanism":
        """From C++ description objects (:class:`mechbal.Joint`, :class:`mechbal.Body`,
        :class:`mechbal.Frame`). Raises ValueError naming the field on bad input."""
        desc = _core.MechanismDescription(list(joints), list(bodies), list(frames),
                                          np.asarray(gravity, dtype=float), root_name)
        return cls(_core.MechanismModel(desc), name=name)

    @classmethod
    def from_urdf(cls, path: str | Path) -> "Mechanism":
        """Read a URDF file through urdfdom in C++ (the same reader an embedded controller uses):
        links with inertials become bodies named after the links, revolute / continuous /
        prismatic / fixed joints keep their names (continuous = revolute without position
        limits, one coordinate), ``mimic`` becomes a gear coupling, limits are kept, and every
        URDF link is a named frame (see ``cpp/include/mechbal/urdf.hpp`` for the mapping).
        Raises :class:`mechbal.config.ConfigError` (a ValueError) naming the URDF element."""
        from mechbal.config import ConfigError

        path = Path(path)
        field = f"URDF file '{path}'"
        if not path.is_file():
            raise ConfigError(field, "not found", has_value=False)
        try:
            model = _core.mechanism_from_urdf(str(path))
        except ValueError as exc:
            message = str(exc)
            if message.startswith(field + ": "):
                message = message[len(field) + 2:]
            raise ConfigError(field, message, has_value=False) from None
        return cls(model, name=path.stem, source=str(path))

    @classmethod
    def from_urdf_string(cls, xml: str, name: str = "urdf") -> "Mechanism":
        """As :meth:`from_urdf`, from a URDF document held in a string."""
        from mechbal.config import ConfigError

        try:
            model = _core.mechanism_from_urdf_string(xml)
        except ValueError as exc:
            field, _, message = str(exc).partition(": ")  # the C++ message names its element first
            raise ConfigError(field, message, has_value=False) from None
        return cls(model, name=name)

    @classmethod
    def from_toml(cls, path: str | Path) -> "Mechanism":
        """Read the ``[mechanism]`` table of a TOML case file (serial chains, trees, extra bodies,
        gear couplings, frames; see the README's "Describing a mechanism")."""
        from mechbal.config import ConfigError, case_path, chain_from_config, read_toml

        path = case_path(path)
        config = read_toml(path)
        if "mechanism" not in config:
            raise ConfigError("mechanism", "is required", has_value=False)
        chain = chain_from_config(config["mechanism"])
        model = _core.MechanismModel(_core.chain_description(chain))
        return cls(model, name=path.stem, source=str(path))

    # ---- structure ---------------------------------------------------------------------------
    @property
    def dof(self) -> int:
        """Number of independent coordinates (gear-coupled joints follow their master)."""
        return self.model.dof

    @property
    def joint_names(self) -> list[str]:
        """Names of the joints whose positions are the coordinates q, in order."""
        return list(self.model.coordinate_names)

    @property
    def link_names(self) -> list[str]:
        """Link names, the base first (each joint moves the link of its name)."""
        return list(self.model.link_names)

    @property
    def body_names(self) -> list[str]:
        return list(self.model.body_names)

    @property
    def frame_names(self) -> list[str]:
        return list(self.model.frame_names)

    @property
    def total_mass(self) -> float:
        """Total mass of all bodies [kg]."""
        return float(self.model.total_mass)

    @property
    def gravity(self) -> np.ndarray:
        return np.array(self.model.gravity)

    @property
    def bodies(self):
        return list(self.model.bodies)

    def __repr__(self) -> str:
        return (f"<Mechanism {self.name!r}: {self.dof} dof, {len(self.link_names) - 1} joints, "
                f"{len(self.body_names)} bodies, {self.total_mass:.4g} kg>")

    # ---- argument handling -------------------------------------------------------------------
    def _args(self, names: tuple[str, ...], values: tuple) -> tuple[bool, list[np.ndarray]]:
        arrays = []
        single = None
        for name, value in zip(names, values):
            a = np.asarray(value)
            if a.dtype.kind not in "biuf":
                raise TypeError(f"{name} must be a real numeric array, got dtype {a.dtype}")
            a = np.ascontiguousarray(a, dtype=float)
            if a.ndim == 1:
                is_single = True
                a = a.reshape(1, -1)
            elif a.ndim == 2:
                is_single = False
            else:
                raise ValueError(f"{name} must have shape ({self.dof},) or (N, {self.dof}), got {a.shape}")
            if a.shape[1] != self.dof:
                raise ValueError(f"{name} must have shape ({self.dof},) or (N, {self.dof}), "
                                 f"got {np.asarray(value).shape}")
            if single is None:
                single = is_single
            elif single != is_single or a.shape[0] != arrays[0].shape[0]:
                raise ValueError(f"{name} has shape {np.asarray(value).shape}, which does not match "
                                 f"{names[0]} {np.asarray(values[0]).shape}")
            arrays.append(a)
        return bool(single), arrays

    def _finish(self, single: bool, result: dict, keys: Sequence[str]):
        status = np.asarray(result["status"])
        if single:
            if status[0] != 0:
                raise ValueError(f"{self.name}: input rejected ({_status_text(int(status[0]))}); "
                                 "q, v, a must be finite, of the right size, and give finite results")
            return [np.asarray(result[k])[0] for k in keys], status[0]
        return [np.asarray(result[k]) for k in keys], status

    # ---- algorithms --------------------------------------------------------------------------
    def inverse_dynamics(self, q, v, a) -> np.ndarray:
        """Joint forces tau = M(q) a + C(q, v) v + G(q) [N m or N], gear couplings projected.
        A batch returns (N, dof); see :meth:`status_of` for per-instant statuses."""
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (tau,), _ = self._finish(single, _core.mechanism_inverse_dynamics(self.model, q, v, a),
                                 ["joint_torque"])
        return tau

    def mass_matrix(self, q) -> np.ndarray:
        """Joint-space mass matrix M(q) (dof, dof) [kg m^2, kg]; a batch gives (N, dof, dof)."""
        single, (q,) = self._args(("q",), (q,))
        (M,), _ = self._finish(single, _core.mechanism_mass_matrix(self.model, q), ["mass_matrix"])
        return M

    def gravity_torque(self, q) -> np.ndarray:
        """Gravity torques G(q): the joint forces that hold the mechanism still [N m or N]."""
        single, (q,) = self._args(("q",), (q,))
        (g,), _ = self._finish(single, _core.mechanism_gravity_torque(self.model, q), ["gravity_torque"])
        return g

    def bias_torque(self, q, v) -> np.ndarray:
        """C(q, v) v + G(q) [N m or N]."""
        single, (q, v) = self._args(("q", "v"), (q, v))
        (b,), _ = self._finish(single, _core.mechanism_bias_torque(self.model, q, v), ["bias_torque"])
        return b

    def center_of_mass(self, q) -> np.ndarray:
        """Centre of mass of all bodies in O [m]: (3,) or (N, 3)."""
        single, (q,) = self._args(("q",), (q,))
        (c,), _ = self._finish(single, _core.mechanism_center_of_mass(self.model, q), ["center_of_mass"])
        return c

    def momentum(self, q, v) -> Momentum:
        """Linear momentum and angular momentum about O."""
        single, (q, v) = self._args(("q", "v"), (q, v))
        (P, H), st = self._finish(single, _core.mechanism_momentum(self.model, q, v),
                                  ["linear_momentum", "angular_momentum"])
        return Momentum(P, H, st)

    def momentum_matrix(self, q) -> np.ndarray:
        """A(q) with [P; H_O] = A(q) v: (6, dof), linear rows first."""
        single, (q,) = self._args(("q",), (q,))
        (A,), _ = self._finish(single, _core.mechanism_momentum_matrix(self.model, q), ["momentum_matrix"])
        return A

    def shaking_wrench(self, q, v, a) -> ShakingWrench:
        """Shaking force F = dP/dt [N] and shaking moment M_O = dH_O/dt [N m] about O, with the
        momenta, for the motion (q, v, a) (Briot & Arakelian 2009, eqs 1-4)."""
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (F, M, P, H), st = self._finish(
            single, _core.mechanism_shaking_wrench(self.model, q, v, a, False),
            ["shaking_force", "shaking_moment", "linear_momentum", "angular_momentum"])
        return ShakingWrench(F, M, P, H, st)

    def base_reaction(self, q, v, a) -> BaseReaction:
        """Wrench the base exerts on the mechanism, gravity included: force = dP/dt - m g,
        moment about O = dH_O/dt - (m c) x g."""
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (F, M), st = self._finish(single, _core.mechanism_shaking_wrench(self.model, q, v, a, True),
                                  ["base_reaction_force", "base_reaction_moment"])
        return BaseReaction(F, M, st)

    def body_motion(self, q, v=None, a=None) -> BodyMotion:
        """Every body's pose, velocity and acceleration in O (v and a default to zero)."""
        q_arr = np.asarray(q, dtype=float)
        v = np.zeros_like(q_arr) if v is None else v
        a = np.zeros_like(q_arr) if a is None else a
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        keys = ["com", "rotation", "com_velocity", "com_acceleration", "angular_velocity",
                "angular_acceleration", "link_rotation", "link_position", "frame_placement"]
        values, st = self._finish(single, _core.mechanism_kinematics(self.model, q, v, a), keys)
        return BodyMotion(*values, st)

    def body_poses(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(com, rotation) of every body: (B, 3) and (B, 3, 3), or with a leading N axis."""
        m = self.body_motion(q)
        return m.com, m.rotation

    def frame_placement(self, q, frame: str) -> np.ndarray:
        """4x4 placement of a named frame in O."""
        i = self._frame(frame)
        return self.body_motion(q).frame_placement[..., i, :, :]

    def frame_jacobian(self, q, frame: str) -> np.ndarray:
        """[v; w] = J(q) qdot of a named frame's origin, O's axes: (6, dof)."""
        self._frame(frame)
        single, (q,) = self._args(("q",), (q,))
        (J,), _ = self._finish(single, _core.mechanism_frame_jacobian(self.model, q, frame), ["jacobian"])
        return J

    def torque_regressor(self, q, v, a) -> np.ndarray:
        """Y(q, v, a) with tau = Y pi, pi the stacked 10 inertial parameters of every body
        ([m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], c and I about the link origin, link frame)."""
        single, (q, v, a) = self._args(("q", "v", "a"), (q, v, a))
        (Y,), _ = self._finish(single, _core.mechanism_torque_regressor(self.model, q, v, a), ["regressor"])
        return Y

    def gravity_regressor(self, q) -> np.ndarray:
        """Y(q) with G(q) = Y pi."""
        single, (q,) = self._args(("q",), (q,))
        (Y,), _ = self._finish(single, _core.mechanism_gravity_regressor(self.model, q), ["regressor"])
        return Y

    def momentum_regressor(self, q, v) -> np.ndarray:
        """Y(q, v) with [P; H_O] = Y pi (6, 10 B)."""
        single, (q, v) = self._args(("q", "v"), (q, v))
        (Y,), _ = self._finish(single, _core.mechanism_momentum_regressor(self.model, q, v), ["regressor"])
        return Y

    def inertial_parameters(self) -> np.ndarray:
        """pi: the stacked 10 inertial parameters of every body, in the regressors' convention."""
        out = []
        for b in self.model.bodies:
            m, c, I = b.mass, np.asarray(b.com), np.asarray(b.inertia)
            Io = I + m * (c @ c * np.eye(3) - np.outer(c, c))
            out.append([m, *(m * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])
        return np.array(out, dtype=float).reshape(-1)

    def _frame(self, frame: str) -> int:
        i = self.model.frame_index(frame)
        if i < 0:
            import difflib
            hint = difflib.get_close_matches(frame, self.frame_names, n=1)
            more = f" (did you mean '{hint[0]}'?)" if hint else f" (frames: {', '.join(self.frame_names)})"
            raise ValueError(f"frame: no frame named '{frame}'{more}")
        return i
