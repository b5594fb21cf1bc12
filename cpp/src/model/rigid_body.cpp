#include "mechbal/model/rigid_body.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mechbal {

void validate_rigid_body(const RigidBody& body, const char* field) {
  std::ostringstream msg;
  if (!std::isfinite(body.mass) || body.mass < 0.0) {
    msg << field << ".mass must be a finite number >= 0, got " << body.mass;
    throw std::invalid_argument(msg.str());
  }
  const Mat3& I = body.inertia_body;
  if (!I.allFinite()) {
    msg << field << ".inertia must be finite, got [" << I.format(Eigen::IOFormat(6, 0, ", ", "; "))
        << "]";
    throw std::invalid_argument(msg.str());
  }
  const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) {
    msg << field << ".inertia must be symmetric, got ["
        << I.format(Eigen::IOFormat(6, 0, ", ", "; ")) << "]";
    throw std::invalid_argument(msg.str());
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig(I, Eigen::EigenvaluesOnly);
  const Vec3 p = eig.eigenvalues();  // ascending
  const double tol = 1e-12 * scale;
  if (p(0) < -tol) {
    msg << field << ".inertia must be positive semi-definite, smallest principal moment is "
        << p(0);
    throw std::invalid_argument(msg.str());
  }
  if (p(2) > p(0) + p(1) + tol) {
    msg << field << ".inertia violates the triangle inequality of a physical body: principal "
        << "moments " << p(0) << ", " << p(1) << ", " << p(2);
    throw std::invalid_argument(msg.str());
  }
}

namespace {

inline bool finite_state(const BodyState& s) noexcept {
  return s.com.allFinite() && s.com_velocity.allFinite() && s.com_acceleration.allFinite() &&
         s.rotation.allFinite() && s.angular_velocity.allFinite() &&
         s.angular_acceleration.allFinite();
}

inline bool finite_wrench(const ShakingWrench& w) noexcept {
  return w.linear_momentum.allFinite() && w.angular_momentum.allFinite() && w.force.allFinite() &&
         w.moment.allFinite();
}

// Contribution of one body to P, H_O, dP/dt, dH_O/dt.
inline void accumulate(const RigidBody& b, const Vec3& c, const Vec3& v, const Vec3& a,
                       const Mat3& R, const Vec3& w, const Vec3& alpha, ShakingWrench& out) noexcept {
  out.linear_momentum.noalias() += b.mass * v;
  out.angular_momentum.noalias() += b.mass * c.cross(v);
  out.force.noalias() += b.mass * a;
  // d/dt(m c x v) = m c x a ; d/dt(I w) = I alpha + w x (I w)
  out.moment.noalias() += b.mass * c.cross(a);
  if (b.inertia_body.isZero(0.0)) return;  // point mass (exactly): no rotational terms
  // I = R J R^T applied as R (J (R^T x)): six matrix-vector products instead of forming I
  const Vec3 Iw = R * (b.inertia_body * (R.transpose() * w));
  const Vec3 Ialpha = R * (b.inertia_body * (R.transpose() * alpha));
  out.angular_momentum.noalias() += Iw;
  out.moment.noalias() += Ialpha + w.cross(Iw);
}

}  // namespace

Status shaking_wrench(const RigidBody* bodies, const BodyState* states, std::size_t count,
                      ShakingWrench& out) noexcept {
  out = ShakingWrench{};
  for (std::size_t j = 0; j < count; ++j) {
    if (!finite_state(states[j])) {
      out = ShakingWrench{};
      return Status::non_finite_input;
    }
    const BodyState& s = states[j];
    accumulate(bodies[j], s.com, s.com_velocity, s.com_acceleration, s.rotation,
               s.angular_velocity, s.angular_acceleration, out);
  }
  if (!finite_wrench(out)) {  // finite input that overflowed
    out = ShakingWrench{};
    return Status::out_of_range;
  }
  return Status::ok;
}

Status base_reaction(const RigidBody* bodies, const BodyState* states, std::size_t count,
                     const Vec3& gravity, const ShakingWrench& inertial,
                     BaseReaction& out) noexcept {
  Vec3 weight_force = Vec3::Zero();
  Vec3 weight_moment = Vec3::Zero();
  for (std::size_t j = 0; j < count; ++j) {
    const Vec3 w = bodies[j].mass * gravity;
    weight_force += w;
    weight_moment += states[j].com.cross(w);
  }
  out.force = inertial.force - weight_force;
  out.moment = inertial.moment - weight_moment;
  if (!gravity.allFinite() || !finite_wrench(inertial)) {
    out = BaseReaction{};
    return Status::non_finite_input;
  }
  if (!out.force.allFinite() || !out.moment.allFinite()) {
    out = BaseReaction{};
    return Status::out_of_range;
  }
  return Status::ok;
}

Status shaking_wrench_batch(const RigidBody* bodies, const BodyTrajectoryView& m, double* force,
                            double* moment, double* linear_momentum,
                            double* angular_momentum, std::uint32_t* status_per_instant) noexcept {
  using CVec3 = Eigen::Map<const Vec3>;
  // rotation is stored row-major (numpy C order): map as the transpose of a column-major 3x3.
  using CMat3Row = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;
  Status status = Status::ok;
  for (std::size_t k = 0; k < m.instants; ++k) {
    ShakingWrench out;
    bool finite = true;
    for (std::size_t j = 0; j < m.count; ++j) {
      const std::size_t v3 = (k * m.count + j) * 3;
      const std::size_t m9 = (k * m.count + j) * 9;
      const CVec3 c(m.com + v3), v(m.com_velocity + v3), a(m.com_acceleration + v3);
      const CVec3 w(m.angular_velocity + v3), al(m.angular_acceleration + v3);
      const Mat3 R = CMat3Row(m.rotation + m9);
      if (!(c.allFinite() && v.allFinite() && a.allFinite() && w.allFinite() && al.allFinite() &&
            R.allFinite())) {
        finite = false;
        break;
      }
      accumulate(bodies[j], c, v, a, R, w, al, out);
    }
    Status s = Status::ok;
    if (!finite) {
      s = Status::non_finite_input;
    } else if (!finite_wrench(out)) {
      s = Status::out_of_range;  // finite input that overflowed
    }
    if (s != Status::ok) out = ShakingWrench{};
    status |= s;
    if (status_per_instant) status_per_instant[k] = static_cast<std::uint32_t>(s);
    if (force) Eigen::Map<Vec3>(force + 3 * k) = out.force;
    if (moment) Eigen::Map<Vec3>(moment + 3 * k) = out.moment;
    if (linear_momentum) Eigen::Map<Vec3>(linear_momentum + 3 * k) = out.linear_momentum;
    if (angular_momentum) Eigen::Map<Vec3>(angular_momentum + 3 * k) = out.angular_momentum;
  }
  return status;
}

}  // namespace mechbal
