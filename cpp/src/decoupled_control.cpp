#include "mechbal/decoupled_control.hpp"
#include "mechbal/detail/joint_control.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

DecoupledJointController::DecoupledJointController(const Eigen::VectorXd& k,
                                                   const Eigen::VectorXd& kp,
                                                   const Eigen::VectorXd& kd,
                                                   const Eigen::VectorXd& torque_limit) {
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
  if (torque_limit.size() == 0) {
    limit_ = VecN::Constant(n, std::numeric_limits<double>::infinity());
  } else {
    detail::check_positive_vector(torque_limit, "decoupled_control.torque_limit", n, true);
    limit_ = torque_limit;
  }
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
  if (q.size() != n || qd.size() != n || q_des.size() != n || qd_des.size() != n ||
      qdd_des.size() != n || tau.size() != n)
    return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite() || !q_des.allFinite() || !qd_des.allFinite() ||
      !qdd_des.allFinite()) {
    tau = last_;
    return Status::non_finite_input;
  }
  // eqs 15, 26, 36 with the computed-torque outer loop: tau_i = k_i (qdd_d + Kp e + Kd e').
  raw_ = k_.cwiseProduct(qdd_des + kp_.cwiseProduct(q_des - q) + kd_.cwiseProduct(qd_des - qd));
  if (!raw_.allFinite()) {
    tau = last_;
    return Status::non_finite_input;
  }
  const Status status = detail::clip_to_limits(raw_, limit_, n);
  last_ = raw_;
  tau = last_;
  return status;
}

}  // namespace mechbal
