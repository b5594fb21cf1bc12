#pragma once
/// \file reactionless_wrist.hpp
/// Reactionless z-x-z wrist: the real-time controller that cancels the shaking moment of a
/// force-balanced manipulator by spinning its wrist (Briot & Arakelian 2009, eqs 19-26, re-derived).
///
/// The total angular momentum about O is H = D + H_wrist, where D (eq 19) is the angular momentum
/// of everything except the wrist's rotation and H_wrist = N(q_w) qdot_w (eqs 22-23) that of the
/// wrist links spinning about their common centre of mass. Keeping H equal to its initial value
/// H_target makes the shaking moment dH/dt zero:
///
///     N(q_w) qdot_w = H_target - D(t)                       (eq 25, corrected)
///     q_w(t + dt) = q_w(t) + dt qdot_w(t)                   (eq 26, explicit Euler), or RK4
///     N qddot_w = -Ddot - d/dt(N) qdot_w                    (servo feed-forward)
///
/// Corrections to the paper's printed equations (derivation in docs/paminsa_derivation.md, re-checked
/// here by the tests against the wrist links' angular momentum computed body by body):
///  1. eq 23: N = [(I1+I2+I3) e_z | (I2+I3) x1 | I3 z2], with x1 = Rz(phi) e_x,
///     z2 = Rz(phi) Rx(theta) e_z and base-frame I_k = R_k J_k R_k^T. The printed matrix omits I2, I3
///     from the phi column, adds a rotation to an inertia ("I_w2 + I_w3 E3"), and orders the rates
///     [theta phi psi]; here they are (phi, theta, psi) throughout.
///  2. eq 21/25: H_target is the initial total angular momentum, not 0 (they agree from rest).
///  3. det N = 0 at theta = 0 or pi (z-x-z gimbal lock), which includes the paper's start pose
///     "orientation equal to zero": the controller then uses damped least squares and reports
///     Status::singular. The damped solve is a closed-form 3x3 (the normal equations
///     (N^T N + lambda^2 1) x = N^T b, cond <= 1 + 1/damping^2), so a singular tick costs about
///     what a regular one does (bench/README.md).
#include <Eigen/Geometry>
#include <array>
#include <limits>

#include "mechbal/model/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

/// Body-frame inertia tensors of the three wrist links about their centres of mass (all at the
/// wrist centre). Link k's body frame is its joint frame: R1 = Rz(phi), R2 = R1 Rx(theta),
/// R3 = R2 Rz(psi).
using WristInertias = std::array<Mat3, 3>;

/// Rotation, angular velocity and angular acceleration (base frame) of each z-x-z wrist link:
/// w1 = phid e_z, w2 = w1 + thetad x1, w3 = w2 + psid z2 and their derivatives.
struct WristLinkMotion {
  std::array<Mat3, 3> rotation;
  std::array<Vec3, 3> angular_velocity;
  std::array<Vec3, 3> angular_acceleration;
};
void wrist_link_motion(const Vec3& angles, const Vec3& rates, const Vec3& accelerations,
                       WristLinkMotion& out) noexcept;
/// The same from the cosines and sines of the angles (e.g. WristCommand::cos_angles/sin_angles).
void wrist_link_motion(const Vec3& cos_angles, const Vec3& sin_angles, const Vec3& rates,
                       const Vec3& accelerations, WristLinkMotion& out) noexcept;

/// N(q) of eq 23 (corrected): H_wrist = N(q) qdot with H_wrist = sum_k I_k w_k.
Mat3 wrist_momentum_matrix(const WristInertias& inertia_body, const Vec3& angles) noexcept;

/// d/dt(N qdot) - N qddot = sum_k [I_k wdot_k|_{qddot=0} + w_k x I_k w_k] (the Ndot qdot term).
Vec3 wrist_momentum_bias(const WristInertias& inertia_body, const Vec3& angles,
                         const Vec3& rates) noexcept;

enum class WristIntegrator { euler, rk4 };

/// Configuration and input ranges of the wrist tick. Every limit is finite (issue 14: nothing
/// absurd passes as ok): an input outside its range gives Status::out_of_range and the held
/// command, an output above its limit is clipped with Status::saturated.
struct ReactionlessWristConfig {
  double rate_hz = 1000.0;  ///< tick rate [Hz], in [1, 1e6]
  WristIntegrator integrator = WristIntegrator::euler;
  /// per-axis wrist rate limit [rad/s], finite: the rate vector is scaled down (direction kept)
  /// and the tick reports Status::saturated (100 rad/s ~ 950 rpm: above any wrist joint)
  double max_rate = 100.0;
  /// per-axis limit of the acceleration feed-forward [rad/s^2], finite: scaled down (direction
  /// kept), Status::saturated
  double max_acceleration = 1e4;
  /// input range of D(t) (every component) and of the target momentum [kg m^2/s]: beyond it the
  /// tick holds, Status::out_of_range (1e4: e.g. 100 kg at 10 m/s, 10 m from O)
  double max_momentum = 1e4;
  /// input range of dD/dt (every component) [N m]: beyond it the tick holds, Status::out_of_range
  double max_moment = 1e5;
  /// cond(N) above which N counts as singular: damped least squares, Status::singular
  double max_condition = 1e4;
  /// damping of the damped least squares, relative to the largest singular value of N
  double damping = 1e-2;
};

