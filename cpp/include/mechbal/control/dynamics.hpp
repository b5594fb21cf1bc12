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
  virtual ~InverseDynamics();  // (defined in the library: its vtable's one home, interfaces.cpp)
  virtual int dof() const noexcept = 0;
  /// Real-time: noexcept, allocation-free. Sizes must equal dof() (else Status::bad_size and tau
  /// untouched); non-finite input gives Status::non_finite_input and tau untouched.
  virtual Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                                  const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                  Eigen::Ref<Eigen::VectorXd> tau) noexcept = 0;
};

/// An InverseDynamics back end that can also give the wrench the base exerts on the moving links
/// (KdlChainDynamics, MechanismDynamics). `Derived` defines
///   Status inverse_dynamics(q, qd, qdd, tau, Eigen::Vector3d* support_force,
///                           Eigen::Vector3d* support_moment) noexcept;
/// (null pointers: no wrench) and brings this class's overload into its scope (`using
/// SupportWrenchDynamics<Derived>::inverse_dynamics;`). The interface's call is that one without
/// the wrench, dispatched statically (CRTP: no second virtual call in a tick).
///
/// A class template with a virtual function has no key function: every translation unit that
/// constructs or destroys a Derived would emit this base's vtable and typeinfo, and the linker
/// keeps one of them. A unit compiled without RTTI (embedded code; tests/cpp/rt_no_exceptions.cpp)
/// emits a vtable with no typeinfo, which breaks dynamic_cast and UBSan's vptr check wherever that
/// copy is the one kept. So each Derived's header declares the instantiation extern (`extern
/// template class SupportWrenchDynamics<Derived>;`, before the class) and its source file in the
/// library defines it (`template class SupportWrenchDynamics<Derived>;`): the vtable and typeinfo
/// exist in that one object, compiled with RTTI. A new Derived does the same.
template <typename Derived>
class SupportWrenchDynamics : public InverseDynamics {
 public:
  /// InverseDynamics interface: joint torques only.
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau) noexcept override {
    return static_cast<Derived&>(*this).inverse_dynamics(q, qd, qdd, tau, nullptr, nullptr);
  }
};

/// Forward-dynamics interface of a plant for closed-loop simulation: qdd = M^-1 (tau - C qd - G).
class ForwardDynamics {
 public:
  virtual ~ForwardDynamics();  // (defined in the library: its vtable's one home, interfaces.cpp)
  virtual int dof() const noexcept = 0;
  /// Real-time: noexcept, allocation-free; sizes must equal dof() (else bad_size, qdd untouched);
  /// non-finite input -> non_finite_input, qdd untouched; singular mass matrix -> singular.
  virtual Status forward_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                                  const Eigen::Ref<const Eigen::VectorXd>& tau,
                                  Eigen::Ref<Eigen::VectorXd> qdd) noexcept = 0;
};

}  // namespace mechbal
