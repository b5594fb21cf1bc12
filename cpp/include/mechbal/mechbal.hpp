#pragma once
/// \file mechbal.hpp
/// Umbrella header of the mechbal C++ core: includes every public header in
/// cpp/include/mechbal/ (the ctest `install_and_consume` fails when one is missing here).
///
/// Model and algorithms
#include "mechbal/status.hpp"
#include "mechbal/version.hpp"
#include "mechbal/rigid_body.hpp"
#include "mechbal/serial_chain.hpp"
#include "mechbal/trajectory.hpp"
#include "mechbal/dynamics.hpp"
#include "mechbal/rnea.hpp"
#include "mechbal/kdl_chain.hpp"
#include "mechbal/coupled_model.hpp"
/// Controllers and closed-loop simulation
#include "mechbal/computed_torque.hpp"
#include "mechbal/decoupled_control.hpp"
#include "mechbal/reactionless_wrist.hpp"
#include "mechbal/closed_loop.hpp"
/// Fast paths of the papers' mechanisms
#include "mechbal/arm2dof.hpp"
#include "mechbal/disc_arm.hpp"
#include "mechbal/five_bar.hpp"
#include "mechbal/paminsa.hpp"
