#pragma once
/// \file mechbal.hpp
/// Umbrella header of the mechbal C++ core: includes every public header in
/// cpp/include/mechbal/ and cpp/include/mechbal/algorithm/ (the ctest `install_and_consume` fails
/// when one is missing here; detail/ is private).
///
/// The general mechanism model and its algorithms (one header each)
#include "mechbal/status.hpp"
#include "mechbal/urdf.hpp"
#include "mechbal/version.hpp"
#include "mechbal/rigid_body.hpp"
#include "mechbal/joint_type.hpp"
#include "mechbal/model.hpp"
#include "mechbal/data.hpp"
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
#include "mechbal/mechanism_dynamics.hpp"
/// Serial chains, trajectories, dynamics back ends
#include "mechbal/serial_chain.hpp"
#include "mechbal/trajectory.hpp"
#include "mechbal/dynamics.hpp"
#include "mechbal/rnea.hpp"
#include "mechbal/kdl_chain.hpp"
#include "mechbal/coupled_model.hpp"
/// Controllers and closed-loop simulation
#include "mechbal/joint_controller.hpp"
#include "mechbal/computed_torque.hpp"
#include "mechbal/decoupled_control.hpp"
#include "mechbal/joint_limits.hpp"
#include "mechbal/reactionless_wrist.hpp"
#include "mechbal/closed_loop.hpp"
#include "mechbal/control/reactionless.hpp"
/// Fast paths of the papers' mechanisms
#include "mechbal/arm2dof.hpp"
#include "mechbal/five_bar.hpp"
#include "mechbal/paminsa.hpp"
