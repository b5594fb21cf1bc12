// Closed loops on the general model (algorithm/loops.hpp).
#include "mechbal/algorithm/loops.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/detail/tree.hpp"

namespace mechbal {

namespace {

/// Row `row` of the loop Jacobian: sum_k (lin_k . JX_lin col) + (ang_k . JY_ang col), written
/// column by column (no temporaries).
template <typename J>
void set_row(J& jac, int row, const Vec3& lin, const Eigen::MatrixXd& JL, double lin_sign_b,
             const Eigen::MatrixXd& JLa, const Vec3& ang, const Eigen::MatrixXd& JW) {
  // jac(row, c) = lin . (JL_lin(c) * sign_b - JLa_lin(c)) + ang . JW_ang(c)
  for (Eigen::Index c = 0; c < jac.cols(); ++c) {
    const Vec3 dl = lin_sign_b * JL.col(c).head<3>() - JLa.col(c).head<3>();
    jac(row, c) = lin.dot(dl) + ang.dot(JW.col(c).tail<3>());
  }
}

/// Residual (and Jacobian) of every loop, from placed links (world poses computed).
void constraint_rows(const MechanismModel& model, MechanismData& data, bool jacobian) noexcept {
  Eigen::MatrixXd& jac = data.loop_jacobian;
  const Eigen::MatrixXd& JA = data.loop_frame_jacobian_a;
  const Eigen::MatrixXd& JB = data.loop_frame_jacobian_b;
  for (int i = 0; i < model.num_loops(); ++i) {
    const int row = model.loop_row(i), fa = model.loop_frame_a(i), fb = model.loop_frame_b(i);
    const detail::FrameMotion A = detail::frame_motion(model, data, fa);
    const detail::FrameMotion B = detail::frame_motion(model, data, fb);
    const Vec3 d = B.position - A.position;
    if (jacobian) {
      detail::frame_jacobian_placed(model, data, fa, data.loop_frame_jacobian_a);
      detail::frame_jacobian_placed(model, data, fb, data.loop_frame_jacobian_b);
    }
    const LoopType type = model.loop(i).type;
    if (type == LoopType::planar_point) {
      for (int k = 0; k < 2; ++k) {
        const Vec3 x = A.rotation.col(k);
        data.loop_residual(row + k) = x.dot(d);
        if (jacobian) set_row(jac, row + k, x, JB, 1.0, JA, x.cross(d), JA);
      }
      continue;
    }
    // point part of point, axis and weld
    data.loop_residual.segment<3>(row) = d;
    if (jacobian) {
      for (Eigen::Index c = 0; c < jac.cols(); ++c) {
        jac.block<3, 1>(row, c) = JB.col(c).head<3>() - JA.col(c).head<3>();
      }
    }
    if (type == LoopType::axis) {
      const Vec3 z = A.rotation.col(2);
      for (int k = 0; k < 2; ++k) {
        const Vec3 e = B.rotation.col(k);
        data.loop_residual(row + 3 + k) = z.dot(e);
        if (jacobian) {
          const Vec3 ze = z.cross(e);
          for (Eigen::Index c = 0; c < jac.cols(); ++c) {
            jac(row + 3 + k, c) = ze.dot(JA.col(c).tail<3>() - JB.col(c).tail<3>());
          }
        }
      }
    } else if (type == LoopType::weld) {
      const Eigen::AngleAxisd err(Mat3(B.rotation * A.rotation.transpose()));
      data.loop_residual.segment<3>(row + 3) = err.angle() * err.axis();
      if (jacobian) {
        for (Eigen::Index c = 0; c < jac.cols(); ++c) {
          jac.block<3, 1>(row + 3, c) = JB.col(c).tail<3>() - JA.col(c).tail<3>();
        }
      }
    }
  }
}

/// gamma = dA/dt v from a forward pass with velocities (accelerations at a = 0).
void constraint_bias(const MechanismModel& model, MechanismData& data) noexcept {
  for (int i = 0; i < model.num_loops(); ++i) {
    const int row = model.loop_row(i);
    const detail::FrameMotion A = detail::frame_motion(model, data, model.loop_frame_a(i));
    const detail::FrameMotion B = detail::frame_motion(model, data, model.loop_frame_b(i));
    const Vec3 d = B.position - A.position, dd = B.velocity - A.velocity, ddd = B.acceleration - A.acceleration;
    const LoopType type = model.loop(i).type;
    if (type == LoopType::planar_point) {
      for (int k = 0; k < 2; ++k) {
        const Vec3 x = A.rotation.col(k);
        const Vec3 xd = A.angular_velocity.cross(x);
        const Vec3 xdd = A.angular_acceleration.cross(x) + A.angular_velocity.cross(xd);
        data.loop_bias(row + k) = xdd.dot(d) + 2.0 * xd.dot(dd) + x.dot(ddd);
      }
      continue;
    }
    data.loop_bias.segment<3>(row) = ddd;
    if (type == LoopType::axis) {
      const Vec3 z = A.rotation.col(2);
      const Vec3 dw = A.angular_velocity - B.angular_velocity;
      const Vec3 dal = A.angular_acceleration - B.angular_acceleration;
      for (int k = 0; k < 2; ++k) {
        const Vec3 e = B.rotation.col(k);
        const Vec3 rate = A.angular_velocity.cross(z).cross(e) + z.cross(B.angular_velocity.cross(e));
        data.loop_bias(row + 3 + k) = rate.dot(dw) + z.cross(e).dot(dal);
      }
    } else if (type == LoopType::weld) {
      data.loop_bias.segment<3>(row + 3) = B.angular_acceleration - A.angular_acceleration;
    }
  }
}

/// Residual (and Jacobian) at q (full coordinates).
void evaluate(const MechanismModel& model, MechanismData& data, const Eigen::Ref<const Eigen::VectorXd>& q,
              bool jacobian) noexcept {
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  constraint_rows(model, data, jacobian);
}

/// N = A°^T A° + damping from data.loop_jacobian, factorised; returns the rcond estimate of A°.
double factor_passive(const MechanismModel& model, MechanismData& data) noexcept {
  const auto& passive = model.passive_coordinates();
  const auto np = static_cast<Eigen::Index>(passive.size());
  for (Eigen::Index j = 0; j < np; ++j) {
    data.loop_passive_jacobian.col(j) = data.loop_jacobian.col(passive[static_cast<std::size_t>(j)]);
  }
  data.loop_normal.noalias() = data.loop_passive_jacobian.transpose() * data.loop_passive_jacobian;
  const double scale = std::max(1.0, data.loop_normal.diagonal().maxCoeff());
  data.loop_normal.diagonal().array() += 1e-14 * scale;
  data.loop_ldlt.compute(data.loop_normal);
  const auto D = data.loop_ldlt.vectorD();
  if (np == 0) return 1.0;
  const double dmax = D.cwiseAbs().maxCoeff(), dmin = D.cwiseAbs().minCoeff();
  return dmax > 0.0 ? std::sqrt(std::max(0.0, dmin - 1e-14 * scale) / dmax) : 0.0;
}

Status check(const MechanismModel& model, const MechanismData& data, const Eigen::Ref<const Eigen::VectorXd>& q,
             const Eigen::Ref<const Eigen::VectorXd>* qa, const Eigen::Ref<const Eigen::VectorXd>* va = nullptr,
             const Eigen::Ref<const Eigen::VectorXd>* aa = nullptr) noexcept {
  if (!detail::data_matches(model, data) || data.loop_residual.size() != model.num_constraints()) {
    return Status::bad_size;
  }
  const Eigen::Index na = model.num_actuated();
  if (q.size() != model.dof() || (qa && qa->size() != na) || (va && va->size() != na) || (aa && aa->size() != na)) {
    return Status::bad_size;
  }
  if (!q.allFinite() || (qa && !qa->allFinite()) || (va && !va->allFinite()) || (aa && !aa->allFinite())) {
    return Status::non_finite_input;
  }
  return Status::ok;
}

}  // namespace

Status loop_constraints(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check(model, data, q, nullptr); s != Status::ok) return s;
  evaluate(model, data, q, true);
  return Status::ok;
}

