#pragma once
/// \file joint_limits.hpp
/// Input ranges and torque limits of the joint controllers (ComputedTorque,
/// DecoupledJointController). No hidden limits: every limit is what the user declared (the
/// model's joint limits, the `[control]` table, a constructor argument); an undeclared limit is
/// +infinity, i.e. no limit. A tick whose input is outside a declared range holds the last safe
/// command and returns Status::out_of_range; a command beyond its declared torque limit is
/// clipped (Status::saturated); without limits only overflow is guarded (non-finite input or
/// results: the held command and a status).
#include <Eigen/Core>
#include <limits>

#include "mechbal/status.hpp"

namespace mechbal {

/// An undeclared limit: no limit.
constexpr double no_limit = std::numeric_limits<double>::infinity();

/// Input range of a joint controller tick, per component: q and q_des within +-max_position
/// [rad or m], qd and qd_des within +-max_speed [rad/s or m/s], qdd_des within +-max_acceleration
/// [rad/s^2 or m/s^2]. Each > 0, +infinity (the default) meaning no limit.
struct JointInputRange {
  double max_position = no_limit;
  double max_speed = no_limit;
  double max_acceleration = no_limit;
};

/// Construction time: throws std::invalid_argument naming `field` (e.g. "computed_torque") and
/// the member when a bound is NaN or not > 0 (+infinity is allowed: no limit).
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
