#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/detail/joint_control.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

ComputedTorque::ComputedTorque(InverseDynamics& model, const Eigen::VectorXd& kp,
                               const Eigen::VectorXd& kd, const Eigen::VectorXd& torque_limit,
                               const JointInputRange& range)
    : model_(model), n_(model.dof()), kp_(kp), kd_(kd), range_(range) {
  if (n_ <= 0) throw std::invalid_argument("computed_torque.model must have at least one joint");
  detail::check_positive_vector(kp, "computed_torque.kp", n_, false);
  detail::check_positive_vector(kd, "computed_torque.kd", n_, false);
  detail::check_torque_limit(torque_limit, "computed_torque.torque_limit", n_, limit_);
  validate_joint_input_range(range, "computed_torque");
  v_ = Eigen::VectorXd::Zero(n_);
  raw_ = Eigen::VectorXd::Zero(n_);
  last_ = Eigen::VectorXd::Zero(n_);
}

Status ComputedTorque::step(const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& qd,
                            const Eigen::Ref<const Eigen::VectorXd>& q_des,
                            const Eigen::Ref<const Eigen::VectorXd>& qd_des,
                            const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
                            Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  const Status input = detail::check_tick_input(range_, n_, q, qd, q_des, qd_des, qdd_des, tau.size());
  if (input != Status::ok) {
    if (input != Status::bad_size) tau = last_;
    return input;
  }
  // eq 4: v = qdd_d + Kp e + Kd edot (diagonal gains); computed into raw_ first so that v_ keeps
  // the last good value if the model fails.
  raw_ = qdd_des + kp_.cwiseProduct(q_des - q) + kd_.cwiseProduct(qd_des - qd);
  if (!raw_.allFinite()) {  // finite inputs can still overflow (large gains)
    tau = last_;
    return Status::out_of_range;
  }
  v_ = raw_;
  // eq 2: tau = A_hat v + C_hat qd + Q_hat = inverse dynamics of the model at (q, qd, v)
  const Status s = model_.inverse_dynamics(q, qd, v_, raw_);
  if (s != Status::ok || !raw_.allFinite()) {
    tau = last_;
    return s != Status::ok ? s : Status::out_of_range;
  }
  const Status status = detail::clip_to_limits(raw_, limit_, n_);
  last_ = raw_;
  tau = last_;
  return status;
}

}  // namespace mechbal
