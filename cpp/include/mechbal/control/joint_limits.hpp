#pragma once
/// \file joint_limits.hpp
/// Input ranges and torque limits of the joint controllers (ComputedTorque,
/// DecoupledJointController). Every limit is finite (issue 14: nothing absurd passes as ok): a
/// tick whose input is outside its range holds the last safe command and returns
/// Status::out_of_range; a command beyond its torque limit is clipped (Status::saturated).
#include <Eigen/Core>

#include "mechbal/status.hpp"

namespace mechbal {

/// Torque (or force) limit used for every joint when none is configured, and in place of a
/// configured +infinity [N m or N]: above the peak torque of any joint of an industrial arm.
constexpr double default_torque_limit = 1e4;

/// Input range of a joint controller tick, per component: q and q_des within +-max_position
/// [rad or m], qd and qd_des within +-max_speed [rad/s or m/s], qdd_des within +-max_acceleration
/// [rad/s^2 or m/s^2]. Finite and > 0 (checked at construction).
struct JointInputRange {
  double max_position = 1e3;
  double max_speed = 1e2;
  double max_acceleration = 1e4;
};

/// Construction time: throws std::invalid_argument naming `field` (e.g. "computed_torque") and
/// the member when a bound is not finite and > 0.
void validate_joint_input_range(const JointInputRange& range, const char* field);

/// Real time: every component of q, q_des within max_position, of qd, qd_des within max_speed, of
/// qdd_des within max_acceleration (the inputs must already be finite).
inline bool within(const JointInputRange& r, const Eigen::Ref<const Eigen::VectorXd>& q,
                   const Eigen::Ref<const Eigen::VectorXd>& qd,
                   const Eigen::Ref<const Eigen::VectorXd>& q_des,
                   const Eigen::Ref<const Eigen::VectorXd>& qd_des,
                   const Eigen::Ref<const Eigen::VectorXd>& qdd_des) noexcept {
  if (q.size() == 0) return true;
  return q.cwiseAbs().maxCoeff() <= r.max_position && q_des.cwiseAbs().maxCoeff() <= r.max_position &&
         qd.cwiseAbs().maxCoeff() <= r.max_speed && qd_des.cwiseAbs().maxCoeff() <= r.max_speed &&
         qdd_des.cwiseAbs().maxCoeff() <= r.max_acceleration;
}

}  // namespace mechbal
