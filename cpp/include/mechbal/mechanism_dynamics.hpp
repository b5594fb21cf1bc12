#pragma once
/// \file mechanism_dynamics.hpp
/// MechanismDynamics: the InverseDynamics back end of the general model, so the controllers
/// (ComputedTorque, DecoupledJointController) and simulators drive any MechanismModel. It owns an
/// immutable copy of the model (shared, never a reference to something that can change underneath,
/// unlike KDL's solvers) and its MechanismData; every call is noexcept and allocation-free.
#include <Eigen/Core>
#include <memory>

#include "mechbal/data.hpp"
#include "mechbal/dynamics.hpp"
#include "mechbal/model.hpp"
#include "mechbal/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

class MechanismDynamics : public InverseDynamics {
 public:
  explicit MechanismDynamics(MechanismModel model);
  explicit MechanismDynamics(std::shared_ptr<const MechanismModel> model);

  int dof() const noexcept override { return model_->dof(); }
  const MechanismModel& model() const noexcept { return *model_; }
  MechanismData& data() noexcept { return data_; }

  /// tau = M(q) qdd + C(q, qd) qd + G(q). Sizes must equal dof() (Status::bad_size), input finite
  /// (Status::non_finite_input), tau untouched otherwise.
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau) noexcept override {
    return inverse_dynamics(q, qd, qdd, tau, nullptr, nullptr);
  }
  /// As above; `support_force`/`support_moment` (when non-null) receive the wrench the base exerts
  /// on the moving links (moment about O, gravity included; bodies fixed to the base excluded).
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                          Vec3* support_moment) noexcept;
  Status mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::MatrixXd> M) noexcept;
  Status gravity(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::VectorXd> g) noexcept;
  /// C(q, qd) qd + G(q).
  Status bias(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
              Eigen::Ref<Eigen::VectorXd> b) noexcept;
  /// C(q, qd) qd alone (no gravity).
  Status coriolis(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                  Eigen::Ref<Eigen::VectorXd> c) noexcept;

 private:
  std::shared_ptr<const MechanismModel> model_;
  MechanismData data_;
};

}  // namespace mechbal
