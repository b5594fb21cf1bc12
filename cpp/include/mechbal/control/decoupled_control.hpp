#pragma once
/// \file decoupled_control.hpp
/// Decoupled joint control of a dynamically balanced arm, Coutinho & Hess Coelho, eqs 15-16,
/// 26-27 (corrected), 36-37: once static balancing and the counter-rotating discs make the mass
/// matrix constant and diagonal, diag(k), and cancel the velocity and gravity terms, the dynamics
/// are tau_i = k_i q''_i, and the computed-torque law (mechbal::ComputedTorque) reduces to one
/// independent PD loop per joint,
///   tau_i = k_i (q''_d,i + Kp_i e_i + Kd_i e'_i),   e = q_d - q,
/// with no model evaluation per tick. For a prismatic joint k_i is a mass and tau_i a force.
#include <Eigen/Core>

#include "mechbal/control/joint_limits.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

class DecoupledJointController : public JointController {
 public:
  static constexpr int max_dof = 8;
  using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_dof, 1>;

  /// k: the constant diagonal of the balanced mass matrix (finite, > 0); kp, kd: gains (finite,
  /// > 0); torque_limit: empty (no limit) or one value > 0 per joint
  /// (+infinity: no limit on that joint), the command is clipped and step() returns
  /// Status::saturated; range: the input range of a tick. Sizes 1..max_dof, all equal.
  /// Throws std::invalid_argument naming the field and value.
  DecoupledJointController(const Eigen::VectorXd& k, const Eigen::VectorXd& kp,
                           const Eigen::VectorXd& kd,
                           const Eigen::VectorXd& torque_limit = Eigen::VectorXd(),
                           const JointInputRange& range = JointInputRange{});

  int dof() const noexcept override { return static_cast<int>(k_.size()); }
  const VecN& k() const noexcept { return k_; }
  const VecN& kp() const noexcept { return kp_; }
  const VecN& kd() const noexcept { return kd_; }
  const VecN& torque_limit() const noexcept { return limit_; }
  const JointInputRange& input_range() const noexcept { return range_; }

  /// One tick. Real-time: noexcept, allocation-free, bounded. Wrong sizes: bad_size, tau
  /// untouched. Non-finite input (non_finite_input), input outside input_range() or an
  /// overflowing command (out_of_range): tau = the last safe command (zero before the first good
  /// tick). Otherwise tau = the command clipped to torque_limit() (finite).
  Status step(const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& qd,
              const Eigen::Ref<const Eigen::VectorXd>& q_des,
              const Eigen::Ref<const Eigen::VectorXd>& qd_des,
              const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
              Eigen::Ref<Eigen::VectorXd> tau) noexcept override;

  const VecN& last_command() const noexcept { return last_; }
  void reset() noexcept { last_.setZero(); }

 private:
  VecN k_, kp_, kd_, limit_, raw_, last_;
  JointInputRange range_;
};

}  // namespace mechbal
