#pragma once
/// \file detail/placed.hpp
/// Internal: algorithms over links that the caller has just placed at q (data.joint_position and
/// every link's placement, world_* included, are those of q: e.g. right after closed_motion or
/// momentum_matrix at the same q), so they skip the placement pass (sin/cos and rotation products
/// of every link) the public functions start with. The results are bit for bit those of the
/// public functions at q. noexcept and allocation-free; no input checks (the caller's).
#include <Eigen/Core>
#include <vector>

#include "mechbal/detail/link_subset.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal::detail {

using Vec6 = Eigen::Matrix<double, 6, 1>;

/// momentum_matrix at the placed q.
Status momentum_matrix_placed(const MechanismModel& model, MechanismData& data) noexcept;
/// The momentum-matrix columns of `coordinates` (6 x coordinates.size(), written whole) at the
/// placed q, from the composites of `links` alone: the links of those coordinates and all their
/// descendants. The rest of the matrix and its bookkeeping are untouched.
void momentum_columns_placed(const MechanismModel& model, MechanismData& data, const LinkSubset& links,
                             const std::vector<int>& coordinates, Eigen::Ref<Eigen::MatrixXd> columns) noexcept;
/// The velocities of the placed links from data.joint_velocity (into data.work, as a forward
/// pass's) and their momenta (linear; angular about O), summed over `links` into `inside` and,
/// with `whole`, over the others into `rest`. Without `whole`, only `links` are moved and summed
/// (`rest` untouched): their parents outside must have current velocities (an earlier whole pass
/// at the same placements and rates).
void velocity_momentum(const MechanismModel& model, MechanismData& data, const LinkSubset& links, bool whole,
                       Vec6& inside, Vec6& rest) noexcept;
/// shaking_wrench(q, v, a) at the placed q (q: the coordinates the links are placed at).
/// `momenta` false: the force and moment only (data.shaking's momenta are left as they were).
Status shaking_wrench_placed(const MechanismModel& model, MechanismData& data, const Eigen::Ref<const Eigen::VectorXd>& q,
                             const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::Ref<const Eigen::VectorXd>& a,
                             bool momenta = true) noexcept;

}  // namespace mechbal::detail
