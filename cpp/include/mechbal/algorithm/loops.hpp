#pragma once
/// \file algorithm/loops.hpp
/// Closed-loop mechanisms on the general model: loop-closure equations, the position solve, the
/// velocity/acceleration projection of the coupling-matrix method and the projected dynamics.
///
/// Coutinho & Hess Coelho (the discs paper), generalised: with the closure equations Phi(q) = 0 and
/// A = dPhi/dq split into the passive columns A° and the actuated columns A#, the velocities are
/// v = C v# with C = [I; -(A°)^-1 A#] (rows reordered to q's order) and the accelerations
/// a = C a# + c with c = [0; -(A°)^-1 gamma], gamma = dA/dt v. With more equations than passive
/// coordinates (planar loops closed by spatial point constraints, redundant closures) (A°)^-1 is
/// the least-squares inverse (A°^T A°)^-1 A°^T, exact for consistent constraints.
/// The actuated forces are tau# = C^T tau(q, v, a) (virtual power), the reduced mass matrix
/// C^T M C, the reduced gravity C^T G; every tree algorithm (shaking wrench, base reaction, ...)
/// applies to the closed mechanism at the solved (q, v, a).
///
/// Closure equations of loop (A, B) with d = p_B - p_A (origins, in O):
///   point: d (3); planar_point: [x_A . d, y_A . d] (2); axis: d and [z_A . x_B, z_A . y_B] (5);
///   weld: d and the rotation vector of R_B R_A^T (6).
/// Open mechanisms (no loops) give C = the selection of the actuated coordinates and c = 0, so
/// the closed_* functions apply to every mechanism.
///
/// Real time: noexcept, allocation-free, bounded (LoopSolveOptions::max_iterations).
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

struct LoopSolveOptions {
  int max_iterations = 50;      ///< Newton iterations (each with at most 8 step halvings)
  double tolerance = 1e-13;     ///< on max |Phi| [m, rad]
  double max_step = 0.5;        ///< largest change of a passive coordinate per iteration [rad, m]
  double singular_rcond = 1e-7; ///< reciprocal condition of A° under which Status::singular is set
  /// C and c come from the normal equations of A° (damped by 1e-16 of their largest diagonal), whose
  /// relative error grows as eps / rcond^2: below this rcond (about 1e-12 relative error) they get
  /// one step of iterative refinement, which brings them to the accuracy of A° itself (rcond 1:
  /// always). PAMINSA's rcond is about 0.05 (error ~1e-13), the Orthoglide's 0.13 to 0.26.
  double refine_rcond = 0.02;
};

/// data.loop_residual = Phi(q) and data.loop_jacobian = A(q) (and world poses of every link).
Status loop_constraints(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;

/// Position solve: the passive coordinates of `q` (in/out; its actuated entries are replaced by
/// `q_actuated`, its passive entries are the warm start) such that Phi(q) = 0, by damped Newton
/// with step limiting and backtracking. Status::ok when converged; Status::singular is added when
/// A° is near singular (rcond in data.loop_rcond); Status::solver_error when it does not converge
/// within the iteration bound (the mechanism cannot be assembled there): `q` is then left
/// unchanged. data.loop_iterations, data.loop_residual_norm report the solve. When `q` is the
/// position of the last projection (data.closed_position: the usual tick passes back the q it got),
/// the warm start is first moved along the closure manifold to second order (q + C d + s^2 c / 2,
/// d the change of the actuated coordinates), plus the third- and fourth-order terms estimated
/// from the last ticks' prediction errors and, when the last solve took no Newton step, one
/// Newton step of its residual: at control rates most ticks then close the loops at the
/// prediction, with no Newton step (data.loop_iterations = 0).
Status solve_loop_positions(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                            Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options = {}) noexcept;

/// At a solved q: data.loop_projection (C), data.closed_position = q, data.closed_velocity = C v#,
/// data.loop_bias (gamma), data.loop_acceleration_bias (c), data.loop_rcond. Status::singular near a parallel singularity
/// (rcond below options.singular_rcond, or actuated velocities that the loops cannot accept).
Status loop_projection(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                       const ConstVector& v_actuated, const LoopSolveOptions& options = {}) noexcept;

/// The whole motion from the actuated coordinates: solve positions (q in/out as above), project
/// velocities and accelerations: data.closed_position, closed_velocity, closed_acceleration.
Status closed_motion(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                     const ConstVector& v_actuated, const ConstVector& a_actuated, Eigen::Ref<Eigen::VectorXd> q,
                     const LoopSolveOptions& options = {}) noexcept;

/// closed_motion and the shaking wrench of its motion (data.shaking: momenta about O and their
/// rates, as shaking_wrench(model, data, data.closed_position, data.closed_velocity,
/// data.closed_acceleration) gives them, to round-off), in one: the wrench is linear in the
/// accelerations, so the projection's pass over the links' velocities (which gamma needs) also
/// gives the momenta and the rates at a = 0, and one pass of the accelerations' own part, with no
/// velocity terms, completes them (not a second Newton-Euler pass over the whole motion).
/// Status as closed_motion's, plus Status::out_of_range for a non-finite wrench.
Status closed_shaking_wrench(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                             const ConstVector& v_actuated, const ConstVector& a_actuated,
                             Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options = {}) noexcept;

/// closed_motion up to the velocities: positions solved (q in/out), data.loop_projection (C),
/// data.closed_position and data.closed_velocity = C v#, without the acceleration level (no
/// gamma, no c: the pass over the links' velocities and its solve are skipped). For callers that
/// need C at a pose and not the accelerations (the stages of an integrator). data.loop_bias,
/// loop_acceleration_bias and closed_acceleration keep their last values: the next position
/// solve's warm start still uses that c as its curvature estimate.
Status closed_velocity_motion(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                              const ConstVector& v_actuated, Eigen::Ref<Eigen::VectorXd> q,
                              const LoopSolveOptions& options = {}) noexcept;

/// Actuated forces of the closed mechanism for the motion: data.actuated_force = C^T tau(q, v, a)
/// (tau of inverse_dynamics: springs included)
/// (after closed_motion with the same arguments; also fills data.joint_torque of the tree).
Status closed_inverse_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                               const ConstVector& v_actuated, const ConstVector& a_actuated,
                               Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options = {}) noexcept;

/// data.reduced_mass_matrix = C^T M C, data.actuated_gravity = C^T G and
/// data.actuated_static_torque = C^T (G + K) (springs, algorithm/springs.hpp) at the solved q.
Status closed_mass_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                          Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options = {}) noexcept;

/// Forward dynamics: data.actuated_acceleration = a# with C^T M C a# = tau# - C^T (M c + b(q, v)).
Status closed_forward_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                               const ConstVector& v_actuated, const ConstVector& tau_actuated,
                               Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options = {}) noexcept;

}  // namespace mechbal
