#include "mechbal/papers/paminsa/reactionless_wrist.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

namespace {

/// cos / sin of each angle, written as scalar calls on the same argument so that the compiler
/// pairs them into one sincos each
inline void cos_sin(const Vec3& q, Vec3& c, Vec3& s) noexcept {
  for (int i = 0; i < 3; ++i) {
    c(i) = std::cos(q(i));
    s(i) = std::sin(q(i));
  }
}
inline Vec3 cos_of(const Vec3& q) noexcept { return Vec3(std::cos(q(0)), std::cos(q(1)), std::cos(q(2))); }
inline Vec3 sin_of(const Vec3& q) noexcept { return Vec3(std::sin(q(0)), std::sin(q(1)), std::sin(q(2))); }

/// The wrist at one set of angles, in the frame of link 2 (nothing is formed in the base
/// frame). With R2 = Rz(phi) Rx(theta): x1 = R2 e_x, z2 = R2 e_z, R2^T e_z = (0, sin th, cos th),
/// and the link inertias in frame 2 are I1 = Rx^T J1 Rx, I2 = J2, I3 = Rz(psi) J3 Rz(psi)^T, so
///     N = R2 N2,  N2 = [I1 ez + (J2 + I3) ez | (J2 + I3) e_x | I3 e_z]   (ez = R2^T e_z)
/// with I1 ez = Rx^T (J1 e_z). N x = b <=> N2 x = R2^T b, and cond(N) = cond(N2). J may be any
/// 3x3 matrix (the formulas do not assume symmetry or diagonal inertias).
struct WristFrame2 {
  WristFrame2(const WristInertias& J, const Vec3& q) noexcept
      : WristFrame2(J, cos_of(q), sin_of(q)) {}
  /// from the cosines and sines of the angles; `diagonal`: every J_k is diagonal (exactly)
  WristFrame2(const WristInertias& J, const Vec3& cq, const Vec3& sq,
              bool diagonal = false) noexcept {
    cphi = cq(0); sphi = sq(0);
    cth = cq(1); sth = sq(1);
    const double cps = cq(2), sps = sq(2);
    const Mat3& J3 = J[2];
    if (diagonal) {
      // I3 = Rz J3 Rz^T = [x c^2 + y s^2, (x - y) c s, 0; ., x s^2 + y c^2, 0; 0, 0, z]
      const double x = J3(0, 0), y = J3(1, 1), cs = (x - y) * cps * sps;
      I3 << x * cps * cps + y * sps * sps, cs, 0.0,  //
          cs, x * sps * sps + y * cps * cps, 0.0,     //
          0.0, 0.0, J3(2, 2);
      I1ez = Vec3(0.0, sth * J[0](2, 2), cth * J[0](2, 2));
    } else {
      // I3 = Rz(psi) J3 Rz(psi)^T, written out (Rz mixes the first two rows / columns only)
      Mat3 T;  // Rz J3
      T.row(0) = cps * J3.row(0) - sps * J3.row(1);
      T.row(1) = sps * J3.row(0) + cps * J3.row(1);
      T.row(2) = J3.row(2);
      I3.col(0) = cps * T.col(0) - sps * T.col(1);
      I3.col(1) = sps * T.col(0) + cps * T.col(1);
      I3.col(2) = T.col(2);
      // I1 ez = Rx^T (J1 e_z)
      const Vec3 j1 = J[0].col(2);
      I1ez = Vec3(j1(0), cth * j1(1) + sth * j1(2), -sth * j1(1) + cth * j1(2));
    }
    J2 = &J[1];
    const Mat3 S = *J2 + I3;  // (I2 + I3) in frame 2
    N2.col(0) = I1ez + sth * S.col(1) + cth * S.col(2);
    N2.col(1) = S.col(0);
    N2.col(2) = I3.col(2);
  }
  /// R2^T b = Rx(th)^T Rz(phi)^T b
  Vec3 to_frame2(const Vec3& b) const noexcept {
    const double x = cphi * b(0) + sphi * b(1), y = -sphi * b(0) + cphi * b(1);
    return Vec3(x, cth * y + sth * b(2), -sth * y + cth * b(2));
  }
  /// R2 v
  Vec3 to_base(const Vec3& v) const noexcept {
    const double y = cth * v(1) - sth * v(2), z = sth * v(1) + cth * v(2);
    return Vec3(cphi * v(0) - sphi * y, sphi * v(0) + cphi * y, z);
  }
  /// N of eq 23 (corrected), base frame
  Mat3 momentum_matrix() const noexcept {
    Mat3 N;
    for (int j = 0; j < 3; ++j) N.col(j) = to_base(N2.col(j));
    return N;
  }
  /// R2^T sum_k [I_k wdot_k|_{qddot=0} + w_k x I_k w_k], all in frame 2 (x1 = e_x, z2 = e_z)
  Vec3 bias_frame2(const Vec3& qd) const noexcept {
    const Vec3 ez(0.0, sth, cth);
    const Vec3 w1 = qd(0) * ez;
    const Vec3 w2 = w1 + qd(1) * Vec3::UnitX();
    const Vec3 w3 = w2 + qd(2) * Vec3::UnitZ();
    const Vec3 a2 = qd(1) * w1.cross(Vec3::UnitX());
    const Vec3 a3 = a2 + qd(2) * w2.cross(Vec3::UnitZ());
    const Vec3 Iw1 = qd(0) * I1ez, Iw2 = *J2 * w2, Iw3 = I3 * w3;
    return w1.cross(Iw1) + *J2 * a2 + w2.cross(Iw2) + I3 * a3 + w3.cross(Iw3);
  }
  double cphi, sphi, cth, sth;
  Mat3 I3, N2;
  Vec3 I1ez;
  const Mat3* J2;
};

/// cos and sin of q0 + delta from those of q0 (the RK4 stages: |delta| = dt |qdot| / 2 or
/// dt |qdot|, small): for |delta| <= 1/32 the angle-addition formulas with Taylor polynomials of
/// sin delta, cos delta whose first omitted terms are below 1e-18 relative (exact to rounding,
/// without the libm calls); otherwise libm at q.
inline void sincos_near(double c0, double s0, double delta, double q, double& c,
                        double& s) noexcept {
  if (std::abs(delta) <= 1.0 / 32.0) {
    const double d2 = delta * delta;
    const double sd = delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
    const double cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)));
    c = c0 * cd - s0 * sd;
    s = s0 * cd + c0 * sd;
  } else {
    c = std::cos(q);
    s = std::sin(q);
  }
}