Status solve_loop_positions(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                            Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated); s != Status::ok) return s;
  const auto& actuated = model.actuated_coordinates();
  const auto& passive = model.passive_coordinates();
  Eigen::VectorXd& trial = data.loop_trial;
  trial = q;
  for (std::size_t i = 0; i < actuated.size(); ++i) trial(actuated[i]) = q_actuated(static_cast<Eigen::Index>(i));
  data.loop_iterations = 0;
  if (!model.is_closed()) {
    data.loop_residual_norm = 0.0;
    data.loop_rcond = 1.0;
    q = trial;
    return Status::ok;
  }
  evaluate(model, data, trial, true);
  double norm = data.loop_residual.cwiseAbs().maxCoeff();
  Eigen::VectorXd& candidate = data.loop_vector_work;
  for (int it = 0; it < options.max_iterations && norm > options.tolerance && !passive.empty(); ++it) {
    data.loop_iterations = it + 1;
    factor_passive(model, data);
    data.loop_step.noalias() = -data.loop_passive_jacobian.transpose() * data.loop_residual;
    data.loop_ldlt.solveInPlace(data.loop_step);
    const double biggest = data.loop_step.cwiseAbs().maxCoeff();
    if (!(biggest < 1e300)) break;  // non-finite step: cannot assemble here
    if (biggest > options.max_step) data.loop_step *= options.max_step / biggest;
    bool improved = false;
    for (int halving = 0; halving <= 8; ++halving) {
      candidate = trial;
      for (std::size_t j = 0; j < passive.size(); ++j) {
        candidate(passive[j]) += data.loop_step(static_cast<Eigen::Index>(j));
      }
      evaluate(model, data, candidate, true);
      const double n = data.loop_residual.cwiseAbs().maxCoeff();
      if (n < norm) {
        trial = candidate;
        norm = n;
        improved = true;
        break;
      }
      data.loop_step *= 0.5;
    }
    if (!improved) {
      evaluate(model, data, trial, true);
      break;
    }
  }
  data.loop_residual_norm = norm;
  if (!(norm <= options.tolerance)) {
    data.loop_rcond = passive.empty() ? 1.0 : factor_passive(model, data);
    return Status::solver_error;
  }
  data.loop_rcond = factor_passive(model, data);
  q = trial;
  return data.loop_rcond < options.singular_rcond ? Status::singular : Status::ok;
}

