#pragma once
/// \file algorithm/regressor.hpp
/// Inertial-parameter regressors: joint torque, gravity torque and momentum as linear functions of
/// every body's 10 inertial parameters pi_b = [m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], with c and
/// I (about the link frame's origin) in the frame of the link that carries body b (the frame the
/// user described the link in). Columns 10 b .. 10 b + 9 belong to body b; bodies on the base
/// have zero columns. These are what balancing by counterweights, discs and springs is sized on.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.torque_regressor: tau(q, v, a) = Y pi (gravity included).
Status torque_regressor(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                        const ConstVector& v, const ConstVector& a) noexcept;
/// data.gravity_regressor: G(q) = Y pi.
Status gravity_regressor(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// data.momentum_regressor: [P; H_O](q, v) = Y pi.
Status momentum_regressor(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                          const ConstVector& v) noexcept;

}  // namespace mechbal
