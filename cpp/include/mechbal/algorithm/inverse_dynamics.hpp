#pragma once
/// \file algorithm/inverse_dynamics.hpp
/// Inverse dynamics of the tree by the recursive Newton-Euler algorithm (Luh, Walker & Paul 1980;
/// Featherstone 2008, alg. 5.1 on 3-vectors, joint-aligned frames as in rnea.hpp), with gear
/// couplings projected: tau = G^T tau_joint, where joint positions are G q + offset.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.joint_torque = M(q) a + C(q, v) v + G(q) + K(q): the joint forces the motors provide, the
/// springs' K(q) = dV_s/dq included (algorithm/springs.hpp; data.spring_torque is written too).
/// The base's entry of the backward pass (data.work[0]) is the whole wrench the base exerts on the
/// moving links, through their joints and through the springs anchored to it.
Status inverse_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                        const ConstVector& v, const ConstVector& a) noexcept;
/// data.gravity_torque = G(q), gravity alone (as Pinocchio's computeGeneralizedGravity): the
/// springs' part is spring_torque, their sum static_torque (algorithm/springs.hpp).
Status gravity_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// data.bias_torque = C(q, v) v + G(q) + K(q) (Pinocchio's nle, plus the springs): the inverse
/// dynamics at a = 0, what the forward dynamics subtracts.
Status bias_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                   const ConstVector& v) noexcept;

}  // namespace mechbal
