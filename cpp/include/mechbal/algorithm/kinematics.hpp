#pragma once
/// \file algorithm/kinematics.hpp
/// Forward kinematics of every link, body and named frame of a MechanismModel: pose, velocity and
/// acceleration in the base frame O (data.link_*, data.body_states, data.frame_placements).
///
/// Every algorithm over a MechanismModel follows the same contract (docs/architecture.md, "Data flow": real time):
/// noexcept, allocation-free once the MechanismData exists; q, v, a have model.dof() entries
/// (Status::bad_size otherwise, also when `data` was built for another model); non-finite input
/// gives Status::non_finite_input; in both cases nothing in `data` is written.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// Positions only (velocities and accelerations set to zero).
Status forward_kinematics(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;
/// Positions and velocities (accelerations set to zero).
Status forward_kinematics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                          const ConstVector& v) noexcept;
/// Positions, velocities and accelerations (gravity excluded from the accelerations).
Status forward_kinematics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                          const ConstVector& v, const ConstVector& a) noexcept;
/// data.frame_placements[frame] only: the placement in O of one named frame (positions only, no
/// body or other frame written), at the cost of the link placements. Accepted exactly when the
/// positions-only forward_kinematics is (every link placement and every body's centre finite;
/// Status::out_of_range otherwise); Status::bad_size for a frame index out of range.
Status frame_placement(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                       int frame) noexcept;

}  // namespace mechbal
