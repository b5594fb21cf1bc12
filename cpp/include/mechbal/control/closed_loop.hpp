#pragma once
/// \file closed_loop.hpp
/// Closed-loop simulation of a plant under computed-torque control (Arakelian, Le Baron & Mottu
/// 2011, eqs 2-6) along a rest-to-rest trajectory, integrated by classical RK4 at the controller
/// period (1 kHz by default).
///
/// Two ways to sample the controller, both honest about what they model:
///  - `zero_order_hold` (default): a digital controller. The torque is computed once per tick from
///    the state at t_k and held over [t_k, t_k + dt]. Even with an exact model the error then
///    departs from eq 6 by O(dt) (1.3e-4 rad for the paper's arm at 1 kHz, Kp = 100, Kd = 20).
///  - `every_rk4_stage`: the continuous-time control law of eq 2 is evaluated inside each RK4
///    stage; with an exact model the error follows eq 6 up to RK4's truncation error (~1e-11 rad).
/// The minimum-energy cubic law's acceleration jumps at t = 0 and t = T, so every stage of a step
/// uses the trajectory piece (moving or resting) that contains the step's midpoint; a stage at
/// T + round-off otherwise falls on the resting piece and spoils RK4's order (error 2e-5 rad).
///
/// Batch, not real-time: the log is allocated once up front; the loop itself allocates nothing.
#include <Eigen/Core>
#include <cstdint>

#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/status.hpp"
#include "mechbal/control/trajectory.hpp"

namespace mechbal {

enum class ControlSampling { zero_order_hold, every_rk4_stage };

struct ClosedLoopOptions {
  double dt = 1e-3;        ///< controller period = RK4 step [s]
  double duration = 1.0;   ///< simulated time [s]; steps = round(duration / dt)
  ControlSampling sampling = ControlSampling::zero_order_hold;
  /// Joint stops: the position limits of the plant's coordinates [rad or m], dof() values each
  /// (-inf / +inf: no stop on that side), or both empty (no stops, the default). A stop is
  /// inelastic: a coordinate found beyond it at the end of a step is put back on it, and its rate
  /// towards the stop is removed by an impulse through the plant's inverse mass matrix (the other
  /// coordinates take the reaction, as at a real end stop; projected Gauss-Seidel over the
  /// coordinates on a stop, at most `stop_sweeps` sweeps). A coordinate resting on its stop stays
  /// there to O(dt^2) per step; the energy an impact removes is not returned (no bounce).
  Eigen::VectorXd lower_limit, upper_limit;
  int stop_sweeps = 50;
};

/// One row per tick k = 0..steps (t_k = k dt). tau(k) is the command applied from t_k on (in
/// every_rk4_stage mode: the command at the start of the step).
struct ClosedLoopLog {
  Eigen::VectorXd t;
  Eigen::MatrixXd q, qd, q_des, qd_des, tau;
  /// status of tick k: the controller at t_k (and at the RK4 stages of step k in
  /// every_rk4_stage mode) OR the plant over step k (bit flags of Status)
  Eigen::Matrix<std::uint32_t, Eigen::Dynamic, 1> tick_status;
  Status status = Status::ok;  ///< OR of every controller and plant status
  int saturated_ticks = 0;     ///< ticks on which the controller clipped the torque
  int stop_ticks = 0;          ///< steps that ended with a coordinate on a stop (options' limits)
  int steps_completed = 0;     ///< < steps when the plant failed (then later rows repeat the last state)
};

/// Simulates `plant` (any ForwardDynamics: MechanismDynamics of any mechanism,
/// closed loops included) driven by `controller` (any JointController: ComputedTorque over any
/// model, which may differ from the plant, or DecoupledJointController) tracking `desired`, from
/// the initial state (q0, qd0). Throws std::invalid_argument naming the field on bad sizes or
/// options (stops: lower_limit / upper_limit of dof() values, not NaN, lower <= upper, q0 within
/// them).
ClosedLoopLog simulate_closed_loop(ForwardDynamics& plant, JointController& controller,
                                   const RestToRestTrajectory& desired, const Eigen::VectorXd& q0,
                                   const Eigen::VectorXd& qd0, const ClosedLoopOptions& options);

/// A desired motion given as samples on the half-step grid t_j = j dt / 2, j = 0 .. 2 steps
/// (any trajectory a caller can evaluate: via points, splines of measured data), one row per
/// sample, dof() columns. The controller reads row 2k at tick k (and rows 2k+1, 2k+2 at the
/// RK4 stages in every_rk4_stage mode).
struct SampledMotion {
  Eigen::MatrixXd q, qd, qdd;
};

/// As above, tracking a sampled desired motion: `desired` must have 2 round(duration / dt) + 1
/// finite rows of plant.dof() values each (std::invalid_argument naming the field otherwise).
ClosedLoopLog simulate_closed_loop(ForwardDynamics& plant, JointController& controller,
                                   const SampledMotion& desired, const Eigen::VectorXd& q0,
                                   const Eigen::VectorXd& qd0, const ClosedLoopOptions& options);

/// simulate_closed_loop with a ComputedTorque controller (Arakelian et al. 2011's closed loop).
ClosedLoopLog simulate_computed_torque(ForwardDynamics& plant, ComputedTorque& controller,
                                       const RestToRestTrajectory& desired,
                                       const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0,
                                       const ClosedLoopOptions& options);

/// Solution of e'' + kd e' + kp e = 0 (eq 6) for one joint with e(0) = e0, e'(0) = ed0, at time t,
/// for any damping (under-, critically or over-damped). noexcept.
double pd_error_analytic(double e0, double ed0, double kp, double kd, double t) noexcept;

}  // namespace mechbal
