#include "mechbal/papers/arm2dof/arm2dof.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace mechbal {

namespace {

[[noreturn]] void fail(const char* field, const char* what, double value) {
  std::ostringstream msg;
  msg << field << " " << what << " (got " << value << ")";
  throw std::invalid_argument(msg.str());
}

void finite(const char* field, double v) {
  if (!std::isfinite(v)) fail(field, "must be finite", v);
}
void non_negative(const char* field, double v) {
  finite(field, v);
  if (v < 0.0) fail(field, "must be >= 0", v);
}
void positive(const char* field, double v) {
  finite(field, v);
  if (v <= 0.0) fail(field, "must be > 0", v);
}

void validate_lumped(const Arm2DofLumped& p) {
  positive("arm.j1", p.j1);
  finite("arm.s1", p.s1);
  non_negative("arm.M2", p.M2);
  finite("arm.s2", p.s2);
  positive("arm.j2", p.j2);
  positive("arm.l1", p.l1);
  non_negative("arm.g", p.g);
  // det A(q) = j2 (j1 + M2 l1^2) - (l1 s2 cos q2)^2 must stay > 0 for every q2.
  const double margin = p.j2 * (p.j1 + p.M2 * p.l1 * p.l1) - (p.l1 * p.s2) * (p.l1 * p.s2);
  if (!(margin > 0.0))
    fail("arm (lumped parameters)", "give a mass matrix that is not positive definite: "
         "j2 (j1 + M2 l1^2) - (l1 s2)^2", margin);
}

bool all_finite2(const Eigen::Ref<const Eigen::VectorXd>& v) noexcept { return v.allFinite(); }

}  // namespace

Arm2DofLumped arm2dof_lumped(const Arm2DofParameters& arm, const Arm2DofCounterweights& cw) {
  positive("arm.m1", arm.m1);
  positive("arm.m2", arm.m2);
  positive("arm.l1", arm.l1);
  finite("arm.l_s1", arm.l_s1);
  finite("arm.l_s2", arm.l_s2);
  non_negative("arm.i_s1", arm.i_s1);
  non_negative("arm.i_s2", arm.i_s2);
  non_negative("arm.g", arm.g);
  non_negative("counterweights.m_cw1", cw.m_cw1);
  non_negative("counterweights.m_cw2", cw.m_cw2);
  finite("counterweights.r_cw1", cw.r_cw1);
  finite("counterweights.r_cw2", cw.r_cw2);
  Arm2DofLumped p;
  // Bare arm (eqs 16-22): j1 = I_A = I_S1 + m1 l_S1^2, s1 = m1 l_S1, M2 = m2, s2 = m2 l_S2,
  // j2 = I_S2 + m2 l_S2^2. Counterweights (eqs 25-31) at -r on their links add linearly.
  p.j1 = arm.i_s1 + arm.m1 * arm.l_s1 * arm.l_s1 + cw.m_cw1 * cw.r_cw1 * cw.r_cw1;
  p.s1 = arm.m1 * arm.l_s1 - cw.m_cw1 * cw.r_cw1;
  p.M2 = arm.m2 + cw.m_cw2;
  p.s2 = arm.m2 * arm.l_s2 - cw.m_cw2 * cw.r_cw2;
  p.j2 = arm.i_s2 + arm.m2 * arm.l_s2 * arm.l_s2 + cw.m_cw2 * cw.r_cw2 * cw.r_cw2;
  p.l1 = arm.l1;
  p.g = arm.g;
  validate_lumped(p);
  return p;
}

namespace {

// A link and an optional point mass on its local x axis, merged into one rigid body.
JointSpec planar_link(const char* name, const Eigen::Isometry3d& origin, double mass, double l_com,
                      double inertia_com, double m_cw, double r_cw) {
  JointSpec j;
  j.name = name;
  j.type = JointType::revolute;
  j.origin = origin;
  j.axis = Vec3(0.0, -1.0, 0.0);  // positive rotation lifts +x towards +z
  const double M = mass + m_cw;
  const double x = (mass * l_com - m_cw * r_cw) / M;
  // slender-rod tensor diag(0, I, I) about the link's own centre of mass, then parallel axes
  const double d_link = l_com - x, d_cw = -r_cw - x;
  const double I = inertia_com + mass * d_link * d_link + m_cw * d_cw * d_cw;
  j.link.mass = M;
  j.link.inertia_body = Vec3(0.0, I, I).asDiagonal();
  j.com = Vec3(x, 0.0, 0.0);
  return j;
}

}  // namespace

ChainModel arm2dof_chain_model(const Arm2DofParameters& arm, const Arm2DofCounterweights& cw) {
  arm2dof_lumped(arm, cw);  // validates
  Eigen::Isometry3d elbow = Eigen::Isometry3d::Identity();
  elbow.translation() = Vec3(arm.l1, 0.0, 0.0);
  std::vector<JointSpec> joints;
  joints.push_back(planar_link("shoulder", Eigen::Isometry3d::Identity(), arm.m1, arm.l_s1,
                               arm.i_s1, cw.m_cw1, cw.r_cw1));
  joints.push_back(planar_link("elbow", elbow, arm.m2, arm.l_s2, arm.i_s2, cw.m_cw2, cw.r_cw2));
  return ChainModel(std::move(joints), Vec3(0.0, 0.0, -arm.g));
}

