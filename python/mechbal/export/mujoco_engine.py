"""A mechanism's MJCF export in MuJoCo: an independent engine for mechbal's results.

Needs the optional extra ``mechbal[mujoco]`` (imported when used; a clear ImportError otherwise).

`MujocoMechanism` loads ``mech.to_mjcf()`` and gives, in mechbal's coordinates:

* `inverse_dynamics`: MuJoCo's inverse dynamics (``mj_inverse``) on
  mechbal's full (q, v, a) with the constraints (loops, gears, limits) switched off, i.e. the
  tree's joint forces, projected on mechbal's coordinates through the gear couplings (virtual
  power; for a closed mechanism the actuated forces are ``C^T`` of them, C mechbal's coupling
  matrix); the base reaction from MuJoCo's ``cfrc_int`` of the moving roots (the bodies whose
  parent does not move), after ``mj_rnePostConstraint``, moved to O; ``support_*``: the same over
  every child of the world (the links fixed to the base included: their weight is the base's own).
* `momentum_rate`: the base reaction of MuJoCo's current motion as the
  rate of momentum of the moving bodies from MuJoCo's ``cacc`` and ``cinert`` (every body,
  constraint forces included whatever their bookkeeping), gravity included: what a simulation
  records.
* `set_state`, `coordinates`: mechbal's q, v <->
  MuJoCo's qpos, qvel.

Base reaction: the wrench the base exerts on the moving mechanism, gravity included, moment
about O: force = dP/dt - m g, moment = dH_O/dt - (m c) x g over the bodies that move (mechbal's
`mechbal.Mechanism.base_reaction`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from mechbal import _core
from mechbal._deprecation import DeprecatedAttributes, renamed_kwargs
from mechbal.export.mjcf import MINIMUM, _build, minimum_bodies

__all__ = ["MujocoMechanism", "MujocoInverse", "require_mujoco", "validate_mjcf"]


def require_mujoco():
    """The ``mujoco`` module, or ImportError naming the extra."""
    try:
        import mujoco
    except ImportError:
        raise ImportError("MuJoCo is not installed: pip install 'mechbal[mujoco]' (or pip install mujoco)") from None
    return mujoco


#: largest loop or gear violation [m or rad] of a valid MJCF at its keyframe
VALIDATION_TOLERANCE = 1e-9
#: the one-line note of a file written without MuJoCo to check it
NOT_VALIDATED = "MuJoCo is not installed: the MJCF was not validated (pip install 'mechbal[mujoco]')"


def _body_at_line(xml: str, line: int) -> str | None:
    """Name of the innermost ``<body>`` open at ``line`` (1-based) of ``xml``: the body an
    element of that line belongs to."""
    import re

    stack: list[str] = []
    for k, text in enumerate(xml.splitlines()[:max(line, 0)], start=1):
        for tag in re.finditer(r"<(/?)body\b([^>]*?)(/?)>", text):
            if tag.group(1):
                if stack:
                    stack.pop()
            elif not tag.group(3):
                m = re.search(r'name="([^"]*)"', tag.group(2))
                stack.append(m.group(1) if m else "?")
        if k == line:
            m = re.search(r'<body\b[^>]*name="([^"]*)"', text)
            if m:
                return m.group(1)
    return stack[-1] if stack else None


def validate_mjcf(xml: str, *, tolerance: float = VALIDATION_TOLERANCE) -> dict:
    """Load ``xml`` in MuJoCo and run ``mj_forward`` at its keyframe (``assembled``, else the
    model's reference pose), at rest and without control: MuJoCo must accept the file, raise
    none of its warnings, and find every equality (loop, gear) satisfied to ``tolerance``
    [m or rad]. Returns ``{"validated": True, "mujoco": version, "max_equality_violation": ...}``,
    or ``{"validated": False, "note": NOT_VALIDATED}`` when MuJoCo is not installed; raises
    ExportError (one line naming the body, or the equality and its bodies, and the reason)
    when the file fails."""
    from mechbal.export.common import ExportError

    try:
        mj = require_mujoco()
    except ImportError:
        return {"validated": False, "note": NOT_VALIDATED}
    import re

    try:
        m = mj.MjModel.from_xml_string(xml)
    except ValueError as exc:
        text = str(exc)
        reason = text.splitlines()[0].removeprefix("Error:").strip() if text else "refused"
        where = re.search(r"line (\d+)", text)
        body = _body_at_line(xml, int(where.group(1))) if where else None
        element = re.search(r"Element name '([^']*)'", text)
        what = f"body '{body}'" if body else (f"element '{element.group(1)}'" if element else "the file")
        raise ExportError(f"MuJoCo refuses the MJCF: {what}: {reason}") from None
    d = mj.MjData(m)
    key = mj.mj_name2id(m, mj.mjtObj.mjOBJ_KEY, "assembled")
    if key >= 0:
        mj.mj_resetDataKeyframe(m, d, key)
    mj.mj_forward(m, d)
    body_name = lambda b: mj.mj_id2name(m, mj.mjtObj.mjOBJ_BODY, int(b)) or f"body {int(b)}"  # noqa: E731
    for w in mj.mjtWarning.__members__.values():
        if int(w) < len(d.warning) and d.warning[int(w)].number:
            info = int(d.warning[int(w)].lastinfo)
            name = w.name.removeprefix("mjWARN_")
            where = ""
            if name.startswith("BADQ") and 0 <= info < m.nv:
                where = f" at body '{body_name(m.dof_bodyid[info])}'"
            raise ExportError(f"MuJoCo warns at the MJCF's keyframe ({name}{where}): the file does not hold")
    worst, row = 0.0, -1
    for i in range(int(d.ne)):
        if abs(float(d.efc_pos[i])) > worst:
            worst, row = abs(float(d.efc_pos[i])), i
    if worst > tolerance:
        eq = int(d.efc_id[row])
        name = mj.mj_id2name(m, mj.mjtObj.mjOBJ_EQUALITY, eq) or f"equality {eq}"
        bodies = []
        for obj in (m.eq_obj1id[eq], m.eq_obj2id[eq]):
            if int(m.eq_objtype[eq]) == int(mj.mjtObj.mjOBJ_SITE):
                bodies.append(body_name(m.site_bodyid[obj]))
            elif int(m.eq_objtype[eq]) == int(mj.mjtObj.mjOBJ_BODY):
                bodies.append(body_name(obj))
            elif int(m.eq_objtype[eq]) == int(mj.mjtObj.mjOBJ_JOINT) and obj >= 0:
                bodies.append(body_name(m.jnt_bodyid[obj]))
        between = f" (bodies {', '.join(repr(b) for b in bodies)})" if bodies else ""
        raise ExportError(f"MuJoCo finds equality '{name}'{between} violated by {worst:.3g} (> {tolerance:g}) at the "
                          "MJCF's keyframe: the loops are not closed there")
    return {"validated": True, "mujoco": str(mj.__version__), "max_equality_violation": worst,
            "integrator": _integrator_name(mj, m), "timestep": float(m.opt.timestep)}


def _integrator_name(mj, m) -> str:
    return {int(v): k.removeprefix("mjINT_") for k, v in mj.mjtIntegrator.__members__.items()}.get(
        int(m.opt.integrator), str(int(m.opt.integrator))).replace("IMPLICITFAST", "implicitfast").replace(
        "IMPLICIT", "implicit").replace("EULER", "Euler")


@dataclass(frozen=True)
class MujocoInverse:
    """MuJoCo's inverse dynamics at one instant: ``joint_torque`` (dof,) in mechbal's coordinates,
    ``tree_torque`` (nv,) per MuJoCo joint, ``base_reaction_force`` / ``_moment`` (3,) on the
    moving mechanism, ``support_force`` / ``_moment`` (3,) on everything below the world."""
    joint_torque: np.ndarray
    tree_torque: np.ndarray
    base_reaction_force: np.ndarray
    base_reaction_moment: np.ndarray
    support_force: np.ndarray
    support_moment: np.ndarray


def _mul_inert(i: np.ndarray, v: np.ndarray) -> np.ndarray:
    """MuJoCo's mju_mulInertVec: cinert (10) times a motion [w; v] (6)."""
    return np.array([
        i[0] * v[0] + i[3] * v[1] + i[4] * v[2] - i[8] * v[4] + i[7] * v[5],
        i[3] * v[0] + i[1] * v[1] + i[5] * v[2] + i[8] * v[3] - i[6] * v[5],
        i[4] * v[0] + i[5] * v[1] + i[2] * v[2] - i[7] * v[3] + i[6] * v[4],
        i[8] * v[1] - i[7] * v[2] + i[9] * v[3],
        i[6] * v[2] - i[8] * v[0] + i[9] * v[4],
        i[7] * v[0] - i[6] * v[1] + i[9] * v[5]])


def _cross_force(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """MuJoCo's mju_crossForce: [w x f_rot + v x f_lin; w x f_lin]."""
    w, lin = v[:3], v[3:]
    return np.concatenate([np.cross(w, f[:3]) + np.cross(lin, f[3:]), np.cross(w, f[3:])])


class MujocoMechanism:
    """``mech`` exported to MJCF and loaded in MuJoCo (module docstring). ``q`` / ``q_guess``:
    the assembled pose of the keyframe (closed mechanisms); ``timestep`` [s] (default: the
    file's, `mechbal.export.mjcf.default_timestep`); ``minimum_mass`` (default `MINIMUM`: the
    mechanism itself, for inverse dynamics; the file's own is `mechbal.export.mjcf.default_minimum_mass`):
    of the bodies added to the links MuJoCo would refuse (`mechbal.export.mjcf.minimum_bodies`;
    ``exported`` is ``mech`` with them: the mechanism MuJoCo integrates); ``constraint_weight``:
    factor on MuJoCo's inverse weights of bodies, dofs and tendons, which set how much its soft
    constraints give under load (1: MuJoCo's own)."""

    def __init__(self, mech, *, q=None, q_guess=None, timestep: float | None = None, minimum_mass: float = MINIMUM,
                 constraint_weight: float = 1.0):
        mj = require_mujoco()
        self.mj = mj
        self.mech = mech
        self.xml, self.names = _build(mech, q, q_guess, timestep, name=mech.name, minimum_mass=minimum_mass)
        self.exported = mech.with_bodies(minimum_bodies(mech, minimum_mass)) if self.names.minimum else mech
        self.model = mj.MjModel.from_xml_string(self.xml)
        self.data = mj.MjData(self.model)
        m = self.model
        jid = {n: mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, n) for n in self.names.joints}
        self.qpos_adr = {n: int(m.jnt_qposadr[i]) for n, i in jid.items()}
        self.dof_adr = {n: int(m.jnt_dofadr[i]) for n, i in jid.items()}
        # MuJoCo's dof velocities from mechbal's coordinate velocities: v_mj = G v
        self.G = np.zeros((m.nv, mech.dof))
        self.offset = np.zeros(m.nq)
        coords = {n: k for k, n in enumerate(mech.joint_names)}
        for j in mech.model.description.joints:
            if j.type == _core.JointType.fixed:
                continue
            if j.mimic_joint:
                self.G[self.dof_adr[j.name], coords[j.mimic_joint]] = float(j.mimic_ratio)
                self.offset[self.qpos_adr[j.name]] = float(j.mimic_offset)
            else:
                self.G[self.dof_adr[j.name], coords[j.name]] = 1.0
        self.Gq = np.zeros((m.nq, mech.dof))  # slide and hinge joints: qpos and qvel rows agree
        for n in self.names.joints:
            self.Gq[self.qpos_adr[n]] = self.G[self.dof_adr[n]]
        bid = lambda n: mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, n)  # noqa: E731
        self.moving_roots = [bid(n) for n in self.names.moving_roots]
        self.world_children = [b for b in range(1, m.nbody) if m.body_parentid[b] == 0]
        self.moving_bodies = [b for b in range(1, m.nbody) if m.body_weldid[b] != 0]
        self.key = mj.mj_name2id(m, mj.mjtObj.mjOBJ_KEY, "assembled")
        self.light_bodies = self._weigh_light_bodies()
        if constraint_weight != 1.0:
            m.body_invweight0[:] *= constraint_weight
            m.dof_invweight0[:] *= constraint_weight
            m.tendon_invweight0[:] *= constraint_weight
        self.reset()

    def _weigh_light_bodies(self) -> list[str]:
        """MuJoCo makes a constraint the softer the lighter the bodies it joins (its impedance
        scales with their inverse weights ``body_invweight0``): a massless link of mechbal's (a
        kinematic guide, with `MINIMUM` mass in MJCF) makes its loop
        1e13 times softer than the others, and a closed mechanism driven through it drifts off its
        closure. Such bodies (inverse weight over 1e3 times the median of the bodies with mass)
        get the median: the constraints' softness changes, not the dynamics. Returns their names."""
        m = self.model
        heavy = [b for b in range(1, m.nbody) if m.body_mass[b] > 1e-9]
        if not heavy:
            return []
        ref = np.median(m.body_invweight0[heavy], axis=0)
        light = [b for b in range(1, m.nbody) if m.body_invweight0[b, 0] > 1e3 * ref[0]]
        for b in light:
            m.body_invweight0[b] = ref
        if m.nv:
            dref = float(np.median(m.dof_invweight0))
            m.dof_invweight0[:] = np.minimum(m.dof_invweight0, 1e3 * dref)
        return [self.mj.mj_id2name(m, self.mj.mjtObj.mjOBJ_BODY, b) for b in light]

    # ---- state --------------------------------------------------------------------------------
    def reset(self) -> None:
        """The assembled keyframe, at rest."""
        self.mj.mj_resetDataKeyframe(self.model, self.data, self.key)
        self.mj.mj_forward(self.model, self.data)

    def set_state(self, q, v=None) -> None:
        """MuJoCo's qpos, qvel from mechbal's coordinates q, v (dof,)."""
        q = np.asarray(q, float)
        self.data.qpos[:] = self.Gq @ q + self.offset
        self.data.qvel[:] = self.G @ (np.zeros_like(q) if v is None else np.asarray(v, float))

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """mechbal's q, v (dof,) of MuJoCo's current state (the independent joints' values)."""
        idx = [self.qpos_adr[n] for n in self.mech.joint_names]
        didx = [self.dof_adr[n] for n in self.mech.joint_names]
        return np.array(self.data.qpos[idx]), np.array(self.data.qvel[didx])

    def accelerations(self) -> np.ndarray:
        """mechbal's a (dof,) of MuJoCo's current ``qacc`` (after ``mj_forward``: the acceleration
        its step integrates; the independent joints' values)."""
        didx = [self.dof_adr[n] for n in self.mech.joint_names]
        return np.array(self.data.qacc[didx])

    # ---- inverse dynamics --------------------------------------------------------------------
    def _wrench_at_O(self, bodies, field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        F, M = np.zeros(3), np.zeros(3)
        for b in bodies:
            c = self.data.subtree_com[self.model.body_rootid[b]]
            w = field[b]
            F += w[3:]
            M += w[:3] + np.cross(c, w[3:])
        return F, M

    def inverse_dynamics(self, q, v, a) -> MujocoInverse:
        """MuJoCo's inverse dynamics of the tree at mechbal's (q, v, a) (dof,) (module docstring)."""
        mj, m, d = self.mj, self.model, self.data
        self.set_state(q, v)
        d.qacc[:] = self.G @ np.asarray(a, float)
        flags = m.opt.disableflags
        m.opt.disableflags = flags | int(mj.mjtDisableBit.mjDSBL_CONSTRAINT)
        try:
            mj.mj_inverse(m, d)
            mj.mj_rnePostConstraint(m, d)
        finally:
            m.opt.disableflags = flags
        tree = np.array(d.qfrc_inverse)
        # through the joints (cfrc_int of the moving roots) plus what reaches the moving bodies
        # otherwise (cfrc_ext: the springs anchored to the base, as MuJoCo counts tendon forces)
        F, M = self._wrench_at_O(self.moving_roots, d.cfrc_int)
        Fe, Me = self._wrench_at_O(self.moving_bodies, d.cfrc_ext)
        F, M = F + Fe, M + Me
        Fs, Ms = self._wrench_at_O(self.world_children, d.cfrc_int)
        Fe, Me = self._wrench_at_O(range(1, m.nbody), d.cfrc_ext)
        Fs, Ms = Fs + Fe, Ms + Me
        return MujocoInverse(self.G.T @ tree, tree, F, M, Fs, Ms)

    def gravity_torque(self, q) -> np.ndarray:
        """G(q) in mechbal's coordinates: MuJoCo's bias force at rest, projected."""
        self.set_state(q)
        self.mj.mj_forward(self.model, self.data)
        return self.G.T @ np.array(self.data.qfrc_bias)

    def static_torque(self, q) -> np.ndarray:
        """G(q) + K(q): bias minus passive (springs) forces at rest, projected."""
        self.set_state(q)
        self.mj.mj_forward(self.model, self.data)
        return self.G.T @ (np.array(self.data.qfrc_bias) - np.array(self.data.qfrc_passive))

    def momentum_rate(self) -> tuple[np.ndarray, np.ndarray]:
        """Base reaction (force, moment about O) of MuJoCo's current motion (after ``mj_step`` or
        ``mj_forward``): sum over the moving bodies of cinert cacc + cvel x* cinert cvel (cacc
        carries gravity), moved to O. Calls ``mj_rnePostConstraint`` for cacc."""
        d = self.data
        self.mj.mj_rnePostConstraint(self.model, d)
        F, M = np.zeros(3), np.zeros(3)
        for b in self.moving_bodies:
            i = d.cinert[b]
            w = _mul_inert(i, d.cacc[b]) + _cross_force(d.cvel[b], _mul_inert(i, d.cvel[b]))
            c = d.subtree_com[self.model.body_rootid[b]]
            F += w[3:]
            M += w[:3] + np.cross(c, w[3:])
        return F, M

    def moving_mass(self) -> float:
        return float(sum(self.model.body_mass[b] for b in self.moving_bodies))

    def __repr__(self) -> str:
        m = self.model
        return (f"<MujocoMechanism {self.mech.name!r}: nq {m.nq}, nv {m.nv}, {m.nbody - 1} bodies, "
                f"{m.neq} equalities, {m.ntendon} tendons>")


def load(mech, **kw: Any) -> MujocoMechanism:
    """`MujocoMechanism` of ``mech``."""
    return MujocoMechanism(mech, **kw)


#: co-simulation: the mass given to a massless moving link, as a fraction of the total mass
MINIMUM_FRACTION = 1e-6
#: co-simulation: factor on MuJoCo's inverse weights (its constraints' give under load)
CONSTRAINT_WEIGHT = 1e-4
#: co-simulation: solref of the loop and gear constraints (MuJoCo's default time constant and
#: damping ratio), whatever the file says
COSIM_SOLREF = (0.02, 1.0)


def cosimulated_mechanism(mech, minimum_mass: float | None = None):
    """The mechanism `co_simulate` integrates in MuJoCo: ``mech`` with the bodies added to its
    massless moving links (`mechbal.export.mjcf.minimum_bodies`; ``minimum_mass`` [kg], default
    `MINIMUM_FRACTION` of the total mass), ``mech`` itself when it has none. mechbal's
    predictions of a co-simulation are of this mechanism."""
    if minimum_mass is None:
        minimum_mass = max(MINIMUM_FRACTION * mech.total_mass, MINIMUM)
    bodies = minimum_bodies(mech, minimum_mass)
    return mech.with_bodies(bodies) if bodies else mech


@dataclass(frozen=True)
class CoSimulation(DeprecatedAttributes):
    """A 1 kHz co-simulation (`co_simulate`): the controller's log, one row per tick
    k = 0 .. steps (``t``, ``q``, ``v``, ``q_des``, ``v_des``, ``joint_torque``, ``status``, in
    the controller's coordinates: the actuated joints of a closed mechanism), every coordinate of
    MuJoCo's state and its acceleration at each tick in mechbal's coordinates (``q_full``,
    ``v_full``, ``a_full`` (N, dof): the motion MuJoCo realised, ``a_full`` its ``qacc`` after
    the tick's torque), MuJoCo's base
    reaction at each tick (``base_reaction_force`` / ``_moment``: the moving bodies' momentum rate
    minus their weight, `MujocoMechanism.momentum_rate`) beside mechbal's prediction along
    the desired motion (``predicted_base_reaction_force`` / ``_moment``), the moving mass ``mass``
    and first moment ``mass_moment`` (N, 3) that turn them into shaking wrenches, and the largest
    loop-closure violation ``constraint_violation`` (N,) [m or rad] of MuJoCo's soft constraints.
    ``steps_completed`` is ``steps`` unless MuJoCo failed: a non-finite state, or its own
    instability warnings (it zeroes a non-finite or huge control and resets a diverging state
    rather than stop). The failed tick and the later ones then have ``Status.out_of_range`` in
    ``status``, and the rows after the last one written repeat it."""
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    q_des: np.ndarray
    v_des: np.ndarray
    joint_torque: np.ndarray
    status: np.ndarray
    saturated_ticks: int
    steps_completed: int
    base_reaction_force: np.ndarray
    base_reaction_moment: np.ndarray
    predicted_base_reaction_force: np.ndarray
    predicted_base_reaction_moment: np.ndarray
    gravity: np.ndarray
    mass: float
    mass_moment: np.ndarray
    predicted_mass_moment: np.ndarray
    constraint_violation: np.ndarray
    q_full: np.ndarray | None = None
    v_full: np.ndarray | None = None
    a_full: np.ndarray | None = None
    #: MuJoCo's settings of the run: integrator, timestep [s] (dt / substeps), substeps, solref of
    #: the loops and gears, constraint_weight, minimum_mass [kg] (`mujoco_options`)
    options: dict | None = None

    _renamed: ClassVar[dict[str, str]] = {"qd": "v", "qd_des": "v_des"}

    @property
    def shaking_force(self) -> np.ndarray:
        """MuJoCo's dP/dt (N, 3) [N]: the base reaction plus the moving weight."""
        return self.base_reaction_force + self.mass * self.gravity

    @property
    def shaking_moment(self) -> np.ndarray:
        """MuJoCo's dH_O/dt (N, 3) [N m]."""
        return self.base_reaction_moment + np.cross(self.mass_moment, self.gravity)

    @property
    def predicted_shaking_force(self) -> np.ndarray:
        return self.predicted_base_reaction_force + self.mass * self.gravity

    @property
    def predicted_shaking_moment(self) -> np.ndarray:
        return self.predicted_base_reaction_moment + np.cross(self.predicted_mass_moment, self.gravity)

    @property
    def tracking_error(self) -> np.ndarray:
        return self.q_des - self.q


@renamed_kwargs(qd0="v0")
def co_simulate(mech, controller, trajectory, q0=None, v0=None, *, dt: float = 1e-3,
                duration: float | None = None, q_guess=None, substeps: int = 1,
                integrator: str = "RK4", solref: tuple[float, float] | None = None,
                solimp: tuple[float, ...] | None = None, minimum_mass: float | None = None,
                constraint_weight: float = CONSTRAINT_WEIGHT) -> CoSimulation:
    """Tick ``controller`` (any mechbal joint controller, in the actuated coordinates of a closed
    mechanism) every ``dt`` against MuJoCo integrating ``mech``'s MJCF export, ``substeps``
    MuJoCo steps of dt / substeps per tick, torque held over the tick (zero-order hold).
    ``integrator``: MuJoCo's (``RK4``, ``Euler``, ``implicitfast``, ``implicit``); ``solref``:
    (time constant [s], damping ratio) of the loop and gear constraints (`COSIM_SOLREF`, MuJoCo's
    default (0.02, 1), when None; the file's own, twice its step, holds a pose stiffer but
    tracks a motion with a larger spurious shaking force); ``solimp``: their impedance (d0, d_width, width[, mid, power]), MuJoCo's
    default (0.9, 0.95, 0.001) when None: the closer d to 1, the harder the constraint (MuJoCo
    caps d at 0.9999). ``minimum_mass`` [kg]: of the bodies added to massless moving links
    (default `MINIMUM_FRACTION` of the total mass: MuJoCo's solver fails on a link of 1e-13
    kg; mechbal's prediction is of the mechanism with them, ``MujocoMechanism.exported``);
    ``constraint_weight``: factor on MuJoCo's inverse weights (`CONSTRAINT_WEIGHT`: a
    constraint under load gives (1 - d) / d x weight x force in acceleration). The state starts on the trajectory at t = 0 (or ``q0``, ``v0``)."""
    from mechbal.trajectory import as_trajectory

    traj = as_trajectory(trajectory)
    if duration is None:
        duration = float(getattr(traj, "end_time", traj.duration))
    if not (np.isfinite(dt) and dt > 0 and np.isfinite(duration) and duration >= dt):
        raise ValueError(f"dt must be > 0 and duration >= dt, got dt={dt}, duration={duration}")
    if int(substeps) < 1:
        raise ValueError(f"substeps must be >= 1, got {substeps}")
    from mechbal.tables import check_run_ticks

    check_run_ticks(duration, 1.0 / dt, "dt")  # bounded work before the run
    steps = int(round(duration / dt))
    t = np.arange(steps + 1) * dt
    q_des, v_des, a_des = (np.atleast_2d(np.asarray(x, float)) for x in traj.evaluate(t))
    if q_des.shape[0] != t.size:
        q_des, v_des, a_des = (x.reshape(t.size, -1) for x in (q_des, v_des, a_des))
    closed = mech.is_closed
    act = [mech.joint_names.index(n) for n in mech.actuated_names] if closed else list(range(mech.dof))
    # mechbal's prediction along the desired motion (full coordinates)
    if closed:
        motion = mech.closed_motion(q_des, v_des, a_des, q_guess=q_guess)
        Q, V, A = motion.q, motion.v, motion.a
    else:
        Q, V, A = q_des, v_des, a_des
    if minimum_mass is None:
        minimum_mass = max(MINIMUM_FRACTION * mech.total_mass, MINIMUM)
    sim = MujocoMechanism(mech, q=Q[0], q_guess=q_guess, timestep=dt / int(substeps), minimum_mass=minimum_mass,
                          constraint_weight=constraint_weight)
    model = sim.exported   # the mechanism MuJoCo integrates (mech with the minimum bodies)
    br = model.base_reaction(Q, V, A)
    mj, m, d = sim.mj, sim.model, sim.data
    m.opt.integrator = int(getattr(mj.mjtIntegrator, f"mjINT_{integrator.upper()}"))
    # the co-simulation's constraint settings, not the file's (which are chosen to hold a pose):
    # MuJoCo's default time constant tracks a motion with the smallest spurious shaking force
    m.eq_solref[:] = np.asarray(COSIM_SOLREF if solref is None else solref, float)
    if solimp is not None:
        imp = np.asarray(solimp, float)
        m.eq_solimp[:, :imp.size] = imp
    q_start, v_start = Q[0], V[0]
    if q0 is not None or v0 is not None:   # a given start (controller coordinates)
        qa0 = q_des[0] if q0 is None else np.asarray(q0, float)
        va0 = v_des[0] if v0 is None else np.asarray(v0, float)
        if closed:
            start = mech.closed_motion(qa0, va0, q_guess=Q[0])
            q_start, v_start = np.asarray(start.q), np.asarray(start.v)
        else:
            q_start, v_start = qa0, va0
    sim.set_state(q_start, v_start)
    mj.mj_forward(m, d)
    g = np.asarray(mech.gravity, float)
    moving = sim.moving_bodies
    n = len(act)
    log = {k: np.zeros((steps + 1, n)) for k in ("q", "v", "tau")}
    full = {k: np.zeros((steps + 1, mech.dof)) for k in ("q", "v", "a")}
    status = np.zeros(steps + 1, dtype=np.uint32)
    F = np.zeros((steps + 1, 3))
    M = np.zeros((steps + 1, 3))
    mc = np.zeros((steps + 1, 3))
    viol = np.zeros(steps + 1)
    saturated = 0
    completed = steps
    mass = sim.moving_mass()
    tau = np.zeros(n)
    # MuJoCo does not fail on a bad state or control: it zeroes a non-finite or huge control
    # (mjWARN_BADCTRL) and resets its state on a diverging one (BADQACC, BADQPOS, BADQVEL), then
    # goes on. A new count of those warnings ends the co-simulation as a non-finite state does.
    unstable = [getattr(mj.mjtWarning, f"mjWARN_{w}") for w in ("BADCTRL", "BADQACC", "BADQPOS", "BADQVEL")]

    def warnings() -> int:
        return sum(int(d.warning[int(w)].number) for w in unstable)

    warned = warnings()
    last = steps   # the last row written
    for k in range(steps + 1):
        qk, vk = sim.coordinates()
        qa, va = qk[act], vk[act]
        cmd = controller.step(qa, va, q_des[k], v_des[k], a_des[k])
        # a wrapped controller returns a JointCommand, a bare core one (tau, status)
        tau_k, status_k = (cmd.joint_torque, cmd.status) if hasattr(cmd, "joint_torque") else cmd
        tau = np.asarray(tau_k, float)
        status[k] = int(status_k)
        if int(status_k) & int(_core.Status.saturated):
            saturated += 1
        d.ctrl[:] = tau
        mj.mj_forward(m, d)
        F[k], M[k] = sim.momentum_rate()
        full["q"][k], full["v"][k], full["a"][k] = qk, vk, sim.accelerations()
        mc[k] = sum(m.body_mass[b] * d.xipos[b] for b in moving) if moving else np.zeros(3)
        viol[k] = float(np.max(np.abs(d.efc_pos[:d.ne]))) if d.ne else 0.0
        log["q"][k], log["v"][k], log["tau"][k] = qa, va, tau
        if warnings() != warned:   # MuJoCo refused this tick's torque (the row's wrench is without it)
            completed, last = k, k
            status[k:] |= np.uint32(int(_core.Status.out_of_range))
            break
        if k == steps:
            break
        for _ in range(int(substeps)):
            mj.mj_step(m, d)
        if warnings() != warned or not (np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))):
            completed, last = k, k
            status[k + 1:] = int(_core.Status.out_of_range)
            break
    # after a failure the later rows repeat the last one written (as mechbal's own simulator does)
    for series in (*log.values(), *full.values(), F, M, mc, viol):
        series[last + 1:] = series[last]
    bm = model.body_motion(Q)
    still_bodies = _still_bodies(model)
    masses = np.array([0.0 if b.name in still_bodies else float(b.mass) for b in model.bodies])
    mc_pred = np.einsum("b,nbi->ni", masses, bm.com)
    return CoSimulation(t=t, q=log["q"], v=log["v"], q_des=q_des, v_des=v_des, joint_torque=log["tau"],
                        status=status, saturated_ticks=saturated, steps_completed=completed,
                        base_reaction_force=F, base_reaction_moment=M,
                        predicted_base_reaction_force=np.asarray(br.base_reaction_force),
                        predicted_base_reaction_moment=np.asarray(br.base_reaction_moment),
                        gravity=g, mass=mass, mass_moment=mc, predicted_mass_moment=mc_pred,
                        constraint_violation=viol, q_full=full["q"], v_full=full["v"], a_full=full["a"],
                        options={"integrator": _integrator_name(mj, m), "timestep": float(m.opt.timestep),
                                 "substeps": int(substeps), "solref": [float(x) for x in m.eq_solref[0]] if m.neq
                                 else [float(x) for x in COSIM_SOLREF], "constraint_weight": float(constraint_weight),
                                 "minimum_mass": float(minimum_mass)})


def mujoco_options(cs: "CoSimulation") -> dict:
    """The ``mujoco_options`` of a summary.json: MuJoCo's integrator and time step [s] of the
    co-simulation ``cs`` and its constraint settings."""
    return dict(cs.options or {})


def _still_bodies(mech) -> set[str]:
    from mechbal.export.common import fixed_to_root

    still = fixed_to_root(mech)
    return {b.name for b in mech.bodies if b.link in still}
