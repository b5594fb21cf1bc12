"""mechbal: balancing of mechanisms and real-time control of balanced robots.

The performance-critical algorithms live in the C++ core (``mechbal._core``); this package adds
configuration (TOML -> validated models), offline sizing, batch simulation, reports and the
``mechbal`` command line.
"""
from mechbal._core import (  # noqa: F401
    Arm2DofDynamics,
    Arm2DofParameters,
    ChainModel,
    ComputedTorque,
    InverseDynamics,
    JointSpec,
    JointType,
    KdlChainDynamics,
    MechanismDynamics,
    PaminsaModel,
    PaminsaParameters,
    ReactionlessWrist,
    ReactionlessWristConfig,
    RestToRestTrajectory,
    RneChainDynamics,
    Status,
    TimeLaw,
    WristIntegrator,
    chain_kinematics,
    paminsa_kinematics,
    paminsa_reactionless_run,
    shaking_wrench,
    validate_rigid_body,
)
from mechbal._core import __version__  # noqa: F401
from mechbal.config import ConfigError, ConfigWarning, load_case  # noqa: F401
from mechbal._core import (  # noqa: F401,E402
    Body, Frame, Joint, LoopConstraint, LoopType, MechanismDescription, MechanismModel)
from mechbal.mechanism import Mechanism  # noqa: F401,E402
