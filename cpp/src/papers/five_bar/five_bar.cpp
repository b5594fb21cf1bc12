#include "mechbal/papers/five_bar/five_bar.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mechbal {

namespace {

void check(double value, const char* field, bool positive) {
  const bool ok = std::isfinite(value) && (positive ? value > 0.0 : value >= 0.0);
  if (!ok) {
    std::ostringstream msg;
    msg << "five_bar." << field << " must be finite and " << (positive ? "> 0" : ">= 0")
        << " (got " << value << ")";
    throw std::invalid_argument(msg.str());
  }
}

inline Eigen::Vector2d e(double t) noexcept { return {std::cos(t), std::sin(t)}; }
inline Eigen::Vector2d n(double t) noexcept { return {-std::sin(t), std::cos(t)}; }

/// One leg's own model (a serial 2R arm in the vertical plane, the closed form of eqs 7/9 with
/// two links), its tip Jacobian (y, z) and tip bias acceleration (qdd = 0).
struct Leg {
  Eigen::Matrix2d mass, tip_jacobian;
  Eigen::Vector2d velocity, gravity, tip_bias;
};

void leg_model(double a, double b, double mp, double md, double cp, double cd, double Jp,
               double Jd, double g, double t1, double t2, double w1, double w2, Leg& leg) noexcept {
  const double c2 = std::cos(t2), s2 = std::sin(t2), t12 = t1 + t2;
  const double h = md * a * cd * s2;
  leg.mass(0, 0) = Jp + mp * cp * cp + Jd + md * (a * a + cd * cd + 2.0 * a * cd * c2);
  leg.mass(0, 1) = leg.mass(1, 0) = Jd + md * (cd * cd + a * cd * c2);
  leg.mass(1, 1) = Jd + md * cd * cd;
  leg.velocity = {-h * (2.0 * w1 * w2 + w2 * w2), h * w1 * w1};
  const double g12 = g * md * cd * std::cos(t12);
  leg.gravity = {g * (mp * cp + md * a) * std::cos(t1) + g12, g12};
  leg.tip_jacobian.col(0) = a * n(t1) + b * n(t12);
  leg.tip_jacobian.col(1) = b * n(t12);
  const double w12 = w1 + w2;
  leg.tip_bias = -a * w1 * w1 * e(t1) - b * w12 * w12 * e(t12);
}

}  // namespace

FiveBarDynamics::FiveBarDynamics(const FiveBarParameters& parameters, double singular_tolerance)
    : p_(parameters), tol_(singular_tolerance) {
  check(p_.a1, "a1", true);
  check(p_.a2, "a2", true);
  check(p_.b1, "b1", true);
  check(p_.b2, "b2", true);
  check(p_.d, "d", false);
  check(p_.mp1, "mp1", false);
  check(p_.mp2, "mp2", false);
  check(p_.md1, "md1", false);
  check(p_.md2, "md2", false);
  check(p_.mP, "mP", false);
  check(p_.Jp1, "Jp1", false);
  check(p_.Jp2, "Jp2", false);
  check(p_.Jd1, "Jd1", false);
  check(p_.Jd2, "Jd2", false);
  check(p_.gravity, "gravity", false);
  for (auto [v, name] : {std::pair{p_.cp1, "cp1"}, {p_.cp2, "cp2"}, {p_.cd1, "cd1"},
                         {p_.cd2, "cd2"}}) {
    if (!std::isfinite(v)) {
      std::ostringstream msg;
      msg << "five_bar." << name << " must be finite (got " << v << ")";
      throw std::invalid_argument(msg.str());
    }
  }
  if (!(tol_ > 0.0 && tol_ < 1.0)) {
    std::ostringstream msg;
    msg << "five_bar.singular_tolerance must be in (0, 1) (got " << tol_ << ")";
    throw std::invalid_argument(msg.str());
  }
}