/// Cofactor inverse of a 3x3 matrix and its determinant.
inline Mat3 cofactor_inverse(const Mat3& A, double& det) noexcept {
  Mat3 C;
  C.col(0) = A.col(1).cross(A.col(2));
  C.col(1) = A.col(2).cross(A.col(0));
  C.col(2) = A.col(0).cross(A.col(1));
  det = A.col(0).dot(C.col(0));
  return C.transpose() / det;
}

[[noreturn]] void fail(const char* field, const std::string& what, double value) {
  std::ostringstream msg;
  msg << field << " " << what << ", got " << value;
  throw std::invalid_argument(msg.str());
}

}  // namespace

void wrist_link_motion(const Vec3& q, const Vec3& qd, const Vec3& qdd,
                       WristLinkMotion& out) noexcept {
  Vec3 c, s;
  cos_sin(q, c, s);
  wrist_link_motion(c, s, qd, qdd, out);
}

void wrist_link_motion(const Vec3& c, const Vec3& s, const Vec3& qd, const Vec3& qdd,
                       WristLinkMotion& out) noexcept {
  Mat3 R1, Rx, Rz3;
  R1 << c(0), -s(0), 0.0, s(0), c(0), 0.0, 0.0, 0.0, 1.0;
  Rx << 1.0, 0.0, 0.0, 0.0, c(1), -s(1), 0.0, s(1), c(1);
  Rz3 << c(2), -s(2), 0.0, s(2), c(2), 0.0, 0.0, 0.0, 1.0;
  const Mat3 R2 = R1 * Rx;
  const Mat3 R3 = R2 * Rz3;
  const Vec3 x1 = R1.col(0), z2 = R2.col(2);
  const Vec3 w1 = qd(0) * Vec3::UnitZ();
  const Vec3 w2 = w1 + qd(1) * x1;
  const Vec3 w3 = w2 + qd(2) * z2;
  // x1 turns with w1, z2 with w2: d/dt x1 = w1 x x1, d/dt z2 = w2 x z2
  const Vec3 a1 = qdd(0) * Vec3::UnitZ();
  const Vec3 a2 = a1 + qdd(1) * x1 + qd(1) * w1.cross(x1);
  const Vec3 a3 = a2 + qdd(2) * z2 + qd(2) * w2.cross(z2);
  out.rotation = {R1, R2, R3};
  out.angular_velocity = {w1, w2, w3};
  out.angular_acceleration = {a1, a2, a3};
}

