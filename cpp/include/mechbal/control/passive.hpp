#pragma once
/// \file control/passive.hpp
/// PassiveController: no controller at all. Every tick commands zero joint effort, so a plant
/// driven by it moves under gravity, its springs and its own inertia only (a free pendulum, a
/// spring-balanced arm let go). It is the JointController of a passive simulation (`[control]
/// kind = "passive"`, mechbal.simulate.passive): the closed-loop simulator then integrates the
/// unforced forward dynamics. Real-time: step() is noexcept, allocation-free and O(n).
///
/// simulate_passive runs that simulation; the model's joint limits are inelastic stops there
/// (ClosedLoopOptions::lower_limit / upper_limit, closed_loop.hpp), as MuJoCo's limits are in
/// mechbal's MJCF export.
#include <Eigen/Core>

#include "mechbal/control/closed_loop.hpp"
#include "mechbal/control/dynamics.hpp"
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

/// The passive motion of `plant` from (q0, qd0): simulate_closed_loop with a PassiveController
/// (zero effort; `options.sampling` is irrelevant), stops from `options.lower_limit` /
/// `upper_limit` (e.g. the actuated entries of MechanismModel::lower_limits() / upper_limits()).
/// q_des and qd_des of the log hold q0 and zeros. Throws std::invalid_argument as
/// simulate_closed_loop.
ClosedLoopLog simulate_passive(ForwardDynamics& plant, const Eigen::VectorXd& q0,
                               const Eigen::VectorXd& qd0, const ClosedLoopOptions& options);

}  // namespace mechbal
