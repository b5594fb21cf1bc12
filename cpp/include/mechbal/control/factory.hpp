#pragma once
/// \file control/factory.hpp
/// make_controller: the controller a ControlConfig describes, over a MechanismModel.
///  - computed_torque: ComputedTorque over MechanismDynamics (the general model, closed loops
///    through the loop projection), gains kp, kd, torque_limit;
///  - decoupled: DecoupledJointController with k (the constant diagonal of the balanced mass
///    matrix; from the model at q = 0 when the config leaves it empty), kp, kd, torque_limit;
///  - reactionless: not in this build yet (std::invalid_argument saying so);
///  - passive: PassiveController (zero effort: gravity and springs move the mechanism).
/// Construction time only: throws std::invalid_argument naming the `control.` field and the value.
/// The returned controller owns everything it uses (its own copy of the model); step() is
/// noexcept and allocation-free as the controller's own. `q_guess` (model.dof() values, or empty
/// for zeros): the full coordinates near the assembly the loops of a closed mechanism start from
/// (the assembly mode; a case's `[trajectory] initial_guess`).
#include <Eigen/Core>
#include <memory>

#include "mechbal/control/config.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/model/model.hpp"

namespace mechbal {

std::unique_ptr<JointController> make_controller(const MechanismModel& model, const ControlConfig& control,
                                                 const Eigen::VectorXd& q_guess = Eigen::VectorXd());

}  // namespace mechbal