Status FiveBarDynamics::compute(const Eigen::Vector2d& q, const Eigen::Vector2d& qd) noexcept {
  if (!q.allFinite() || !qd.allFinite()) return Status::non_finite_input;
  proj_.reciprocal_condition = 0.0;
  // ---- loop closure: passive angles (circle intersection) ----
  const Eigen::Vector2d A2(p_.d, 0.0);
  const Eigen::Vector2d B1 = p_.a1 * e(q(0)), B2 = A2 + p_.a2 * e(q(1));
  const Eigen::Vector2d D = B2 - B1;
  const double L = D.norm();
  if (!(L > 1e-12 * (p_.b1 + p_.b2))) return Status::singular;
  const double x = (p_.b1 * p_.b1 - p_.b2 * p_.b2 + L * L) / (2.0 * L);
  const double h2 = p_.b1 * p_.b1 - x * x;
  if (h2 < -1e-12 * p_.b1 * p_.b1) return Status::singular;  // cannot be assembled
  const double h = std::sqrt(h2 > 0.0 ? h2 : 0.0);
  const Eigen::Vector2d u = D / L, nrm(-u(1), u(0));
  const Eigen::Vector2d ref = B1 + (B2 - A2);
  const Eigen::Vector2d Pp = B1 + x * u + h * nrm, Pm = B1 + x * u - h * nrm;
  tip_ = (Pp - ref).norm() <= (Pm - ref).norm() ? Pp : Pm;
  const Eigen::Vector2d r1 = tip_ - B1, r2 = tip_ - B2;
  angles_ = {q(0), std::atan2(r1(1), r1(0)) - q(0), q(1), std::atan2(r2(1), r2(0)) - q(1)};

  // ---- constraints v_P - J_tip,i qd_leg,i = 0, p = (th1', th2', th12', th22', vPy, vPz) ----
  Leg l1, l2;
  leg_model(p_.a1, p_.b1, p_.mp1, p_.md1, p_.cp1, p_.cd1, p_.Jp1, p_.Jd1, p_.gravity, angles_(0),
            angles_(1), 0.0, 0.0, l1);
  leg_model(p_.a2, p_.b2, p_.mp2, p_.md2, p_.cp2, p_.cd2, p_.Jp2, p_.Jd2, p_.gravity, angles_(2),
            angles_(3), 0.0, 0.0, l2);
  proj_.a_independent.setZero();
  proj_.a_independent.block<2, 1>(0, 0) = -l1.tip_jacobian.col(0);
  proj_.a_independent.block<2, 1>(2, 1) = -l2.tip_jacobian.col(0);
  proj_.a_dependent.setZero();
  proj_.a_dependent.block<2, 1>(0, 0) = -l1.tip_jacobian.col(1);
  proj_.a_dependent.block<2, 1>(2, 1) = -l2.tip_jacobian.col(1);
  proj_.a_dependent.block<2, 2>(0, 2).setIdentity();
  proj_.a_dependent.block<2, 2>(2, 2).setIdentity();
  const Status s = proj_.factor(tol_);
  if (s != Status::ok) return s;

  // ---- subsystem models at the consistent rates ----
  const Projection::VecP p = proj_.rates(qd);
  rates_ = {p(0), p(2), p(1), p(3)};
  leg_model(p_.a1, p_.b1, p_.mp1, p_.md1, p_.cp1, p_.cd1, p_.Jp1, p_.Jd1, p_.gravity, angles_(0),
            angles_(1), p(0), p(2), l1);
  leg_model(p_.a2, p_.b2, p_.mp2, p_.md2, p_.cp2, p_.cd2, p_.Jp2, p_.Jd2, p_.gravity, angles_(2),
            angles_(3), p(1), p(3), l2);
  constexpr int i1[2] = {0, 2}, i2[2] = {1, 3};
  proj_.mass.setZero();
  proj_.velocity.setZero();
  proj_.gravity.setZero();
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) {
      proj_.mass(i1[r], i1[c]) = l1.mass(r, c);
      proj_.mass(i2[r], i2[c]) = l2.mass(r, c);
    }
    proj_.velocity(i1[r]) = l1.velocity(r);
    proj_.velocity(i2[r]) = l2.velocity(r);
    proj_.gravity(i1[r]) = l1.gravity(r);
    proj_.gravity(i2[r]) = l2.gravity(r);
  }
  proj_.mass.block<2, 2>(4, 4) = p_.mP * Eigen::Matrix2d::Identity();
  proj_.gravity(5) = p_.mP * p_.gravity;
  proj_.constraint_bias << -l1.tip_bias, -l2.tip_bias;
  proj_.project();
  if (!proj_.reduced_mass.allFinite() || !proj_.reduced_velocity.allFinite() ||
      !proj_.reduced_gravity.allFinite())
    return Status::out_of_range;  // A° passed the singularity test: finite input that overflowed
  return Status::ok;
}

Status FiveBarDynamics::evaluate(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                                 Eigen::Matrix2d& mass, Eigen::Vector2d& velocity_terms,
                                 Eigen::Vector2d& gravity_terms) noexcept {
  const Status s = compute(q, qd);
  if (s != Status::ok) return s;
  mass = proj_.reduced_mass;
  velocity_terms = proj_.reduced_velocity;
  gravity_terms = proj_.reduced_gravity;
  return Status::ok;
}

Status FiveBarDynamics::motion(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                               const Eigen::Vector2d& qdd, FiveBarMotion& out) noexcept {
  if (!qdd.allFinite()) return Status::non_finite_input;
  const Status s = compute(q, qd);
  if (s != Status::ok) return s;
  const Projection::VecP p = proj_.rates(qd);
  const Projection::VecP a = proj_.accelerations(qdd);
  if (!p.allFinite() || !a.allFinite()) return Status::out_of_range;  // out untouched
  out.angles = angles_;
  out.rates = rates_;
  out.accelerations = {a(0), a(2), a(1), a(3)};
  out.end_effector = tip_;
  out.end_effector_velocity = p.tail<2>();
  out.end_effector_acceleration = a.tail<2>();
  return Status::ok;
}

Status FiveBarDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                         const Eigen::Ref<const Eigen::VectorXd>& qd,
                                         const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                         Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  if (q.size() != 2 || qd.size() != 2 || qdd.size() != 2 || tau.size() != 2)
    return Status::bad_size;
  if (!qdd.allFinite()) return Status::non_finite_input;
  const Status s = compute(Eigen::Vector2d(q), Eigen::Vector2d(qd));
  if (s != Status::ok) return s;
  const Eigen::Vector2d t = proj_.reduced_mass * Eigen::Vector2d(qdd) + proj_.reduced_velocity +
                            proj_.reduced_gravity;
  if (!t.allFinite()) return Status::out_of_range;  // finite input that overflowed; tau untouched
  tau = t;
  return Status::ok;
}

}  // namespace mechbal
