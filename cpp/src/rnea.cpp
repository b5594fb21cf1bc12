#include "mechbal/rnea.hpp"

#include <cmath>

namespace mechbal {

namespace {

/// A rotation A with A e_z = axis (axis unit): the joint-aligned frame of a link.
Mat3 aligned_with_z(const Vec3& axis) {
  // Seed the x axis with the basis vector least aligned with `axis`.
  Vec3 seed = Vec3::UnitX();
  if (std::abs(axis.y()) < std::abs(axis(0)) && std::abs(axis.y()) <= std::abs(axis.z())) {
    seed = Vec3::UnitY();
  } else if (std::abs(axis.z()) < std::abs(axis(0))) {
    seed = Vec3::UnitZ();
  }
  const Vec3 x = (seed - seed.dot(axis) * axis).normalized();
  Mat3 A;
  A.col(0) = x;
  A.col(1) = axis.cross(x);
  A.col(2) = axis;
  return A;
}

/// Status::ok when `out` is finite, else zeroes it and returns Status::out_of_range (finite input
/// that overflowed: never report ok with a non-finite output).
template <typename Derived>
inline Status finite_or_zero(Eigen::MatrixBase<Derived>&& out) noexcept {
  if (out.allFinite()) return Status::ok;
  out.setZero();
  return Status::out_of_range;
}
template <typename Derived>
inline Status finite_or_zero(Eigen::MatrixBase<Derived>& out) noexcept {
  if (out.allFinite()) return Status::ok;
  out.setZero();
  return Status::out_of_range;
}

/// w x e_z and h x e_z without the multiplications by zero.
inline Vec3 cross_ez(const Vec3& w) { return Vec3(w.y(), -w.x(), 0.0); }

}  // namespace

RneChainDynamics::RneChainDynamics(const ChainModel& model)
    : dof_(model.dof()),
      gravity_(model.gravity()),
      links_(static_cast<std::size_t>(model.dof())),
      states_(static_cast<std::size_t>(model.dof())),
      composite_h_(static_cast<std::size_t>(model.dof()), Vec3::Zero()),
      composite_I_(static_cast<std::size_t>(model.dof()), Mat3::Zero()),
      composite_m_(static_cast<std::size_t>(model.dof()), 0.0) {
  Mat3 A_parent = Mat3::Identity();  // the world frame for joint 1 (base folded into its origin)
  for (int i = 0; i < dof_; ++i) {
    const JointSpec& j = model.joints()[static_cast<std::size_t>(i)];
    const Eigen::Isometry3d origin = i == 0 ? model.base() * j.origin : j.origin;
    const Mat3 A = aligned_with_z(j.axis);
    Link& l = links_[static_cast<std::size_t>(i)];
    l.rotation = A_parent.transpose() * origin.linear() * A;
    l.translation = A_parent.transpose() * origin.translation();
    l.revolute = j.type == JointType::revolute;
    l.mass = j.link.mass;
    const Vec3 c = A.transpose() * j.com;
    const Mat3 I_com = A.transpose() * j.link.inertia_body * A;
    l.first_moment = l.mass * c;
    // parallel axis theorem: inertia about the link frame origin
    l.inertia_origin = I_com + l.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
    A_parent = A;
    State& s = states_[static_cast<std::size_t>(i)];
    s.rotation = l.rotation;
    s.translation = l.translation;
    s.w = s.alpha = s.acc = s.force = s.moment = Vec3::Zero();
  }
}

void RneChainDynamics::place(const Eigen::Ref<const Eigen::VectorXd>& q) noexcept {
  for (int i = 0; i < dof_; ++i) {
    const Link& l = links_[static_cast<std::size_t>(i)];
    State& s = states_[static_cast<std::size_t>(i)];
    if (l.revolute) {
      // C_R Rz(q): only the first two columns change
      const double c = std::cos(q(i)), sn = std::sin(q(i));
      s.rotation.col(0) = c * l.rotation.col(0) + sn * l.rotation.col(1);
      s.rotation.col(1) = c * l.rotation.col(1) - sn * l.rotation.col(0);
      s.rotation.col(2) = l.rotation.col(2);
      s.translation = l.translation;
    } else {
      s.rotation = l.rotation;
      s.translation = l.translation + l.rotation.col(2) * q(i);
    }
  }
}

template <bool Velocity, bool Acceleration, bool Gravity>
void RneChainDynamics::rne(const Eigen::Ref<const Eigen::VectorXd>& qd,
                           const Eigen::Ref<const Eigen::VectorXd>& qdd,
                           Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  // Forward pass: motion of every link in its own frame. Gravity enters as an upward
  // acceleration of the (fixed) base, so F = m a below already contains the weight.
  Vec3 w_p = Vec3::Zero(), alpha_p = Vec3::Zero();
  Vec3 acc_p = Gravity ? Vec3(-gravity_) : Vec3::Zero();
  for (int i = 0; i < dof_; ++i) {
    const Link& l = links_[static_cast<std::size_t>(i)];
    State& s = states_[static_cast<std::size_t>(i)];
    const Vec3& p = s.translation;
    Vec3 a_lin = acc_p;
    if (Acceleration || Velocity) a_lin += alpha_p.cross(p);
    if (Velocity) a_lin += w_p.cross(w_p.cross(p));
    Vec3 w = Velocity ? Vec3(s.rotation.transpose() * w_p) : Vec3::Zero();
    Vec3 alpha = Acceleration || Velocity ? Vec3(s.rotation.transpose() * alpha_p) : Vec3::Zero();
    Vec3 acc = s.rotation.transpose() * a_lin;
    const double v = Velocity ? qd(i) : 0.0;
    const double a = Acceleration ? qdd(i) : 0.0;
    if (l.revolute) {
      if (Velocity) {
        alpha += cross_ez(w) * v;
        w.z() += v;
      }
      if (Acceleration) alpha.z() += a;
    } else {
      if (Velocity) acc += cross_ez(w) * (2.0 * v);
      if (Acceleration) acc.z() += a;
    }
    // Newton-Euler about the link frame origin: f = m a_G, n_O = I_O alpha + w x I_O w + h x a_O
    const Vec3& h = l.first_moment;
    s.force = l.mass * acc + alpha.cross(h);
    s.moment = l.inertia_origin * alpha + h.cross(acc);
    if (Velocity) {
      s.force += w.cross(w.cross(h));
      s.moment += w.cross(l.inertia_origin * w);
    }
    s.w = w;
    s.alpha = alpha;
    s.acc = acc;
    w_p = w;
    alpha_p = alpha;
    acc_p = acc;
  }
  // Backward pass: wrench transmitted by each joint, and its component along the joint axis.
  for (int i = dof_ - 1; i >= 0; --i) {
    State& s = states_[static_cast<std::size_t>(i)];
    if (i + 1 < dof_) {
      const State& c = states_[static_cast<std::size_t>(i + 1)];
      const Vec3 f = c.rotation * c.force;
      s.force += f;
      s.moment += c.rotation * c.moment + c.translation.cross(f);
    }
    tau(i) = links_[static_cast<std::size_t>(i)].revolute ? s.moment.z() : s.force.z();
  }
}

Status RneChainDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                          Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                                          Vec3* support_moment) noexcept {
  if (q.size() != dof_ || qd.size() != dof_ || qdd.size() != dof_ || tau.size() != dof_) {
    return Status::bad_size;
  }
  if (!q.allFinite() || !qd.allFinite() || !qdd.allFinite()) return Status::non_finite_input;
  place(q);
  rne<true, true, true>(qd, qdd, tau);
  // link 1's frame is placed directly in the world frame
  const State& s = states_[0];
  const Vec3 F = s.rotation * s.force;
  const Vec3 Mo = s.rotation * s.moment + s.translation.cross(F);
  if (!tau.allFinite() || !F.allFinite() || !Mo.allFinite()) {
    tau.setZero();  // finite input that overflowed
    return Status::out_of_range;
  }
  if (support_force) *support_force = F;
  if (support_moment) *support_moment = Mo;
  return Status::ok;
}

