#pragma once
/// \file control/passive.hpp
/// PassiveController: no controller at all. Every tick commands zero joint effort, so a plant
/// driven by it moves under gravity, its springs and its own inertia only (a free pendulum, a
/// spring-balanced arm let go). It is the JointController of a passive simulation (`[control]
/// kind = "passive"`, mechbal.simulate.passive): the closed-loop simulator then integrates the
/// unforced forward dynamics. Real-time: step() is noexcept, allocation-free and O(n).
#include <Eigen/Core>

#include "mechbal/control/joint_controller.hpp"

namespace mechbal {

class PassiveController : public JointController {
 public:
  /// `dof` actuated coordinates (>= 1; std::invalid_argument naming "dof" otherwise).
  explicit PassiveController(int dof);
  int dof() const noexcept override { return dof_; }
  /// tau = 0. Non-finite q or qd: Status::non_finite_input (tau is still 0: zero effort is the
  /// passive command whatever the state); a wrong size: Status::bad_size, tau untouched.
  Status step(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
              const Eigen::Ref<const Eigen::VectorXd>& q_des, const Eigen::Ref<const Eigen::VectorXd>& qd_des,
              const Eigen::Ref<const Eigen::VectorXd>& qdd_des, Eigen::Ref<Eigen::VectorXd> tau) noexcept override;
  /// The last command (always zero); for the bindings' tick interface.
  const Eigen::VectorXd& last_command() const noexcept { return zero_; }
  void reset() noexcept {}

 private:
  int dof_;
  Eigen::VectorXd zero_;
};

}  // namespace mechbal