Status loop_projection(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                       const ConstVector& v_actuated, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &v_actuated); s != Status::ok) return s;
  const auto& actuated = model.actuated_coordinates();
  const auto& passive = model.passive_coordinates();
  Status status = Status::ok;
  data.loop_acceleration_bias.setZero();
  if (!model.is_closed()) {
    data.loop_rcond = 1.0;
    data.closed_velocity.noalias() = data.loop_projection * v_actuated;
    return Status::ok;
  }
  evaluate(model, data, q, true);
  data.loop_rcond = factor_passive(model, data);
  if (data.loop_rcond < options.singular_rcond) status = Status::singular;
  // C: passive rows -(A°^T A°)^-1 A°^T A#
  for (std::size_t i = 0; i < actuated.size(); ++i) {
    data.loop_actuated_jacobian.col(static_cast<Eigen::Index>(i)) = data.loop_jacobian.col(actuated[i]);
  }
  data.loop_solution.noalias() = -data.loop_passive_jacobian.transpose() * data.loop_actuated_jacobian;
  data.loop_ldlt.solveInPlace(data.loop_solution);
  for (std::size_t j = 0; j < passive.size(); ++j) {
    data.loop_projection.row(passive[j]) = data.loop_solution.row(static_cast<Eigen::Index>(j));
  }
  data.closed_velocity.noalias() = data.loop_projection * v_actuated;
  // the loops must accept the actuated velocities (A v = 0); they do not at a serial singularity of
  // the closure or when the actuators over-constrain the mechanism
  data.loop_constraint_work.noalias() = data.loop_jacobian * data.closed_velocity;
  const double scale = 1.0 + data.loop_jacobian.cwiseAbs().maxCoeff() * data.closed_velocity.cwiseAbs().maxCoeff();
  if (!(data.loop_constraint_work.cwiseAbs().maxCoeff() <= 1e-8 * scale)) status = Status::singular;
  // gamma at (q, v), then c = [0; -(A°^T A°)^-1 A°^T gamma]
  detail::joint_state<true, false>(model, data, q, data.closed_velocity, data.closed_velocity);
  detail::place(model, data);
  detail::forward_pass<true, false, false, false>(model, data);
  constraint_bias(model, data);
  data.loop_step.noalias() = -data.loop_passive_jacobian.transpose() * data.loop_bias;
  data.loop_ldlt.solveInPlace(data.loop_step);
  for (std::size_t j = 0; j < passive.size(); ++j) {
    data.loop_acceleration_bias(passive[j]) = data.loop_step(static_cast<Eigen::Index>(j));
  }
  if (!data.loop_projection.allFinite() || !data.loop_acceleration_bias.allFinite()) {
    return status | Status::singular;
  }
  return status;
}