Arm2DofDynamics::Arm2DofDynamics(const Arm2DofParameters& arm, const Arm2DofCounterweights& cw)
    : p_(arm2dof_lumped(arm, cw)) {}

Arm2DofDynamics::Arm2DofDynamics(const Arm2DofLumped& lumped) : p_(lumped) {
  validate_lumped(p_);
}

Mat2 Arm2DofDynamics::mass_matrix(const Vec2& q) const noexcept {
  // eqs 14-19 (corrected): k11 + k12 cos q2, k31 + k32 cos q2, 2 k2
  const double k = p_.l1 * p_.s2 * std::cos(q(1));
  Mat2 A;
  A(0, 0) = p_.j1 + p_.j2 + p_.M2 * p_.l1 * p_.l1 + 2.0 * k;
  A(0, 1) = A(1, 0) = p_.j2 + k;
  A(1, 1) = p_.j2;
  return A;
}

Mat2 Arm2DofDynamics::coriolis_matrix(const Vec2& q, const Vec2& qd) const noexcept {
  // Christoffel form; C qd = [-h (2 qd1 qd2 + qd2^2), h qd1^2] with h = l1 s2 sin q2
  // (eq 14 prints -k32 qd2^2 without its sin q2).
  const double h = p_.l1 * p_.s2 * std::sin(q(1));
  Mat2 C;
  C << -h * qd(1), -h * (qd(0) + qd(1)), h * qd(0), 0.0;
  return C;
}

Vec2 Arm2DofDynamics::gravity(const Vec2& q) const noexcept {
  // eqs 21-22: p1 cos q1 + p2 cos(q1 + q2), p2 cos(q1 + q2), p1 = g (s1 + M2 l1), p2 = g s2
  const double c12 = std::cos(q(0) + q(1));
  return Vec2(p_.g * (p_.s1 + p_.M2 * p_.l1) * std::cos(q(0)) + p_.g * p_.s2 * c12,
              p_.g * p_.s2 * c12);
}

Vec2 Arm2DofDynamics::torque(const Vec2& q, const Vec2& qd, const Vec2& qdd) const noexcept {
  return mass_matrix(q) * qdd + coriolis_matrix(q, qd) * qd + gravity(q);
}

Vec2 Arm2DofDynamics::acceleration(const Vec2& q, const Vec2& qd, const Vec2& tau) const noexcept {
  const Mat2 A = mass_matrix(q);
  const Vec2 rhs = tau - coriolis_matrix(q, qd) * qd - gravity(q);
  const double det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  return Vec2(A(1, 1) * rhs(0) - A(0, 1) * rhs(1), -A(1, 0) * rhs(0) + A(0, 0) * rhs(1)) / det;
}

double Arm2DofDynamics::kinetic_energy(const Vec2& q, const Vec2& qd) const noexcept {
  return 0.5 * qd.dot(mass_matrix(q) * qd);
}

double Arm2DofDynamics::potential_energy(const Vec2& q) const noexcept {
  return p_.g * ((p_.s1 + p_.M2 * p_.l1) * std::sin(q(0)) + p_.s2 * std::sin(q(0) + q(1)));
}

Status Arm2DofDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                         const Eigen::Ref<const Eigen::VectorXd>& qd,
                                         const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                         Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  if (q.size() != 2 || qd.size() != 2 || qdd.size() != 2 || tau.size() != 2)
    return Status::bad_size;
  if (!all_finite2(q) || !all_finite2(qd) || !all_finite2(qdd)) return Status::non_finite_input;
  const Vec2 t = torque(Vec2(q(0), q(1)), Vec2(qd(0), qd(1)), Vec2(qdd(0), qdd(1)));
  if (!t.allFinite()) return Status::out_of_range;  // finite input that overflowed; tau untouched
  tau = t;
  return Status::ok;
}

Status Arm2DofDynamics::forward_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                         const Eigen::Ref<const Eigen::VectorXd>& qd,
                                         const Eigen::Ref<const Eigen::VectorXd>& tau,
                                         Eigen::Ref<Eigen::VectorXd> qdd) noexcept {
  if (q.size() != 2 || qd.size() != 2 || tau.size() != 2 || qdd.size() != 2)
    return Status::bad_size;
  if (!all_finite2(q) || !all_finite2(qd) || !all_finite2(tau)) return Status::non_finite_input;
  const Vec2 a = acceleration(Vec2(q(0), q(1)), Vec2(qd(0), qd(1)), Vec2(tau(0), tau(1)));
  if (!a.allFinite()) return Status::out_of_range;  // qdd untouched
  qdd = a;
  return Status::ok;
}

}  // namespace mechbal
