#pragma once
/// \file control/factory.hpp
/// The controllers a ControlConfig describes, over a MechanismModel (the `[control]` table that
/// io/case.hpp reads, or one filled in code).
///  - make_controller: a joint controller (torques from measured and desired joint motion):
///    - computed_torque: ComputedTorque over MechanismDynamics (the general model, closed loops
///      through the loop projection), gains kp, kd, torque_limit;
///    - decoupled: DecoupledJointController with k (the constant diagonal of the balanced mass
///      matrix; from the model at q = 0 when the config leaves it empty), kp, kd, torque_limit;
///    - passive: PassiveController (zero effort: gravity and springs move the mechanism);
///    - reactionless: ReactionlessJointController, the reactionless controller followed by its
///      computed-torque stage (kp, kd required here, torque_limit), starting at the actuated
///      coordinates `q0` (the case's `[trajectory] start`: a balancing joint's start is its initial
///      position). The concrete type follows the kind, so a caller that needs the reactionless
///      command (the predicted shaking wrench) may static_cast to ReactionlessJointController.
///  - make_reactionless_controller: the reactionless motion command alone (kind reactionless in
///    joint-space mode: no task_frame; kp and kd are not used).
///  - make_task_controller: the operational-space mode (kind reactionless with task_frame).
/// Construction time only: each throws std::invalid_argument naming the `control.` field and the
/// value. The returned controller owns everything it uses (its own copy of the model); its ticks
/// are noexcept and allocation-free. `q_guess` (model.dof() values, or empty for zeros): the full
/// coordinates near the assembly the loops of a closed mechanism start from (the assembly mode; a
/// case's `[trajectory] initial_guess`). `q0`, `v0`: the start (empty: zeros, rest).
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mechbal/control/config.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/control/reactionless.hpp"
#include "mechbal/model/model.hpp"

namespace mechbal {

std::unique_ptr<JointController> make_controller(const MechanismModel& model, const ControlConfig& control,
                                                 const Eigen::VectorXd& q_guess = Eigen::VectorXd(),
                                                 const Eigen::VectorXd& q0 = Eigen::VectorXd());

/// The ReactionlessConfig of a `[control]` table of kind reactionless (cancel names as a mask,
/// the integrator, rate, damping, limits and gains); the other fields keep their defaults.
ReactionlessConfig reactionless_config(const ControlConfig& control);
/// The TaskSpaceConfig of a `[control]` table of kind reactionless with a task_frame.
TaskSpaceConfig task_space_config(const ControlConfig& control);

/// The cancel mask (MomentumComponent bits) of momentum component names: "moment", "force",
/// "both", "moment_x|y|z", "force_x|y|z" (at least one; momentum_component). Throws
/// std::invalid_argument naming `field` (the `[control]` table's, or "cancel" for a caller's own
/// argument) and the entry: every reader of cancel gives the same message.
std::uint32_t cancel_mask(const std::vector<std::string>& cancel, const std::string& field = "control.cancel");

/// The TaskSpaceConfig::task_rows mask (MomentumComponent bits of [v; w]) of twist component names:
/// "all", "linear", "angular", "v_x", "v_y", "v_z", "w_x", "w_y", "w_z" (at least one). Throws
/// std::invalid_argument naming `field` (the `[control]` table's, or "task_rows" for a caller's
/// own argument) and the entry: every reader of task_rows gives the same message.
std::uint32_t task_rows_mask(const std::vector<std::string>& rows, const std::string& field = "control.task_rows");

/// `q0`, `v0`: actuated coordinates (empty: zeros, rest).
std::unique_ptr<ReactionlessController> make_reactionless_controller(
    const MechanismModel& model, const ControlConfig& control, const Eigen::VectorXd& q0 = Eigen::VectorXd(),
    const Eigen::VectorXd& v0 = Eigen::VectorXd(), const Eigen::VectorXd& q_guess = Eigen::VectorXd());

/// `q0`, `v0`: every coordinate (an open mechanism; empty: zeros, rest).
std::unique_ptr<ReactionlessTaskController> make_task_controller(const MechanismModel& model,
                                                                 const ControlConfig& control,
                                                                 const Eigen::VectorXd& q0 = Eigen::VectorXd(),
                                                                 const Eigen::VectorXd& v0 = Eigen::VectorXd());

}  // namespace mechbal
