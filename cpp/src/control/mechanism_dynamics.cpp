#include "mechbal/control/mechanism_dynamics.hpp"

#include <stdexcept>
#include <string>

#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/springs.hpp"
#include "mechbal/detail/tree.hpp"

namespace mechbal {

// The one definition of the base's vtable and typeinfo (declared extern in the header).
template class SupportWrenchDynamics<MechanismDynamics>;

MechanismDynamics::MechanismDynamics(MechanismModel model, const Eigen::VectorXd& q_guess)
    : MechanismDynamics(std::make_shared<const MechanismModel>(std::move(model)), q_guess) {}

MechanismDynamics::MechanismDynamics(std::shared_ptr<const MechanismModel> model, const Eigen::VectorXd& q_guess)
    : model_(std::move(model)), data_(*model_) {
  data_.reserve_mass_matrix();  // the mass matrix is used from the loop: sized here, not there
  if (!model_->is_closed() && model_->num_passive() > 0) {
    throw std::invalid_argument("actuated: an open mechanism with passive joints ('" +
                                model_->coordinate_name(model_->passive_coordinates()[0]) +
                                "') cannot be driven by MechanismDynamics: actuate every joint");
  }
  if (q_guess.size() != 0 && q_guess.size() != model_->dof()) {
    throw std::invalid_argument("q_guess must have " + std::to_string(model_->dof()) + " values, got " +
                                std::to_string(q_guess.size()));
  }
  if (q_guess.size() != 0 && !q_guess.allFinite()) throw std::invalid_argument("q_guess must be finite");
  q_ = q_guess.size() ? q_guess : Eigen::VectorXd::Zero(model_->dof());
  zero_ = Eigen::VectorXd::Zero(dof());
  work_ = Eigen::VectorXd::Zero(dof());
  ldlt_.compute(Eigen::MatrixXd::Identity(dof(), dof()));
}

Status MechanismDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                           const Eigen::Ref<const Eigen::VectorXd>& qd,
                                           const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                           Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                                           Vec3* support_moment) noexcept {
  if (tau.size() != dof()) return Status::bad_size;
  Status s = Status::ok;
  if (model_->is_closed()) {
    s = closed_inverse_dynamics(*model_, data_, q, qd, qdd, q_, options_);
    if (failed(s)) return s;
    if (!data_.actuated_force.allFinite()) s |= Status::out_of_range;
  } else {
    s = mechbal::inverse_dynamics(*model_, data_, q, qd, qdd);
    if (s != Status::ok && s != Status::out_of_range) return s;
  }
  if (has(s, Status::out_of_range)) {  // a finite input that overflowed: zeros, never garbage
    tau.setZero();
    if (support_force) support_force->setZero();
    if (support_moment) support_moment->setZero();
    return s;
  }
  tau = model_->is_closed() ? data_.actuated_force : data_.joint_torque;
  // the base's entry of the backward pass holds the wrench on the root links, in O, about O
  if (support_force) *support_force = data_.work[0].force;
  if (support_moment) *support_moment = data_.work[0].moment;
  return s;
}

Status MechanismDynamics::forward_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                           const Eigen::Ref<const Eigen::VectorXd>& qd,
                                           const Eigen::Ref<const Eigen::VectorXd>& tau,
                                           Eigen::Ref<Eigen::VectorXd> qdd) noexcept {
  if (qdd.size() != dof() || tau.size() != dof()) return Status::bad_size;
  if (!tau.allFinite()) return Status::non_finite_input;
  if (model_->is_closed()) {
    const Status s = closed_forward_dynamics(*model_, data_, q, qd, tau, q_, options_);
    if (failed(s) || has(s, Status::singular) || has(s, Status::out_of_range)) return s;  // qdd untouched
    qdd = data_.actuated_acceleration;
    return s;
  }
  if (Status s = bias_torque(*model_, data_, q, qd); s != Status::ok) return s;
  mechbal::mass_matrix(*model_, data_, q);
  ldlt_.compute(data_.mass_matrix);
  if (ldlt_.info() != Eigen::Success || !(ldlt_.vectorD().minCoeff() > 0.0)) return Status::singular;
  work_ = tau - data_.bias_torque;
  ldlt_.solveInPlace(work_);
  if (!work_.allFinite()) return Status::out_of_range;
  qdd = work_;
  return Status::ok;
}