Mat3 wrist_momentum_matrix(const WristInertias& J, const Vec3& q) noexcept {
  return WristFrame2(J, q).momentum_matrix();
}

Vec3 wrist_momentum_bias(const WristInertias& J, const Vec3& q, const Vec3& qd) noexcept {
  WristLinkMotion m;
  wrist_link_motion(q, qd, Vec3::Zero(), m);
  Vec3 bias = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const Mat3 I = m.rotation[k] * J[k] * m.rotation[k].transpose();
    const Vec3& w = m.angular_velocity[k];
    bias += I * m.angular_acceleration[k] + w.cross(I * w);
  }
  return bias;
}

void validate_wrist_config(const ReactionlessWristConfig& c) {
  // [1, 1e6] Hz: dt = 1/rate_hz finite and a step that is a control tick (5e-324 Hz would
  // give an infinite step)
  if (!(c.rate_hz >= 1.0 && c.rate_hz <= 1e6)) fail("rate_hz", "must be in [1, 1e6] Hz", c.rate_hz);
  if (!std::isfinite(c.max_rate) || c.max_rate <= 0.0) fail("max_rate", "must be finite and > 0", c.max_rate);
  if (!std::isfinite(c.max_acceleration) || c.max_acceleration <= 0.0)
    fail("max_acceleration", "must be finite and > 0", c.max_acceleration);
  if (!std::isfinite(c.max_momentum) || c.max_momentum <= 0.0)
    fail("max_momentum", "must be finite and > 0", c.max_momentum);
  if (!std::isfinite(c.max_moment) || c.max_moment <= 0.0)
    fail("max_moment", "must be finite and > 0", c.max_moment);
  if (!std::isfinite(c.max_condition) || c.max_condition <= 1.0)
    fail("max_condition", "must be finite and > 1", c.max_condition);
  if (!std::isfinite(c.damping) || c.damping <= 0.0 || c.damping >= 1.0)
    fail("damping", "must be in (0, 1)", c.damping);
  if (c.integrator != WristIntegrator::euler && c.integrator != WristIntegrator::rk4)
    fail("integrator", "must be euler or rk4", static_cast<double>(c.integrator));
}

ReactionlessWrist::ReactionlessWrist(const WristInertias& inertia_body,
                                     const ReactionlessWristConfig& config,
                                     const Vec3& initial_angles, const Vec3& target_momentum)
    : inertia_(inertia_body), config_(config), dt_(0.0) {
  validate_wrist_config(config);
  static const char* names[3] = {"wrist_inertia[0]", "wrist_inertia[1]", "wrist_inertia[2]"};
  for (int k = 0; k < 3; ++k) validate_rigid_body(RigidBody{0.0, inertia_body[k]}, names[k]);
  if (!initial_angles.allFinite() || initial_angles.cwiseAbs().maxCoeff() > max_angle)
    fail("initial_angles", "must be finite and within +-1e6 rad", initial_angles.cwiseAbs().maxCoeff());
  if (!target_momentum.allFinite() || target_momentum.cwiseAbs().maxCoeff() > config.max_momentum)
    fail("target_momentum", "must be finite and within +-max_momentum",
         target_momentum.cwiseAbs().maxCoeff());
  dt_ = 1.0 / config.rate_hz;
  diagonal_inertia_ = true;
  for (const Mat3& J : inertia_)
    diagonal_inertia_ = diagonal_inertia_ && (J - Mat3(J.diagonal().asDiagonal())).isZero(0.0);
  angles_ = initial_angles;
  target_ = target_momentum;
  command_.angles = command_.next_angles = initial_angles;
  cos_sin(initial_angles, command_.cos_angles, command_.sin_angles);
  command_.condition_number = 1.0;
}

