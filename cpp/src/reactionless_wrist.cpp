#include "mechbal/reactionless_wrist.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

namespace {

Mat3 rot_x(double a) noexcept {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 R;
  R << 1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c;
  return R;
}

Mat3 rot_z(double a) noexcept {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 R;
  R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  return R;
}

/// The wrist at one set of angles: base-frame link inertias I_k = R_k J_k R_k^T and the axes
/// x1 = R1 e_x, z2 = R2 e_z; N and the bias term are both built from them (once per tick).
struct WristAt {
  WristAt(const WristInertias& J, const Vec3& q) noexcept {
    const Mat3 R1 = rot_z(q(0));
    const Mat3 R2 = R1 * rot_x(q(1));
    const Mat3 R3 = R2 * rot_z(q(2));
    I[0] = R1 * J[0] * R1.transpose();
    I[1] = R2 * J[1] * R2.transpose();
    I[2] = R3 * J[2] * R3.transpose();
    x1 = R1.col(0);
    z2 = R2.col(2);
  }
  /// eq 23 (corrected): N = [(I1+I2+I3) e_z | (I2+I3) x1 | I3 z2]
  Mat3 momentum_matrix() const noexcept {
    Mat3 N;
    N.col(0) = (I[0] + I[1] + I[2]).col(2);
    N.col(1) = (I[1] + I[2]) * x1;
    N.col(2) = I[2] * z2;
    return N;
  }
  /// sum_k [I_k wdot_k|_{qddot=0} + w_k x I_k w_k]
  Vec3 bias(const Vec3& qd) const noexcept {
    const Vec3 w1 = qd(0) * Vec3::UnitZ();
    const Vec3 w2 = w1 + qd(1) * x1;
    const Vec3 w3 = w2 + qd(2) * z2;
    const Vec3 a2 = qd(1) * w1.cross(x1);
    const Vec3 a3 = a2 + qd(2) * w2.cross(z2);
    const Vec3 Iw1 = I[0] * w1, Iw2 = I[1] * w2, Iw3 = I[2] * w3;
    return w1.cross(Iw1) + I[1] * a2 + w2.cross(Iw2) + I[2] * a3 + w3.cross(Iw3);
  }
  std::array<Mat3, 3> I;
  Vec3 x1, z2;
};

[[noreturn]] void fail(const char* field, const std::string& what, double value) {
  std::ostringstream msg;
  msg << field << " " << what << ", got " << value;
  throw std::invalid_argument(msg.str());
}

}  // namespace

void wrist_link_motion(const Vec3& q, const Vec3& qd, const Vec3& qdd,
                       WristLinkMotion& out) noexcept {
  const Mat3 R1 = rot_z(q(0));
  const Mat3 R2 = R1 * rot_x(q(1));
  const Mat3 R3 = R2 * rot_z(q(2));
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
  return WristAt(J, q).momentum_matrix();
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
  if (!std::isfinite(c.rate_hz) || c.rate_hz <= 0.0) fail("rate_hz", "must be finite and > 0", c.rate_hz);
  if (std::isnan(c.max_rate) || c.max_rate <= 0.0) fail("max_rate", "must be > 0 (may be inf)", c.max_rate);
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
  if (!initial_angles.allFinite()) fail("initial_angles", "must be finite", initial_angles.sum());
  if (!target_momentum.allFinite()) fail("target_momentum", "must be finite", target_momentum.sum());
  dt_ = 1.0 / config.rate_hz;
  angles_ = initial_angles;
  target_ = target_momentum;
  command_.angles = command_.next_angles = initial_angles;
  command_.condition_number = 1.0;
}

Status ReactionlessWrist::reset(const Vec3& angles, const Vec3& target_momentum) noexcept {
  if (!angles.allFinite() || !target_momentum.allFinite()) return Status::non_finite_input;
  angles_ = angles;
  target_ = target_momentum;
  command_ = WristCommand{};
  command_.angles = command_.next_angles = angles;
  return Status::ok;
}