Status closed_motion(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                     const ConstVector& v_actuated, const ConstVector& a_actuated, Eigen::Ref<Eigen::VectorXd> q,
                     const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated, &v_actuated, &a_actuated); s != Status::ok) return s;
  Status status = solve_loop_positions(model, data, q_actuated, q, options);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  status |= loop_projection(model, data, q, v_actuated, options);
  data.closed_acceleration = data.loop_acceleration_bias;
  data.closed_acceleration.noalias() += data.loop_projection * a_actuated;
  return status;
}

Status closed_inverse_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                               const ConstVector& v_actuated, const ConstVector& a_actuated,
                               Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  Status status = closed_motion(model, data, q_actuated, v_actuated, a_actuated, q, options);
  if (has(status, Status::solver_error) || has(status, Status::bad_size) || has(status, Status::non_finite_input)) {
    return status;
  }
  status |= inverse_dynamics(model, data, data.closed_position, data.closed_velocity, data.closed_acceleration);
  data.actuated_force.noalias() = data.loop_projection.transpose() * data.joint_torque;
  if (!data.actuated_force.allFinite()) status |= Status::out_of_range;
  return status;
}

Status closed_mass_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                          Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated); s != Status::ok) return s;
  Status status = solve_loop_positions(model, data, q_actuated, q, options);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  data.actuated_force.setZero();  // v# = 0 for the projection only
  status |= loop_projection(model, data, q, data.actuated_force, options);
  mass_matrix(model, data, q);
  data.loop_reduced_work.noalias() = data.mass_matrix * data.loop_projection;
  data.reduced_mass_matrix.noalias() = data.loop_projection.transpose() * data.loop_reduced_work;
  gravity_torque(model, data, q);
  data.actuated_gravity.noalias() = data.loop_projection.transpose() * data.gravity_torque;
  return status;
}

Status closed_forward_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                               const ConstVector& v_actuated, const ConstVector& tau_actuated,
                               Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated, &v_actuated, &tau_actuated); s != Status::ok) return s;
  Status status = solve_loop_positions(model, data, q_actuated, q, options);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  status |= loop_projection(model, data, q, v_actuated, options);
  // C^T (M c + b) = C^T tau(q, v, c)
  inverse_dynamics(model, data, q, data.closed_velocity, data.loop_acceleration_bias);
  data.actuated_acceleration.noalias() = -data.loop_projection.transpose() * data.joint_torque;
  data.actuated_acceleration += tau_actuated;
  mass_matrix(model, data, q);
  data.loop_reduced_work.noalias() = data.mass_matrix * data.loop_projection;
  data.reduced_mass_matrix.noalias() = data.loop_projection.transpose() * data.loop_reduced_work;
  data.reduced_ldlt.compute(data.reduced_mass_matrix);
  if (data.reduced_ldlt.info() != Eigen::Success || !(data.reduced_ldlt.vectorD().minCoeff() > 0.0)) {
    return status | Status::singular;
  }
  data.reduced_ldlt.solveInPlace(data.actuated_acceleration);
  data.closed_acceleration = data.loop_acceleration_bias;
  data.closed_acceleration.noalias() += data.loop_projection * data.actuated_acceleration;
  return status;
}

}  // namespace mechbal