Status ReactionlessWrist::reset(const Vec3& angles, const Vec3& target_momentum) noexcept {
  if (!angles.allFinite() || !target_momentum.allFinite()) return Status::non_finite_input;
  if (angles.cwiseAbs().maxCoeff() > max_angle ||
      target_momentum.cwiseAbs().maxCoeff() > config_.max_momentum)
    return Status::out_of_range;
  angles_ = angles;
  target_ = target_momentum;
  command_ = WristCommand{};
  command_.angles = command_.next_angles = angles;
  cos_sin(angles, command_.cos_angles, command_.sin_angles);
  return Status::ok;
}

Status ReactionlessWrist::solve(const Mat3& N, const Vec3& rhs, Vec3& x, double& condition,
                                Mat3* inverse) const noexcept {
  // Fast path (a 3x3 JacobiSVD costs ~0.7 us, the whole tick budget): the singular values
  // of N are the square roots of the eigenvalues of N^T N, which Eigen gives in closed form; when
  // N is well conditioned the exact solve is the cofactor inverse. The eigenvalues of N^T N lose
  // about cond^2 eps relative accuracy (1e-8 at cond = 1e4), enough to decide well-conditioned
  // and to report cond(N).
  const Mat3 NtN = N.transpose() * N;
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(NtN);
  const Vec3& lambda = eig.eigenvalues();  // ascending
  constexpr double huge = std::numeric_limits<double>::max();
  if (!std::isfinite(lambda(2)) || !(lambda(2) > 0.0) || !NtN.allFinite()) {
    x.setZero();  // N zero, overflowing or not finite: no solution worth returning
    condition = huge;
    return Status::singular;
  }
  const double c = lambda(0) > 0.0 ? std::sqrt(lambda(2) / lambda(0)) : huge;
  if (c <= config_.max_condition) {
    const Mat3 inv = N.inverse();
    const Vec3 y = inv * rhs;
    if (y.allFinite() && inv.allFinite()) {
      if (inverse) *inverse = inv;
      x = y;
      condition = c;
      return Status::ok;
    }
  }
  // reported cond(N) of a singular N: sigma_min from |det N| = s1 s2 s3 (relative error ~ cond eps)
  // rather than from the smallest eigenvalue of N^T N (~ cond^2 eps, 1e-4 at cond = 1e6)
  {
    const double det_N = N.col(0).dot(N.col(1).cross(N.col(2)));
    const double s1 = std::sqrt(lambda(2)), s2 = std::sqrt(std::max(lambda(1), 0.0));
    const double s3 = s2 > 0.0 ? std::abs(det_N) / (s1 * s2) : 0.0;
    condition = s3 > s1 / huge ? s1 / s3 : huge;
    if (!std::isfinite(condition)) condition = huge;
  }
  // Singular (a JacobiSVD fallback costs 4-5 us, ten times the tick budget):
  // damped least squares, x minimises |N x - rhs|^2 + lambda^2 |x|^2 with lambda = damping
  // sigma_max(N), i.e. the 3x3 normal equations (N^T N + lambda^2 1) x = N^T rhs. Their matrix is
  // symmetric positive definite with cond <= 1 + 1/damping^2 (1e4 + 1 by default) whatever N is,
  // so the cofactor inverse is accurate; the solution equals the SVD form
  // sum_i s_i (u_i . rhs) / (s_i^2 + lambda^2) v_i to rounding.
  Mat3 A = NtN;
  A.diagonal().array() += config_.damping * config_.damping * lambda(2);
  double det = 0.0;
  const Mat3 pinv = cofactor_inverse(A, det) * N.transpose();  // damped pseudo-inverse
  x = pinv * rhs;
  if (!x.allFinite()) {
    x.setZero();
  } else if (inverse && pinv.allFinite()) {
    *inverse = pinv;
  }
  return Status::singular;
}

Status ReactionlessWrist::rates(const Vec3& q, const Vec3& D, Vec3& qd,
                                double& condition) const noexcept {
  return rates_with(wrist_momentum_matrix(inertia_, q), D, qd, condition);
}

Status ReactionlessWrist::rates_with(const Mat3& N, const Vec3& D, Vec3& qd, double& condition,
                                     Mat3* inverse) const noexcept {
  const Status st = solve(N, target_ - D, qd, condition, inverse);
  return st | limit_rate(qd);
}

