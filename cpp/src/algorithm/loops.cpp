// Closed loops on the general model (algorithm/loops.hpp).
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/springs.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/detail/placed.hpp"
#include "mechbal/detail/tree.hpp"

namespace mechbal {

namespace {

/// Position and orientation (O axes) of a named frame, from placed links.
struct FramePose {
  Vec3 position;
  Mat3 rotation;
};

/// (the rotation only when `rotation`: a point loop's rows need the origins alone)
FramePose frame_pose(const MechanismModel& model, const MechanismData& data, int frame, bool rotation) noexcept {
  const auto& W = data.work[static_cast<std::size_t>(model.frame_link(frame))];
  const auto f = static_cast<std::size_t>(frame);
  FramePose pose;
  pose.position = W.world_position + W.world_rotation * data.frame_position_in_link[f];
  if (rotation) pose.rotation.noalias() = W.world_rotation * data.frame_rotation_in_link[f];
  return pose;
}

/// Each closure row is a linear function of the frames' relative motion:
/// row = a . (v_B - v_A) + b . w_A + e . w_B (v: origin velocities, w: angular velocities, O axes).
struct RowFunctional {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero(), e = Vec3::Zero();
};

/// Residual (and Jacobian) of every loop, from placed links (world poses computed).
void constraint_rows(const MechanismModel& model, MechanismData& data, bool jacobian) noexcept {
  // (A's entries outside the loops' path columns are zero from construction and never written:
  // each loop's rows are set in its path columns alone, not the whole m x n matrix cleared)
  Eigen::MatrixXd& jac = data.loop_jacobian;
  for (int i = 0; i < model.num_loops(); ++i) {
    const int row = model.loop_row(i), fa = model.loop_frame_a(i), fb = model.loop_frame_b(i);
    const LoopType type = model.loop(i).type;
    const FramePose A = frame_pose(model, data, fa, type != LoopType::point);
    const FramePose B = frame_pose(model, data, fb, type == LoopType::axis || type == LoopType::weld);
    const Vec3 d = B.position - A.position;
    RowFunctional f[6];
    int rows = 0;
    if (type == LoopType::planar_point) {
      // x_k . d: its rate is x_k . (v_B - v_A) + (w_A x x_k) . d = x_k . (v_B - v_A) + (x_k x d) . w_A
      for (int k = 0; k < 2; ++k) {
        const Vec3 x = A.rotation.col(k);
        data.loop_residual(row + k) = x.dot(d);
        f[k].a = x;
        f[k].b = x.cross(d);
      }
      rows = 2;
    } else {
      // point part of point, axis and weld
      data.loop_residual.segment<3>(row) = d;
      for (int k = 0; k < 3; ++k) f[k].a = Vec3::Unit(k);
      rows = 3;
      if (type == LoopType::axis) {
        // z_A . e_k (e_k = x_B, y_B): its rate is (z x e_k) . (w_A - w_B)
        const Vec3 z = A.rotation.col(2);
        for (int k = 0; k < 2; ++k) {
          const Vec3 e = B.rotation.col(k);
          data.loop_residual(row + 3 + k) = z.dot(e);
          f[3 + k].b = z.cross(e);
          f[3 + k].e = -f[3 + k].b;
        }
        rows = 5;
      } else if (type == LoopType::weld) {
        // rotation vector of R_B R_A^T: its rate at the solution is w_B - w_A
        const Eigen::AngleAxisd err(Mat3(B.rotation * A.rotation.transpose()));
        data.loop_residual.segment<3>(row + 3) = err.angle() * err.axis();
        for (int k = 0; k < 3; ++k) {
          f[3 + k].b = -Vec3::Unit(k);
          f[3 + k].e = Vec3::Unit(k);
        }
        rows = 6;
      }
    }
    if (jacobian) {
      // (the columns above a planar_point loop's common ancestor are zero from construction: no
      // loop type writes them in its rows; its paths stop below it, data.loop_path_stop)
      // joint k moves a frame's origin p by r z x (p - p_k) (revolute) or r z (prismatic) and turns
      // it by r z (revolute): -1 times that for frame A, +1 for B; a joint on both paths (a common
      // ancestor) moves d = p_B - p_A by r z x d (revolute) or not at all (prismatic). Only the
      // loop's own columns are touched (no dense 6 x n frame Jacobians).
      const auto* const begin = data.loop_path_joints.data() + data.loop_path_joint_start[static_cast<std::size_t>(i)];
      const auto* const end = data.loop_path_joints.data() + data.loop_path_joint_start[static_cast<std::size_t>(i) + 1];
      const Eigen::Index m = jac.rows();
      // (a coordinate may drive several links, gears: its first joint in the list sets the
      // column's rows, the others add to them)
      const bool point = type == LoopType::point;
      for (const auto* e = begin; e != end; ++e) {
        const auto& K = data.work[static_cast<std::size_t>(e->link)];
        const Vec3 z = e->ratio * K.world_rotation.col(2);
        const bool on_a = (e->sides & 1) != 0, on_b = (e->sides & 2) != 0;
        Vec3 lin;
        if (e->revolute) {
          lin = z.cross(on_a ? (on_b ? Vec3(B.position - A.position) : Vec3(K.world_position - A.position))
                             : Vec3(B.position - K.world_position));
        } else {
          lin = on_a ? (on_b ? Vec3::Zero() : Vec3(-z)) : z;
        }
        double* column = jac.data() + static_cast<Eigen::Index>(e->coordinate) * m + row;
        if (point) {  // a point loop's rows are d itself (a = e_k, b = e = 0)
          if (e->first) {
            for (int r = 0; r < 3; ++r) column[r] = lin(r);
          } else {
            for (int r = 0; r < 3; ++r) column[r] += lin(r);
          }
          continue;
        }
        for (int r = 0; r < rows; ++r) {
          double value = f[r].a.dot(lin);
          if (e->revolute && on_a) value += f[r].b.dot(z);
          if (e->revolute && on_b) value += f[r].e.dot(z);
          column[r] = e->first ? value : column[r] + value;
        }
      }
    }
  }
}

/// detail::frame_motion from the frames' placements in their links (data.frame_*_in_link, as
/// frame_pose), the rotation only when the loop's bias needs it, for the axis and weld loops'
/// bias: the origin's acceleration and the angular motion (not the origin's position and velocity,
/// which only planar_point's reads: planar_bias).
detail::FrameMotion loop_frame_motion(const MechanismModel& model, const MechanismData& data, int frame,
                                      bool rotation) noexcept {
  const auto& W = data.work[static_cast<std::size_t>(model.frame_link(frame))];
  const auto f = static_cast<std::size_t>(frame);
  const Mat3& R = W.world_rotation;
  detail::FrameMotion m;
  const Vec3 r = R * data.frame_position_in_link[f];
  if (rotation) m.rotation.noalias() = R * data.frame_rotation_in_link[f];
  m.angular_velocity.noalias() = R * W.w;
  m.angular_acceleration.noalias() = R * W.alpha;
  m.acceleration = R * W.acc + m.angular_acceleration.cross(r) + m.angular_velocity.cross(m.angular_velocity.cross(r));
  return m;
}

/// 3-vectors as three scalars, for gamma's short products: written as Eigen expressions, each
/// cross product went through a stack temporary stored as scalars and read back by the next sum
/// as a 16-byte packet straddling two of those stores, which the store buffer cannot forward (a
/// third of constraint_bias's time sat on such loads). These stay in registers.
struct P3 {
  double x, y, z;
};
inline P3 p3(const Vec3& v) noexcept { return {v.x(), v.y(), v.z()}; }
inline P3 operator+(const P3& a, const P3& b) noexcept { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline P3 operator-(const P3& a, const P3& b) noexcept { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline P3 cross(const P3& a, const P3& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dot(const P3& a, const P3& b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline P3 rotate(const Mat3& R, const P3& v) noexcept {
  return {R(0, 0) * v.x + R(0, 1) * v.y + R(0, 2) * v.z, R(1, 0) * v.x + R(1, 1) * v.y + R(1, 2) * v.z,
          R(2, 0) * v.x + R(2, 1) * v.y + R(2, 2) * v.z};
}

/// A planar_point loop's rows of gamma: x_k . d has the second derivative
/// xdd . d + 2 xd . dd + x . ddd (x_k of frame A, d = p_B - p_A), in O (as loop_frame_motion).
void planar_bias(const MechanismModel& model, MechanismData& data, int i, int row) noexcept {
  struct Motion {
    P3 position, velocity, acceleration, angular_velocity, angular_acceleration;
  };
  const auto motion = [&](int frame) {
    const auto& W = data.work[static_cast<std::size_t>(model.frame_link(frame))];
    const Mat3& R = W.world_rotation;
    const P3 r = rotate(R, p3(data.frame_position_in_link[static_cast<std::size_t>(frame)]));
    Motion m;
    m.angular_velocity = rotate(R, p3(W.w));
    m.angular_acceleration = rotate(R, p3(W.alpha));
    m.position = p3(W.world_position) + r;
    m.velocity = rotate(R, p3(W.vel)) + cross(m.angular_velocity, r);
    m.acceleration = rotate(R, p3(W.acc)) + cross(m.angular_acceleration, r) +
                     cross(m.angular_velocity, cross(m.angular_velocity, r));
    return m;
  };
  const int fa = model.loop_frame_a(i);
  const Motion A = motion(fa), B = motion(model.loop_frame_b(i));
  const P3 d = B.position - A.position, dd = B.velocity - A.velocity, ddd = B.acceleration - A.acceleration;
  const Mat3& RA = data.work[static_cast<std::size_t>(model.frame_link(fa))].world_rotation;
  const Mat3& F = data.frame_rotation_in_link[static_cast<std::size_t>(fa)];
  for (int k = 0; k < 2; ++k) {
    const P3 x = rotate(RA, P3{F(0, k), F(1, k), F(2, k)});
    const P3 xd = cross(A.angular_velocity, x);
    const P3 xdd = cross(A.angular_acceleration, x) + cross(A.angular_velocity, xd);
    data.loop_bias(row + k) = dot(xdd, d) + 2.0 * dot(xd, dd) + dot(x, ddd);
  }
}

/// gamma = dA/dt v from a forward pass with velocities (accelerations at a = 0).
void constraint_bias(const MechanismModel& model, MechanismData& data) noexcept {
  for (int i = 0; i < model.num_loops(); ++i) {
    const int row = model.loop_row(i);
    const LoopType type = model.loop(i).type;
    if (type == LoopType::point) {
      // the origins' accelerations only, each in its link's axes, rotated once:
      // R (acc + alpha x p + w x (w x p)) (in scalars: P3)
      const auto acceleration = [&](int frame) {
        const auto& W = data.work[static_cast<std::size_t>(model.frame_link(frame))];
        const P3 p = p3(data.frame_position_in_link[static_cast<std::size_t>(frame)]), w = p3(W.w);
        return rotate(W.world_rotation, p3(W.acc) + cross(p3(W.alpha), p) + cross(w, cross(w, p)));
      };
      const P3 ddd = acceleration(model.loop_frame_b(i)) - acceleration(model.loop_frame_a(i));
      data.loop_bias(row) = ddd.x;
      data.loop_bias(row + 1) = ddd.y;
      data.loop_bias(row + 2) = ddd.z;
      continue;
    }
    if (type == LoopType::planar_point) {
      planar_bias(model, data, i, row);
      continue;
    }
    const bool axis = type == LoopType::axis;
    const detail::FrameMotion A = loop_frame_motion(model, data, model.loop_frame_a(i), axis);
    const detail::FrameMotion B = loop_frame_motion(model, data, model.loop_frame_b(i), axis);
    const Vec3 ddd = B.acceleration - A.acceleration;
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

/// N = L D L^T in place (data.loop_factor_values: N's pivots and lower triangle on L's structure,
/// assembled by factor_passive), without pivoting: D in the first np entries, L's strict lower
/// part (unit diagonal implied) after them, in loop_factor_rows' order. N is symmetric positive
/// semi-definite (the normal matrix of A° plus a small damping, in the elimination order).
/// Left-looking, column by column: each pivot and entry of L is its entry of N minus one sum of
/// the products l_jk u_ik over the columns k before (u: the entries before scaling by the pivot,
/// data.loop_factor_unscaled), summed in registers over the pairs listed at construction
/// (loop_factor_updates), so the factorisation is straight loops over contiguous arrays. A pivot
/// that is not positive (a singular A°) is kept as is and its component is zeroed by the solves,
/// as Eigen's LDLT does (pseudo-inverse of D: loop_pivot_inverse, which the solves multiply by,
/// holds 0 there).
void ldl_factor(MechanismData& data) noexcept {
  double* const V = data.loop_factor_values.data();
  const auto np = static_cast<int>(data.loop_elimination.size());
  double* const L = V + np;
  double* const U = data.loop_factor_unscaled.data();
  const int* start = data.loop_factor_start.data();
  const int* sum_start = data.loop_factor_update_start.data();
  const int* pairs = data.loop_factor_updates.data();
  double* const inverse = data.loop_pivot_inverse.data();
  const auto reduced = [&](int entry, double value) {  // value - sum over the entry's pairs
    double sum = 0.0;
    for (int e = sum_start[entry]; e < sum_start[entry + 1]; ++e) sum += L[pairs[2 * e]] * U[pairs[2 * e + 1]];
    return value - sum;
  };
  for (int j = 0; j < np; ++j) {
    const double d = reduced(j, V[j]);
    V[j] = d;
    const double inv = d > 0.0 ? 1.0 / d : 0.0;
    inverse[j] = inv;
    for (int q = start[j]; q < start[j + 1]; ++q) {
      const double u = reduced(np + q, L[q]);
      U[q] = u;
      L[q] = u * inv;
    }
  }
}

/// x = (L D L^T)^-1 x with the factors of ldl_factor. Both triangular solves form each unknown
/// as one sum (in registers, not through memory): forwards over the row's entries of L
/// (loop_factor_row_*), backwards over the column's.
void ldl_solve(const MechanismData& data, Eigen::Ref<Eigen::VectorXd> x) noexcept {
  const auto np = static_cast<int>(data.loop_elimination.size());
  const double* const L = data.loop_factor_values.data() + np;  // (after the pivots)
  const int* rows = data.loop_factor_rows.data();
  const int* start = data.loop_factor_start.data();
  const int* row_start = data.loop_factor_row_start.data();
  const int* row_entries = data.loop_factor_row_entries.data();
  const int* row_columns = data.loop_factor_row_columns.data();
  const double* const inverse = data.loop_pivot_inverse.data();
  double* const v = x.data();
  for (int i = 0; i < np; ++i) {
    double sum = 0.0;
    for (int e = row_start[i]; e < row_start[i + 1]; ++e) sum += L[row_entries[e]] * v[row_columns[e]];
    v[i] -= sum;
  }
  for (int k = np - 1; k >= 0; --k) {
    double sum = 0.0;
    for (int p = start[k]; p < start[k + 1]; ++p) sum += L[p] * v[rows[p]];
    v[k] = v[k] * inverse[k] - sum;
  }
}

/// y += a x over W contiguous entries (rows of the row-major blocks: a handful of actuated columns,
/// too short for Eigen's dynamic-size expressions to pay off); W = 0: n entries.
template <int W = 0>
inline void axpy(double* y, double a, const double* x, Eigen::Index n) noexcept {
  const Eigen::Index count = W > 0 ? W : n;
  for (Eigen::Index j = 0; j < count; ++j) y[j] += a * x[j];
}

/// ldl_solve_block with w = W columns (0: X.cols()), unrolled for the usual one to four; with
/// Extra (W > 0), the vector y (np) is solved in the same pass over L (its sums beside X's).
template <int W, bool Extra = false>
void ldl_solve_block_width(const MechanismData& data, MechanismData::RowMajorMatrix& X, double* y = nullptr) noexcept {
  static_assert(W > 0 || !Extra, "the extra right-hand side needs a fixed width");
  const auto np = static_cast<int>(data.loop_elimination.size());
  const double* const L = data.loop_factor_values.data() + np;  // (after the pivots)
  const int* rows = data.loop_factor_rows.data();
  const int* start = data.loop_factor_start.data();
  const int* row_start = data.loop_factor_row_start.data();
  const int* row_entries = data.loop_factor_row_entries.data();
  const int* row_columns = data.loop_factor_row_columns.data();
  const Eigen::Index w = W > 0 ? W : X.cols();
  double* x = X.data();
  // (W > 0: the row's sums in registers, as ldl_solve; otherwise through the row itself)
  for (int i = 0; i < np; ++i) {
    double* xi = x + i * w;
    if (W > 0) {
      double sum[W > 0 ? W : 1] = {};
      double extra = 0.0;
      for (int e = row_start[i]; e < row_start[i + 1]; ++e) {
        const double l = L[row_entries[e]];
        axpy<W>(sum, l, x + row_columns[e] * w, w);
        if (Extra) extra += l * y[row_columns[e]];
      }
      for (Eigen::Index j = 0; j < w; ++j) xi[j] -= sum[j];
      if (Extra) y[i] -= extra;
    } else {
      for (int e = row_start[i]; e < row_start[i + 1]; ++e) axpy<W>(xi, -L[row_entries[e]], x + row_columns[e] * w, w);
    }
  }
  for (int k = np - 1; k >= 0; --k) {
    double* xk = x + k * w;
    const double inv = data.loop_pivot_inverse(k);
    if (W > 0) {
      double sum[W > 0 ? W : 1] = {};
      double extra = 0.0;
      for (int p = start[k]; p < start[k + 1]; ++p) {
        axpy<W>(sum, L[p], x + rows[p] * w, w);
        if (Extra) extra += L[p] * y[rows[p]];
      }
      for (Eigen::Index j = 0; j < w; ++j) xk[j] = xk[j] * inv - sum[j];
      if (Extra) y[k] = y[k] * inv - extra;
    } else {
      for (Eigen::Index j = 0; j < w; ++j) xk[j] *= inv;
      for (int p = start[k]; p < start[k + 1]; ++p) axpy<W>(xk, -L[p], x + rows[p] * w, w);
    }
  }
}

/// X = (L D L^T)^-1 X for a block of right-hand sides (np x na, row-major): one pass over L for
/// all of them (the columns of C); and y = (L D L^T)^-1 y when `y` is given (in the same pass for
/// up to three columns of X).
void ldl_solve_block(const MechanismData& data, MechanismData::RowMajorMatrix& X,
                     Eigen::VectorXd* y = nullptr) noexcept {
  if (y) {
    switch (X.cols()) {
      case 1: return ldl_solve_block_width<1, true>(data, X, y->data());
      case 2: return ldl_solve_block_width<2, true>(data, X, y->data());
      case 3: return ldl_solve_block_width<3, true>(data, X, y->data());
      default: ldl_solve(data, *y); break;
    }
  }
  switch (X.cols()) {
    case 1: return ldl_solve_block_width<1>(data, X);
    case 2: return ldl_solve_block_width<2>(data, X);
    case 3: return ldl_solve_block_width<3>(data, X);
    case 4: return ldl_solve_block_width<4>(data, X);
    default: return ldl_solve_block_width<0>(data, X);
  }
}

/// X = -A°^T A# (np x w, row-major) over the loops' blocks of A° and A# (data.loop_blocks: the
/// products of each loop's passive and actuated columns over its rows).
/// One loop's part of passive_transpose_actuated, R rows (0: lb.rows; unrolled as block_velocity).
template <int R>
inline void add_block_products(const MechanismData& data, const MechanismData::LoopBlockInfo& lb,
                               MechanismData::RowMajorMatrix& X) noexcept {
  const int nr = R > 0 ? R : lb.rows;
  const Eigen::Index w = X.cols();
  const double* a = data.loop_passive_blocks.data() + lb.block;
  const int* members = data.loop_members.data() + lb.member;
  const int* actuated = data.loop_actuated_members.data() + lb.actuated;
  for (int c = 0; c < lb.count; ++c, a += nr) {
    double* x = X.data() + members[c] * w;
    const double* b = data.loop_actuated_blocks.data() + lb.actuated_block;
    for (int t = 0; t < lb.actuated_count; ++t, b += nr) {
      double sum = 0.0;
      for (int r = 0; r < nr; ++r) sum += a[r] * b[r];
      x[actuated[t]] -= sum;
    }
  }
}

void passive_transpose_actuated(const MechanismData& data, MechanismData::RowMajorMatrix& X) noexcept {
  X.setZero();
  for (const auto& lb : data.loop_blocks) {
    if (lb.actuated_count == 0) continue;
    switch (lb.rows) {
      case 2: add_block_products<2>(data, lb, X); break;
      case 3: add_block_products<3>(data, lb, X); break;
      case 5: add_block_products<5>(data, lb, X); break;
      case 6: add_block_products<6>(data, lb, X); break;
      default: add_block_products<0>(data, lb, X); break;
    }
  }
}

/// One loop's part of normal_rhs: o[members[c]] += (or -=) column c of its block . y's rows, R
/// rows (0: lb.rows), unrolled for the loop types' 2, 3, 5 and 6.
template <int R, bool Negate>
inline void add_block_transpose(const MechanismData& data, const MechanismData::LoopBlockInfo& lb, const double* y,
                                double* o) noexcept {
  const int nr = R > 0 ? R : lb.rows;
  const double* a = data.loop_passive_blocks.data() + lb.block;
  const int* members = data.loop_members.data() + lb.member;
  const double* yl = y + lb.row;
  for (int c = 0; c < lb.count; ++c, a += nr) {
    double sum = 0.0;
    for (int r = 0; r < nr; ++r) sum += a[r] * yl[r];
    if (Negate) {
      o[members[c]] -= sum;
    } else {
      o[members[c]] += sum;
    }
  }
}

/// out = A°^T y (or its negative with `Negate`) over A°'s blocks, summed from zero loop by loop
/// (the columns in no loop are zero).
template <bool Negate>
void normal_rhs(const MechanismData& data, const double* y, Eigen::VectorXd& out) noexcept {
  out.setZero();  // (the columns in no loop stay zero; the others are sums from zero)
  double* o = out.data();
  for (const auto& lb : data.loop_blocks) {
    switch (lb.rows) {
      case 2: add_block_transpose<2, Negate>(data, lb, y, o); break;
      case 3: add_block_transpose<3, Negate>(data, lb, y, o); break;
      case 5: add_block_transpose<5, Negate>(data, lb, y, o); break;
      case 6: add_block_transpose<6, Negate>(data, lb, y, o); break;
      default: add_block_transpose<0, Negate>(data, lb, y, o); break;
    }
  }
}

/// out = (A°^T A°)^-1 A°^T y (or its negative with `Negate`: the least-squares correction of
/// A° x = -y) from the factors.
template <bool Negate>
void normal_solve(const MechanismData& data, const double* y, Eigen::VectorXd& out) noexcept {
  normal_rhs<Negate>(data, y, out);
  ldl_solve(data, out);
}

/// The warm start's last step once data.loop_prediction_offset is solved: the recorded prediction
/// error moves to the estimated exact solution (solve_positions).
void finish_prediction_offset(const MechanismModel& model, MechanismData& data) noexcept {
  const auto& passive = model.passive_coordinates();
  Eigen::VectorXd& raw = data.loop_prediction_error;
  for (std::size_t j = 0; j < passive.size(); ++j) {
    raw(data.loop_elimination[j]) += data.loop_prediction_offset(static_cast<Eigen::Index>(j));
  }
  data.loop_prediction_size = raw.cwiseAbs().maxCoeff();
  data.loop_prediction_offset_pending = false;
}

/// Relative damping of the normal equations: keeps the solves bounded at a singular A° (Status::singular).
constexpr double kDamping = 1e-16;

/// One loop's block of A° from A (its rows, R of them (0: `rows`), of its passive columns), then
/// N += the products of its columns (column pairs a <= b in order, into the entries `target`
/// lists, ~entry for an entry's first product: symbolic factorisation).
template <int R>
const int* add_loop_products(const MechanismData& data, const MechanismData::LoopBlockInfo& lb, double* block,
                             double* V, const int* target) noexcept {
  const int nr = R > 0 ? R : lb.rows;
  const int count = lb.count;
  const int* members = data.loop_members.data() + lb.member;
  const Eigen::Index m = data.loop_jacobian.rows();
  for (int c = 0; c < count; ++c) {
    const double* from = data.loop_jacobian.data() +
                         static_cast<Eigen::Index>(data.loop_elimination[static_cast<std::size_t>(members[c])]) * m + lb.row;
    for (int r = 0; r < nr; ++r) block[c * nr + r] = from[r];
  }
  const int* const end = target + 3 * (count * (count + 1) / 2);
  for (; target != end; target += 3) {
    const double* ai = block + target[1];
    const double* aj = block + target[2];
    double sum = 0.0;
    for (int r = 0; r < nr; ++r) sum += ai[r] * aj[r];
    const int t = target[0];
    if (t < 0) {
      V[~t] = sum;
    } else {
      V[t] += sum;
    }
  }
  return target;
}

/// N = A°^T A° + damping from data.loop_jacobian, factorised; returns the rcond estimate of A°.
double factor_passive(MechanismData& data) noexcept {
  const auto np = static_cast<int>(data.loop_elimination.size());
  // A°'s blocks from A (each loop's rows of its passive columns; A°'s other entries are zero),
  // then N = A°^T A° on the structure of L: the sum over the loops of the products of their own
  // columns over their own rows (2 to 6 rows, a handful of columns each)
  double* const V = data.loop_factor_values.data();
  for (const int t : data.loop_factor_clear) V[t] = 0.0;
  const int* target = data.loop_normal_targets.data();
  for (const auto& lb : data.loop_blocks) {
    double* block = data.loop_passive_blocks.data() + lb.block;
    // (the loop types' row counts unrolled: 2 planar_point, 3 point, 5 axis, 6 weld)
    switch (lb.rows) {
      case 2: target = add_loop_products<2>(data, lb, block, V, target); break;
      case 3: target = add_loop_products<3>(data, lb, block, V, target); break;
      case 5: target = add_loop_products<5>(data, lb, block, V, target); break;
      case 6: target = add_loop_products<6>(data, lb, block, V, target); break;
      default: target = add_loop_products<0>(data, lb, block, V, target); break;
    }
  }
  double scale = 1.0;
  for (int i = 0; i < np; ++i) scale = std::max(scale, V[i]);
  for (int i = 0; i < np; ++i) V[i] += kDamping * scale;
  ldl_factor(data);
  if (np == 0) return 1.0;
  const auto D = data.loop_factor_values.head(np);
  const double dmax = D.cwiseAbs().maxCoeff(), dmin = D.cwiseAbs().minCoeff();
  return dmax > 0.0 ? std::sqrt(std::max(0.0, dmin - kDamping * scale) / dmax) : 0.0;
}

Status check(const MechanismModel& model, MechanismData& data, const Eigen::Ref<const Eigen::VectorXd>& q,
             const Eigen::Ref<const Eigen::VectorXd>* qa, const Eigen::Ref<const Eigen::VectorXd>* va = nullptr,
             const Eigen::Ref<const Eigen::VectorXd>* aa = nullptr) noexcept {
  if (!detail::data_matches(model, data) || data.loop_residual.size() != model.num_constraints()) {
    return Status::bad_size;
  }
  if (!data.size_actuated_buffers(model)) return Status::out_of_range;  // open model: first call
  const Eigen::Index na = model.num_actuated();
  if (q.size() != model.dof() || (qa && qa->size() != na) || (va && va->size() != na) || (aa && aa->size() != na)) {
    return Status::bad_size;
  }
  if (!detail::all_finite(q) || (qa && !detail::all_finite(*qa)) || (va && !detail::all_finite(*va)) ||
      (aa && !detail::all_finite(*aa))) {
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

namespace {

/// solve_loop_positions after its input checks (the closed_* functions check once).
/// `defer_offset`: the warm start's Newton step from the solution (data.loop_prediction_offset,
/// for the next tick) is left as its right-hand side, data.loop_prediction_offset_pending set:
/// project, which always follows, solves it in its pass over the factors for C.
Status solve_positions(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                       Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options,
                       bool defer_offset = false) noexcept {
  if (data.loop_prediction_offset_pending) {  // (not reached: project follows every deferral)
    ldl_solve(data, data.loop_prediction_offset);
    finish_prediction_offset(model, data);
  }
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
  if (tangent) {
    // (C d over C's structure: its passive rows are data.loop_solution's over the actuated
    // columns that move a loop, its other passive entries zero; its actuated rows are d itself,
    // which q_actuated replaces below)
    const auto& columns = data.loop_actuated_columns;
    const MechanismData::RowMajorMatrix& X = data.loop_solution;
    const Eigen::Index w = X.cols();
    double* const step = data.loop_vector_work.data();  // (n >= nla entries, free until the Newton steps)
    for (Eigen::Index t = 0; t < w; ++t) {
      const int c = columns[static_cast<std::size_t>(t)];
      step[t] = q_actuated(c) - q(actuated[static_cast<std::size_t>(c)]);
    }
    for (std::size_t j = 0; j < passive.size(); ++j) {
      const double* x = X.data() + static_cast<Eigen::Index>(j) * w;
      double& p = trial(data.loop_elimination[j]);
      for (Eigen::Index t = 0; t < w; ++t) p += x[t] * step[t];
    }
  }
  for (std::size_t i = 0; i < actuated.size(); ++i) trial(actuated[i]) = q_actuated(static_cast<Eigen::Index>(i));
  // the path parameter and the history over the loops' own coordinates: the actuated coordinates
  // that move no loop (a wrist carried by a parallel mechanism) change neither the solution nor c,
  // which is quadratic in the loops' rates alone, so their moves keep the warm start's history
  bool moved = false;  // the loops' actuators moved since q (a solve at the same q# from its solution returns it)
  for (const int i : data.loop_actuated_columns) {
    const auto k = static_cast<Eigen::Index>(i);
    const int c = actuated[static_cast<std::size_t>(i)];
    const double step = q_actuated(k) - q(c), rate = data.closed_velocity(c);
    moved = moved || step != 0.0;
    vv += rate * rate;
    dv += step * rate;
  }
  // Third and fourth order: the last warm-started tick's prediction error (its solution minus its
  // second-order prediction) is e = E s^3 + O(s^4) along the path; E s^3 from it, scaled to this
  // step, removes the O(s^3) term of this prediction, and E extrapolated linearly from the last two
  // ticks (steps in the same direction) the O(s^4) one, so that the warm start often closes the
  // loops within the tolerance with no Newton step at control rates. Only when q is the solution
  // the last error was recorded at, and the steps are comparable; Newton then converges as before.
  Eigen::VectorXd& raw = data.loop_prediction_error;  // the second-order prediction, then its error
  Eigen::VectorXd& older = data.loop_prediction_error_old;
  double s = 0.0;
  bool record = false;
  bool history = tangent;  // q is the solution the last error was recorded at, in the loops' coordinates
  for (std::size_t j = 0; j < passive.size() && history; ++j) {
    history = q(passive[j]) == data.loop_prediction_origin(passive[j]);
  }
  for (std::size_t t = 0; t < data.loop_actuated_columns.size() && history; ++t) {
    const int c = actuated[static_cast<std::size_t>(data.loop_actuated_columns[t])];
    history = q(c) == data.loop_prediction_origin(c);
  }
  if (tangent && vv > 0.0) {
    s = dv / vv;
    trial.noalias() += (0.5 * s * s) * data.loop_acceleration_bias;  // zero on the actuated rows
    const double last = data.loop_prediction_step, before = data.loop_prediction_step_old;
    const double ratio = history && last != 0.0 ? s / last : 0.0;
    double c_last = 0.0, c_before = 0.0;  // trial += c_last e_last + c_before e_before
    if (std::abs(ratio) <= 2.0) {
      c_last = ratio * ratio * ratio;
      const double previous = before != 0.0 ? last / before : 0.0;
      // (the errors are known to about the tolerance at worst, the solutions' accuracy: their
      // difference only carries the O(s^4) term when they are well above it. Not too far above:
      // at 1e3 times the tolerance, the 2e-11 to 6e-11 errors of PAMINSA's 0.5 ms steps left
      // the O(s^4) term, ~1e-13, in the prediction, and a Newton step on 3 % of the ticks)
      if (data.loop_prediction_depth >= 2 && ratio >= 0.5 && previous >= 0.5 && previous <= 2.0 &&
          !(data.loop_prediction_size < 100.0 * options.tolerance)) {
        const double k = (s + last) / (last + before), r = s / before;  // E = E_last + k (E_last - E_before)
        c_before = -k * r * r * r;
        c_last *= 1.0 + k;
      }
    }
    if (history && moved && data.loop_prediction_offset_valid) {
      for (std::size_t j = 0; j < passive.size(); ++j) {
        trial(data.loop_elimination[j]) += data.loop_prediction_offset(static_cast<Eigen::Index>(j));
      }
    }
    for (Eigen::Index i = 0; i < trial.size(); ++i) {
      const double e = raw(i), e_before = older(i);
      older(i) = e;
      raw(i) = trial(i);
      trial(i) += c_last * e + c_before * e_before;
    }
    record = true;
  }
  if (tangent && !((trial - q).cwiseAbs().maxCoeff() <= options.max_step)) {
    trial = q;
    for (std::size_t i = 0; i < actuated.size(); ++i) trial(actuated[i]) = q_actuated(static_cast<Eigen::Index>(i));
    record = false;
  }
  // (forgotten whole: the history compares the loops' coordinates only)
  if (!record) data.loop_prediction_origin.setConstant(std::numeric_limits<double>::quiet_NaN());
  data.loop_iterations = 0;
  if (!model.is_closed()) {
    data.loop_residual_norm = 0.0;
    data.loop_rcond = 1.0;
    q = trial;
    return Status::ok;
  }
  // Newton on Phi(q) = 0 over the passive coordinates. On a warm-started tick the factorisation of
  // the last solve (at data.closed_position, a few micrometres away) is reused: chord steps, which
  // need only the residual at each trial point, no Jacobian and no factorisation; the Jacobian is
  // evaluated and factorised once, at the solution (the projection needs it there). When a chord
  // step does not reduce the residual fourfold, the solve switches to full Newton (Jacobian and
  // factorisation at every iterate), as it does from the start without a warm start.
  bool chord = tangent;
  // when the last warm-started solve closed the loops at its prediction (no Newton step), this
  // one most likely does too and then needs the Jacobian there: computed with the residual, from
  // the same frame poses, instead of after it
  const bool likely_solved = history && moved && data.loop_prediction_offset_valid;
  bool jacobian_at_trial = likely_solved;  // data.loop_jacobian is that of `trial`
  bool placed_at_trial = true;             // the links are placed at `trial` (the last evaluation)
  evaluate(model, data, trial, likely_solved);
  double norm = data.loop_residual.cwiseAbs().maxCoeff();
  Eigen::VectorXd& candidate = data.loop_vector_work;
  for (int it = 0; it < options.max_iterations && norm > options.tolerance && !passive.empty(); ++it) {
    data.loop_iterations = it + 1;
    if (!chord) {
      if (!jacobian_at_trial) {
        if (placed_at_trial) {
          constraint_rows(model, data, true);
        } else {
          evaluate(model, data, trial, true);
        }
        jacobian_at_trial = placed_at_trial = true;
      }
      factor_passive(data);
    } else if (!placed_at_trial) {
      evaluate(model, data, trial, false);  // the residual at trial (the step needs it)
      placed_at_trial = true;
    }
    normal_solve<true>(data, data.loop_residual.data(), data.loop_step);
    const double biggest = data.loop_step.cwiseAbs().maxCoeff();
    if (!(biggest < 1e300)) {  // non-finite step: cannot assemble here
      if (chord) {
        chord = false;
        continue;
      }
      break;
    }
    if (biggest > options.max_step) data.loop_step *= options.max_step / biggest;
    bool improved = false;
    for (int halving = 0; halving <= 8; ++halving) {
      candidate = trial;
      for (std::size_t j = 0; j < passive.size(); ++j) {
        candidate(data.loop_elimination[j]) += data.loop_step(static_cast<Eigen::Index>(j));
      }
      // a chord step's candidate is usually the solution (one step at control rates): its Jacobian
      // comes with its residual, from the same frame poses (the chord steps themselves read A°
      // of the old factorisation, not data.loop_jacobian)
      evaluate(model, data, candidate, chord);
      const double n = data.loop_residual.cwiseAbs().maxCoeff();
      if (n < norm) {
        jacobian_at_trial = chord;
        if (chord && !(n <= 0.25 * norm)) chord = false;  // slow: full Newton from here
        trial = candidate;
        norm = n;
        improved = true;
        placed_at_trial = true;
        break;
      }
      placed_at_trial = false;
      if (chord) break;  // a stale factorisation: retry this iterate with full Newton
      data.loop_step *= 0.5;
    }
    if (!improved) {
      if (chord) {
        chord = false;
        continue;
      }
      break;
    }
  }
  data.loop_residual_norm = norm;
  // the Jacobian at the result, and the links placed there (project relies on both)
  if (!placed_at_trial) {
    evaluate(model, data, trial, true);
  } else if (!jacobian_at_trial && !passive.empty()) {
    constraint_rows(model, data, true);
  }
  data.loop_rcond = passive.empty() ? 1.0 : factor_passive(data);
  if (!(norm <= options.tolerance)) {
    data.loop_prediction_origin.setConstant(std::numeric_limits<double>::quiet_NaN());
    return Status::solver_error;
  }
  q = trial;
  if (record) {
    raw = trial - raw;
    // with no Newton step the solution is the prediction, within the tolerance but no closer: one
    // Newton step from the factorisation at hand (not applied to q, which the links are placed at)
    // estimates the exact solution, which the error and the next prediction then start from
    Eigen::VectorXd& offset = data.loop_prediction_offset;
    data.loop_prediction_offset_valid = data.loop_iterations == 0 && norm > 0.0 && !passive.empty();
    if (data.loop_prediction_offset_valid && defer_offset) {
      normal_rhs<true>(data, data.loop_residual.data(), offset);
      data.loop_prediction_offset_pending = true;  // project solves it and finishes the record
    } else if (data.loop_prediction_offset_valid) {
      normal_solve<true>(data, data.loop_residual.data(), offset);
      finish_prediction_offset(model, data);
    } else {
      data.loop_prediction_size = raw.cwiseAbs().maxCoeff();
    }
    data.loop_prediction_origin = trial;
    data.loop_prediction_step_old = data.loop_prediction_step;
    data.loop_prediction_step = s;
    data.loop_prediction_depth = history ? 2 : 1;
  }
  return data.loop_rcond < options.singular_rcond ? Status::singular : Status::ok;
}

}  // namespace

Status solve_loop_positions(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                            Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated); s != Status::ok) return s;
  return solve_positions(model, data, q_actuated, q, options);
}

namespace {

/// One step of iterative refinement of x, the least-squares solution of A° x = -b from the factored
/// normal equations: x += (A°^T A°)^-1 A°^T (-(b + A° x)). The normal equations square A°'s
/// condition and carry a small damping; one step brings x back to the accuracy of A° itself (a
/// machine's internal spring forces of thousands of newtons multiply C's error: Orthoglide).
template <typename B, typename X>
void refine(MechanismData& data, const B& b, X&& x) noexcept {
  Eigen::VectorXd& r = data.loop_constraint_work;
  r = -b;
  for (const auto& lb : data.loop_blocks) {
    const double* a = data.loop_passive_blocks.data() + lb.block;
    const int* members = data.loop_members.data() + lb.member;
    for (int c = 0; c < lb.count; ++c, a += lb.rows) {
      const double xi = x(members[c]);
      for (int k = 0; k < lb.rows; ++k) r(lb.row + k) -= a[k] * xi;
    }
  }
  Eigen::VectorXd& step = data.loop_step;
  normal_solve<false>(data, r.data(), step);
  x += step;
}

/// y = C x (or y += C x with `add`) over C's structure, after project: the actuated rows are x, the
/// passive rows X x over the actuated coordinates that move a loop (data.loop_solution; C's other
/// passive entries are zero). An open model's C is the selection of the actuated coordinates.
void apply_projection(const MechanismModel& model, const MechanismData& data, const ConstVector& x,
                      Eigen::VectorXd& y, bool add = false) noexcept {
  const auto& actuated = model.actuated_coordinates();
  if (!add) y.setZero();
  for (std::size_t i = 0; i < actuated.size(); ++i) y(actuated[i]) += x(static_cast<Eigen::Index>(i));
  if (!model.is_closed()) return;
  const auto& columns = data.loop_actuated_columns;
  const MechanismData::RowMajorMatrix& X = data.loop_solution;
  const Eigen::Index w = X.cols();
  constexpr Eigen::Index kHeld = 8;  // (x over C's solved columns held in registers, up to 8 of them)
  if (w > kHeld) {
    for (std::size_t j = 0; j < data.loop_elimination.size(); ++j) {
      const double* row = X.data() + static_cast<Eigen::Index>(j) * w;
      double sum = 0.0;
      for (Eigen::Index t = 0; t < w; ++t) sum += row[t] * x(columns[static_cast<std::size_t>(t)]);
      y(data.loop_elimination[j]) += sum;
    }
    return;
  }
  double held[kHeld];
  for (Eigen::Index t = 0; t < w; ++t) held[t] = x(columns[static_cast<std::size_t>(t)]);
  double* const out = y.data();
  const int* const elimination = data.loop_elimination.data();
  const double* row = X.data();
  for (std::size_t j = 0; j < data.loop_elimination.size(); ++j, row += w) {
    double sum = 0.0;
    for (Eigen::Index t = 0; t < w; ++t) sum += row[t] * held[t];
    out[elimination[j]] += sum;
  }
}

/// out = C^T y over C's structure, after project (as apply_projection).
void apply_projection_transpose(const MechanismModel& model, const MechanismData& data, const Eigen::VectorXd& y,
                                Eigen::VectorXd& out) noexcept {
  const auto& actuated = model.actuated_coordinates();
  for (std::size_t i = 0; i < actuated.size(); ++i) out(static_cast<Eigen::Index>(i)) = y(actuated[i]);
  if (!model.is_closed()) return;
  const auto& columns = data.loop_actuated_columns;
  const MechanismData::RowMajorMatrix& X = data.loop_solution;
  const Eigen::Index w = X.cols();
  for (Eigen::Index t = 0; t < w; ++t) {
    double sum = 0.0;
    for (std::size_t j = 0; j < data.loop_elimination.size(); ++j) {
      sum += X(static_cast<Eigen::Index>(j), t) * y(data.loop_elimination[j]);
    }
    out(columns[static_cast<std::size_t>(t)]) += sum;
  }
}

/// c = [0; -(A°^T A°)^-1 A°^T gamma] into data.loop_acceleration_bias (its passive rows; the
/// actuated ones stay zero) from gamma = dA/dt v, the loops' bias from the link accelerations at
/// a = 0 in data.work, with the factorisation of A° at the placed q; false when c is not finite.
bool acceleration_bias(const MechanismModel& model, MechanismData& data, bool refine_solves) noexcept {
  constraint_bias(model, data);
  normal_solve<true>(data, data.loop_bias.data(), data.loop_step);
  data.loop_refine_solution = data.loop_step;
  if (refine_solves) refine(data, data.loop_bias, data.loop_refine_solution);
  const auto& passive = model.passive_coordinates();
  for (std::size_t j = 0; j < passive.size(); ++j) {
    data.loop_acceleration_bias(data.loop_elimination[j]) = data.loop_refine_solution(static_cast<Eigen::Index>(j));
  }
  return detail::all_finite(data.loop_acceleration_bias);
}

/// One loop's rows of A v (into out, at the loop's rows): its block of A# times v# (over the
/// actuated columns that move it), then its block of A° times the passive velocities (`velocity`,
/// elimination order), each row summed in that order; R rows (0: lb.rows), unrolled for the loop
/// types' 2, 3, 5 and 6 (the row's sums in registers, the columns' entries contiguous).
template <int R>
inline void block_velocity(const MechanismData& data, const MechanismData::LoopBlockInfo& lb,
                           const ConstVector& v_actuated, const double* velocity, double* out) noexcept {
  const int nr = R > 0 ? R : lb.rows;
  const double* a = data.loop_passive_blocks.data() + lb.block;
  const double* b = data.loop_actuated_blocks.data() + lb.actuated_block;
  const int* members = data.loop_members.data() + lb.member;
  const int* actuated_members = data.loop_actuated_members.data() + lb.actuated;
  const auto& columns = data.loop_actuated_columns;
  if (R == 0) {
    for (int k = 0; k < nr; ++k) {
      double sum = 0.0;
      for (int t = 0; t < lb.actuated_count; ++t) {
        sum += b[t * nr + k] * v_actuated(columns[static_cast<std::size_t>(actuated_members[t])]);
      }
      for (int c = 0; c < lb.count; ++c) sum += a[c * nr + k] * velocity[members[c]];
      out[lb.row + k] = sum;
    }
    return;
  }
  double sum[R > 0 ? R : 1] = {};
  for (int t = 0; t < lb.actuated_count; ++t, b += nr) {
    const double x = v_actuated(columns[static_cast<std::size_t>(actuated_members[t])]);
    for (int k = 0; k < nr; ++k) sum[k] += b[k] * x;
  }
  for (int c = 0; c < lb.count; ++c, a += nr) {
    const double x = velocity[members[c]];
    for (int k = 0; k < nr; ++k) sum[k] += a[k] * x;
  }
  for (int k = 0; k < nr; ++k) out[lb.row + k] = sum[k];
}

/// loop_projection at q (checked); `solved`: q is where solve_loop_positions just converged, so
/// data.loop_jacobian, the factorisation of A° and data.loop_rcond are already those of q (its last
/// evaluation) and are not recomputed.
Status project(const MechanismModel& model, MechanismData& data, const ConstVector& q,
               const ConstVector& v_actuated, const LoopSolveOptions& options, bool solved,
               bool acceleration = true) noexcept {
  const auto& actuated = model.actuated_coordinates();
  const auto& passive = model.passive_coordinates();
  Status status = Status::ok;
  if (acceleration) data.loop_acceleration_bias.setZero();
  data.closed_position = q;
  if (!model.is_closed()) {
    data.loop_rcond = 1.0;
    data.closed_velocity.noalias() = data.loop_projection * v_actuated;
    return Status::ok;
  }
  if (!solved) {
    evaluate(model, data, q, true);
    data.loop_rcond = factor_passive(data);
  }
  if (data.loop_rcond < options.singular_rcond) status = Status::singular;
  // C: passive rows -(A°^T A°)^-1 A°^T A#
  // (only the columns of the actuated coordinates that move a loop: C's others are unit vectors)
  // (A#'s blocks: each loop's rows of the actuated columns that move it)
  const auto& columns = data.loop_actuated_columns;
  const Eigen::Index m = data.loop_jacobian.rows();
  for (const auto& lb : data.loop_blocks) {
    double* b = data.loop_actuated_blocks.data() + lb.actuated_block;
    const int* members = data.loop_actuated_members.data() + lb.actuated;
    for (int t = 0; t < lb.actuated_count; ++t, b += lb.rows) {
      const int coordinate = actuated[static_cast<std::size_t>(columns[static_cast<std::size_t>(members[t])])];
      const double* from = data.loop_jacobian.data() + static_cast<Eigen::Index>(coordinate) * m + lb.row;
      for (int r = 0; r < lb.rows; ++r) b[r] = from[r];
    }
  }
  // X = -A°^T A# (over the loops' blocks), solved for all columns at once, then one step of
  // iterative refinement (see refine): R = -A# - A° X, X += (A°^T A°)^-1 A°^T R
  MechanismData::RowMajorMatrix& X = data.loop_solution;
  const Eigen::Index w = X.cols();
  passive_transpose_actuated(data, X);
  if (data.loop_prediction_offset_pending) {  // (solve_positions' deferred step, at the same factors)
    ldl_solve_block(data, X, &data.loop_prediction_offset);
    finish_prediction_offset(model, data);
  } else {
    ldl_solve_block(data, X);
  }
  const bool refine_solves = data.loop_rcond < options.refine_rcond;
  if (refine_solves) {
    MechanismData::RowMajorMatrix& R = data.loop_block_residual;
    MechanismData::RowMajorMatrix& S = data.loop_block_step;
    for (std::size_t t = 0; t < columns.size(); ++t) {
      R.col(static_cast<Eigen::Index>(t)) = -data.loop_jacobian.col(actuated[static_cast<std::size_t>(columns[t])]);
    }
    S.setZero();
    for (const auto& lb : data.loop_blocks) {
      const double* a = data.loop_passive_blocks.data() + lb.block;
      const int* members = data.loop_members.data() + lb.member;
      for (int c = 0; c < lb.count; ++c, a += lb.rows) {
        const double* x = X.data() + members[c] * w;
        for (int k = 0; k < lb.rows; ++k) axpy(R.data() + (lb.row + k) * w, -a[k], x, w);
      }
    }
    for (const auto& lb : data.loop_blocks) {
      const double* a = data.loop_passive_blocks.data() + lb.block;
      const int* members = data.loop_members.data() + lb.member;
      for (int c = 0; c < lb.count; ++c, a += lb.rows) {
        double* si = S.data() + members[c] * w;
        for (int k = 0; k < lb.rows; ++k) axpy(si, a[k], R.data() + (lb.row + k) * w, w);
      }
    }
    ldl_solve_block(data, S);
    X += S;
  }
  // (C's other entries are 0 and 1)
  const bool finite = detail::all_finite(Eigen::Map<const Eigen::VectorXd>(X.data(), X.size()));
  for (std::size_t j = 0; j < passive.size(); ++j) {
    const double* x = X.data() + static_cast<Eigen::Index>(j) * w;
    for (Eigen::Index t = 0; t < w; ++t) {
      data.loop_projection(data.loop_elimination[j], columns[static_cast<std::size_t>(t)]) = x[t];
    }
  }
  apply_projection(model, data, v_actuated, data.closed_velocity);
  // the loops must accept the actuated velocities (A v = 0); they do not at a serial singularity of
  // the closure or when the actuators over-constrain the mechanism
  // (A v over A's nonzeros, the loops' blocks of A# and A°; the others are zero)
  // (the largest |entry| per column first: short, independent chains of max)
  // (row by row over each loop's columns, the sums in registers; the passive velocities in the
  // elimination order in data.loop_step, free until the bias solve below; A#'s are v#)
  Eigen::VectorXd& Av = data.loop_constraint_work;
  double* const velocity = data.loop_step.data();
  for (std::size_t j = 0; j < passive.size(); ++j) velocity[j] = data.closed_velocity(data.loop_elimination[j]);
  double biggest = 0.0;
  for (const auto& lb : data.loop_blocks) {
    switch (lb.rows) {  // (the loop types' row counts unrolled, as factor_passive)
      case 2: block_velocity<2>(data, lb, v_actuated, velocity, Av.data()); break;
      case 3: block_velocity<3>(data, lb, v_actuated, velocity, Av.data()); break;
      case 5: block_velocity<5>(data, lb, v_actuated, velocity, Av.data()); break;
      case 6: block_velocity<6>(data, lb, v_actuated, velocity, Av.data()); break;
      default: block_velocity<0>(data, lb, v_actuated, velocity, Av.data()); break;
    }
  }
  // (over all the blocks at once: A's nonzeros, contiguous)
  if (data.loop_actuated_blocks.size() > 0) biggest = data.loop_actuated_blocks.cwiseAbs().maxCoeff();
  if (data.loop_passive_blocks.size() > 0) biggest = std::max(biggest, data.loop_passive_blocks.cwiseAbs().maxCoeff());
  const double scale = 1.0 + biggest * data.closed_velocity.cwiseAbs().maxCoeff();
  if (!(Av.cwiseAbs().maxCoeff() <= 1e-8 * scale)) status = Status::singular;
  if (!acceleration) return finite ? status : status | Status::singular;
  // gamma at (q, v), then c
  // (the joints' rates only: their positions are q's already, from the last evaluation; the
  // velocity pass below reads no joint acceleration)
  {
    const double* v = data.closed_velocity.data();
    const int nl = model.num_links();
    for (int l = 1; l < nl; ++l) {
      const int c = model.coordinate(l);
      data.joint_velocity[static_cast<std::size_t>(l)] = c < 0 ? 0.0 : model.coordinate_ratio(l) * v[c];
    }
  }
  // (the links are placed at q: by the solve's last evaluation, or by evaluate above)
  detail::forward_pass<true, false, false, false>(model, data);
  if (!acceleration_bias(model, data, refine_solves) || !finite) return status | Status::singular;
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
  Status status = solve_positions(model, data, q_actuated, q, options, true);
  if (has(status, Status::solver_error)) return status;
  status |= project(model, data, q, v_actuated, options, true);  // (closed_position = q)
  data.closed_acceleration = data.loop_acceleration_bias;
  apply_projection(model, data, a_actuated, data.closed_acceleration, true);
  return status;
}

namespace {

/// The shaking wrench of the closed motion, after project (closed model: the links placed at q in
/// O, the joints' rates those of closed_velocity, and every link's velocities and its accelerations
/// at a = 0 from the bias pass). The wrench is linear in a: the rates of the momenta are those at
/// a = 0 plus A(q) a, so the bias pass's motion needs only a's part added, propagated down the
/// tree with no velocity terms (the acceleration field of a alone: alpha_a, acc_a, in
/// data.loop_acceleration_field); each link's Newton-Euler wrench and momentum are then formed
/// from the totals and summed about O in the same sweep. work[].alpha and acc end as the total
/// accelerations and data.joint_acceleration as a's (as shaking_wrench leaves them); work[].force
/// and moment are not written. Equal to shaking_wrench at (q, v, a) to round-off.
MECHBAL_FLATTEN void closed_wrench_of_projected(const MechanismModel& model, MechanismData& data) noexcept {
  const double* a = data.closed_acceleration.data();
  Vec3* field = data.loop_acceleration_field.data();
  field[0].setZero();
  field[1].setZero();
  Vec3 P = Vec3::Zero(), H = Vec3::Zero(), F = Vec3::Zero(), M = Vec3::Zero();
  const int nl = model.num_links();
  for (int l = 1; l < nl; ++l) {
    const auto k = static_cast<std::size_t>(l);
    auto& W = data.work[k];
    const auto parent = static_cast<std::size_t>(model.parent(l));
    const Vec3& parent_angular = field[2 * parent];
    const Vec3& parent_linear = field[2 * parent + 1];
    Vec3 angular, linear;
    detail::with_local_rotation(model.local_rotation(l), [&](auto kind) {
      constexpr auto K = decltype(kind)::value;
      angular = detail::to_child<K>(W.rotation, parent_angular);
      linear = detail::to_child<K>(W.rotation, Vec3(parent_linear + parent_angular.cross(W.translation)));
    });
    const int c = model.coordinate(l);
    const double qdd = c >= 0 ? model.coordinate_ratio(l) * a[c] : 0.0;
    data.joint_acceleration[k] = qdd;
    switch (model.joint_type(l)) {
      case JointType::revolute:
        angular.z() += qdd;
        break;
      case JointType::prismatic:
        linear.z() += qdd;
        break;
      case JointType::fixed:
        break;
    }
    field[2 * k] = angular;
    field[2 * k + 1] = linear;
    // (the link's motion in locals for the sums below: read back from W right after its totals
    // are stored, 16-byte loads straddle those stores and wait for them to retire)
    const Vec3 w = W.w, vel = W.vel, alpha = W.alpha + angular, acc = W.acc + linear;
    W.alpha = alpha;
    W.acc = acc;
    if (!model.has_inertia(l)) continue;  // adds nothing to the sums
    const auto& cst = model.link_constants(l);
    Vec3 force, moment;
    detail::link_wrench(cst, w, alpha, acc, force, moment);
    const Vec3 f = W.world_rotation * force;
    F += f;
    M += W.world_rotation * moment + W.world_position.cross(f);
    detail::add_link_momentum(cst, W, w, vel, P, H);
  }
  data.shaking.linear_momentum = P;
  data.shaking.angular_momentum = H;
  data.shaking.force = F;
  data.shaking.moment = M;
}

}  // namespace

Status closed_shaking_wrench(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                             const ConstVector& v_actuated, const ConstVector& a_actuated,
                             Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  Status status = closed_motion(model, data, q_actuated, v_actuated, a_actuated, q, options);
  if (has(status, Status::solver_error) || has(status, Status::bad_size) || has(status, Status::non_finite_input) ||
      has(status, Status::out_of_range)) {
    return status;
  }
  if (!model.is_closed()) {  // no bias pass to build on (project does none for an open model)
    return status | shaking_wrench(model, data, data.closed_position, data.closed_velocity, data.closed_acceleration);
  }
  closed_wrench_of_projected(model, data);
  const ShakingWrench& w = data.shaking;
  if (!detail::all_finite(w.linear_momentum) || !detail::all_finite(w.angular_momentum) ||
      !detail::all_finite(w.force) || !detail::all_finite(w.moment)) {
    status |= Status::out_of_range;
  }
  return status;
}

Status closed_velocity_motion(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                              const ConstVector& v_actuated, Eigen::Ref<Eigen::VectorXd> q,
                              const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated, &v_actuated); s != Status::ok) return s;
  Status status = solve_positions(model, data, q_actuated, q, options, true);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  return status | project(model, data, q, v_actuated, options, true, false);
}

Status detail::loop_acceleration_bias_placed(const MechanismModel& model, MechanismData& data,
                                             double refine_rcond) noexcept {
  if (!model.is_closed()) return Status::ok;
  return acceleration_bias(model, data, data.loop_rcond < refine_rcond) ? Status::ok : Status::singular;
}

Status closed_inverse_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                               const ConstVector& v_actuated, const ConstVector& a_actuated,
                               Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  Status status = closed_motion(model, data, q_actuated, v_actuated, a_actuated, q, options);
  if (has(status, Status::solver_error) || has(status, Status::bad_size) || has(status, Status::non_finite_input)) {
    return status;
  }
  status |= inverse_dynamics(model, data, data.closed_position, data.closed_velocity, data.closed_acceleration);
  apply_projection_transpose(model, data, data.joint_torque, data.actuated_force);
  if (!data.actuated_force.allFinite()) status |= Status::out_of_range;
  return status;
}

Status closed_mass_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q_actuated,
                          Eigen::Ref<Eigen::VectorXd> q, const LoopSolveOptions& options) noexcept {
  if (Status s = check(model, data, q, &q_actuated); s != Status::ok) return s;
  Status status = solve_positions(model, data, q_actuated, q, options, true);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  data.actuated_force.setZero();  // v# = 0 for the projection only
  status |= project(model, data, q, data.actuated_force, options, true);
  if (mass_matrix(model, data, q) != Status::ok && data.mass_matrix.rows() != model.dof()) {
    return status | Status::out_of_range;  // no memory for M: nothing to project
  }
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
  Status status = solve_positions(model, data, q_actuated, q, options, true);
  if (has(status, Status::solver_error)) return status;
  data.closed_position = q;
  status |= project(model, data, q, v_actuated, options, true);
  // C^T (M c + b) = C^T tau(q, v, c)
  inverse_dynamics(model, data, q, data.closed_velocity, data.loop_acceleration_bias);
  data.actuated_acceleration.noalias() = -data.loop_projection.transpose() * data.joint_torque;
  data.actuated_acceleration += tau_actuated;
  if (mass_matrix(model, data, q) != Status::ok && data.mass_matrix.rows() != model.dof()) {
    return status | Status::out_of_range;  // no memory for M: nothing to project
  }
  data.loop_reduced_work.noalias() = data.mass_matrix * data.loop_projection;
  data.reduced_mass_matrix.noalias() = data.loop_projection.transpose() * data.loop_reduced_work;
  data.reduced_ldlt.compute(data.reduced_mass_matrix);
  if (data.reduced_ldlt.info() != Eigen::Success || !(data.reduced_ldlt.vectorD().minCoeff() > 0.0)) {
    return status | Status::singular;
  }
  data.reduced_ldlt.solveInPlace(data.actuated_acceleration);
  data.closed_acceleration = data.loop_acceleration_bias;
  data.closed_acceleration.noalias() += data.loop_projection * data.actuated_acceleration;
  // finite input can overflow (tau = 1.8e308): never an ok status on a non-finite result
  if (!data.actuated_acceleration.allFinite() || !data.closed_acceleration.allFinite()) status |= Status::out_of_range;
  return status;
}

}  // namespace mechbal