/// Throws std::invalid_argument naming the field.
void validate_wrist_config(const ReactionlessWristConfig& config);

/// What one tick commands: angles q_n (the position set-point for this tick), the rates and
/// accelerations at t_n (feed-forward), the angles for the next tick, cond(N(q_n)).
/// When the rate limit saturates, the acceleration feed-forward is zero (the unsaturated formula
/// no longer describes the commanded motion).
struct WristCommand {
  Vec3 angles = Vec3::Zero();
  Vec3 rates = Vec3::Zero();
  Vec3 accelerations = Vec3::Zero();
  Vec3 next_angles = Vec3::Zero();
  /// cos and sin of `angles` (the tick needs them; the kinematics of the same tick can reuse them)
  Vec3 cos_angles = Vec3::Ones(), sin_angles = Vec3::Zero();
  double condition_number = 1.0;
  Status status = Status::ok;
};

class ReactionlessWrist {
 public:
  /// Throws std::invalid_argument (naming the field) on a bad configuration, inertia or start.
  ReactionlessWrist(const WristInertias& inertia_body, const ReactionlessWristConfig& config,
                    const Vec3& initial_angles, const Vec3& target_momentum);

  /// Angles are kept within [-max_angle, max_angle] rad (double resolution there: 1e-10 rad): a
  /// start or reset beyond it is refused, a tick that would leave it holds (Status::out_of_range).
  static constexpr double max_angle = 1e6;

  /// Restart from `angles` with a new target total angular momentum H_target. Non-finite input:
  /// nothing changes, Status::non_finite_input; angles beyond max_angle or a target beyond
  /// config().max_momentum: nothing changes, Status::out_of_range.
  Status reset(const Vec3& angles, const Vec3& target_momentum) noexcept;

  /// One tick with the configured integrator. D_now = D(t_n), D_dot = dD/dt(t_n); RK4 also
  /// needs D(t_n + dt/2) and D(t_n + dt) (from the planned trajectory); Euler ignores them.
  /// Non-finite input: the angles are held, rates and accelerations are zero, the state does not
  /// advance, Status::non_finite_input. A D beyond config().max_momentum or a D_dot beyond
  /// config().max_moment (any component), or a step that would overflow or leave max_angle: the
  /// same hold with Status::out_of_range. Never writes NaN; |rates| <= max_rate and
  /// |accelerations| <= max_acceleration per axis whatever the input.
  Status step(const Vec3& D_now, const Vec3& D_dot, const Vec3& D_half,
              const Vec3& D_next) noexcept;
  /// One explicit-Euler tick (eq 26), whatever the configured integrator.
  Status step_euler(const Vec3& D_now, const Vec3& D_dot) noexcept;

  /// Hold: the command keeps the current angles with zero rates and accelerations, the state does
  /// not advance; returns `why` (also stored in command().status). For callers that detect bad
  /// input upstream of the wrist (PaminsaController).
  Status hold(Status why) noexcept;

  const WristCommand& command() const noexcept { return command_; }
  const Vec3& angles() const noexcept { return angles_; }  ///< state q_n for the next tick
  const Vec3& target_momentum() const noexcept { return target_; }
  const ReactionlessWristConfig& config() const noexcept { return config_; }
  const WristInertias& inertia_body() const noexcept { return inertia_; }
  double dt() const noexcept { return dt_; }

  /// qdot = N(q)^-1 (H_target - D) with damping and the rate limit; condition number of N(q).
  Status rates(const Vec3& angles, const Vec3& D, Vec3& rates, double& condition) const noexcept;

 private:
  /// `inverse` (when given) receives the operator applied to rhs: N^-1 (Status::ok) or the damped
  /// pseudo-inverse (N^T N + lambda^2 1)^-1 N^T (Status::singular); left untouched when N is zero
  /// or not finite.
  Status solve(const Mat3& N, const Vec3& rhs, Vec3& x, double& condition,
               Mat3* inverse = nullptr) const noexcept;
  Status rates_with(const Mat3& N, const Vec3& D, Vec3& rates, double& condition,
                    Mat3* inverse = nullptr) const noexcept;
  /// Status::saturated (and qd scaled down, direction kept) when a rate exceeds max_rate.
  Status limit_rate(Vec3& qd) const noexcept;
  /// D, D_dot (and the RK4 samples) within max_momentum / max_moment.
  bool in_range(const Vec3& D_now, const Vec3& D_dot, const Vec3* D_half,
                const Vec3* D_next) const noexcept;
  /// The rates at the RK4 stage angles_ + delta (cos_n, sin_n: of angles_): same result and
  /// status as rates() without computing cond(N).
  Status stage_rates(const Vec3& delta, const Vec3& cos_n, const Vec3& sin_n, const Vec3& D,
                     Vec3& qd) const noexcept;
  Status tick(const Vec3& D_now, const Vec3& D_dot, const Vec3* D_half, const Vec3* D_next) noexcept;

  WristInertias inertia_;
  ReactionlessWristConfig config_;
  double dt_;
  bool diagonal_inertia_ = false;  ///< every J_k diagonal (exactly): the stages' N2 in closed form
  Vec3 angles_;
  Vec3 target_;
  WristCommand command_;
};

}  // namespace mechbal