Status ReactionlessWrist::solve(const Mat3& N, const Vec3& rhs, Vec3& x, double& condition,
                                Mat3* inverse) const noexcept {
  // Fast path (issue 6: a 3x3 JacobiSVD costs ~0.7 us, the whole tick budget): the singular values
  // of N are the square roots of the eigenvalues of N^T N, which Eigen gives in closed form; when
  // N is well conditioned the exact solve is the cofactor inverse. The eigenvalues of N^T N lose
  // about cond^2 eps relative accuracy (1e-8 at cond = 1e4), enough to decide well-conditioned
  // and to report cond(N); anything else (ill-conditioned, non-finite) takes the SVD below.
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(N.transpose() * N);
  const Vec3& lambda = eig.eigenvalues();  // ascending
  if (lambda(0) > 0.0 && std::isfinite(lambda(2))) {
    const double c = std::sqrt(lambda(2) / lambda(0));
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
  }
  Eigen::JacobiSVD<Mat3> svd(N, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 s = svd.singularValues();  // descending
  const double smax = s(0);
  if (!(smax > 0.0) || !std::isfinite(smax)) {
    x.setZero();
    condition = std::numeric_limits<double>::max();
    return Status::singular;
  }
  condition = s(2) > smax / std::numeric_limits<double>::max() ? smax / s(2)
                                                                 : std::numeric_limits<double>::max();
  const Vec3 b = svd.matrixU().transpose() * rhs;
  Vec3 y;
  Status st = Status::ok;
  if (condition > config_.max_condition) {
    // damped least squares: minimises |N x - rhs|^2 + lambda^2 |x|^2
    const double lambda = config_.damping * smax;
    for (int i = 0; i < 3; ++i) y(i) = s(i) * b(i) / (s(i) * s(i) + lambda * lambda);
    st = Status::singular;
  } else {
    for (int i = 0; i < 3; ++i) y(i) = b(i) / s(i);
  }
  x = svd.matrixV() * y;
  return st;
}

Status ReactionlessWrist::rates(const Vec3& q, const Vec3& D, Vec3& qd,
                                double& condition) const noexcept {
  return rates_with(wrist_momentum_matrix(inertia_, q), D, qd, condition);
}

Status ReactionlessWrist::rates_with(const Mat3& N, const Vec3& D, Vec3& qd, double& condition,
                                     Mat3* inverse) const noexcept {
  Status st = solve(N, target_ - D, qd, condition, inverse);
  const double peak = qd.cwiseAbs().maxCoeff();
  if (peak > config_.max_rate) {
    qd *= config_.max_rate / peak;  // keep the direction of the commanded rate vector
    st |= Status::saturated;
  }
  return st;
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
  const auto hold = [this](Status why) noexcept {
    command_.angles = command_.next_angles = angles_;
    command_.rates.setZero();
    command_.accelerations.setZero();
    command_.status = why;
    return why;
  };
  if (!finite) return hold(Status::non_finite_input);

  Vec3 k1;
  double cond = 1.0, unused = 1.0;
  // N(q_n) and the link inertias are built once for k1 and the feed-forward; when N is well
  // conditioned its inverse is reused for both (issue 6: the tick recomputed them)
  const WristAt at(inertia_, angles_);
  const Mat3 N = at.momentum_matrix();
  Mat3 N_inv = Mat3::Constant(std::numeric_limits<double>::quiet_NaN());  // set by the fast path
  Status st = rates_with(N, D_now, k1, cond, &N_inv);
  // feed-forward acceleration: N qdd = -Ddot - bias(q, qdot)
  Vec3 qdd;
  const Vec3 rhs = -D_dot - at.bias(k1);
  if (N_inv.allFinite())
    qdd = N_inv * rhs;  // well conditioned: the fast path's inverse
  else
    st |= solve(N, rhs, qdd, unused);
  Vec3 next;
  if (D_half != nullptr && D_next != nullptr) {
    Vec3 k2, k3, k4;
    st |= rates(angles_ + 0.5 * dt_ * k1, *D_half, k2, unused);
    st |= rates(angles_ + 0.5 * dt_ * k2, *D_half, k3, unused);
    st |= rates(angles_ + dt_ * k3, *D_next, k4, unused);
    next = angles_ + dt_ / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  } else {
    next = angles_ + dt_ * k1;  // eq 26
  }
  if (!next.allFinite() || !k1.allFinite() || !qdd.allFinite()) return hold(Status::non_finite_input);
  command_.angles = angles_;
  command_.rates = k1;
  command_.accelerations = has(st, Status::saturated) ? Vec3::Zero() : qdd;
  command_.next_angles = next;
  command_.condition_number = cond;
  command_.status = st;
  angles_ = next;
  return st;
}

}  // namespace mechbal
