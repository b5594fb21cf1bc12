#pragma once
/// \file algorithm/springs.hpp
/// Springs of a MechanismModel (model.hpp, `Spring`): anchor distances, tensions, elastic and
/// total potential energy, and the joint forces they need.
///
/// **Convention (and why gravity_torque stays pure gravity).** `spring_torque` K(q) = dV_s/dq is
/// the joint force that holds the springs still, with the sign of gravity_torque G(q) = dV_g/dq, so
/// the static motor torque is `static_torque` = G(q) + K(q), and a mechanism is statically
/// balanced by its springs exactly when the total potential energy V_g + V_s is constant, i.e.
/// static_torque = 0 (Martini et al. 2015, eqs 11-14). `gravity_torque` (inverse_dynamics.hpp)
/// stays the gravity alone, as in Pinocchio (computeGeneralizedGravity), because the gravity
/// regressors and the counterweight methods rely on G = Y(q) pi being the weights only.
/// Everything that means "the force the motors provide" includes the springs: inverse_dynamics
/// (tau = M a + C v + G + K), bias_torque (C v + G + K), hence the forward dynamics, the projected
/// closed-loop dynamics (loops.hpp) and the simulator; a model without springs computes exactly
/// what it did before, at the cost of one branch.
///
/// Same contract as every algorithm over a MechanismModel (kinematics.hpp): noexcept,
/// allocation-free, Status::bad_size / non_finite_input with nothing written.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.spring_length (anchor distance d [m]), data.spring_tension (T at the anchors [N]) and
/// data.spring_energy (sum of V(d) [J]) at q.
Status spring_state(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// data.spring_torque = K(q) = dV_s/dq [N m or N] (with spring_state's results).
Status spring_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// data.static_torque = G(q) + K(q); also data.gravity_torque = G(q) and data.spring_torque.
Status static_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// data.potential_energy = V_g + V_s [J]: gravity -sum m g . c (zero at O's origin) plus the
/// springs' energy (data.spring_energy, spring_length, spring_tension also written).
Status potential_energy(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;

}  // namespace mechbal
