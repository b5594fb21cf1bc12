#include "mechbal/decoupled_control.hpp"
#include "mechbal/detail/saturation.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

namespace {

void check(const Eigen::VectorXd& v, const char* field, Eigen::Index n, bool allow_inf) {
  std::ostringstream msg;
  if (v.size() != n) {
    msg << field << " must have " << n << " values (got " << v.size() << ")";
    throw std::invalid_argument(msg.str());
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double x = v(i);
    const bool ok = allow_inf ? (x > 0.0 && !std::isnan(x)) : (std::isfinite(x) && x > 0.0);
    if (!ok) {
      msg << field << "[" << i << "] must be " << (allow_inf ? "> 0" : "finite and > 0")
          << " (got " << x << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

}  // namespace

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
  check(k, "decoupled_control.k", n, false);
  check(kp, "decoupled_control.kp", n, false);
  check(kd, "decoupled_control.kd", n, false);
  k_ = k;
  kp_ = kp;
  kd_ = kd;
  if (torque_limit.size() == 0) {
    limit_ = VecN::Constant(n, std::numeric_limits<double>::infinity());
  } else {
    check(torque_limit, "decoupled_control.torque_limit", n, true);
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