Status ReactionlessWrist::hold(Status why) noexcept {
  command_.angles = command_.next_angles = angles_;
  cos_sin(angles_, command_.cos_angles, command_.sin_angles);
  command_.rates.setZero();
  command_.accelerations.setZero();
  command_.status = why;
  return why;
}

bool ReactionlessWrist::in_range(const Vec3& D_now, const Vec3& D_dot, const Vec3* D_half,
                                 const Vec3* D_next) const noexcept {
  const double H = config_.max_momentum;
  return D_now.cwiseAbs().maxCoeff() <= H && D_dot.cwiseAbs().maxCoeff() <= config_.max_moment &&
         (D_half == nullptr || D_half->cwiseAbs().maxCoeff() <= H) &&
         (D_next == nullptr || D_next->cwiseAbs().maxCoeff() <= H);
}

Status ReactionlessWrist::limit_rate(Vec3& qd) const noexcept {
  const double peak = qd.cwiseAbs().maxCoeff();
  if (peak > config_.max_rate) {
    qd *= config_.max_rate / peak;  // keep the direction of the commanded rate vector
    return Status::saturated;
  }
  return Status::ok;
}

Status ReactionlessWrist::stage_rates(const Vec3& delta, const Vec3& cos_n, const Vec3& sin_n,
                                      const Vec3& D, Vec3& qd) const noexcept {
  // An RK4 stage needs the rates only, not cond(N) (the closed-form eigenvalues cost as
  // much as the rest of the stage). The decision "well conditioned" must stay the one solve()
  // makes (cond(N) <= max_condition, else damped least squares + Status::singular), so it is
  // taken on an upper bound: cond_2(N) <= |N|_F |N^-1|_F. When the bound is within the limit,
  // so is cond(N), and the fast solve is exactly solve()'s fast path (cofactor inverse); the
  // bound exceeds cond(N) by at least 1 + 1/cond and at most a factor 3, far above the eigenvalue
  // route's cond^2 eps rounding, so the decision is the same. Otherwise solve() decides.
  const Vec3 q = angles_ + delta;
  Vec3 cq, sq;
  for (int i = 0; i < 3; ++i) sincos_near(cos_n(i), sin_n(i), delta(i), q(i), cq(i), sq(i));
  Mat3 N2;
  if (diagonal_inertia_) {
    // J_k = diag(x_k, y_k, z_k) (PAMINSA's wrist): WristFrame2's N2 written out, with
    // I3 = Rz(psi) J3 Rz(psi)^T = [x3 c^2 + y3 s^2, (x3 - y3) c s, 0; ..., x3 s^2 + y3 c^2, 0; 0, 0, z3]
    // and I1 ez = (0, sin th z1, cos th z1):
    // N2 = [sin th S01, S00, 0; sin th (z1 + S11), S01, 0; cos th (z1 + S22), 0, z3], S = J2 + I3
    const double c = cq(2), s = sq(2), cth = cq(1), sth = sq(1);
    const Mat3 &J1 = inertia_[0], &J2 = inertia_[1], &J3 = inertia_[2];
    const double x3 = J3(0, 0), y3 = J3(1, 1), z3 = J3(2, 2), z1 = J1(2, 2);
    const double S00 = J2(0, 0) + x3 * c * c + y3 * s * s, S01 = (x3 - y3) * c * s;
    const double S11 = J2(1, 1) + x3 * s * s + y3 * c * c, S22 = J2(2, 2) + z3;
    N2 << sth * S01, S00, 0.0,  //
        sth * (z1 + S11), S01, 0.0,  //
        cth * (z1 + S22), 0.0, z3;
  } else {
    N2 = WristFrame2(inertia_, cq, sq).N2;
  }
  // R2^T (H_target - D), R2 = Rz(phi) Rx(theta)
  const Vec3 b = target_ - D;
  const double bx = cq(0) * b(0) + sq(0) * b(1), by = -sq(0) * b(0) + cq(0) * b(1);
  const Vec3 rhs(bx, cq(1) * by + sq(1) * b(2), -sq(1) * by + cq(1) * b(2));
  double det = 0.0;
  const Mat3 inv = cofactor_inverse(N2, det);
  const double bound2 = N2.squaredNorm() * inv.squaredNorm();
  const double max_c = config_.max_condition;
  Status st = Status::ok;
  double unused = 1.0;
  if (det != 0.0 && bound2 <= max_c * max_c && inv.allFinite()) {
    qd = inv * rhs;
    if (!qd.allFinite()) st = solve(N2, rhs, qd, unused);
  } else {
    st = solve(N2, rhs, qd, unused);
  }
  return st | limit_rate(qd);
}

