#pragma once
/// \file detail/placed.hpp
/// Internal: algorithms over links that the caller has just placed at q (data.joint_position and
/// every link's placement, world_* included, are those of q: e.g. right after closed_motion or
/// momentum_matrix at the same q), so they skip the placement pass (sin/cos and rotation products
/// of every link) the public functions start with. The results are bit for bit those of the
/// public functions at q. noexcept and allocation-free; no input checks (the caller's).
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal::detail {

/// momentum_matrix at the placed q.
Status momentum_matrix_placed(const MechanismModel& model, MechanismData& data) noexcept;
/// shaking_wrench(q, v, a) at the placed q (q: the coordinates the links are placed at).
Status shaking_wrench_placed(const MechanismModel& model, MechanismData& data, const Eigen::Ref<const Eigen::VectorXd>& q,
                             const Eigen::Ref<const Eigen::VectorXd>& v,
                             const Eigen::Ref<const Eigen::VectorXd>& a) noexcept;

}  // namespace mechbal::detail
