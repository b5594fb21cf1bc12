#pragma once
/// \file detail/joint_control.hpp
/// Shared by the joint controllers (ComputedTorque, DecoupledJointController): construction-time
/// checks of gain and limit vectors, and the real-time clipping of a command to per-joint limits.
#include <Eigen/Core>

#include "mechbal/control/joint_limits.hpp"
#include "mechbal/status.hpp"

namespace mechbal::detail {

/// Construction time (throws): `v` must have `n` values, each > 0 and finite (or > 0, possibly
/// +infinity, when `allow_inf`); the std::invalid_argument names `field`, the index and the value.
void check_positive_vector(const Eigen::VectorXd& v, const char* field, Eigen::Index n,
                           bool allow_inf);

/// Construction time (throws): the torque limit of n joints into `out`: empty gives +infinity (no
/// limit) for every joint; otherwise n entries > 0, +infinity meaning no limit.
void check_torque_limit(const Eigen::VectorXd& limit, const char* field, Eigen::Index n,
                        Eigen::VectorXd& out);

/// Real time: the checks a joint controller's tick starts with, in this order: a size other than
/// n (tau_size is the output's) gives Status::bad_size, a NaN or infinite input
/// Status::non_finite_input, an input outside `range` Status::out_of_range; Status::ok otherwise.
/// The caller holds its last command on the last two (and leaves tau untouched on bad_size).
inline Status check_tick_input(const JointInputRange& range, Eigen::Index n,
                               const Eigen::Ref<const Eigen::VectorXd>& q,
                               const Eigen::Ref<const Eigen::VectorXd>& qd,
                               const Eigen::Ref<const Eigen::VectorXd>& q_des,
                               const Eigen::Ref<const Eigen::VectorXd>& qd_des,
                               const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
                               Eigen::Index tau_size) noexcept {
  if (q.size() != n || qd.size() != n || q_des.size() != n || qd_des.size() != n ||
      qdd_des.size() != n || tau_size != n)
    return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite() || !q_des.allFinite() || !qd_des.allFinite() ||
      !qdd_des.allFinite())
    return Status::non_finite_input;
  if (!within(range, q, qd, q_des, qd_des, qdd_des)) return Status::out_of_range;
  return Status::ok;
}

/// Clips x(i) to [-limit(i), limit(i)] for the first n entries (limits may be +infinity).
/// Returns Status::saturated when any entry was clipped, Status::ok otherwise. noexcept, no
/// allocation.
template <typename Command, typename Limit>
inline Status clip_to_limits(Eigen::DenseBase<Command>& x, const Eigen::DenseBase<Limit>& limit,
                             Eigen::Index n) noexcept {
  Status status = Status::ok;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (x(i) > limit(i)) {
      x(i) = limit(i);
      status = Status::saturated;
    } else if (x(i) < -limit(i)) {
      x(i) = -limit(i);
      status = Status::saturated;
    }
  }
  return status;
}

}  // namespace mechbal::detail
