#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/detail/joint_control.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

DecoupledJointController::DecoupledJointController(const Eigen::VectorXd& k,
                                                   const Eigen::VectorXd& kp,
                                                   const Eigen::VectorXd& kd,
                                                   const Eigen::VectorXd& torque_limit,
                                                   const JointInputRange& range)
    : range_(range) {
  const Eigen::Index n = k.size();
  if (n < 1 || n > max_dof) {
    std::ostringstream msg;
    msg << "decoupled_control.k must have 1.." << max_dof << " values (got " << n << ")";
    throw std::invalid_argument(msg.str());
  }
  detail::check_positive_vector(k, "decoupled_control.k", n, false);
  detail::check_positive_vector(kp, "decoupled_control.kp", n, false);
  detail::check_positive_vector(kd, "decoupled_control.kd", n, false);
  k_ = k;
  kp_ = kp;
  kd_ = kd;
  Eigen::VectorXd limit;
  detail::check_torque_limit(torque_limit, "decoupled_control.torque_limit", n, limit);
  limit_ = limit;
  validate_joint_input_range(range, "decoupled_control");
  raw_ = VecN::Zero(n);
  last_ = VecN::Zero(n);
}

Status DecoupledJointController::step(const Eigen::Ref<const Eigen::VectorXd>& q,
                                      const Eigen::Ref<const Eigen::VectorXd>& qd,
                                      const Eigen::Ref<const Eigen::VectorXd>& q_des,
                                      const Eigen::Ref<const Eigen::VectorXd>& qd_des,
                                      const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
                                      Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  const Eigen::Index n = k_.size();
  const Status input = detail::check_tick_input(range_, n, q, qd, q_des, qd_des, qdd_des, tau.size());
  if (input != Status::ok) {
    if (input != Status::bad_size) tau = last_;
    return input;
  }
  // eqs 15, 26, 36 with the computed-torque outer loop: tau_i = k_i (qdd_d + Kp e + Kd e').
  raw_ = k_.cwiseProduct(qdd_des + kp_.cwiseProduct(q_des - q) + kd_.cwiseProduct(qd_des - qd));
  if (!raw_.allFinite()) {  // finite inputs can still overflow (large gains)
    tau = last_;
    return Status::out_of_range;
  }
  const Status status = detail::clip_to_limits(raw_, limit_, n);
  last_ = raw_;
  tau = last_;
  return status;
}

}  // namespace mechbal
