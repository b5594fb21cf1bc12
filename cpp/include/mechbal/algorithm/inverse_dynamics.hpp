#pragma once
/// \file algorithm/inverse_dynamics.hpp
/// Inverse dynamics of the tree by the recursive Newton-Euler algorithm (Luh, Walker & Paul 1980;
/// Featherstone 2008, alg. 5.1 on 3-vectors, joint-aligned frames as in rnea.hpp), with gear
/// couplings projected: tau = G^T tau_joint, where joint positions are G q + offset.
#include <Eigen/Core>

#include "mechbal/data.hpp"
#include "mechbal/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.joint_torque = M(q) a + C(q, v) v + G(q).
Status inverse_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                        const ConstVector& v, const ConstVector& a) noexcept;
/// data.gravity_torque = G(q).
Status gravity_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// data.bias_torque = C(q, v) v + G(q) (Pinocchio's nle).
Status bias_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                   const ConstVector& v) noexcept;

}  // namespace mechbal
