// Closed loops on the general model (algorithm/loops.hpp).
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/springs.hpp"

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

/// N = L D L^T in place, without pivoting (N is symmetric positive semi-definite: the normal matrix
/// of A° plus a small damping): L in N's strict lower triangle (unit diagonal implied), D in `D`.
/// Written out for the small sizes of loop closures, where Eigen's LDLT (pivot search, blocked
/// triangular solves) costs several times more. A pivot that is not positive (a singular A°) is
/// kept as is and its component is zeroed by ldl_solve, as Eigen's LDLT does (pseudo-inverse of D).
void ldl_factor(Eigen::MatrixXd& N, Eigen::VectorXd& D) noexcept {
  const Eigen::Index n = N.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double d = N(k, k);
    D(k) = d;
    const Eigen::Index rest = n - k - 1;
    if (!(d > 0.0)) {
      N.col(k).tail(rest).setZero();
      continue;
    }
    for (Eigen::Index j = k + 1; j < n; ++j) {
      const double f = N(j, k) / d;
      if (f != 0.0) N.col(j).segment(j, n - j) -= f * N.col(k).segment(j, n - j);
    }
    N.col(k).tail(rest) /= d;
  }
}

/// x = (L D L^T)^-1 x with the factors of ldl_factor (plain loops: these are short vectors).
void ldl_solve(const Eigen::MatrixXd& L, const Eigen::VectorXd& D, Eigen::Ref<Eigen::VectorXd> x) noexcept {
  const Eigen::Index n = L.rows();
  double* const v = x.data();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double xk = v[k];
    if (xk == 0.0) continue;
    const double* l = L.data() + k * n;
    for (Eigen::Index i = k + 1; i < n; ++i) v[i] -= xk * l[i];
  }
  for (Eigen::Index k = 0; k < n; ++k) v[k] = D(k) > 0.0 ? v[k] / D(k) : 0.0;
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    const double* l = L.data() + k * n;
    double sum = 0.0;
    for (Eigen::Index i = k + 1; i < n; ++i) sum += l[i] * v[i];
    v[k] -= sum;
  }
}

