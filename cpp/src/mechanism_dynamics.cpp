#include "mechbal/mechanism_dynamics.hpp"

#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/detail/tree.hpp"

namespace mechbal {

MechanismDynamics::MechanismDynamics(MechanismModel model)
    : MechanismDynamics(std::make_shared<const MechanismModel>(std::move(model))) {}

MechanismDynamics::MechanismDynamics(std::shared_ptr<const MechanismModel> model)
    : model_(std::move(model)), data_(*model_) {}

Status MechanismDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                           const Eigen::Ref<const Eigen::VectorXd>& qd,
                                           const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                           Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                                           Vec3* support_moment) noexcept {
  if (tau.size() != dof()) return Status::bad_size;
  const Status s = mechbal::inverse_dynamics(*model_, data_, q, qd, qdd);
  if (s != Status::ok) return s;
  tau = data_.joint_torque;
  // the base's entry of the backward pass holds the wrench on the root links, in O, about O
  if (support_force) *support_force = data_.work[0].force;
  if (support_moment) *support_moment = data_.work[0].moment;
  return Status::ok;
}

Status MechanismDynamics::mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q,
                                      Eigen::Ref<Eigen::MatrixXd> M) noexcept {
  if (M.rows() != dof() || M.cols() != dof()) return Status::bad_size;
  const Status s = mechbal::mass_matrix(*model_, data_, q);
  if (s == Status::ok) M = data_.mass_matrix;
  return s;
}

Status MechanismDynamics::gravity(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  Eigen::Ref<Eigen::VectorXd> g) noexcept {
  if (g.size() != dof()) return Status::bad_size;
  const Status s = gravity_torque(*model_, data_, q);
  if (s == Status::ok) g = data_.gravity_torque;
  return s;
}

Status MechanismDynamics::bias(const Eigen::Ref<const Eigen::VectorXd>& q,
                               const Eigen::Ref<const Eigen::VectorXd>& qd,
                               Eigen::Ref<Eigen::VectorXd> b) noexcept {
  if (b.size() != dof()) return Status::bad_size;
  const Status s = bias_torque(*model_, data_, q, qd);
  if (s == Status::ok) b = data_.bias_torque;
  return s;
}

Status MechanismDynamics::coriolis(const Eigen::Ref<const Eigen::VectorXd>& q,
                                   const Eigen::Ref<const Eigen::VectorXd>& qd,
                                   Eigen::Ref<Eigen::VectorXd> c) noexcept {
  if (c.size() != dof()) return Status::bad_size;
  if (Status s = detail::check_state(*model_, data_, &q, &qd); s != Status::ok) return s;
  detail::joint_state<true, false>(*model_, data_, q, qd, qd);
  detail::place<false>(*model_, data_);
  detail::forward_pass<true, false, false, true>(*model_, data_);
  detail::backward_pass(*model_, data_, c);
  return Status::ok;
}

}  // namespace mechbal
