#pragma once
/// \file algorithm/jacobian.hpp
/// Jacobian of a named frame: [v; w] = J(q) qdot, v the velocity of the frame origin and w the
/// angular velocity, both in O's axes (Pinocchio's LOCAL_WORLD_ALIGNED).
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.frame_jacobian (6 x dof) of frame index `frame` (model.frame_index(name)); an index out
/// of range gives Status::bad_size.
Status frame_jacobian(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                      int frame) noexcept;

}  // namespace mechbal
