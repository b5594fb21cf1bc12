#include "mechbal/reactionless_wrist.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
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
  const Mat3 R1 = rot_z(q(0));
  const Mat3 R2 = R1 * rot_x(q(1));
  const Mat3 R3 = R2 * rot_z(q(2));
  const Mat3 I1 = R1 * J[0] * R1.transpose();
  const Mat3 I2 = R2 * J[1] * R2.transpose();
  const Mat3 I3 = R3 * J[2] * R3.transpose();
  Mat3 N;
  N.col(0) = (I1 + I2 + I3) * Vec3::UnitZ();
  N.col(1) = (I2 + I3) * R1.col(0);
  N.col(2) = I3 * R2.col(2);
  return N;
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

Status ReactionlessWrist::solve(const Mat3& N, const Vec3& rhs, Vec3& x,
                                double& condition) const noexcept {
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
  Status st = solve(wrist_momentum_matrix(inertia_, q), target_ - D, qd, condition);
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
  Status st = rates(angles_, D_now, k1, cond);
  // feed-forward acceleration: N qdd = -Ddot - bias(q, qdot)
  Vec3 qdd;
  st |= solve(wrist_momentum_matrix(inertia_, angles_),
              -D_dot - wrist_momentum_bias(inertia_, angles_, k1), qdd, unused);
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
