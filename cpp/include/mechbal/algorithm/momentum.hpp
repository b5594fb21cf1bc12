#pragma once
/// \file algorithm/momentum.hpp
/// Linear momentum P = sum m v_G and angular momentum about O, H_O = sum (OG x m v_G + I w), of all
/// bodies (Briot & Arakelian 2009, eqs 1-4), and the momentum matrix A(q) with [P; H_O] = A(q) v.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.shaking.linear_momentum, data.shaking.angular_momentum.
Status momentum(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                const ConstVector& v) noexcept;
/// data.momentum_matrix (6 x dof, linear rows first).
Status momentum_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;

}  // namespace mechbal
