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
/// at the same placements and rates). With `accelerations` (and `whole`), also every link's
/// accelerations at a = 0 (work[].acc and alpha: the velocity products alone, as a
/// forward_pass<true, false, false, false>), which loop_acceleration_bias_placed needs.
void velocity_momentum(const MechanismModel& model, MechanismData& data, const LinkSubset& links, bool whole,
                       Vec6& inside, Vec6& rest, bool accelerations = false) noexcept;
/// The loops' acceleration bias c (data.loop_acceleration_bias: a = C a# + c) at the placed q
/// from the link accelerations at a = 0 that a pass with velocities left in data.work (at least
/// on the links of the loops' paths: forward_pass<true, false, false, false> or
/// velocity_momentum with `accelerations`), with the velocity projection computed at the same q
/// (closed_velocity_motion just before: its factorisation of A° is reused). What closed_motion
/// computes after closed_velocity_motion's work, with the same refinement (the solve's options'
/// refine_rcond). Status::singular when c is not finite; nothing for an open model (c = 0).
Status loop_acceleration_bias_placed(const MechanismModel& model, MechanismData& data, double refine_rcond) noexcept;
/// shaking_wrench(q, v, a) at the placed q (q: the coordinates the links are placed at).
/// `momenta` false: the force and moment only (data.shaking's momenta are left as they were).
Status shaking_wrench_placed(const MechanismModel& model, MechanismData& data, const Eigen::Ref<const Eigen::VectorXd>& q,
                             const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::Ref<const Eigen::VectorXd>& a,
                             bool momenta = true) noexcept;

}  // namespace mechbal::detail
