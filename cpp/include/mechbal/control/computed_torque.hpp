#pragma once
/// \file computed_torque.hpp
/// Computed-torque (feedback-linearising) joint control, Arakelian, Le Baron & Mottu 2011,
/// eqs 2-6:
///   tau = A_hat(q) v + C_hat(q, qd) qd + Q_hat(q),   v = qdd_d + Kp (q_d - q) + Kd (qd_d - qd)
/// (eq 2 prints "v double-dot": it is v). The model (A_hat, C_hat, Q_hat) is any InverseDynamics
/// back end, evaluated as tau = inverse_dynamics(q, qd, v): the closed-form Arm2DofDynamics, KDL
/// (KdlChainDynamics) or mechbal's recursive Newton-Euler. With an exact model the tracking error
/// e = q_d - q obeys e'' + Kd e' + Kp e = 0 (eq 6), decoupled per joint.
#include <Eigen/Core>

#include "mechbal/control/dynamics.hpp"
#include "mechbal/control/joint_limits.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

class ComputedTorque : public JointController {
 public:
  /// kp, kd: diagonal gains (dof() values each, finite and > 0). torque_limit: empty (no limit)
  /// or dof() values > 0 (+infinity: no limit on that joint): the
  /// command is clipped to [-limit, limit] and the step returns Status::saturated. range: the
  /// input range of a tick. Throws std::invalid_argument naming the field on bad values. The model
  /// must outlive the controller.
  ComputedTorque(InverseDynamics& model, const Eigen::VectorXd& kp, const Eigen::VectorXd& kd,
                 const Eigen::VectorXd& torque_limit = Eigen::VectorXd(),
                 const JointInputRange& range = JointInputRange{});

  int dof() const noexcept override { return n_; }
  const Eigen::VectorXd& kp() const noexcept { return kp_; }
  const Eigen::VectorXd& kd() const noexcept { return kd_; }
  const Eigen::VectorXd& torque_limit() const noexcept { return limit_; }
  const JointInputRange& input_range() const noexcept { return range_; }

  /// One control tick. Real-time: noexcept, allocation-free, bounded.
  /// Wrong sizes: Status::bad_size, tau untouched. Non-finite input (non_finite_input), input
  /// outside input_range() or an overflowing command (out_of_range), or a model failure (the
  /// model's status): tau receives the last safe command (zero before the first good tick) and
  /// the controller's state is unchanged. Otherwise tau is the computed torque clipped to
  /// torque_limit() (finite), remembered as the last safe command.
  Status step(const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& qd,
              const Eigen::Ref<const Eigen::VectorXd>& q_des,
              const Eigen::Ref<const Eigen::VectorXd>& qd_des,
              const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
              Eigen::Ref<Eigen::VectorXd> tau) noexcept override;

  /// The last command returned (held on bad input).
  const Eigen::VectorXd& last_command() const noexcept { return last_; }
  /// The outer-loop acceleration v of the last good tick (eq 4).
  const Eigen::VectorXd& commanded_acceleration() const noexcept { return v_; }
  /// Forget the held command (sets it to zero). Not needed in the loop; allocation-free.
  void reset() noexcept { last_.setZero(); }

 private:
  InverseDynamics& model_;
  int n_;
  Eigen::VectorXd kp_, kd_, limit_;
  JointInputRange range_;
  Eigen::VectorXd v_, raw_, last_;
};

}  // namespace mechbal
