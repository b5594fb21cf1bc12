#pragma once
/// \file algorithm/mass_matrix.hpp
/// Joint-space mass matrix by the composite rigid body algorithm (Featherstone 2008, alg. 6.2) on
/// the tree, projected through the gear couplings (M = G^T M_joint G).
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.mass_matrix (dof x dof, both triangles).
Status mass_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;

}  // namespace mechbal
