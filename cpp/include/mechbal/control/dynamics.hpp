#pragma once
/// \file dynamics.hpp
/// The one interface every joint-space dynamics back end implements: inverse dynamics
/// tau = M(q) qdd + C(q, qd) qd + G(q). Controllers (computed torque, decoupled control) and the
/// closed-loop simulators are written against it, so a closed-form model, KDL or mechbal's own
/// recursive Newton-Euler can be swapped without touching them.
#include <Eigen/Core>

#include "mechbal/status.hpp"

namespace mechbal {

class InverseDynamics {
 public:
  virtual ~InverseDynamics() = default;
  virtual int dof() const noexcept = 0;
  /// Real-time: noexcept, allocation-free. Sizes must equal dof() (else Status::bad_size and tau
  /// untouched); non-finite input gives Status::non_finite_input and tau untouched.
  virtual Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                                  const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                  Eigen::Ref<Eigen::VectorXd> tau) noexcept = 0;
};

/// Forward-dynamics interface of a plant for closed-loop simulation: qdd = M^-1 (tau - C qd - G).
class ForwardDynamics {
 public:
  virtual ~ForwardDynamics() = default;
  virtual int dof() const noexcept = 0;
  /// Real-time: noexcept, allocation-free; sizes must equal dof() (else bad_size, qdd untouched);
  /// non-finite input -> non_finite_input, qdd untouched; singular mass matrix -> singular.
  virtual Status forward_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                                  const Eigen::Ref<const Eigen::VectorXd>& tau,
                                  Eigen::Ref<Eigen::VectorXd> qdd) noexcept = 0;
};

}  // namespace mechbal