Status MechanismDynamics::mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q,
                                      Eigen::Ref<Eigen::MatrixXd> M) noexcept {
  if (M.rows() != dof() || M.cols() != dof()) return Status::bad_size;
  if (model_->is_closed()) {
    const Status s = closed_mass_matrix(*model_, data_, q, q_, options_);
    if (!failed(s)) M = data_.reduced_mass_matrix;
    return s;
  }
  const Status s = mechbal::mass_matrix(*model_, data_, q);
  if (s == Status::ok) M = data_.mass_matrix;
  return s;
}

Status MechanismDynamics::gravity(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  Eigen::Ref<Eigen::VectorXd> g) noexcept {
  if (g.size() != dof()) return Status::bad_size;
  if (model_->is_closed()) {
    const Status s = closed_mass_matrix(*model_, data_, q, q_, options_);
    if (!failed(s)) g = data_.actuated_gravity;
    return s;
  }
  const Status s = gravity_torque(*model_, data_, q);
  if (s == Status::ok) g = data_.gravity_torque;
  return s;
}

Status MechanismDynamics::static_torque(const Eigen::Ref<const Eigen::VectorXd>& q,
                                        Eigen::Ref<Eigen::VectorXd> g) noexcept {
  if (g.size() != dof()) return Status::bad_size;
  if (model_->is_closed()) {
    const Status s = closed_mass_matrix(*model_, data_, q, q_, options_);
    if (!failed(s)) g = data_.actuated_static_torque;
    return s;
  }
  const Status s = mechbal::static_torque(*model_, data_, q);
  if (s == Status::ok) g = data_.static_torque;
  return s;
}

Status MechanismDynamics::bias(const Eigen::Ref<const Eigen::VectorXd>& q,
                               const Eigen::Ref<const Eigen::VectorXd>& qd,
                               Eigen::Ref<Eigen::VectorXd> b) noexcept {
  if (b.size() != dof()) return Status::bad_size;
  if (model_->is_closed()) {
    // b# = C^T tau(q, v, c): the actuated forces at a# = 0
    const Status s = closed_inverse_dynamics(*model_, data_, q, qd, zero_, q_, options_);
    if (!failed(s)) b = data_.actuated_force;
    return s;
  }
  const Status s = bias_torque(*model_, data_, q, qd);
  if (s == Status::ok) b = data_.bias_torque;
  return s;
}

Status MechanismDynamics::coriolis(const Eigen::Ref<const Eigen::VectorXd>& q,
                                   const Eigen::Ref<const Eigen::VectorXd>& qd,
                                   Eigen::Ref<Eigen::VectorXd> c) noexcept {
  if (c.size() != dof()) return Status::bad_size;
  if (model_->is_closed()) {
    Status s = bias(q, qd, c);
    if (failed(s)) return s;
    work_ = c;
    s |= static_torque(q, c);
    if (failed(s)) return s;
    c = work_ - c;
    if (!c.allFinite()) s |= Status::out_of_range;
    return s;
  }
  if (Status s = detail::check_state(*model_, data_, &q, &qd); s != Status::ok) return s;
  detail::joint_state<true, false>(*model_, data_, q, qd, qd);
  detail::place<false>(*model_, data_);
  detail::forward_pass<true, false, false, true, false>(*model_, data_);
  detail::backward_pass(*model_, data_, c);
  return c.allFinite() ? Status::ok : Status::out_of_range;  // finite input can overflow (qd = 1e300)
}

}  // namespace mechbal
