#pragma once
/// \file mechbal.hpp
/// Umbrella header of the mechbal C++ core: includes every public header of
/// cpp/include/mechbal/ and its layer folders, bottom up (model, algorithm, control, io, then the
/// papers' fast paths); the ctest `install_and_consume` fails when one is missing here; detail/ is
/// private.
///
/// The general mechanism model and its algorithms (one header each)
#include "mechbal/build_config.hpp"
#include "mechbal/status.hpp"
#include "mechbal/version.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/model/joint_type.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/regressor.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/algorithm/springs.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
/// Trajectories, dynamics back ends
#include "mechbal/control/trajectory.hpp"
#include "mechbal/control/dynamics.hpp"
#if MECHBAL_WITH_KDL
#include "mechbal/control/kdl_chain.hpp"
#endif
/// Controllers and closed-loop simulation
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/passive.hpp"
#include "mechbal/control/joint_limits.hpp"
#include "mechbal/control/closed_loop.hpp"
#include "mechbal/control/reactionless.hpp"
#include "mechbal/control/config.hpp"
#include "mechbal/control/factory.hpp"
/// Reading mechbal's case format (TOML) and URDF
#include "mechbal/io/case.hpp"
#if MECHBAL_WITH_URDF
#include "mechbal/io/urdf.hpp"
#endif
/// Fast paths of the papers' mechanisms (a build with MECHBAL_WITH_PAPERS)
#if MECHBAL_WITH_PAPERS
#include "mechbal/papers/arm2dof/arm2dof.hpp"
#include "mechbal/papers/five_bar/coupled_projection.hpp"
#include "mechbal/papers/five_bar/five_bar.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/papers/paminsa/reactionless_wrist.hpp"
#endif