Status RneChainDynamics::gravity(const Eigen::Ref<const Eigen::VectorXd>& q,
                                 Eigen::Ref<Eigen::VectorXd> g) noexcept {
  if (q.size() != dof_ || g.size() != dof_) return Status::bad_size;
  if (!q.allFinite()) return Status::non_finite_input;
  place(q);
  rne<false, false, true>(q, q, g);
  return finite_or_zero(g);
}

Status RneChainDynamics::bias(const Eigen::Ref<const Eigen::VectorXd>& q,
                              const Eigen::Ref<const Eigen::VectorXd>& qd,
                              Eigen::Ref<Eigen::VectorXd> b) noexcept {
  if (q.size() != dof_ || qd.size() != dof_ || b.size() != dof_) return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite()) return Status::non_finite_input;
  place(q);
  rne<true, false, true>(qd, qd, b);
  return finite_or_zero(b);
}

Status RneChainDynamics::coriolis(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                                  Eigen::Ref<Eigen::VectorXd> c) noexcept {
  if (q.size() != dof_ || qd.size() != dof_ || c.size() != dof_) return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite()) return Status::non_finite_input;
  place(q);
  rne<true, false, false>(qd, qd, c);
  return finite_or_zero(c);
}

Status RneChainDynamics::mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q,
                                     Eigen::Ref<Eigen::MatrixXd> M) noexcept {
  if (q.size() != dof_ || M.rows() != dof_ || M.cols() != dof_) return Status::bad_size;
  if (!q.allFinite()) return Status::non_finite_input;
  place(q);
  // Composite inertias, tip to base, each about its own link origin in its own frame:
  // I_O' = R I R^T + m ((p.p) 1 - p p^T) + 2 (p.h) 1 - h p^T - p h^T with h = R h_child.
  for (int i = dof_ - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    const Link& l = links_[k];
    composite_m_[k] = l.mass;
    composite_h_[k] = l.first_moment;
    composite_I_[k] = l.inertia_origin;
    if (i + 1 < dof_) {
      const State& c = states_[k + 1];
      const double m = composite_m_[k + 1];
      const Vec3& p = c.translation;
      const Vec3 h = c.rotation * composite_h_[k + 1];
      Mat3 I = c.rotation * composite_I_[k + 1] * c.rotation.transpose();
      const Mat3 hp = h * p.transpose();
      I += (m * p.squaredNorm() + 2.0 * p.dot(h)) * Mat3::Identity() - m * p * p.transpose() - hp -
           hp.transpose();
      composite_m_[k] += m;
      composite_h_[k] += h + m * p;
      composite_I_[k] += I;
    }
  }
  // Column i: momentum of composite i under a unit rate of joint i, carried to every ancestor.
  for (int i = 0; i < dof_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    Vec3 L, P;  // angular momentum about the link origin, linear momentum
    if (links_[k].revolute) {
      L = composite_I_[k].col(2);
      P = -cross_ez(composite_h_[k]);
      M(i, i) = L.z();
    } else {
      L = cross_ez(composite_h_[k]);
      P = Vec3(0.0, 0.0, composite_m_[k]);
      M(i, i) = P.z();
    }
    for (int j = i - 1; j >= 0; --j) {
      const State& c = states_[static_cast<std::size_t>(j + 1)];
      P = c.rotation * P;
      L = c.rotation * L + c.translation.cross(P);
      M(j, i) = M(i, j) = links_[static_cast<std::size_t>(j)].revolute ? L.z() : P.z();
    }
  }
  return finite_or_zero(M);
}

}  // namespace mechbal