Status ReactionlessWrist::step(const Vec3& D_now, const Vec3& D_dot, const Vec3& D_half,
                               const Vec3& D_next) noexcept {
  if (config_.integrator == WristIntegrator::rk4) return tick(D_now, D_dot, &D_half, &D_next);
  return tick(D_now, D_dot, nullptr, nullptr);
}

Status ReactionlessWrist::step_euler(const Vec3& D_now, const Vec3& D_dot) noexcept {
  return tick(D_now, D_dot, nullptr, nullptr);
}

Status ReactionlessWrist::tick(const Vec3& D_now, const Vec3& D_dot, const Vec3* D_half,
                               const Vec3* D_next) noexcept {
  const bool finite = D_now.allFinite() && D_dot.allFinite() &&
                      (D_half == nullptr || D_half->allFinite()) &&
                      (D_next == nullptr || D_next->allFinite());
  if (!finite) return hold(Status::non_finite_input);
  if (!in_range(D_now, D_dot, D_half, D_next)) return hold(Status::out_of_range);

  Vec3 k1;
  double cond = 1.0, unused = 1.0;
  // N(q_n) is built once (in link 2's frame) for k1 and the feed-forward; cond(N(q_n)), the
  // reported one, comes from solve()'s closed-form eigenvalues; the operator of k1's solve (N's
  // inverse, or its damped pseudo-inverse at the singularity) is reused for both
  Vec3 cos_n, sin_n;
  cos_sin(angles_, cos_n, sin_n);
  const WristFrame2 at(inertia_, cos_n, sin_n, diagonal_inertia_);
  Mat3 N2_inv = Mat3::Constant(std::numeric_limits<double>::quiet_NaN());  // set by solve()
  Status st = solve(at.N2, at.to_frame2(target_ - D_now), k1, cond, &N2_inv);
  st |= limit_rate(k1);
  // feed-forward acceleration: N qdd = -Ddot - bias(q, qdot)  <=>  N2 qdd = R2^T(-Ddot) - bias2
  Vec3 qdd;
  const Vec3 rhs = at.to_frame2(-D_dot) - at.bias_frame2(k1);
  if (N2_inv.allFinite())
    qdd = N2_inv * rhs;  // same operator, same status as solving again
  else
    st |= solve(at.N2, rhs, qdd, unused);
  Vec3 next;
  if (D_half != nullptr && D_next != nullptr) {
    Vec3 k2, k3, k4;
    st |= stage_rates(0.5 * dt_ * k1, cos_n, sin_n, *D_half, k2);
    st |= stage_rates(0.5 * dt_ * k2, cos_n, sin_n, *D_half, k3);
    st |= stage_rates(dt_ * k3, cos_n, sin_n, *D_next, k4);
    next = angles_ + dt_ / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  } else {
    next = angles_ + dt_ * k1;  // eq 26
  }
  // finite, in-range input cannot overflow here (the rates are clipped), but the tick must never
  // emit a non-finite command or leave the angle range whatever happens
  if (!next.allFinite() || !k1.allFinite() || !qdd.allFinite() ||
      next.cwiseAbs().maxCoeff() > max_angle)
    return hold(Status::out_of_range);
  if (has(st, Status::saturated)) {
    qdd.setZero();  // the unsaturated formula no longer describes the commanded motion
  } else {
    const double peak = qdd.cwiseAbs().maxCoeff();
    if (peak > config_.max_acceleration) {
      qdd *= config_.max_acceleration / peak;  // direction kept
      st |= Status::saturated;
    }
  }
  command_.angles = angles_;
  command_.cos_angles = cos_n;
  command_.sin_angles = sin_n;
  command_.rates = k1;
  command_.accelerations = qdd;
  command_.next_angles = next;
  command_.condition_number = cond;
  command_.status = st;
  angles_ = next;
  return st;
}

}  // namespace mechbal