/// N = A°^T A° + damping from data.loop_jacobian, factorised; returns the rcond estimate of A°.
double factor_passive(const MechanismModel& model, MechanismData& data) noexcept {
  const auto& passive = model.passive_coordinates();
  const auto np = static_cast<Eigen::Index>(passive.size());
  for (Eigen::Index j = 0; j < np; ++j) {
    data.loop_passive_jacobian.col(j) = data.loop_jacobian.col(passive[static_cast<std::size_t>(j)]);
  }
  // N = A°^T A°, lower triangle only (what ldl_factor reads), each entry a dot product over the rows
  // where both columns can be nonzero: a loop's rows involve only the coordinates of its two
  // frames' branches, so on mechanisms with several loops most column pairs do not overlap
  // (PAMINSA: the legs' coordinates meet only through the platform's), several times cheaper than
  // the dense product
  const Eigen::MatrixXd& Ap = data.loop_passive_jacobian;
  Eigen::MatrixXd& N = data.loop_normal;
  const auto m = static_cast<int>(Ap.rows());
  for (Eigen::Index j = 0; j < np; ++j) {
    int first = m, last = -1;
    for (int r = 0; r < m; ++r) {
      if (Ap(r, j) != 0.0) {
        if (first == m) first = r;
        last = r;
      }
    }
    data.loop_passive_first(j) = first;
    data.loop_passive_last(j) = last;
  }
  for (Eigen::Index i = 0; i < np; ++i) {
    const double* ai = Ap.data() + i * m;
    for (Eigen::Index j = i; j < np; ++j) {
      const int lo = std::max(data.loop_passive_first(i), data.loop_passive_first(j));
      const int hi = std::min(data.loop_passive_last(i), data.loop_passive_last(j));
      const double* aj = Ap.data() + j * m;
      double sum = 0.0;
      for (int r = lo; r <= hi; ++r) sum += ai[r] * aj[r];
      N(j, i) = sum;
    }
  }
  const double scale = std::max(1.0, data.loop_normal.diagonal().maxCoeff());
  data.loop_normal.diagonal().array() += 1e-14 * scale;
  ldl_factor(data.loop_normal, data.loop_normal_pivots);
  const Eigen::VectorXd& D = data.loop_normal_pivots;
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
  // Warm start from the last solved motion (q is where data.loop_projection was computed: the
  // usual tick, which passes back the q it got): follow the closure manifold to second order,
  // q + C d + (s^2 / 2) c with d = q#_new - q# and s = d . v# / |v#|^2 (d = s v# to first order
  // along a motion, and c, the acceleration bias of the last projection, is quadratic in v#), so
  // that Newton starts O(|d|^3) from the solution instead of O(|d|) (two iterations fewer at
  // 1 kHz). Only a starting point: Newton then converges as before. Not when the step would
  // exceed options.max_step.
  const bool tangent = model.is_closed() && q == data.closed_position;
  double vv = 0.0, dv = 0.0;
  for (std::size_t i = 0; i < actuated.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const double step = q_actuated(k) - q(actuated[i]), rate = data.closed_velocity(actuated[i]);
    if (tangent) trial.noalias() += data.loop_projection.col(k) * step;
    trial(actuated[i]) = q_actuated(k);
    vv += rate * rate;
    dv += step * rate;
  }
  if (tangent && vv > 0.0) {
    const double s = dv / vv;
    trial.noalias() += (0.5 * s * s) * data.loop_acceleration_bias;  // zero on the actuated rows
  }
  if (tangent && !((trial - q).cwiseAbs().maxCoeff() <= options.max_step)) {
    trial = q;
    for (std::size_t i = 0; i < actuated.size(); ++i) trial(actuated[i]) = q_actuated(static_cast<Eigen::Index>(i));
  }
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
    ldl_solve(data.loop_normal, data.loop_normal_pivots, data.loop_step);
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

namespace {

/// loop_projection at q (checked); `solved`: q is where solve_loop_positions just converged, so
/// data.loop_jacobian, the factorisation of A° and data.loop_rcond are already those of q (its last
/// evaluation) and are not recomputed.
/// One step of iterative refinement of x, the least-squares solution of A° x = -b from the factored
/// normal equations: x += (A°^T A°)^-1 A°^T (-(b + A° x)). The normal equations square A°'s
/// condition and carry a small damping; one step brings x back to the accuracy of A° itself (a
/// machine's internal spring forces of thousands of newtons multiply C's error: Orthoglide).
template <typename B, typename X>
void refine(MechanismData& data, const B& b, X&& x) noexcept {
  const Eigen::MatrixXd& Ap = data.loop_passive_jacobian;
  Eigen::VectorXd& r = data.loop_constraint_work;
  for (Eigen::Index row = 0; row < Ap.rows(); ++row) {
    double v = -b(row);
    for (Eigen::Index i = 0; i < Ap.cols(); ++i) {
      const double a = Ap(row, i);
      if (a != 0.0) v -= a * x(i);
    }
    r(row) = v;
  }
  Eigen::VectorXd& step = data.loop_step;
  step.setZero();
  for (Eigen::Index row = 0; row < Ap.rows(); ++row) {
    const double rv = r(row);
    if (rv == 0.0) continue;
    for (Eigen::Index i = 0; i < Ap.cols(); ++i) step(i) += Ap(row, i) * rv;
  }
  ldl_solve(data.loop_normal, data.loop_normal_pivots, step);
  x += step;
}

Status project(const MechanismModel& model, MechanismData& data, const ConstVector& q,
               const ConstVector& v_actuated, const LoopSolveOptions& options, bool solved) noexcept {
  const auto& actuated = model.actuated_coordinates();
  const auto& passive = model.passive_coordinates();
  Status status = Status::ok;
  data.loop_acceleration_bias.setZero();
  data.closed_position = q;
  if (!model.is_closed()) {
    data.loop_rcond = 1.0;
    data.closed_velocity.noalias() = data.loop_projection * v_actuated;
    return Status::ok;
  }
  if (!solved) {
    evaluate(model, data, q, true);
    data.loop_rcond = factor_passive(model, data);
  }
  if (data.loop_rcond < options.singular_rcond) status = Status::singular;
  // C: passive rows -(A°^T A°)^-1 A°^T A#
  for (std::size_t i = 0; i < actuated.size(); ++i) {
    data.loop_actuated_jacobian.col(static_cast<Eigen::Index>(i)) = data.loop_jacobian.col(actuated[i]);
  }
  // -A°^T A#, skipping the exact zeros of A° (as in factor_passive), then one solve per column
  const Eigen::MatrixXd& Ap = data.loop_passive_jacobian;
  data.loop_solution.setZero();
  for (Eigen::Index r = 0; r < Ap.rows(); ++r) {
    for (Eigen::Index i = 0; i < Ap.cols(); ++i) {
      const double a = Ap(r, i);
      if (a != 0.0) data.loop_solution.row(i) -= a * data.loop_actuated_jacobian.row(r);
    }
  }
  for (Eigen::Index j = 0; j < data.loop_solution.cols(); ++j) {
    ldl_solve(data.loop_normal, data.loop_normal_pivots, data.loop_solution.col(j));
    refine(data, data.loop_actuated_jacobian.col(j), data.loop_solution.col(j));
  }
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
  ldl_solve(data.loop_normal, data.loop_normal_pivots, data.loop_step);
  data.loop_refine_solution = data.loop_step;
  refine(data, data.loop_bias, data.loop_refine_solution);
  for (std::size_t j = 0; j < passive.size(); ++j) {
    data.loop_acceleration_bias(passive[j]) = data.loop_refine_solution(static_cast<Eigen::Index>(j));
  }
  if (!data.loop_projection.allFinite() || !data.loop_acceleration_bias.allFinite()) {
    return status | Status::singular;
  }
  return status;
}

}  // namespace

Status loop_projection(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                       const ConstVector& v_actuated, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &v_actuated); s != Status::ok) return s;
  return project(model, data, q, v_actuated, options, false);
}

Status closed_motion(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                     const ConstVector& v_actuated, const ConstVector& a_actuated, Eigen::Ref<Eigen::VectorXd> q,
                     const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated, &v_actuated, &a_actuated); s != Status::ok) return s;
  Status status = solve_loop_positions(model, data, q_actuated, q, options);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  status |= project(model, data, q, v_actuated, options, true);
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
  status |= project(model, data, q, data.actuated_force, options, true);
  mass_matrix(model, data, q);
  data.loop_reduced_work.noalias() = data.mass_matrix * data.loop_projection;
  data.reduced_mass_matrix.noalias() = data.loop_projection.transpose() * data.loop_reduced_work;
  static_torque(model, data, q);  // G and, with springs, K
  data.actuated_gravity.noalias() = data.loop_projection.transpose() * data.gravity_torque;
  data.actuated_static_torque.noalias() = data.loop_projection.transpose() * data.static_torque;
  return status;
}

Status closed_forward_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                               const ConstVector& v_actuated, const ConstVector& tau_actuated,
                               Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated, &v_actuated, &tau_actuated); s != Status::ok) return s;
  Status status = solve_loop_positions(model, data, q_actuated, q, options);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  status |= project(model, data, q, v_actuated, options, true);
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
