# Generated from the bindings by pybind11-stubgen 3.0.0 (pybind11 3.1.0): do not edit;
# regenerate with `make stubs` (tests/python/test_typing.py checks it is current).
"""
mechbal C++ core: shaking wrench, serial chains, trajectories, real-time controllers
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Arm2DofCounterweights', 'Arm2DofDynamics', 'Arm2DofParameters', 'Body', 'ComputedTorque', 'ControlConfig', 'DecoupledJointController', 'FiveBarDynamics', 'FiveBarParameters', 'ForwardDynamics', 'Frame', 'InverseDynamics', 'Joint', 'JointController', 'JointType', 'KdlChainDynamics', 'LoopConstraint', 'LoopType', 'MAX_URDF_BYTES', 'MAX_URDF_DEPTH', 'MechanismDescription', 'MechanismDynamics', 'MechanismModel', 'PaminsaController', 'PaminsaCounterweights', 'PaminsaModel', 'PaminsaParameters', 'PassiveController', 'ReactionlessCommand', 'ReactionlessController', 'ReactionlessJointController', 'ReactionlessTaskController', 'ReactionlessWrist', 'ReactionlessWristConfig', 'RestToRestTrajectory', 'Spring', 'Status', 'TimeLaw', 'TrajectoryConfig', 'WristCommand', 'WristIntegrator', 'arm2dof_description', 'case_from_toml', 'load_case_file', 'load_case_trajectory', 'load_mechanism_file', 'mechanism_bias_torque', 'mechanism_center_of_mass', 'mechanism_closed_forward_dynamics', 'mechanism_closed_mass_matrix', 'mechanism_closed_motion', 'mechanism_frame_jacobian', 'mechanism_from_toml', 'mechanism_from_urdf', 'mechanism_from_urdf_string', 'mechanism_gravity_regressor', 'mechanism_gravity_torque', 'mechanism_inverse_dynamics', 'mechanism_kinematics', 'mechanism_mass_matrix', 'mechanism_momentum', 'mechanism_momentum_matrix', 'mechanism_momentum_regressor', 'mechanism_shaking_wrench', 'mechanism_single_sample', 'mechanism_springs', 'mechanism_static_torque', 'mechanism_torque_regressor', 'name_problem', 'paminsa_kinematics', 'paminsa_reactionless_run', 'pd_error_analytic', 'read_urdf', 'simulate_closed_loop', 'simulate_closed_loop_sampled', 'simulate_computed_torque', 'simulate_passive', 'status_name', 'urdf_description', 'validate_rigid_body', 'wrist_momentum_bias', 'wrist_momentum_matrix']
class Status:
    """
    Bit flags returned by real-time algorithms
    
    Members:
    
      ok
    
      non_finite_input
    
      singular
    
      saturated
    
      bad_size
    
      solver_error
    
      out_of_range
    """
    __members__: typing.ClassVar[dict[str, Status]]
    bad_size: typing.ClassVar[Status]
    non_finite_input: typing.ClassVar[Status]
    ok: typing.ClassVar[Status]
    out_of_range: typing.ClassVar[Status]
    saturated: typing.ClassVar[Status]
    singular: typing.ClassVar[Status]
    solver_error: typing.ClassVar[Status]
    @staticmethod
    def __eq__(*args, **kwargs):
        """
        (self: object, other: object) -> object
        """
    @staticmethod
    def __hash__(*args, **kwargs):
        """
        (self: object) -> int
        """
    @staticmethod
    def __ne__(*args, **kwargs):
        """
        (self: object, other: object) -> object
        """
    @typing.overload
    def __ge__(self, other: Status) -> bool:
        ...
    @typing.overload
    def __ge__(self, other: typing.Any) -> None:
        ...
    def __getstate__(self) -> int:
        ...
    @typing.overload
    def __gt__(self, other: Status) -> bool:
        ...
    @typing.overload
    def __gt__(self, other: typing.Any) -> None:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __le__(self, other: Status) -> bool:
        ...
    @typing.overload
    def __le__(self, other: typing.Any) -> None:
        ...
    @typing.overload
    def __lt__(self, other: Status) -> bool:
        ...
    @typing.overload
    def __lt__(self, other: typing.Any) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class TimeLaw:
    """
    Members:
    
      quintic
    
      cubic
    """
    __members__: typing.ClassVar[dict[str, TimeLaw]]
    cubic: typing.ClassVar[TimeLaw]
    quintic: typing.ClassVar[TimeLaw]
    @typing.overload
    def __eq__(self, other: TimeLaw) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: TimeLaw) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class RestToRestTrajectory:
    """
    Rest-to-rest motion q0 -> q1 in T seconds along a quintic
    or minimum-energy cubic law (Arakelian et al. 2011, eqs 10-13).
    """
    def __init__(self, start: numpy.typing.ArrayLike, end: numpy.typing.ArrayLike, duration: typing.SupportsFloat | typing.SupportsIndex, law: TimeLaw = TimeLaw.quintic) -> None:
        ...
    def evaluate(self, t: typing.SupportsFloat | typing.SupportsIndex) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        """
        (q, v, a) at time t
        """
    def evaluate_batch(self, times: numpy.typing.ArrayLike) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
        """
        (q, v, a), each (N, size), at the N given times
        """
    @property
    def duration(self) -> float:
        ...
    @property
    def law(self) -> TimeLaw:
        ...
    @property
    def size(self) -> int:
        ...
class InverseDynamics:
    """
    Joint-space inverse dynamics back end (base class of Arm2DofDynamics, KdlChainDynamics, MechanismDynamics)
    """
    @property
    def dof(self) -> int:
        ...
class ForwardDynamics:
    """
    Forward dynamics of a plant for closed-loop simulation (base class of Arm2DofDynamics and MechanismDynamics)
    """
class JointController:
    """
    Joint-space tracking controller (base class of ComputedTorque and DecoupledJointController)
    """
    @property
    def dof(self) -> int:
        ...
class JointType:
    """
    Members:
    
      revolute
    
      prismatic
    
      fixed
    """
    __members__: typing.ClassVar[dict[str, JointType]]
    fixed: typing.ClassVar[JointType]
    prismatic: typing.ClassVar[JointType]
    revolute: typing.ClassVar[JointType]
    @typing.overload
    def __eq__(self, other: JointType) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: JointType) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class Joint:
    """
    One joint of a MechanismDescription; it moves the link of the same name (model.hpp for frames and conventions)
    """
    def __init__(self, name: str, type: JointType = JointType.revolute, parent: str = 'base', placement: numpy.typing.ArrayLike = ..., axis: numpy.typing.ArrayLike = ..., lower: typing.SupportsFloat | typing.SupportsIndex = ..., upper: typing.SupportsFloat | typing.SupportsIndex = ..., velocity_limit: typing.SupportsFloat | typing.SupportsIndex = ..., effort_limit: typing.SupportsFloat | typing.SupportsIndex = ..., mimic_joint: str = '', mimic_ratio: typing.SupportsFloat | typing.SupportsIndex = 1.0, mimic_offset: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def axis(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def effort_limit(self) -> float:
        ...
    @property
    def lower(self) -> float:
        ...
    @property
    def mimic_joint(self) -> str:
        ...
    @property
    def mimic_offset(self) -> float:
        ...
    @property
    def mimic_ratio(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def parent(self) -> str:
        ...
    @property
    def placement(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        ...
    @property
    def type(self) -> JointType:
        ...
    @property
    def upper(self) -> float:
        ...
    @property
    def velocity_limit(self) -> float:
        ...
class Body:
    """
    A named rigid body on a link: mass [kg], centre of mass [m] and inertia about it [kg m^2], both in the link frame
    """
    def __init__(self, name: str, link: str, mass: typing.SupportsFloat | typing.SupportsIndex, com: numpy.typing.ArrayLike = ..., inertia: numpy.typing.ArrayLike = ..., kind: str = 'link') -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def com(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def inertia(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        ...
    @property
    def kind(self) -> str:
        ...
    @property
    def link(self) -> str:
        ...
    @property
    def mass(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
class Frame:
    """
    A named frame on a link (placement in the link frame)
    """
    def __init__(self, name: str, link: str, placement: numpy.typing.ArrayLike = ...) -> None:
        ...
    @property
    def link(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def placement(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        ...
class LoopType:
    """
    Loop-closure types (algorithm/loops.hpp)
    
    Members:
    
      point
    
      planar_point
    
      axis
    
      weld
    """
    __members__: typing.ClassVar[dict[str, LoopType]]
    axis: typing.ClassVar[LoopType]
    planar_point: typing.ClassVar[LoopType]
    point: typing.ClassVar[LoopType]
    weld: typing.ClassVar[LoopType]
    @typing.overload
    def __eq__(self, other: LoopType) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: LoopType) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class LoopConstraint:
    """
    A loop closure between two named frames
    """
    def __init__(self, name: str, type: LoopType, frame_a: str, frame_b: str) -> None:
        ...
    @property
    def frame_a(self) -> str:
        ...
    @property
    def frame_b(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def type(self) -> LoopType:
        ...
class Spring:
    """
    A linear spring between anchor A on link_a and anchor B on link_b (anchors in the link frames [m]): count identical springs of rate [N/m] each, carrying preload [N] at the anchor distance free_length [m], through a block and tackle of ratio pulley_ratio (model.hpp)
    """
    def __init__(self, name: str, link_a: str, anchor_a: numpy.typing.ArrayLike, link_b: str, anchor_b: numpy.typing.ArrayLike, rate: typing.SupportsFloat | typing.SupportsIndex, free_length: typing.SupportsFloat | typing.SupportsIndex = 0.0, preload: typing.SupportsFloat | typing.SupportsIndex = 0.0, count: typing.SupportsInt | typing.SupportsIndex = 1, pulley_ratio: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def anchor_a(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def anchor_b(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def count(self) -> int:
        ...
    @property
    def equivalent_rate(self) -> float:
        ...
    @property
    def free_length(self) -> float:
        ...
    @property
    def link_a(self) -> str:
        ...
    @property
    def link_b(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def preload(self) -> float:
        ...
    @property
    def pulley_ratio(self) -> float:
        ...
    @property
    def rate(self) -> float:
        ...
class MechanismDescription:
    """
    Joints, bodies, frames, gravity and loop closures: what a MechanismModel is built from
    """
    def __init__(self, joints: collections.abc.Sequence[Joint], bodies: collections.abc.Sequence[Body] = [], frames: collections.abc.Sequence[Frame] = [], gravity: numpy.typing.ArrayLike = ..., root_name: str = 'base', loops: collections.abc.Sequence[LoopConstraint] = [], actuated: collections.abc.Sequence[str] = [], springs: collections.abc.Sequence[Spring] = []) -> None:
        ...
    @property
    def actuated(self) -> list[str]:
        ...
    @property
    def bodies(self) -> list[Body]:
        ...
    @property
    def frames(self) -> list[Frame]:
        ...
    @property
    def gravity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def joints(self) -> list[Joint]:
        ...
    @property
    def loops(self) -> list[LoopConstraint]:
        ...
    @property
    def root_name(self) -> str:
        ...
    @property
    def springs(self) -> list[Spring]:
        ...
class MechanismModel:
    """
    The validated general mechanism model (C++ mechbal::MechanismModel). Use mechbal.Mechanism for the Python API.
    """
    def __getstate__(self) -> tuple[MechanismDescription]:
        ...
    def __init__(self, description: MechanismDescription) -> None:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def body_index(self, name: str) -> int:
        ...
    def frame_index(self, name: str) -> int:
        ...
    def link_index(self, name: str) -> int:
        ...
    def spring_index(self, name: str) -> int:
        ...
    @property
    def actuated_coordinates(self) -> list[int]:
        ...
    @property
    def bodies(self) -> list[Body]:
        ...
    @property
    def body_links(self) -> list[int]:
        ...
    @property
    def body_names(self) -> list[str]:
        ...
    @property
    def coordinate_names(self) -> list[str]:
        ...
    @property
    def description(self) -> MechanismDescription:
        ...
    @property
    def dof(self) -> int:
        ...
    @property
    def effort_limits(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def frame_names(self) -> list[str]:
        ...
    @property
    def gravity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def is_closed(self) -> bool:
        ...
    @property
    def is_serial_chain(self) -> bool:
        ...
    @property
    def link_names(self) -> list[str]:
        ...
    @property
    def link_parents(self) -> list[int]:
        ...
    @property
    def lower_limits(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def num_bodies(self) -> int:
        ...
    @property
    def num_constraints(self) -> int:
        ...
    @property
    def num_frames(self) -> int:
        ...
    @property
    def num_links(self) -> int:
        ...
    @property
    def num_springs(self) -> int:
        ...
    @property
    def passive_coordinates(self) -> list[int]:
        ...
    @property
    def root_name(self) -> str:
        ...
    @property
    def spring_links(self) -> list[tuple[int, int]]:
        ...
    @property
    def spring_names(self) -> list[str]:
        ...
    @property
    def springs(self) -> list[Spring]:
        ...
    @property
    def total_mass(self) -> float:
        ...
    @property
    def upper_limits(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def velocity_limits(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class MechanismDynamics(InverseDynamics, ForwardDynamics):
    """
    Joint-space dynamics of a MechanismModel (recursive Newton-Euler inverse dynamics with the base support wrench, composite rigid body mass matrix): the InverseDynamics back end of the general model, for ComputedTorque and the simulators
    """
    def __init__(self, model: MechanismModel, q_guess: numpy.typing.ArrayLike = ...) -> None:
        """
        Dynamics in the actuated coordinates (loops solved each call, warm-started from q_guess, the full coordinates near the assembly)
        """
    def bias(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Bias torques C(q, v) v + G(q) + K(q) (springs included)
        """
    def coriolis(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Coriolis and centrifugal torques C(q, v) v
        """
    def forward_dynamics(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, tau: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Accelerations a = M^-1 (tau - b) (actuated coordinates)
        """
    def gravity(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Gravity torques G(q) (gravity alone; with springs see static_torque)
        """
    def inverse_dynamics(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
        """
        Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, support_moment about the base origin, (N, 3)); q, v, a each (N, dof). Instants with non-finite input give zeros and set their flag in `status`.
        """
    def mass_matrix(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Mass matrix M(q) (dof, dof) by the composite rigid body algorithm
        """
    def static_torque(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Static torques G(q) + K(q): gravity and springs
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def solved_position(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class KdlChainDynamics(InverseDynamics):
    """
    Joint-space dynamics of a serial MechanismModel through Orocos KDL (the independent engine)
    """
    def __init__(self, model: MechanismModel) -> None:
        """
        From the general MechanismModel when it is a serial chain (bodies lumped per link); ValueError naming the link or joint otherwise
        """
    def coriolis(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Coriolis and centrifugal torques C(q, v) v
        """
    def gravity(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Gravity torques G(q)
        """
    def inverse_dynamics(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
        """
        Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, support_moment about the base origin, (N, 3)) by KDL's ChainIdSolver_RNE.
        """
    def mass_matrix(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Mass matrix M(q) (dof, dof); ValueError for non-finite or overflowing q
        """
    @property
    def dof(self) -> int:
        ...
class ControlConfig:
    """
    The [control] table as the C++ reader checked it (read only)
    """
    @property
    def balancing_joints(self) -> list[str]:
        ...
    @property
    def cancel(self) -> list[str]:
        ...
    @property
    def damping(self) -> float:
        ...
    @property
    def home_gain(self) -> float:
        ...
    @property
    def integrator(self) -> str:
        ...
    @property
    def k(self) -> list[float]:
        ...
    @property
    def kd(self) -> list[float]:
        ...
    @property
    def kind(self) -> str:
        ...
    @property
    def kp(self) -> list[float]:
        ...
    @property
    def limit_gain(self) -> float:
        ...
    @property
    def max_rate(self) -> float:
        ...
    @property
    def rate_hz(self) -> float:
        ...
    @property
    def task_frame(self) -> str:
        ...
    @property
    def torque_limit(self) -> list[float]:
        ...
class TrajectoryConfig:
    """
    The [trajectory] table as the C++ reader checked it (read only)
    """
    @property
    def branch(self) -> str:
        ...
    @property
    def constant_speed(self) -> bool:
        ...
    @property
    def duration(self) -> float:
        ...
    @property
    def end(self) -> list[float]:
        ...
    @property
    def initial_guess(self) -> list[float]:
        ...
    @property
    def law(self) -> TimeLaw:
        ...
    @property
    def present(self) -> bool:
        ...
    @property
    def revolutions(self) -> float:
        ...
    @property
    def samples(self) -> int:
        ...
    @property
    def speed(self) -> list[float]:
        ...
    @property
    def start(self) -> list[float]:
        ...
class ComputedTorque(JointController):
    """
    Computed-torque control, Arakelian et al. 2011 eqs 2-6, over any inverse-dynamics back end (keeps the model alive)
    """
    def __init__(self, model: InverseDynamics, kp: numpy.typing.ArrayLike, kd: numpy.typing.ArrayLike, torque_limit: typing.Any = None, max_position: typing.SupportsFloat | typing.SupportsIndex = ..., max_speed: typing.SupportsFloat | typing.SupportsIndex = ..., max_acceleration: typing.SupportsFloat | typing.SupportsIndex = ...) -> None:
        """
        model: any InverseDynamics back end (MechanismDynamics, KdlChainDynamics, a paper's closed form such as Arm2DofDynamics or FiveBarDynamics). torque_limit: one value per joint (default and +inf: no limit); max_position, max_speed, max_acceleration: the input range of a tick (default +inf: no limit; beyond it: the held command and Status.out_of_range)
        """
    def _tick(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        step() with the status as an int (what the Python classes' step wraps in a JointCommand)
        """
    def reset(self) -> None:
        """
        Forget the held command (zero torque).
        """
    @typing.overload
    def run(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> dict:
        """
        N consecutive ticks in one call: q, v [rad or m, rad/s or m/s], q_des, v_des, a_des, each (N, n) -> {'joint_torque': (N, n) [N m or N], 'status': (N,) per tick}
        """
    @typing.overload
    def run(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        One tick: (tau, status), tau [N m or N] (n,). Any real array-like input; non-finite or out-of-range input returns the held command and a non-ok status.
        """
    @typing.overload
    def step(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step_into(self, q: numpy.typing.NDArray[numpy.float64], v: numpy.typing.NDArray[numpy.float64], q_des: numpy.typing.NDArray[numpy.float64], v_des: numpy.typing.NDArray[numpy.float64], a_des: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: writes tau [N m or N] into `out` (a preallocated float64 array of n values) and returns the status as an int (0 = ok, bit flags of mechbal.Status). Every argument must be a C-contiguous float64 numpy array of n values; nothing is copied or allocated.
        """
    @typing.overload
    def step_into(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def last_command(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def torque_limit(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class PaminsaCounterweights:
    """
    Counterweight masses [kg] of PAMINSA (Briot & Arakelian 2009, eqs 11, 14-16): at_A (CP1), at_F (CP2), at_L (CP3), vertical
    """
    def __init__(self) -> None:
        ...
    @property
    def at_A(self) -> typing.Annotated[list[float], "FixedSize(3)"]:
        ...
    @at_A.setter
    def at_A(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(3)"]) -> None:
        ...
    @property
    def at_F(self) -> typing.Annotated[list[float], "FixedSize(3)"]:
        ...
    @at_F.setter
    def at_F(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(3)"]) -> None:
        ...
    @property
    def at_L(self) -> typing.Annotated[list[float], "FixedSize(3)"]:
        ...
    @at_L.setter
    def at_L(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(3)"]) -> None:
        ...
    @property
    def vertical(self) -> float:
        ...
    @vertical.setter
    def vertical(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class PaminsaParameters:
    """
    Every PAMINSA parameter (defaults: the paper's Sec. II.A and the reconstruction choices A1-A11), SI units
    """
    counterweights: PaminsaCounterweights
    vertical_mass_at_centroid: bool
    def __init__(self) -> None:
        ...
    @property
    def a(self) -> float:
        ...
    @a.setter
    def a(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def b(self) -> float:
        ...
    @b.setter
    def b(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def c(self) -> float:
        ...
    @c.setter
    def c(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cp3_ratio(self) -> float:
        ...
    @cp3_ratio.setter
    def cp3_ratio(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def d(self) -> float:
        ...
    @d.setter
    def d(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def e(self) -> float:
        ...
    @e.setter
    def e(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def elbow(self) -> float:
        ...
    @elbow.setter
    def elbow(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def f(self) -> float:
        ...
    @f.setter
    def f(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def k(self) -> float:
        ...
    @k.setter
    def k(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_AE(self) -> float:
        ...
    @length_AE.setter
    def length_AE(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_AF(self) -> float:
        ...
    @length_AF.setter
    def length_AF(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_BG(self) -> float:
        ...
    @length_BG.setter
    def length_BG(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_CE(self) -> float:
        ...
    @length_CE.setter
    def length_CE(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_CJ(self) -> float:
        ...
    @length_CJ.setter
    def length_CJ(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_DF(self) -> float:
        ...
    @length_DF.setter
    def length_DF(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_MO(self) -> float:
        ...
    @length_MO.setter
    def length_MO(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length_MS5(self) -> float:
        ...
    @length_MS5.setter
    def length_MS5(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def link_inertia(self) -> typing.Annotated[list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]], "FixedSize(8)"]:
        ...
    @link_inertia.setter
    def link_inertia(self, arg0: typing.Annotated[collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]], "FixedSize(8)"]) -> None:
        ...
    @property
    def link_mass(self) -> typing.Annotated[list[float], "FixedSize(8)"]:
        ...
    @link_mass.setter
    def link_mass(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(8)"]) -> None:
        ...
    @property
    def nominal_platform(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @nominal_platform.setter
    def nominal_platform(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def nominal_rho(self) -> float:
        ...
    @nominal_rho.setter
    def nominal_rho(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def platform_mass(self) -> float:
        ...
    @platform_mass.setter
    def platform_mass(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def vertical_mass_xy(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @vertical_mass_xy.setter
    def vertical_mass_xy(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]) -> None:
        ...
    @property
    def vertical_mass_z0(self) -> float:
        ...
    @vertical_mass_z0.setter
    def vertical_mass_z0(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def wrist_inertia(self) -> typing.Annotated[list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]], "FixedSize(3)"]:
        ...
    @wrist_inertia.setter
    def wrist_inertia(self, arg0: typing.Annotated[collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]], "FixedSize(3)"]) -> None:
        ...
    @property
    def z_A(self) -> float:
        ...
    @z_A.setter
    def z_A(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class WristIntegrator:
    """
    Members:
    
      euler
    
      rk4
    """
    __members__: typing.ClassVar[dict[str, WristIntegrator]]
    euler: typing.ClassVar[WristIntegrator]
    rk4: typing.ClassVar[WristIntegrator]
    @typing.overload
    def __eq__(self, other: WristIntegrator) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: WristIntegrator) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class ReactionlessWristConfig:
    """
    Reactionless wrist tick: rate, integrator, limits (every limit finite) and damping; validated on construction
    """
    def __init__(self, rate_hz: typing.SupportsFloat | typing.SupportsIndex = 1000.0, integrator: WristIntegrator = WristIntegrator.euler, max_rate: typing.SupportsFloat | typing.SupportsIndex = 100.0, max_condition: typing.SupportsFloat | typing.SupportsIndex = 10000.0, damping: typing.SupportsFloat | typing.SupportsIndex = 0.01, max_acceleration: typing.SupportsFloat | typing.SupportsIndex = 10000.0, max_momentum: typing.SupportsFloat | typing.SupportsIndex = 10000.0, max_moment: typing.SupportsFloat | typing.SupportsIndex = 100000.0) -> None:
        ...
    @property
    def damping(self) -> float:
        ...
    @property
    def integrator(self) -> WristIntegrator:
        ...
    @property
    def max_acceleration(self) -> float:
        ...
    @property
    def max_condition(self) -> float:
        ...
    @property
    def max_moment(self) -> float:
        ...
    @property
    def max_momentum(self) -> float:
        ...
    @property
    def max_rate(self) -> float:
        ...
    @property
    def rate_hz(self) -> float:
        ...
class WristCommand:
    """
    A reactionless-wrist tick's command: angles [rad], rates [rad/s], accelerations [rad/s^2] (feed-forward), next_angles [rad], the condition number of N(q) and the status
    """
    @property
    def accelerations(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def angles(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def condition_number(self) -> float:
        ...
    @property
    def next_angles(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def rates(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def status(self) -> Status:
        ...
class ReactionlessWrist:
    """
    Reactionless z-x-z wrist controller (Briot & Arakelian 2009, eqs 23-26, corrected)
    """
    def __init__(self, J1: numpy.typing.ArrayLike, J2: numpy.typing.ArrayLike, J3: numpy.typing.ArrayLike, config: ReactionlessWristConfig, initial_angles: numpy.typing.ArrayLike, target_momentum: numpy.typing.ArrayLike) -> None:
        ...
    def reset(self, angles: numpy.typing.ArrayLike, target_momentum: numpy.typing.ArrayLike) -> Status:
        ...
    def run(self, D: numpy.typing.ArrayLike, D_dot: numpy.typing.ArrayLike, D_half: numpy.typing.ArrayLike, D_next: numpy.typing.ArrayLike) -> dict:
        """
        N consecutive ticks in one call: D, D_dot, D_half, D_next each (N, 3) -> {'wrist_angles', 'wrist_rates', 'wrist_accelerations' (N, 3), 'condition' (N,), 'status' (N,) per tick}
        """
    def step(self, D: numpy.typing.ArrayLike, D_dot: numpy.typing.ArrayLike, D_half: numpy.typing.ArrayLike, D_next: numpy.typing.ArrayLike) -> Status:
        """
        One tick (configured integrator). Returns the Status; the command is in .command
        """
    def step_euler(self, D: numpy.typing.ArrayLike, D_dot: numpy.typing.ArrayLike) -> Status:
        ...
    def step_into(self, D: numpy.typing.NDArray[numpy.float64], D_dot: numpy.typing.NDArray[numpy.float64], D_half: numpy.typing.NDArray[numpy.float64], D_next: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: D [kg m^2/s], D_dot [N m], D_half, D_next as float64 arrays of 3; writes the command into `out` (3, 3): rows angles [rad], rates [rad/s], accelerations [rad/s^2]; returns the status as an int. Nothing is copied or allocated.
        """
    @property
    def angles(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def command(self) -> WristCommand:
        ...
    @property
    def dt(self) -> float:
        ...
class PaminsaModel:
    """
    Immutable PAMINSA model (Briot & Arakelian 2009), validated
    """
    def __init__(self, parameters: PaminsaParameters) -> None:
        ...
    def forward_kinematics(self, alpha1: typing.SupportsFloat | typing.SupportsIndex, alpha3: typing.SupportsFloat | typing.SupportsIndex, z_B: typing.SupportsFloat | typing.SupportsIndex) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], Status]:
        ...
    def inverse_kinematics(self, P: numpy.typing.ArrayLike) -> dict:
        ...
    def leg_points(self, P: numpy.typing.ArrayLike) -> tuple[numpy.typing.NDArray[numpy.float64], Status]:
        """
        (points, status): base-frame points A, B, C, D, E, F of each leg (3, 6, 3) at pose P; zeros and the status when P is not finite, unreachable or overflows
        """
    @property
    def body_names(self) -> list[str]:
        ...
    @property
    def guide_pivots(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 2]"]:
        ...
    @property
    def inertia_body(self) -> numpy.typing.ArrayLike:
        ...
    @property
    def masses(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def parameters(self) -> PaminsaParameters:
        ...
    @property
    def slider_lines(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 2]"]:
        ...
    @property
    def vertical_mass_xy(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
class PaminsaController:
    """
    One tick of the fully balanced PAMINSA (Briot & Arakelian 2009): kinematics at t_n, D (eq 19), the reactionless-wrist step, every body's motion and the shaking wrench
    """
    def __init__(self, model: PaminsaModel, config: ReactionlessWristConfig, initial_wrist_angles: numpy.typing.ArrayLike, max_speed: typing.SupportsFloat | typing.SupportsIndex = 10.0, max_acceleration: typing.SupportsFloat | typing.SupportsIndex = 1000.0) -> None:
        """
        max_speed [m/s], max_acceleration [m/s^2]: the platform motion a tick accepts (per component)
        """
    def reset(self, P: numpy.typing.ArrayLike, wrist_angles: numpy.typing.ArrayLike) -> Status:
        """
        Restart at rest at platform position P [m] with the wrist at `wrist_angles` [rad]; returns the Status (nothing changes unless ok)
        """
    def step(self, P: numpy.typing.ArrayLike, Pd: numpy.typing.ArrayLike, Pdd: numpy.typing.ArrayLike, P_half: numpy.typing.ArrayLike, Pd_half: numpy.typing.ArrayLike, Pdd_half: numpy.typing.ArrayLike, P_next: numpy.typing.ArrayLike, Pd_next: numpy.typing.ArrayLike, Pdd_next: numpy.typing.ArrayLike) -> Status:
        """
        One tick: platform position [m], velocity [m/s], acceleration [m/s^2] at t_n, t_n + dt/2, t_n + dt (Euler ignores the last two). Returns the Status; the result is in shaking_force, shaking_moment, D, D_dot and wrist_command
        """
    def step_into(self, now: numpy.typing.NDArray[numpy.float64], half: numpy.typing.NDArray[numpy.float64], next: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: the platform motion at t_n, t_n + dt/2, t_n + dt, each a (3, 3) float64 array with rows position [m], velocity [m/s], acceleration [m/s^2]; writes the wrist command into `out` (3, 3): rows angles [rad], rates [rad/s], accelerations [rad/s^2]; returns the status as an int (the wrench stays in shaking_force, shaking_moment)
        """
    @property
    def D(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def D_dot(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def shaking_force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def shaking_moment(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def wrist_angles(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def wrist_command(self) -> WristCommand:
        ...
class Arm2DofParameters:
    """
    Bare 2R arm of Arakelian et al. 2011, Fig. 1 (defaults: Sec. 4)
    """
    def __init__(self, m1: typing.SupportsFloat | typing.SupportsIndex = 2.5, m2: typing.SupportsFloat | typing.SupportsIndex = 2.0, l1: typing.SupportsFloat | typing.SupportsIndex = 0.4, l_s1: typing.SupportsFloat | typing.SupportsIndex = 0.1, l_s2: typing.SupportsFloat | typing.SupportsIndex = 0.1, i_s1: typing.SupportsFloat | typing.SupportsIndex = 0.15, i_s2: typing.SupportsFloat | typing.SupportsIndex = 0.1, g: typing.SupportsFloat | typing.SupportsIndex = 9.81) -> None:
        ...
    @property
    def g(self) -> float:
        ...
    @g.setter
    def g(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def i_s1(self) -> float:
        ...
    @i_s1.setter
    def i_s1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def i_s2(self) -> float:
        ...
    @i_s2.setter
    def i_s2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def l1(self) -> float:
        ...
    @l1.setter
    def l1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def l_s1(self) -> float:
        ...
    @l_s1.setter
    def l_s1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def l_s2(self) -> float:
        ...
    @l_s2.setter
    def l_s2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def m1(self) -> float:
        ...
    @m1.setter
    def m1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def m2(self) -> float:
        ...
    @m2.setter
    def m2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Arm2DofCounterweights:
    """
    Point-mass counterweights beyond A and B (eqs 25-31)
    """
    def __init__(self, m_cw1: typing.SupportsFloat | typing.SupportsIndex = 0.0, m_cw2: typing.SupportsFloat | typing.SupportsIndex = 0.0, r_cw1: typing.SupportsFloat | typing.SupportsIndex = 0.0, r_cw2: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @property
    def m_cw1(self) -> float:
        ...
    @m_cw1.setter
    def m_cw1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def m_cw2(self) -> float:
        ...
    @m_cw2.setter
    def m_cw2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def r_cw1(self) -> float:
        ...
    @r_cw1.setter
    def r_cw1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def r_cw2(self) -> float:
        ...
    @r_cw2.setter
    def r_cw2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Arm2DofDynamics(InverseDynamics, ForwardDynamics):
    """
    Closed-form dynamics of the 2-DOF arm, eqs 14-31 (corrected)
    """
    def __init__(self, arm: Arm2DofParameters, counterweights: Arm2DofCounterweights = ...) -> None:
        ...
    def coriolis_matrix(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
        """
        C(q, v) (2, 2), Christoffel form
        """
    def forward_dynamics(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, tau: numpy.typing.ArrayLike) -> dict:
        """
        Accelerations (N, 2): {'a', 'status'}
        """
    def gravity(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        Q(q) (2,), eqs 21-22
        """
    def inverse_dynamics(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
        """
        Joint torques (N, 2): {'tau', 'status'}
        """
    def kinetic_energy(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> float:
        ...
    def mass_matrix(self, q: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
        """
        A(q) (2, 2), eqs 14-19 (corrected)
        """
    def potential_energy(self, q: numpy.typing.ArrayLike) -> float:
        ...
    @property
    def dof(self) -> int:
        ...
    @property
    def lumped(self) -> dict:
        ...
class DecoupledJointController(JointController):
    """
    tau_i = k_i (a_des + Kp e + Kd e') for a dynamically balanced arm (Coutinho & Hess Coelho eqs 15, 26, 36)
    """
    def __init__(self, k: numpy.typing.ArrayLike, kp: numpy.typing.ArrayLike, kd: numpy.typing.ArrayLike, torque_limit: typing.Any = None, max_position: typing.SupportsFloat | typing.SupportsIndex = ..., max_speed: typing.SupportsFloat | typing.SupportsIndex = ..., max_acceleration: typing.SupportsFloat | typing.SupportsIndex = ...) -> None:
        """
        k, kp, kd: one value per joint; torque_limit: one per joint (default and +inf: no limit); max_position, max_speed, max_acceleration: the input range of a tick (default +inf: no limit; beyond it: the held command and Status.out_of_range)
        """
    def _tick(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        step() with the status as an int (what the Python classes' step wraps in a JointCommand)
        """
    def reset(self) -> None:
        """
        Forget the held command (zero torque).
        """
    @typing.overload
    def run(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> dict:
        """
        N consecutive ticks in one call: q, v [rad or m, rad/s or m/s], q_des, v_des, a_des, each (N, n) -> {'joint_torque': (N, n) [N m or N], 'status': (N,) per tick}
        """
    @typing.overload
    def run(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        One tick: (tau, status), tau [N m or N] (n,). Any real array-like input; non-finite or out-of-range input returns the held command and a non-ok status.
        """
    @typing.overload
    def step(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step_into(self, q: numpy.typing.NDArray[numpy.float64], v: numpy.typing.NDArray[numpy.float64], q_des: numpy.typing.NDArray[numpy.float64], v_des: numpy.typing.NDArray[numpy.float64], a_des: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: writes tau [N m or N] into `out` (a preallocated float64 array of n values) and returns the status as an int (0 = ok, bit flags of mechbal.Status). Every argument must be a C-contiguous float64 numpy array of n values; nothing is copied or allocated.
        """
    @typing.overload
    def step_into(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def k(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def last_command(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def torque_limit(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class PassiveController(JointController):
    """
    No controller: zero joint effort every tick, so the plant moves under gravity and its springs only (a passive simulation)
    """
    def __init__(self, dof: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        dof: number of actuated coordinates (>= 1)
        """
    def _tick(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        step() with the status as an int (what the Python classes' step wraps in a JointCommand)
        """
    def reset(self) -> None:
        """
        Forget the held command (zero torque).
        """
    @typing.overload
    def run(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> dict:
        """
        N consecutive ticks in one call: q, v [rad or m, rad/s or m/s], q_des, v_des, a_des, each (N, n) -> {'joint_torque': (N, n) [N m or N], 'status': (N,) per tick}
        """
    @typing.overload
    def run(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        One tick: (tau, status), tau [N m or N] (n,). Any real array-like input; non-finite or out-of-range input returns the held command and a non-ok status.
        """
    @typing.overload
    def step(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step_into(self, q: numpy.typing.NDArray[numpy.float64], v: numpy.typing.NDArray[numpy.float64], q_des: numpy.typing.NDArray[numpy.float64], v_des: numpy.typing.NDArray[numpy.float64], a_des: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: writes tau [N m or N] into `out` (a preallocated float64 array of n values) and returns the status as an int (0 = ok, bit flags of mechbal.Status). Every argument must be a C-contiguous float64 numpy array of n values; nothing is copied or allocated.
        """
    @typing.overload
    def step_into(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @property
    def dof(self) -> int:
        ...
class FiveBarParameters:
    """
    Planar 5R five-bar: lengths, masses, CoM positions along the links, inertias about x (vertical y-z plane, gravity -z)
    """
    def __init__(self, **kwargs) -> None:
        ...
    @property
    def Jd1(self) -> float:
        ...
    @Jd1.setter
    def Jd1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def Jd2(self) -> float:
        ...
    @Jd2.setter
    def Jd2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def Jp1(self) -> float:
        ...
    @Jp1.setter
    def Jp1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def Jp2(self) -> float:
        ...
    @Jp2.setter
    def Jp2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def a1(self) -> float:
        ...
    @a1.setter
    def a1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def a2(self) -> float:
        ...
    @a2.setter
    def a2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def b1(self) -> float:
        ...
    @b1.setter
    def b1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def b2(self) -> float:
        ...
    @b2.setter
    def b2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cd1(self) -> float:
        ...
    @cd1.setter
    def cd1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cd2(self) -> float:
        ...
    @cd2.setter
    def cd2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cp1(self) -> float:
        ...
    @cp1.setter
    def cp1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cp2(self) -> float:
        ...
    @cp2.setter
    def cp2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def d(self) -> float:
        ...
    @d.setter
    def d(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def gravity(self) -> float:
        ...
    @gravity.setter
    def gravity(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mP(self) -> float:
        ...
    @mP.setter
    def mP(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def md1(self) -> float:
        ...
    @md1.setter
    def md1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def md2(self) -> float:
        ...
    @md2.setter
    def md2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mp1(self) -> float:
        ...
    @mp1.setter
    def mp1(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mp2(self) -> float:
        ...
    @mp2.setter
    def mp2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class FiveBarDynamics(InverseDynamics):
    """
    Planar 5R by the coupling-matrix method (4x4 A°), evaluated per tick: M'(q), v'(q, qd), g'(q); Status.singular at type-2 singularities
    """
    def __init__(self, parameters: FiveBarParameters, singular_tolerance: typing.SupportsFloat | typing.SupportsIndex = 1e-06) -> None:
        ...
    def evaluate(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> dict:
        """
        For N states (q, qd each (N, 2)): {'mass' (N, 2, 2), 'velocity', 'gravity' (N, 2), 'ok' (N,), 'reciprocal_condition' (N,), 'status_per_instant' (N,), 'status' (OR)}; failed states give zeros
        """
    def inverse_dynamics(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
        """
        Joint torques (N, 2): {'tau', 'status_per_instant' (N,), 'status' (OR)}
        """
    def motion(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
        """
        Joint angles/rates/accelerations (N, 4) in the order (theta1, theta12, theta2, theta22) and the end effector (y, z) position/velocity/acceleration (N, 2); status_per_instant (N,) and their OR, status; failed instants give zeros
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def parameters(self) -> FiveBarParameters:
        ...
    @property
    def reciprocal_condition(self) -> float:
        ...
class ReactionlessTaskController:
    """
    Operational-space reactionless control: a redundant open mechanism follows a desired twist of a frame, v = J^+ x' + N z, with z minimising the selected momentum components in the null space
    """
    def __init__(self, model: MechanismModel, task_frame: str, task_rows: collections.abc.Sequence[str] = ['all'], cancel: collections.abc.Sequence[str] = ['moment'], integrator: str = 'euler', rate_hz: typing.SupportsFloat | typing.SupportsIndex = 1000.0, damping: typing.SupportsFloat | typing.SupportsIndex = 0.01, max_condition: typing.SupportsFloat | typing.SupportsIndex = 10000.0, max_rate: typing.SupportsFloat | typing.SupportsIndex = ..., null_space: bool = True, q0: typing.Any = None, v0: typing.Any = None, velocity_limits: bool = True) -> None:
        ...
    def run(self, twist: numpy.typing.ArrayLike, twist_rate: typing.Any = None) -> dict:
        """
        Ticks along the desired frame twist [v; w] (O axes) sampled every dt/2 ((2 steps + 1, 6)) and optionally its rate on the same grid (else estimated from the samples): q, v, a (steps + 1, dof), momentum, frame_twist (steps + 1, 6), predicted shaking_force, shaking_moment (steps + 1, 3), status.
        """
    def step(self, twist: numpy.typing.ArrayLike, twist_rate: typing.Any = None, twist_half: typing.Any = None, twist_next: typing.Any = None) -> int:
        """
        One tick: the desired frame twist [v; w] (O axes) at t_n, its rate (default: estimated from the three samples) and, for RK4, the twist at t_n + dt/2 and t_n + dt (default: the twist at t_n). Returns the status (int, 0 = ok); the command is in q, v, a, momentum, frame_twist, shaking_force, shaking_moment. run() gives the same commands over a whole motion.
        """
    @property
    def a(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Acceleration feed-forward at t_n [rad/s^2 or m/s^2] (dof,)
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def dt(self) -> float:
        ...
    @property
    def frame_twist(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 1]"]:
        """
        The frame's twist J v of the command [v; w] (6,)
        """
    @property
    def momentum(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 1]"]:
        """
        Momentum [P; H_O] of the command (6,)
        """
    @property
    def q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Commanded positions at t_n [rad or m] (dof,)
        """
    @property
    def shaking_force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Predicted shaking force of the command [N] (3,)
        """
    @property
    def shaking_moment(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Predicted shaking moment about O of the command [N m] (3,)
        """
    @property
    def status(self) -> int:
        """
        Status of the last tick (int, 0 = ok)
        """
    @property
    def target(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 1]"]:
        ...
    @property
    def v(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Commanded rates at t_n [rad/s or m/s] (dof,)
        """
class ReactionlessCommand:
    """
    One reactionless tick's command: actuated q, v, a (task as given, balancing computed), every coordinate q_full, v_full, a_full, the balancing joints' next positions, momentum [P; H_O], the predicted shaking_force [N] and shaking_moment [N m], condition, status
    """
    @property
    def a(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def a_full(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def condition(self) -> float:
        ...
    @property
    def momentum(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 1]"]:
        ...
    @property
    def next_balancing(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def q_full(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def shaking_force(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def shaking_moment(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def status(self) -> int:
        ...
    @property
    def v(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def v_full(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class ReactionlessController:
    """
    Reactionless control of any MechanismModel (C++ mechbal::ReactionlessController): balancing joints keep the selected momentum components at their target
    """
    def __init__(self, model: MechanismModel, balancing_joints: collections.abc.Sequence[str], q0: typing.Any = None, cancel: collections.abc.Sequence[str] = ['moment'], integrator: str = 'euler', rate_hz: typing.SupportsFloat | typing.SupportsIndex = 1000.0, damping: typing.SupportsFloat | typing.SupportsIndex = 0.01, max_condition: typing.SupportsFloat | typing.SupportsIndex = 10000.0, max_rate: typing.SupportsFloat | typing.SupportsIndex = ..., max_acceleration: typing.SupportsFloat | typing.SupportsIndex = ..., position_limits: bool = True, velocity_limits: bool = True, home_gain: typing.SupportsFloat | typing.SupportsIndex = 0.0, limit_gain: typing.SupportsFloat | typing.SupportsIndex = 0.0, home: typing.Any = None, max_position: typing.SupportsFloat | typing.SupportsIndex = ..., max_speed: typing.SupportsFloat | typing.SupportsIndex = ..., max_task_acceleration: typing.SupportsFloat | typing.SupportsIndex = ..., v0: typing.Any = None, q_guess: typing.Any = None) -> None:
        """
        q0: the actuated coordinates at the start (default zeros); v0: their rates (default rest)
        """
    def reset(self, q0: numpy.typing.ArrayLike, v0: typing.Any = None) -> int:
        ...
    def run(self, q_task: numpy.typing.ArrayLike, v_task: numpy.typing.ArrayLike, a_task: numpy.typing.ArrayLike) -> dict:
        """
        Ticks along the task motion sampled on the half-step grid t_j = j dt/2 ((2 steps + 1, n_task) each): the command at the steps + 1 ticks t_n = n dt (the last tick Euler).
        """
    def set_target(self, momentum: numpy.typing.ArrayLike, momentum_rate: numpy.typing.ArrayLike) -> int:
        ...
    def step(self, q_task: numpy.typing.ArrayLike, v_task: numpy.typing.ArrayLike, a_task: numpy.typing.ArrayLike, q_half: typing.Any = None, v_half: typing.Any = None, q_next: typing.Any = None, v_next: typing.Any = None) -> int:
        """
        One tick; without the half/next samples an Euler tick. Returns the status; the command is in `command`.
        """
    def step_into(self, now: numpy.typing.NDArray[numpy.float64], half: numpy.typing.NDArray[numpy.float64], next: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: now (3, n_task) rows q, v, a of the task joints at t_n; half and next (2, n_task) rows q, v at t_n + dt/2 and t_n + dt; writes the actuated command into out (3, n_actuated) rows q, v, a; returns the status. C-contiguous float64 arrays only.
        """
    @property
    def balancing_indices(self) -> list[int]:
        ...
    @property
    def balancing_joints(self) -> list[str]:
        ...
    @property
    def balancing_state(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def cancelled_rows(self) -> list[int]:
        ...
    @property
    def command(self) -> ReactionlessCommand:
        ...
    @property
    def dt(self) -> float:
        ...
    @property
    def num_actuated(self) -> int:
        ...
    @property
    def num_balancing(self) -> int:
        ...
    @property
    def num_task(self) -> int:
        ...
    @property
    def target(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 1]"]:
        ...
    @property
    def task_indices(self) -> list[int]:
        ...
    @property
    def task_joints(self) -> list[str]:
        ...
class ReactionlessJointController(JointController):
    """
    The reactionless controller followed by computed torque over the model: a JointController over the actuated coordinates (the balancing joints' desired entries are ignored)
    """
    def __init__(self, model: MechanismModel, balancing_joints: collections.abc.Sequence[str], q0: numpy.typing.ArrayLike, kp: numpy.typing.ArrayLike, kd: numpy.typing.ArrayLike, cancel: collections.abc.Sequence[str] = ['moment'], integrator: str = 'euler', rate_hz: typing.SupportsFloat | typing.SupportsIndex = 1000.0, damping: typing.SupportsFloat | typing.SupportsIndex = 0.01, max_condition: typing.SupportsFloat | typing.SupportsIndex = 10000.0, max_rate: typing.SupportsFloat | typing.SupportsIndex = ..., max_acceleration: typing.SupportsFloat | typing.SupportsIndex = ..., position_limits: bool = True, velocity_limits: bool = True, home_gain: typing.SupportsFloat | typing.SupportsIndex = 0.0, limit_gain: typing.SupportsFloat | typing.SupportsIndex = 0.0, home: typing.Any = None, max_position: typing.SupportsFloat | typing.SupportsIndex = ..., max_speed: typing.SupportsFloat | typing.SupportsIndex = ..., max_task_acceleration: typing.SupportsFloat | typing.SupportsIndex = ..., torque_limit: typing.Any = None, q_guess: typing.Any = None) -> None:
        ...
    def _tick(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        step() with the status as an int (what the Python classes' step wraps in a JointCommand)
        """
    def reset(self) -> None:
        """
        Forget the held command (zero torque).
        """
    @typing.overload
    def run(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> dict:
        """
        N consecutive ticks in one call: q, v [rad or m, rad/s or m/s], q_des, v_des, a_des, each (N, n) -> {'joint_torque': (N, n) [N m or N], 'status': (N,) per tick}
        """
    @typing.overload
    def run(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step(self, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike) -> tuple:
        """
        One tick: (tau, status), tau [N m or N] (n,). Any real array-like input; non-finite or out-of-range input returns the held command and a non-ok status.
        """
    @typing.overload
    def step(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @typing.overload
    def step_into(self, q: numpy.typing.NDArray[numpy.float64], v: numpy.typing.NDArray[numpy.float64], q_des: numpy.typing.NDArray[numpy.float64], v_des: numpy.typing.NDArray[numpy.float64], a_des: numpy.typing.NDArray[numpy.float64], out: numpy.typing.NDArray[numpy.float64]) -> int:
        """
        The fast tick: writes tau [N m or N] into `out` (a preallocated float64 array of n values) and returns the status as an int (0 = ok, bit flags of mechbal.Status). Every argument must be a C-contiguous float64 numpy array of n values; nothing is copied or allocated.
        """
    @typing.overload
    def step_into(self, *args, **kwargs) -> typing.Any:
        """
        Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release
        """
    @property
    def dof(self) -> int:
        ...
    @property
    def last_command(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def reactionless(self) -> ReactionlessController:
        ...
def arm2dof_description(arm: Arm2DofParameters, counterweights: Arm2DofCounterweights = ...) -> MechanismDescription:
    """
    The 2-DOF arm (counterweights merged into the links) as a general MechanismDescription: x-z plane, joints 'shoulder' and 'elbow' with axes along -y, gravity (0, 0, -g)
    """
def case_from_toml(text: str, source: str = 'string') -> tuple[MechanismModel, ControlConfig, str]:
    """
    As load_case_file, from TOML text (the whole document).
    """
def load_case_file(path: str) -> tuple[MechanismModel, ControlConfig, str]:
    """
    (model, control, name) of a case file read by the C++ reader (mechbal::load_case): the [mechanism] model, the [control] table checked against it (kind 'none' without one) and [case] name.
    """
def load_case_trajectory(path: str) -> TrajectoryConfig:
    """
    The [trajectory] of a mechanism case file as the C++ reader (mechbal::load_case) checked it: constant_speed with speed [rad/s] per actuated joint (rpm converted) and duration [s] (from revolutions when given), or a rest-to-rest law with start, end and duration.
    """
def load_mechanism_file(path: str) -> MechanismModel:
    """
    The MechanismModel of the [mechanism] table of a case file or balanced.toml, read by the C++ reader (mechbal::load_mechanism). ValueError naming the dotted field and the value.
    """
def mechanism_bias_torque(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_center_of_mass(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_closed_forward_dynamics(model: MechanismModel, q_actuated: numpy.typing.ArrayLike, v_actuated: numpy.typing.ArrayLike, tau_actuated: numpy.typing.ArrayLike, q_guess: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_closed_mass_matrix(model: MechanismModel, q_actuated: numpy.typing.ArrayLike, q_guess: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_closed_motion(model: MechanismModel, q_actuated: numpy.typing.ArrayLike, v_actuated: numpy.typing.ArrayLike, a_actuated: numpy.typing.ArrayLike, q_guess: numpy.typing.ArrayLike, max_iterations: typing.SupportsInt | typing.SupportsIndex = 50, tolerance: typing.SupportsFloat | typing.SupportsIndex = 1e-13, singular_rcond: typing.SupportsFloat | typing.SupportsIndex = 1e-07, dynamics: bool = False) -> dict:
    """
    Solve the loops along a motion of the actuated coordinates (each instant warm-starts the next): full q, v, a (N, dof), rcond of A°, residual, iterations and status per instant; with dynamics=True also the actuated forces C^T tau (N, na).
    """
def mechanism_frame_jacobian(model: MechanismModel, q: numpy.typing.ArrayLike, frame: str) -> dict:
    ...
def mechanism_from_toml(text: str, source: str = 'string') -> MechanismModel:
    """
    As load_mechanism_file, from TOML text (the whole document).
    """
def mechanism_from_urdf(path: str) -> MechanismModel:
    """
    The MechanismModel of a URDF file (urdfdom): links with inertials as bodies, revolute / continuous / prismatic / fixed joints, mimic as gear couplings, limits, a frame per link. ValueError names the URDF element and the value.
    """
def mechanism_from_urdf_string(xml: str) -> MechanismModel:
    """
    The MechanismModel of a URDF document given as a string.
    """
def mechanism_gravity_regressor(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_gravity_torque(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_inverse_dynamics(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_kinematics(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
    """
    Bodies' motion in O (com, com_velocity, com_acceleration (N,B,3), rotation (N,B,3,3) body to O, angular_velocity, angular_acceleration (N,B,3)), link frames (link_rotation, link_position) and named frames (frame_placement (N,F,4,4)).
    """
def mechanism_mass_matrix(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_momentum(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_momentum_matrix(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_momentum_regressor(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> dict:
    ...
def mechanism_shaking_wrench(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike, with_gravity: bool = True) -> dict:
    ...
def mechanism_single_sample(model: typing.Any, status_ok: typing.Any, wrench_type: type) -> dict:
    """
    The per-sample calls of a MechanismModel from float64 arrays (what mechbal.Mechanism uses first), sharing one MechanismData: {name: function}, each returning None when its arguments are not 1-D C-contiguous float64 numpy arrays of dof values, or the instant is rejected (the caller then takes its general path). shaking_wrench returns a `wrench_type` (a class with the fields shaking_force, shaking_moment, linear_momentum, angular_momentum and status, set without calling its __init__; status: `status_ok`).
    """
def mechanism_springs(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    """
    Springs over a batch of configurations (N, dof): spring_length (anchor distance d [m]) and spring_tension (T at the anchors [N]) (N, S), spring_torque K(q) = dV_s/dq (N, dof), spring_energy [J] and potential_energy (gravity plus springs [J]) (N,), status (N,)
    """
def mechanism_static_torque(model: MechanismModel, q: numpy.typing.ArrayLike) -> dict:
    """
    G(q) + K(q): gravity and springs (N, dof)
    """
def mechanism_torque_regressor(model: MechanismModel, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
    ...
def name_problem(name: str) -> str:
    """
    Why `name` (UTF-8 bytes or str) is not a valid name of the model, or '' when it is: the character set of names (docs/case_format.md, Names).
    """
def paminsa_kinematics(model: PaminsaModel, P: numpy.typing.ArrayLike, Pd: numpy.typing.ArrayLike, Pdd: numpy.typing.ArrayLike, q: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, a: numpy.typing.ArrayLike) -> dict:
    """
    Every body's motion (N, 38, ...), the shaking wrench about O and D, dD/dt (eq 19) for platform motion and prescribed wrist motion, each (N, 3).
    """
def paminsa_reactionless_run(model: PaminsaModel, config: ReactionlessWristConfig, initial_wrist_angles: numpy.typing.ArrayLike, P_half: numpy.typing.ArrayLike, Pd_half: numpy.typing.ArrayLike, Pdd_half: numpy.typing.ArrayLike) -> dict:
    """
    Fully balanced run with the reactionless wrist ticking at config.rate_hz. Platform motion sampled every dt/2 ((2 steps + 1, 3) each); outputs at the steps + 1 ticks.
    """
def pd_error_analytic(e0: typing.SupportsFloat | typing.SupportsIndex, ed0: typing.SupportsFloat | typing.SupportsIndex, kp: typing.SupportsFloat | typing.SupportsIndex, kd: typing.SupportsFloat | typing.SupportsIndex, t: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    Solution of e'' + kd e' + kp e = 0 (Arakelian et al. 2011, eq 6) at times t
    """
def read_urdf(path: str, strict: bool = False, allow_massless: bool = False) -> tuple[MechanismModel, list[str]]:
    """
    (MechanismModel, warnings) of a URDF file: strict refuses the defects that the lenient reading repairs with one warning each (mechbal/io/urdf.hpp, UrdfOptions); a URDF with no <inertial> on any moving link is refused unless allow_massless.
    """
def simulate_closed_loop(plant: ForwardDynamics, controller: JointController, desired: RestToRestTrajectory, q0: numpy.typing.ArrayLike, v0: numpy.typing.ArrayLike, dt: typing.SupportsFloat | typing.SupportsIndex = 0.001, duration: typing.SupportsFloat | typing.SupportsIndex = 1.0, sampling: str = 'zero_order_hold') -> dict:
    """
    RK4 closed loop of `plant` (any ForwardDynamics: Arm2DofDynamics, MechanismDynamics of any mechanism) under `controller` (any JointController) tracking `desired`; returns a dict of arrays t (N+1,), q, v, q_des, v_des, tau (N+1, dof), status, saturated_ticks, steps_completed.
    """
def simulate_closed_loop_sampled(plant: ForwardDynamics, controller: JointController, q_des: numpy.typing.ArrayLike, v_des: numpy.typing.ArrayLike, a_des: numpy.typing.ArrayLike, q0: numpy.typing.ArrayLike, v0: numpy.typing.ArrayLike, dt: typing.SupportsFloat | typing.SupportsIndex = 0.001, duration: typing.SupportsFloat | typing.SupportsIndex = 1.0, sampling: str = 'zero_order_hold') -> dict:
    """
    simulate_closed_loop tracking a sampled desired motion: q_des, qd_des, qdd_des each (2 steps + 1, dof), sampled every dt/2 from t = 0 (steps = round(duration / dt)).
    """
def simulate_passive(plant: ForwardDynamics, q0: numpy.typing.ArrayLike, v0: numpy.typing.ArrayLike, dt: typing.SupportsFloat | typing.SupportsIndex, duration: typing.SupportsFloat | typing.SupportsIndex, lower_limit: numpy.typing.ArrayLike, upper_limit: numpy.typing.ArrayLike) -> dict:
    """
    Passive RK4 run of `plant` (any ForwardDynamics) from (q0, v0) with zero effort; lower_limit / upper_limit (dof values each; -inf / inf: no stop on that side) are inelastic stops. Returns a dict: t (N+1,), q, v (N+1, dof), tick_status, steps_completed, stop_ticks (steps that ended on a stop).
    """
def status_name(status: typing.SupportsInt | typing.SupportsIndex) -> str:
    """
    Name of a Status value ('multiple' for a combination of flags)
    """
def urdf_description(path: str) -> MechanismDescription:
    """
    The MechanismDescription of a URDF file (before validation by the model).
    """
def validate_rigid_body(mass: typing.SupportsFloat | typing.SupportsIndex, inertia_body: numpy.typing.ArrayLike, field: str = 'body') -> None:
    """
    Raise ValueError naming `field` if the mass is negative/non-finite or the inertia is not a symmetric positive semi-definite tensor satisfying the triangle inequality.
    """
def wrist_momentum_bias(J1: numpy.typing.ArrayLike, J2: numpy.typing.ArrayLike, J3: numpy.typing.ArrayLike, angles: numpy.typing.ArrayLike, rates: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
    """
    d/dt(N qdot) - N qddot
    """
def wrist_momentum_matrix(J1: numpy.typing.ArrayLike, J2: numpy.typing.ArrayLike, J3: numpy.typing.ArrayLike, angles: numpy.typing.ArrayLike) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
    """
    N(q) of Briot & Arakelian 2009 eq 23 (corrected): wrist angular momentum = N qdot
    """
MAX_URDF_BYTES: int = 67108864
MAX_URDF_DEPTH: int = 64
__version__: str = '0.1.0'
simulate_computed_torque = simulate_closed_loop
