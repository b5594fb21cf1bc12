#pragma once
/// \file joint_controller.hpp
/// The interface every joint-space tracking controller implements (ComputedTorque,
/// DecoupledJointController), so the closed-loop simulator (closed_loop.hpp) and the bindings drive
/// any of them on any plant.
#include <Eigen/Core>

#include "mechbal/status.hpp"

namespace mechbal {

class JointController {
 public:
  virtual ~JointController();  // (defined in the library: its vtable's one home, interfaces.cpp)
  virtual int dof() const noexcept = 0;
  /// One control tick: the command tau tracking (q_des, qd_des, qdd_des) from the measured
  /// (q, qd). Real-time: noexcept, allocation-free, bounded; bad input gives a status and the held
  /// safe command (each controller documents its ranges).
  virtual Status step(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                      const Eigen::Ref<const Eigen::VectorXd>& q_des,
                      const Eigen::Ref<const Eigen::VectorXd>& qd_des,
                      const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
                      Eigen::Ref<Eigen::VectorXd> tau) noexcept = 0;
};

}  // namespace mechbal
