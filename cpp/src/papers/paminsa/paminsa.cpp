#include "mechbal/papers/paminsa/paminsa.hpp"

#include <cmath>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace mechbal {

namespace {

using Vec2 = Eigen::Vector2d;
using Idx = PaminsaBodyIndex;

[[noreturn]] void fail(const std::string& field, const std::string& what, double value) {
  std::ostringstream msg;
  msg << field << " " << what << ", got " << value;
  throw std::invalid_argument(msg.str());
}

void require_positive(double v, const char* field) {
  if (!std::isfinite(v) || v <= 0.0) fail(field, "must be finite and > 0", v);
}
void require_finite(double v, const std::string& field) {
  if (!std::isfinite(v)) fail(field, "must be finite", v);
}
void require_mass(double v, const std::string& field) {
  if (!std::isfinite(v) || v < 0.0) fail(field, "must be finite and >= 0", v);
}


inline double cross2(const Vec2& a, const Vec2& b) noexcept { return a(0) * b(1) - a(1) * b(0); }

/// An angle by its cosine and sine (no atan2 in the tick: every use of an angle is through its
/// cosine and sine, which the vector gives directly), and its first and second derivative.
struct Angle3 {
  double c = 1.0, s = 0.0, d = 0.0, dd = 0.0;
};
struct Point2 {
  Vec2 p = Vec2::Zero(), v = Vec2::Zero(), a = Vec2::Zero();
};

/// Angle of a planar vector w(t): (cos beta, sin beta) = w/|w|; betad = (w x wd)/|w|^2;
/// betadd = (w x wdd)/|w|^2 - 2 betad (w . wd)/|w|^2.
Angle3 angle_of(const Vec2& w, const Vec2& wd, const Vec2& wdd) noexcept {
  const double r2 = w.squaredNorm();
  const double ir = 1.0 / std::sqrt(r2), ir2 = ir * ir;  // one division
  Angle3 out;
  out.c = w(0) * ir;
  out.s = w(1) * ir;
  out.d = cross2(w, wd) * ir2;
  out.dd = (cross2(w, wdd) - 2.0 * out.d * w.dot(wd)) * ir2;
  return out;
}

/// Leg plane frame: X = B_h + s u + z e_z with u = (cos beta, sin beta, 0), n = e_z x u.
struct Plane {
  Vec3 origin, u, n;
  Angle3 beta;
};

/// In-plane point (s, z) with rates relative to the turning plane -> base frame:
/// Xd = sd u + s bd n + zd e_z;  Xdd = (sdd - s bd^2) u + (2 sd bd + s bdd) n + zdd e_z.
/// (u, n, e_z components written out: u = (c, s, 0), n = (-s, c, 0))
inline void to_base(const Plane& pl, const Point2& pt, Vec3& X, Vec3& Xd, Vec3& Xdd) noexcept {
  const double bd = pl.beta.d, bdd = pl.beta.dd, c = pl.beta.c, sn = pl.beta.s;
  const double s = pt.p(0), z = pt.p(1), sd = pt.v(0), zd = pt.v(1), sdd = pt.a(0), zdd = pt.a(1);
  X = Vec3(pl.origin(0) + s * c, pl.origin(1) + s * sn, pl.origin(2) + z);
  const double vn = s * bd;
  Xd = Vec3(sd * c - vn * sn, sd * sn + vn * c, zd);
  const double au = sdd - s * bd * bd, an = 2.0 * sd * bd + s * bdd;
  Xdd = Vec3(au * c - an * sn, au * sn + an * c, zdd);
}

inline void point_body(const Plane& pl, const Point2& pt, BodyState& st) noexcept {
  to_base(pl, pt, st.com, st.com_velocity, st.com_acceleration);
  st.rotation.setIdentity();
  st.angular_velocity.setZero();
  st.angular_acceleration.setZero();
}

/// Pantograph link p1 -> p2 (COM at its middle), body X along the link, Y = plane normal n.
/// gamma = elevation of p1->p2 in the plane (g: its cos, sin and rates): R = [cos g u + sin g e_z,
/// n, X x n] with X x n = cos g e_z - sin g u, w = bd e_z - gd n, wd = bdd e_z - gdd n + gd bd u.
void pantograph_link(const Plane& pl, const Point2& p1, const Point2& p2, const Angle3& g,
                     BodyState& st) noexcept {
  Point2 mid;
  mid.p = 0.5 * (p1.p + p2.p);
  mid.v = 0.5 * (p1.v + p2.v);
  mid.a = 0.5 * (p1.a + p2.a);
  to_base(pl, mid, st.com, st.com_velocity, st.com_acceleration);
  const double cb = pl.beta.c, sb = pl.beta.s, bd = pl.beta.d, bdd = pl.beta.dd;
  // columns: ex = (c cb, c sb, s), n = (-sb, cb, 0), ex x n = (-s cb, -s sb, c)
  st.rotation << g.c * cb, -sb, -g.s * cb,  //
      g.c * sb, cb, -g.s * sb,              //
      g.s, 0.0, g.c;
  st.angular_velocity = Vec3(g.d * sb, -g.d * cb, bd);
  const double t = g.d * bd;
  st.angular_acceleration = Vec3(g.dd * sb + t * cb, -g.dd * cb + t * sb, bdd);
}

inline Point2 affine(const Point2& x, double cx, const Point2& y, double cy, const Point2& z,
                     double cz) noexcept {
  Point2 o;
  o.p = cx * x.p + cy * y.p + cz * z.p;
  o.v = cx * x.v + cy * y.v + cz * z.v;
  o.a = cx * x.a + cy * y.a + cz * z.a;
  return o;
}

bool finite(const PlatformMotion& m) noexcept {
  return m.position.allFinite() && m.velocity.allFinite() && m.acceleration.allFinite();
}

}  // namespace

// ------------------------------------------------------------------------------------- model
PaminsaModel::PaminsaModel(const PaminsaParameters& p) : p_(p) {
  if (!std::isfinite(p.k) || p.k <= 1.0) fail("k", "must be finite and > 1", p.k);
  require_positive(p.a, "a");
  require_positive(p.b, "b");
  require_positive(p.c, "c");
  require_positive(p.d, "d");
  require_finite(p.e, "e");
  require_finite(p.f, "f");
  require_positive(p.length_BG, "length_BG");
  require_positive(p.length_AE, "length_AE");
  require_positive(p.length_DF, "length_DF");
  require_positive(p.length_CE, "length_CE");
  require_positive(p.length_AF, "length_AF");
  require_positive(p.length_CJ, "length_CJ");
  require_positive(p.length_MS5, "length_MS5");
  require_positive(p.length_MO, "length_MO");
  if (std::abs(p.length_DF - p.length_AE) > 1e-9)
    fail("length_DF", "must equal length_AE (A-E-D-F is a parallelogram)", p.length_DF);
  if (std::abs(p.length_AF - p.length_CE / p.k) > 1e-9)
    fail("length_AF", "must equal length_CE / k (pantograph ratio)", p.length_AF);
  if (p.length_MS5 > p.length_MO) fail("length_MS5", "must not exceed length_MO", p.length_MS5);
  require_mass(p.platform_mass, "platform_mass");
  for (int j = 0; j < 8; ++j) {
    const std::string f = "link_mass[" + std::to_string(j) + "]";
    require_mass(p.link_mass[j], f);
  }
  if (!p.nominal_platform.allFinite()) fail("nominal_platform", "must be finite", p.nominal_platform.sum());
  require_positive(p.nominal_rho, "nominal_rho");
  require_finite(p.z_A, "z_A");
  if (p.elbow != 1.0 && p.elbow != -1.0) fail("elbow", "must be +1 or -1", p.elbow);
  if (!p.vertical_mass_xy.allFinite()) fail("vertical_mass_xy", "must be finite", p.vertical_mass_xy.sum());
  require_finite(p.vertical_mass_z0, "vertical_mass_z0");
  if (!std::isfinite(p.cp3_ratio) || p.cp3_ratio == 0.0) fail("cp3_ratio", "must be finite and non-zero", p.cp3_ratio);
  if (std::abs(p.cp3_ratio * p.length_MS5) > p.length_MO)
    fail("cp3_ratio", "puts L_i beyond the guide (|r| l_MS5 > l_MO)", p.cp3_ratio);
  const auto& cw = p.counterweights;
  for (int i = 0; i < 3; ++i) {
    require_mass(cw.at_A[i], "counterweights.at_A[" + std::to_string(i) + "]");
    require_mass(cw.at_F[i], "counterweights.at_F[" + std::to_string(i) + "]");
    require_mass(cw.at_L[i], "counterweights.at_L[" + std::to_string(i) + "]");
  }
  require_mass(cw.vertical, "counterweights.vertical");

  // bodies (inertia: principal axes along each link, A7)
  for (auto& b : bodies_) b = RigidBody{};
  bodies_[Idx::platform].mass = p.platform_mass;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 8; ++j) {
      RigidBody& b = bodies_[Idx::leg(i, j)];
      b.mass = p.link_mass[j];
      b.inertia_body = p.link_inertia[j].asDiagonal();
      const std::string f = "link_inertia[" + std::to_string(j) + "]";
      validate_rigid_body(b, f.c_str());
    }
    bodies_[Idx::cp1(i)].mass = cw.at_A[i];
    bodies_[Idx::cp2(i)].mass = cw.at_F[i];
    bodies_[Idx::cp3(i)].mass = cw.at_L[i];
  }
  bodies_[Idx::vertical_mass].mass = cw.vertical;
  for (int k = 0; k < 3; ++k) {
    wrist_[k] = p.wrist_inertia[k].asDiagonal();
    bodies_[Idx::wrist(k)].inertia_body = wrist_[k];
    const std::string f = "wrist_inertia[" + std::to_string(k) + "]";
    validate_rigid_body(bodies_[Idx::wrist(k)], f.c_str());
  }

  // constant mass data of the closed-form momentum path (paminsa_mechanism_wrench): the in-plane
  // masses at affine combinations c_j of (A, C, E), with ik = 1/k: D = (0, ik, 1-ik),
  // F = (1, ik, -ik), B = (1-ik, ik, 0); link midpoints; link 6 at B + l_BG/2 e_z
  {
    const double ik = 1.0 / p.k;
    const Vec3 cA(1.0, 0.0, 0.0), cC(0.0, 1.0, 0.0), cE(0.0, 0.0, 1.0);
    const Vec3 cD(0.0, ik, 1.0 - ik), cF(1.0, ik, -ik), cB(1.0 - ik, ik, 0.0);
    for (int i = 0; i < 3; ++i) {
      PaminsaLegMass& lm = leg_mass_[static_cast<std::size_t>(i)];
      const auto m = [&](std::size_t j) { return bodies_[Idx::leg(i, j)].mass; };
      const std::pair<double, Vec3> points[] = {
          {m(0), 0.5 * (cE + cC)}, {m(1), 0.5 * (cD + cF)}, {m(2), 0.5 * (cA + cE)},
          {m(3), 0.5 * (cA + cF)}, {m(5), cB}, {m(6), cB},
          {m(7) + bodies_[Idx::cp2(i)].mass, cF}, {bodies_[Idx::cp1(i)].mass, cA}};
      lm.G.setZero();
      lm.mu.setZero();
      for (const auto& pt : points) {
        lm.G += pt.first * pt.second * pt.second.transpose();
        lm.mu += pt.first * pt.second;
      }
      lm.nu = m(5) * 0.5 * p.length_BG * cB;
      const auto J = [&](std::size_t j) { return Vec3(bodies_[Idx::leg(i, j)].inertia_body.diagonal()); };
      lm.J14 = J(0) + J(3);
      lm.J23 = J(1) + J(2);
      lm.J6x = J(5)(0);
      const double l5 = p.length_MS5, l3 = p.cp3_ratio * p.length_MS5;
      const double m3 = bodies_[Idx::cp3(i)].mass;
      lm.guide_first = m(4) * l5 + m3 * l3;
      lm.guide_second = m(4) * l5 * l5 + m3 * l3 * l3 + J(4)(2);
    }
  }

  // layout (A8): joints J_i around P, legs pointing outward along u0, guides along g0
  const Vec3 j_off[3] = {Vec3(-p.a, -p.b, 0.0), Vec3(-p.a, p.b, 0.0), Vec3(p.d, 0.0, 0.0)};
  const Vec2 u0[3] = {Vec2(-1.0, 0.0), Vec2(-1.0, 0.0), Vec2(1.0, 0.0)};
  const Vec2 g0[3] = {Vec2(0.0, 1.0), Vec2(0.0, 1.0), Vec2(1.0, 0.0)};
  Vec2 centroid = Vec2::Zero();
  for (int i = 0; i < 3; ++i) {
    c_off_[i] = j_off[i] - p.length_CJ * Vec3::UnitZ();
    const Vec2 C0 = p.nominal_platform.head<2>() + c_off_[i].head<2>();
    B_h_[i] = C0 + (p.k - 1.0) * p.nominal_rho * u0[i];
    A0_h_[i] = B_h_[i] + p.nominal_rho * u0[i];
    M_h_[i] = A0_h_[i] - 0.5 * p.c * g0[i];
    centroid += B_h_[i] / 3.0;
  }
  vcw_ = p.vertical_mass_at_centroid ? centroid : p.vertical_mass_xy;
  if (0.5 * p.c > p.length_MO) fail("c", "puts A_i beyond the guide at the nominal pose (c/2 > l_MO)", p.c);

  // the nominal pose must be reachable (the pantograph closes)
  PaminsaWorkspace ws;
  PlatformMotion nominal;
  nominal.position = p.nominal_platform;
  if (paminsa_mechanism_kinematics(*this, nominal, ws) != Status::ok)
    fail("nominal_platform", "is not reachable by the pantographs (check lengths, k, nominal_rho)",
         p.nominal_platform.norm());
}

const char* PaminsaModel::body_name(std::size_t index) noexcept {
  static const char* names[Idx::count] = {
      "platform",
      "leg1.link1_EC", "leg1.link2_DF", "leg1.link3_AE", "leg1.link4_AF", "leg1.link5_guide",
      "leg1.link6_BG", "leg1.link7_slider", "leg1.link8_atF", "leg1.CP1_atA", "leg1.CP2_atF",
      "leg1.CP3_atL",
      "leg2.link1_EC", "leg2.link2_DF", "leg2.link3_AE", "leg2.link4_AF", "leg2.link5_guide",
      "leg2.link6_BG", "leg2.link7_slider", "leg2.link8_atF", "leg2.CP1_atA", "leg2.CP2_atF",
      "leg2.CP3_atL",
      "leg3.link1_EC", "leg3.link2_DF", "leg3.link3_AE", "leg3.link4_AF", "leg3.link5_guide",
      "leg3.link6_BG", "leg3.link7_slider", "leg3.link8_atF", "leg3.CP1_atA", "leg3.CP2_atF",
      "leg3.CP3_atL",
      "vertical_counter_mass", "wrist1", "wrist2", "wrist3"};
  return index < Idx::count ? names[index] : "";
}

Status PaminsaModel::inverse_kinematics(const Vec3& P, PaminsaActuators& out) const noexcept {
  if (!P.allFinite()) return Status::non_finite_input;
  const double k = p_.k;
  double alpha[3];
  for (int i = 0; i < 3; ++i) {
    // horizontal copying: A_h = (k B_h - C_h)/(k - 1)
    const Vec2 Ah = (k * B_h_[i] - (P + c_off_[i]).head<2>()) / (k - 1.0);
    const Vec2 v = Ah - M_h_[i];
    alpha[i] = std::atan2(v(1), v(0));
    out.stroke(i) = v.norm();
  }
  const double z_B = p_.z_A + (P(2) - p_.length_CJ - p_.z_A) / k;  // z_C - z_A = k (z_B - z_A)
  if (!out.stroke.allFinite() || !std::isfinite(z_B)) {  // finite P that overflowed
    out = PaminsaActuators{};
    return Status::out_of_range;
  }
  out.alpha1 = alpha[0];
  out.alpha2 = alpha[1];
  out.alpha3 = alpha[2];
  out.z_B = z_B;
  return Status::ok;
}

Status PaminsaModel::forward_kinematics(double alpha1, double alpha3, double z_B,
                                        Vec3& P) const noexcept {
  if (!std::isfinite(alpha1) || !std::isfinite(alpha3) || !std::isfinite(z_B))
    return Status::non_finite_input;
  // All A_i translate together by -(P_h - P0_h)/(k-1): A_1 - A_3 is constant, so
  // M_1 + l1 g1 - M_3 - l3 g3 = A0_1 - A0_3 is a 2x2 linear system in the strokes (l1, l3).
  const Vec2 g1(std::cos(alpha1), std::sin(alpha1)), g3(std::cos(alpha3), std::sin(alpha3));
  const double det = cross2(g1, -g3);
  if (std::abs(det) < 1e-12) return Status::singular;
  const Vec2 rhs = (A0_h_[0] - A0_h_[2]) - (M_h_[0] - M_h_[2]);
  const double l1 = cross2(rhs, -g3) / det;  // Cramer's rule
  const Vec2 A1 = M_h_[0] + l1 * g1;
  const Vec2 Ph = p_.nominal_platform.head<2>() - (p_.k - 1.0) * (A1 - A0_h_[0]);
  P << Ph(0), Ph(1), p_.z_A + p_.k * (z_B - p_.z_A) + p_.length_CJ;
  return P.allFinite() ? Status::ok : Status::out_of_range;  // finite input can overflow (z_B = 1.8e308)
}

// ------------------------------------------------------------------------------ kinematics
namespace {

/// What determines every body of one leg: its turning plane, the in-plane points A, C, E with their
/// rates, and the guide angle alpha of link 5.
struct LegSolution {
  Plane plane;
  Point2 A, C, E;
  Angle3 alpha;
};

/// The closed-form leg geometry shared by the kinematics and the momentum paths. With
/// Accel = false the second derivatives are not computed (left zero): the RK4 stages need D only.
/// Non-finite input: Status::non_finite_input; unreachable: Status::singular.
template <bool Accel>
Status solve_legs(const PaminsaModel& model, const PlatformMotion& pm,
                  std::array<LegSolution, 3>& legs) noexcept {
  if (!finite(pm)) return Status::non_finite_input;
  const PaminsaParameters& p = model.parameters();
  const double k = p.k;
  const double ikm1 = 1.0 / (k - 1.0);
  const Vec3& P = pm.position;
  const Vec3& Pd = pm.velocity;
  const Vec3& Pdd = pm.acceleration;
  const Vec2 Ahd = -Pd.head<2>() * ikm1;
  const Vec2 Ahdd = Accel ? Vec2(-Pdd.head<2>() * ikm1) : Vec2::Zero();
  const double lAE2 = p.length_AE * p.length_AE, lCE2 = p.length_CE * p.length_CE;
  for (int i = 0; i < 3; ++i) {
    LegSolution& L = legs[static_cast<std::size_t>(i)];
    const Vec2& Bh = model.slider_line()[i];
    const Vec3 Cb = P + model.platform_joint_offset()[i];
    const Vec2 Ah = (k * Bh - Cb.head<2>()) * ikm1;
    const Vec2 w = Ah - Bh;
    const double r2 = w.squaredNorm();
    // beta = angle of w, rho = |w| (angle_of / norm_of, sharing |w|)
    const double rho = std::sqrt(r2);
    if (!(rho > 1e-9)) return Status::singular;
    const double wwd = w.dot(Ahd);
    Angle3& beta = L.plane.beta;
    const double irho = 1.0 / rho, ir2 = irho * irho;
    beta.c = w(0) * irho;
    beta.s = w(1) * irho;
    beta.d = cross2(w, Ahd) * ir2;
    const double rhod = wwd * irho;
    double rhodd = 0.0;
    if (Accel) {
      beta.dd = (cross2(w, Ahdd) - 2.0 * beta.d * wwd) * ir2;
      rhodd = (Ahd.squaredNorm() + w.dot(Ahdd) - rhod * rhod) * irho;
    } else {
      beta.dd = 0.0;
    }
    L.plane.origin = Vec3(Bh(0), Bh(1), 0.0);
    L.plane.u = Vec3(beta.c, beta.s, 0.0);
    L.plane.n = Vec3(-beta.s, beta.c, 0.0);
    // in-plane (s, z): A = (rho, z_A), C = (-(k-1) rho, z_C)
    L.A.p = Vec2(rho, p.z_A);
    L.A.v = Vec2(rhod, 0.0);
    L.A.a = Vec2(rhodd, 0.0);
    L.C.p = Vec2(-(k - 1.0) * rho, Cb(2));
    L.C.v = Vec2(-(k - 1.0) * rhod, Pd(2));
    L.C.a = Accel ? Vec2(-(k - 1.0) * rhodd, Pdd(2)) : Vec2::Zero();
    // elbow E: |E - A| = l_AE, |E - C| = l_CE (circle intersection, A6)
    const Vec2 dv = L.C.p - L.A.p;
    const double LL = dv.norm();
    if (!(LL > 1e-9)) return Status::singular;
    const double iLL = 1.0 / LL;
    const Vec2 dh = dv * iLL;
    const double along = (lAE2 - lCE2 + LL * LL) * (0.5 * iLL);
    const double h2 = lAE2 - along * along;
    if (!(h2 > 1e-12)) return Status::singular;
    L.E.p = L.A.p + along * dh + p.elbow * std::sqrt(h2) * Vec2(dh(1), -dh(0));
    // rates from the constraint rows (E-A).(Ed-Ad) = 0, (E-C).(Ed-Cd) = 0 and their derivative
    const Vec2 ea = L.E.p - L.A.p, ec = L.E.p - L.C.p;
    const double det = ea(0) * ec(1) - ea(1) * ec(0);
    if (!(std::abs(det) > 1e-12)) return Status::singular;
    // inverse of [ea^T; ec^T] = [ec(1) -ea(1); -ec(0) ea(0)] / det
    const double idet = 1.0 / det;
    const auto solve2 = [&](double r0, double r1) noexcept {
      return Vec2((ec(1) * r0 - ea(1) * r1) * idet, (-ec(0) * r0 + ea(0) * r1) * idet);
    };
    L.E.v = solve2(ea.dot(L.A.v), ec.dot(L.C.v));
    // guide direction alpha = angle of M_i -> A_i: undefined with A_i on the pivot M_i (the
    // angle of a zero vector would be NaN with Status::ok)
    const Vec2 g = Ah - model.guide_pivot()[i];
    const double g2 = g.squaredNorm();
    if (!(g2 > 1e-18)) return Status::singular;
    if (Accel) {
      const Vec2 rA = L.E.v - L.A.v, rC = L.E.v - L.C.v;
      L.E.a = solve2(ea.dot(L.A.a) - rA.squaredNorm(), ec.dot(L.C.a) - rC.squaredNorm());
      L.alpha = angle_of(g, Ahd, Ahdd);
    } else {
      L.E.a.setZero();
      // angle_of without the second derivative
      const double ign = 1.0 / std::sqrt(g2);
      L.alpha.c = g(0) * ign;
      L.alpha.s = g(1) * ign;
      L.alpha.d = cross2(g, Ahd) * ign * ign;
      L.alpha.dd = 0.0;
    }
  }
  return Status::ok;
}

/// In-plane points of a leg that carry mass: D = E + (C-E)/k, F = A + (C-E)/k,
/// B = ((k-1) A + C)/k.
struct LegPoints {
  Point2 D, F, B;
};
inline LegPoints leg_points(const LegSolution& L, double k) noexcept {
  const double ik = 1.0 / k;
  return {affine(L.E, 1.0 - ik, L.C, ik, L.A, 0.0), affine(L.A, 1.0, L.C, ik, L.E, -ik),
          affine(L.A, 1.0 - ik, L.C, ik, L.E, 0.0)};
}

void fill_states(const PaminsaModel& model, const PlatformMotion& pm,
                 const std::array<LegSolution, 3>& legs, PaminsaWorkspace& ws) noexcept;

}  // namespace

Status paminsa_mechanism_kinematics(const PaminsaModel& model, const PlatformMotion& pm,
                                    PaminsaWorkspace& ws) noexcept {
  std::array<LegSolution, 3> legs;
  const Status s = solve_legs<true>(model, pm, legs);
  if (s != Status::ok) return s;  // the workspace is untouched
  fill_states(model, pm, legs, ws);
  for (std::size_t b = 0; b < Idx::mechanism_count; ++b) {
    const BodyState& st = ws.states[b];
    if (!(st.com.allFinite() && st.com_velocity.allFinite() && st.com_acceleration.allFinite() &&
          st.rotation.allFinite() && st.angular_velocity.allFinite() &&
          st.angular_acceleration.allFinite())) {
      ws = PaminsaWorkspace{};  // finite input overflowed: never leave non-finite states behind
      return Status::out_of_range;
    }
  }
  return Status::ok;
}

namespace {

void fill_states(const PaminsaModel& model, const PlatformMotion& pm,
                 const std::array<LegSolution, 3>& legs, PaminsaWorkspace& ws) noexcept {
  const PaminsaParameters& p = model.parameters();
  const Vec3& P = pm.position;
  const Vec3& Pd = pm.velocity;
  const Vec3& Pdd = pm.acceleration;
  // platform (translates only: yaw locked by the parallel legs, tilt by the pantographs)
  BodyState& pl = ws.states[Idx::platform];
  pl.com = P;
  pl.com_velocity = Pd;
  pl.com_acceleration = Pdd;
  pl.rotation.setIdentity();
  pl.angular_velocity.setZero();
  pl.angular_acceleration.setZero();

  for (int i = 0; i < 3; ++i) {
    const LegSolution& L = legs[static_cast<std::size_t>(i)];
    const LegPoints lp = leg_points(L, p.k);
    const Point2 &Dp = lp.D, &Fp = lp.F, &Bp = lp.B;
    const Plane& pn = L.plane;
    // A-E-D-F is a parallelogram: F - A = (C - E)/k and F - D = A - E, so links 4 and 1 have the
    // same direction and link 2 is link 3 turned by pi (two angles per leg, not four)
    const Angle3 gEC = angle_of(L.C.p - L.E.p, L.C.v - L.E.v, L.C.a - L.E.a);
    const Angle3 gAE = angle_of(L.E.p - L.A.p, L.E.v - L.A.v, L.E.a - L.A.a);
    Angle3 gDF = gAE;
    gDF.c = -gAE.c;
    gDF.s = -gAE.s;
    pantograph_link(pn, L.E, L.C, gEC, ws.states[Idx::leg(i, 0)]);  // link 1, E-C
    pantograph_link(pn, Dp, Fp, gDF, ws.states[Idx::leg(i, 1)]);    // link 2, D-F
    pantograph_link(pn, L.A, L.E, gAE, ws.states[Idx::leg(i, 2)]);  // link 3, A-E
    pantograph_link(pn, L.A, Fp, gEC, ws.states[Idx::leg(i, 3)]);   // link 4, A-F

    // link 5: turns about the vertical through M_i; COM S5 at l_MS5 along M_i -> A_i
    const Angle3& al = L.alpha;
    const Vec3 g(al.c, al.s, 0.0), gp(-al.s, al.c, 0.0);
    const Vec3 M3(model.guide_pivot()[i](0), model.guide_pivot()[i](1), p.z_A);
    const auto on_guide = [&](double l, BodyState& st) noexcept {
      st.com = M3 + l * g;
      st.com_velocity = l * al.d * gp;
      st.com_acceleration = l * al.dd * gp - l * al.d * al.d * g;
    };
    BodyState& l5 = ws.states[Idx::leg(i, 4)];
    on_guide(p.length_MS5, l5);
    l5.rotation << al.c, -al.s, 0.0, al.s, al.c, 0.0, 0.0, 0.0, 1.0;  // Rz(alpha)
    l5.angular_velocity = al.d * Vec3::UnitZ();
    l5.angular_acceleration = al.dd * Vec3::UnitZ();

    // link 6: vertical column on B (A3), turning with the leg plane; body X vertical
    BodyState& l6 = ws.states[Idx::leg(i, 5)];
    to_base(pn, Bp, l6.com, l6.com_velocity, l6.com_acceleration);
    l6.com += 0.5 * p.length_BG * Vec3::UnitZ();
    l6.rotation.col(0) = Vec3::UnitZ();
    l6.rotation.col(1) = pn.n;
    l6.rotation.col(2) = pn.u * -1.0;  // X x Y = e_z x n = -u
    l6.angular_velocity = pn.beta.d * Vec3::UnitZ();
    l6.angular_acceleration = pn.beta.dd * Vec3::UnitZ();

    point_body(pn, Bp, ws.states[Idx::leg(i, 6)]);  // link 7: slider at B (A4)
    point_body(pn, Fp, ws.states[Idx::leg(i, 7)]);  // link 8: point mass at F (A5)
    point_body(pn, L.A, ws.states[Idx::cp1(i)]);   // CP1 at A_i
    ws.states[Idx::cp2(i)] = ws.states[Idx::leg(i, 7)];  // CP2 at F_i, as link 8
    BodyState& l = ws.states[Idx::cp3(i)];          // CP3 at L_i: M_iL_i = r M_iS_5i
    on_guide(p.cp3_ratio * p.length_MS5, l);
    l.rotation.setIdentity();
    l.angular_velocity.setZero();
    l.angular_acceleration.setZero();

    // base-frame points A..F
    const Point2* pts[6] = {&L.A, &Bp, &L.C, &Dp, &L.E, &Fp};
    for (int n = 0; n < 6; ++n)  // positions only (to_base's rates are not needed here)
      ws.leg_points[i][n] = pn.origin + pts[n]->p(0) * pn.u + pts[n]->p(1) * Vec3::UnitZ();
  }

  // vertical counter-mass of the supplementary system (A9): z = z0 - (z_P - z_P0)
  BodyState& vm = ws.states[Idx::vertical_mass];
  vm.com = Vec3(model.vertical_mass_xy()(0), model.vertical_mass_xy()(1),
                p.vertical_mass_z0 - (P(2) - p.nominal_platform(2)));
  vm.com_velocity = -Pd(2) * Vec3::UnitZ();
  vm.com_acceleration = -Pdd(2) * Vec3::UnitZ();
  vm.rotation.setIdentity();
  vm.angular_velocity.setZero();
  vm.angular_acceleration.setZero();
}

}  // namespace

Status paminsa_wrist_kinematics(const PaminsaModel&, const PlatformMotion& pm,
                                const WristMotion& wm, PaminsaWorkspace& ws) noexcept {
  if (!finite(pm) || !wm.angles.allFinite() || !wm.rates.allFinite() ||
      !wm.accelerations.allFinite())
    return Status::non_finite_input;
  WristLinkMotion m;
  wrist_link_motion(wm.angles, wm.rates, wm.accelerations, m);
  for (int k = 0; k < 3; ++k) {
    BodyState& st = ws.states[Idx::wrist(k)];
    st.com = pm.position;
    st.com_velocity = pm.velocity;
    st.com_acceleration = pm.acceleration;
    st.rotation = m.rotation[k];
    st.angular_velocity = m.angular_velocity[k];
    st.angular_acceleration = m.angular_acceleration[k];
  }
  return Status::ok;
}

Status paminsa_kinematics(const PaminsaModel& model, const PlatformMotion& pm,
                          const WristMotion& wm, PaminsaWorkspace& ws) noexcept {
  if (!wm.angles.allFinite() || !wm.rates.allFinite() || !wm.accelerations.allFinite())
    return Status::non_finite_input;
  const Status s = paminsa_mechanism_kinematics(model, pm, ws);
  if (s != Status::ok) return s;
  return paminsa_wrist_kinematics(model, pm, wm, ws);
}

namespace {

/// Momenta of the 35 mechanism bodies straight from the leg solution, without forming any body's
/// state. Each leg's in-plane bodies move in the vertical plane X = O + s u + z e_z that
/// turns about e_z at beta_dot (u = (cos b, sin b, 0), n = e_z x u, du/dt = bd n, dn/dt = -bd u):
///   V = sd u + s bd n + zd e_z,  A = (sdd - s bd^2) u + (2 sd bd + s bdd) n + zdd e_z,
///   (X - O) x V = s^2 bd e_z + (z sd - s zd) n - s z bd u,
///   (X - O) x A = s a_n e_z + (z a_u - s zdd) n - z a_n u   (a_u, a_n: A's u and n parts),
/// so a leg's point masses reduce to m-weighted sums of s, sd, zd, s^2, z sd - s zd, s z (and
/// their rates), and its moment about O is O x (sum m A) + those sums. Every mass point is an
/// affine combination x_j = sum_k c_jk y_k (+ a constant height for link 6) of y = (A, C, E), so
/// those sums are bilinear forms y^T G y' with G = sum_j m_j c_j c_j^T precomputed per leg
/// (PaminsaLegMass). A pantograph link (body
/// axes ex = cos g u + sin g e_z, n, ex x n = cos g e_z - sin g u; principal inertias Jx, Jy, Jz;
/// w = bd e_z - gd n) has
///   I w = bd sin g cos g (Jx - Jz) u - Jy gd n + bd (Jx sin^2 g + Jz cos^2 g) e_z = a_u u + a_n n + a_e e_z
///   d(I w)/dt = (a_u' - a_n bd) u + (a_n' + a_u bd) n + a_e' e_z,
/// the column (link 6, body X = e_z, w = bd e_z) has I w = Jx bd e_z, and the guide (link 5) and
/// CP3 turn about the vertical through M_i: sum m (M + l g) x (l ad g_perp) = (sum m l) ad M x g_perp
/// + (sum m l^2) ad e_z, plus Jz ad e_z. Exact (same quantities as the sum over the bodies'
/// states, sum_bodies; tests/cpp/test_paminsa.cpp checks it to 1e-12 on random models and motions).
/// The inertias are the model's principal ones (link_inertia, diagonal by construction).
inline Vec3 in_base(const Plane& pl, double cu, double cn, double cz) noexcept {
  return Vec3(cu * pl.u(0) + cn * pl.n(0), cu * pl.u(1) + cn * pl.n(1), cz);
}

template <bool Accel>
void mechanism_wrench_from_legs(const PaminsaModel& model, const PlatformMotion& pm,
                                const std::array<LegSolution, 3>& legs,
                                ShakingWrench& out) noexcept {
  const PaminsaParameters& p = model.parameters();
  const auto& bodies = model.bodies();
  Vec3 lin = Vec3::Zero(), ang = Vec3::Zero(), force = Vec3::Zero(), moment = Vec3::Zero();
  // platform and vertical counter-mass (point masses)
  {
    const double mp = bodies[Idx::platform].mass;
    lin += mp * pm.velocity;
    ang += mp * pm.position.cross(pm.velocity);
    const double mv = bodies[Idx::vertical_mass].mass;
    const Vec3 vc(model.vertical_mass_xy()(0), model.vertical_mass_xy()(1),
                  p.vertical_mass_z0 - (pm.position(2) - p.nominal_platform(2)));
    const double vz = -pm.velocity(2);
    lin(2) += mv * vz;
    ang += mv * Vec3(vc(1) * vz, -vc(0) * vz, 0.0);  // vc x (0, 0, vz)
    if (Accel) {
      force += mp * pm.acceleration;
      moment += mp * pm.position.cross(pm.acceleration);
      const double az = -pm.acceleration(2);
      force(2) += mv * az;
      moment += mv * Vec3(vc(1) * az, -vc(0) * az, 0.0);
    }
  }
  for (int i = 0; i < 3; ++i) {
    const LegSolution& L = legs[static_cast<std::size_t>(i)];
    const PaminsaLegMass& lm = model.leg_mass()[static_cast<std::size_t>(i)];
    const Plane& pl = L.plane;
    const double bd = pl.beta.d, bdd = pl.beta.dd;

    // in-plane point masses as bilinear forms in y = (A, C, E) (PaminsaLegMass)
    const Vec3 s(L.A.p(0), L.C.p(0), L.E.p(0)), z(L.A.p(1), L.C.p(1), L.E.p(1));
    const Vec3 sd(L.A.v(0), L.C.v(0), L.E.v(0)), zd(L.A.v(1), L.C.v(1), L.E.v(1));
    const Vec3 Gs = lm.G * s, Gz = lm.G * z;
    const double S = lm.mu.dot(s), Sd = lm.mu.dot(sd), Zd = lm.mu.dot(zd);
    const double Q = s.dot(Gs);                                // sum m s^2
    const double Pz = z.dot(Gs) + lm.nu.dot(s);                // sum m s z
    const double W = sd.dot(Gz) - zd.dot(Gs) + lm.nu.dot(sd);  // sum m (z sd - s zd)

    // rotation of the pantograph links: 1 and 4 are parallel (F - A = (C - E)/k), so are 2 and 3
    // (F - D = A - E); I w depends on the link angle g through cos^2, sin^2, sin cos and its rates
    // only (the same for g + pi), so each parallel pair is one term with summed inertias
    double hu = 0, hn = 0, hz = 0, mu = 0, mn = 0, mz = 0;
    const Vec2 dps[2] = {L.C.p - L.E.p, L.E.p - L.A.p};
    const Vec2 dvs[2] = {L.C.v - L.E.v, L.E.v - L.A.v};
    for (int j = 0; j < 2; ++j) {
      const Vec3& J = j == 0 ? lm.J14 : lm.J23;
      const Vec2 &dp = dps[j], &dv = dvs[j];
      const double ir2 = 1.0 / dp.squaredNorm();  // no square root, one division
      const double c2 = dp(0) * dp(0) * ir2, s2 = dp(1) * dp(1) * ir2, sc = dp(0) * dp(1) * ir2;
      const double gd = cross2(dp, dv) * ir2;
      const double jxz = J(0) - J(2), jsc = J(0) * s2 + J(2) * c2;
      const double au = bd * sc * jxz, an = -J(1) * gd, ae = bd * jsc;
      hu += au;
      hn += an;
      hz += ae;
      if (Accel) {
        const Vec2 da = j == 0 ? Vec2(L.C.a - L.E.a) : Vec2(L.E.a - L.A.a);
        const double gdd = (cross2(dp, da) - 2.0 * gd * dp.dot(dv)) * ir2;
        mu += jxz * (bdd * sc + bd * gd * (c2 - s2)) - an * bd;
        mn += -J(1) * gdd + au * bd;
        mz += bdd * jsc + 2.0 * bd * gd * sc * jxz;
      }
    }
    hz += lm.J6x * bd;  // column: body X = e_z
    if (Accel) mz += lm.J6x * bdd;

    // leg totals: sum m V, sum m A, and the moments about the plane origin, then about O
    const Vec3 Pleg = in_base(pl, Sd, S * bd, Zd);
    const Vec3 Hrel = in_base(pl, -Pz * bd + hu, W + hn, Q * bd + hz);
    lin += Pleg;
    ang += pl.origin.cross(Pleg) + Hrel;
    if (Accel) {
      const Vec3 sdd(L.A.a(0), L.C.a(0), L.E.a(0)), zdd(L.A.a(1), L.C.a(1), L.E.a(1));
      const double Sdd = lm.mu.dot(sdd), Zdd = lm.mu.dot(zdd);
      const double X1 = sd.dot(Gs);                                   // sum m s sd
      const double X2 = sdd.dot(Gz) - zdd.dot(Gs) + lm.nu.dot(sdd);  // sum m (z sdd - s zdd)
      const double X3 = sd.dot(Gz) + lm.nu.dot(sd);                   // sum m z sd
      const Vec3 Fleg = in_base(pl, Sdd - bd * bd * S, 2.0 * bd * Sd + bdd * S, Zdd);
      const Vec3 Mrel = in_base(pl, -(2.0 * bd * X3 + bdd * Pz) + mu,
                                X2 - bd * bd * Pz + mn, 2.0 * bd * X1 + bdd * Q + mz);
      force += Fleg;
      moment += pl.origin.cross(Fleg) + Mrel;
    }

    // guide (link 5) and CP3 on it, turning about the vertical through M_i
    const Angle3& al = L.alpha;
    const Vec3 M3(model.guide_pivot()[i](0), model.guide_pivot()[i](1), p.z_A);
    const Vec3 g(al.c, al.s, 0.0), gp(-al.s, al.c, 0.0);
    const Vec3 Pg = lm.guide_first * al.d * gp;
    lin += Pg;
    ang += M3.cross(Pg);
    ang(2) += lm.guide_second * al.d;
    if (Accel) {
      const Vec3 Fg = lm.guide_first * (al.dd * gp - al.d * al.d * g);
      force += Fg;
      moment += M3.cross(Fg);
      moment(2) += lm.guide_second * al.dd;
    }
  }
  out.linear_momentum = lin;
  out.angular_momentum = ang;
  out.force = force;
  out.moment = moment;
}

}  // namespace

Status paminsa_mechanism_wrench(const PaminsaModel& model, const PlatformMotion& platform,
                                ShakingWrench& out) noexcept {
  std::array<LegSolution, 3> legs;
  const Status s = solve_legs<true>(model, platform, legs);
  if (s != Status::ok) return s;
  ShakingWrench w;
  mechanism_wrench_from_legs<true>(model, platform, legs, w);
  if (!w.linear_momentum.allFinite() || !w.angular_momentum.allFinite() || !w.force.allFinite() ||
      !w.moment.allFinite())
    return Status::out_of_range;  // finite input (solve_legs checked) that overflowed
  out = w;
  return Status::ok;
}

Status paminsa_mechanism_angular_momentum(const PaminsaModel& model, const PlatformMotion& platform,
                                          Vec3& D) noexcept {
  std::array<LegSolution, 3> legs;
  const Status s = solve_legs<false>(model, platform, legs);
  if (s != Status::ok) return s;
  ShakingWrench w;
  mechanism_wrench_from_legs<false>(model, platform, legs, w);
  if (!w.angular_momentum.allFinite()) return Status::out_of_range;
  D = w.angular_momentum;
  return Status::ok;
}

namespace {

/// PAMINSA's own sum over its bodies' states (Briot & Arakelian 2009, eqs 1-4): bodies
/// [first, first + count) of the model and the workspace. P = sum m v, H_O = sum (m c x v + I w),
/// F = sum m a, M_O = sum (m c x a + I alpha + w x I w), I = R J R^T applied as R (J (R^T x)).
/// Non-finite states: Status::non_finite_input; finite states whose sums overflow:
/// Status::out_of_range; either leaves `out` zero. The fast path of the general
/// algorithm/shaking_wrench.hpp (tests/python/test_papers_loops.py checks them equal).
Status sum_bodies(const PaminsaModel& model, const PaminsaWorkspace& ws, std::size_t first,
                  std::size_t count, ShakingWrench& out) noexcept {
  out = ShakingWrench{};
  for (std::size_t j = first; j < first + count; ++j) {
    const RigidBody& b = model.bodies()[j];
    const BodyState& s = ws.states[j];
    if (!(s.com.allFinite() && s.com_velocity.allFinite() && s.com_acceleration.allFinite() &&
          s.rotation.allFinite() && s.angular_velocity.allFinite() &&
          s.angular_acceleration.allFinite())) {
      out = ShakingWrench{};
      return Status::non_finite_input;
    }
    out.linear_momentum.noalias() += b.mass * s.com_velocity;
    out.angular_momentum.noalias() += b.mass * s.com.cross(s.com_velocity);
    out.force.noalias() += b.mass * s.com_acceleration;
    out.moment.noalias() += b.mass * s.com.cross(s.com_acceleration);
    if (b.inertia_body.isZero(0.0)) continue;  // point mass (exactly): no rotational terms
    const Mat3& R = s.rotation;
    const Vec3 Iw = R * (b.inertia_body * (R.transpose() * s.angular_velocity));
    const Vec3 Ialpha = R * (b.inertia_body * (R.transpose() * s.angular_acceleration));
    out.angular_momentum.noalias() += Iw;
    out.moment.noalias() += Ialpha + s.angular_velocity.cross(Iw);
  }
  if (!(out.linear_momentum.allFinite() && out.angular_momentum.allFinite() &&
        out.force.allFinite() && out.moment.allFinite())) {
    out = ShakingWrench{};
    return Status::out_of_range;
  }
  return Status::ok;
}

}  // namespace

Status paminsa_mechanism_momentum(const PaminsaModel& model, const PaminsaWorkspace& ws, Vec3& D,
                                  Vec3& D_dot) noexcept {
  ShakingWrench sw;
  const Status s = sum_bodies(model, ws, 0, Idx::mechanism_count, sw);
  if (s != Status::ok) return s;
  D = sw.angular_momentum;
  D_dot = sw.moment;
  return Status::ok;
}

Status paminsa_shaking_wrench(const PaminsaModel& model, const PaminsaWorkspace& ws,
                              ShakingWrench& out) noexcept {
  return sum_bodies(model, ws, 0, Idx::count, out);
}

// ------------------------------------------------------------------------------ controller
PaminsaController::PaminsaController(const PaminsaModel& model,
                                     const ReactionlessWristConfig& config,
                                     const Vec3& initial_wrist_angles, const PlatformLimits& limits)
    : model_(model),
      limits_(limits),
      wrist_(model.wrist_inertia(), config, initial_wrist_angles, Vec3::Zero()) {
  if (!std::isfinite(limits.max_speed) || limits.max_speed <= 0.0)
    fail("platform_limits.max_speed", "must be finite and > 0", limits.max_speed);
  if (!std::isfinite(limits.max_acceleration) || limits.max_acceleration <= 0.0)
    fail("platform_limits.max_acceleration", "must be finite and > 0", limits.max_acceleration);
}

bool PaminsaController::in_range(const PlatformMotion& m) const noexcept {
  return m.velocity.cwiseAbs().maxCoeff() <= limits_.max_speed &&
         m.acceleration.cwiseAbs().maxCoeff() <= limits_.max_acceleration;
}

Status PaminsaController::reset(const PlatformMotion& initial, const Vec3& wrist_angles) noexcept {
  // everything is computed aside and committed only when the wrist accepts the reset (a
  // rejected reset leaves the workspace as it was)
  if (!finite(initial) || !wrist_angles.allFinite()) return Status::non_finite_input;
  if (!in_range(initial)) return Status::out_of_range;
  PaminsaWorkspace ws;
  Status s = paminsa_mechanism_kinematics(model_, initial, ws);
  if (s != Status::ok) return s;
  Vec3 D, Dd;
  s = paminsa_mechanism_momentum(model_, ws, D, Dd);
  if (s != Status::ok) return s;
  s = wrist_.reset(wrist_angles, D);  // wrist at rest: H_target = D(t0)
  if (s != Status::ok) return s;
  ws_ = ws;
  return Status::ok;
}

Status PaminsaController::tick(const PlatformMotion& now, const PlatformMotion& half,
                               const PlatformMotion& next) noexcept {
  const bool rk4 = wrist_.config().integrator == WristIntegrator::rk4;
  Vec3 D_half = Vec3::Zero(), D_next = Vec3::Zero();
  Status s = Status::ok;
  if (!finite(now) || (rk4 && (!finite(half) || !finite(next))))
    s = Status::non_finite_input;
  else if (!in_range(now) || (rk4 && (!in_range(half) || !in_range(next))))
    s = Status::out_of_range;
  if (rk4 && s == Status::ok) {  // D only at the RK4 stages: leg geometry and rates, no body state, no accelerations
    s = paminsa_mechanism_angular_momentum(model_, half, D_half);
    if (s == Status::ok) s = paminsa_mechanism_angular_momentum(model_, next, D_next);
  }
  // now: the leg geometry once, for the workspace's 35 body states and for the mechanism's
  // momenta and wrench in closed form (D, dD/dt, and the wrench's first 35 terms)
  std::array<LegSolution, 3> legs;
  ShakingWrench mechanism;
  if (s == Status::ok) s = solve_legs<true>(model_, now, legs);
  if (s == Status::ok) {
    mechanism_wrench_from_legs<true>(model_, now, legs, mechanism);
    if (!mechanism.linear_momentum.allFinite() || !mechanism.angular_momentum.allFinite() ||
        !mechanism.force.allFinite() || !mechanism.moment.allFinite())
      s = Status::out_of_range;
  }
  if (s != Status::ok) {
    // hold: the wrist keeps its angles (zero rates), the workspace and wrench keep the last tick's
    return wrist_.hold(s);
  }
  fill_states(model_, now, legs, ws_);
  D_ = mechanism.angular_momentum;  // eq 19
  D_dot_ = mechanism.moment;
  const Status ws = wrist_.step(D_, D_dot_, D_half, D_next);
  // the wrist links' motion (paminsa_wrist_kinematics, with the cos/sin the wrist computed)
  const WristCommand& c = wrist_.command();
  WristLinkMotion m;
  wrist_link_motion(c.cos_angles, c.sin_angles, c.rates, c.accelerations, m);
  for (int k = 0; k < 3; ++k) {
    BodyState& st = ws_.states[Idx::wrist(k)];
    st.com = now.position;
    st.com_velocity = now.velocity;
    st.com_acceleration = now.acceleration;
    st.rotation = m.rotation[k];
    st.angular_velocity = m.angular_velocity[k];
    st.angular_acceleration = m.angular_acceleration[k];
  }
  // all 38 bodies = the mechanism's sums + the three wrist links' (not re-summed from scratch)
  ShakingWrench wrist;
  sum_bodies(model_, ws_, Idx::wrist(0), 3, wrist);
  wrench_.linear_momentum = mechanism.linear_momentum + wrist.linear_momentum;
  wrench_.angular_momentum = mechanism.angular_momentum + wrist.angular_momentum;
  wrench_.force = mechanism.force + wrist.force;
  wrench_.moment = mechanism.moment + wrist.moment;
  return ws;
}

// ------------------------------------------------------------------------------ batch
namespace {

void write_instant(const PaminsaWorkspace& ws, const ShakingWrench& sw, std::size_t n,
                   const PaminsaBatchOutput& out) noexcept {
  constexpr std::size_t B = Idx::count;
  for (std::size_t b = 0; b < B; ++b) {
    const BodyState& st = ws.states[b];
    const std::size_t o3 = (n * B + b) * 3;
    if (out.com) Eigen::Map<Vec3>(out.com + o3) = st.com;
    if (out.com_velocity) Eigen::Map<Vec3>(out.com_velocity + o3) = st.com_velocity;
    if (out.com_acceleration) Eigen::Map<Vec3>(out.com_acceleration + o3) = st.com_acceleration;
    if (out.angular_velocity) Eigen::Map<Vec3>(out.angular_velocity + o3) = st.angular_velocity;
    if (out.angular_acceleration)
      Eigen::Map<Vec3>(out.angular_acceleration + o3) = st.angular_acceleration;
    if (out.rotation)
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(out.rotation + (n * B + b) * 9) =
          st.rotation;
  }
  if (out.force) Eigen::Map<Vec3>(out.force + 3 * n) = sw.force;
  if (out.moment) Eigen::Map<Vec3>(out.moment + 3 * n) = sw.moment;
}

PlatformMotion motion_at(const double* P, const double* Pd, const double* Pdd, std::size_t j) {
  PlatformMotion m;
  m.position = Eigen::Map<const Vec3>(P + 3 * j);
  m.velocity = Eigen::Map<const Vec3>(Pd + 3 * j);
  m.acceleration = Eigen::Map<const Vec3>(Pdd + 3 * j);
  return m;
}

}  // namespace

Status paminsa_kinematics_batch(const PaminsaModel& model, std::size_t instants, const double* P,
                                const double* Pd, const double* Pdd, const double* q,
                                const double* qd, const double* qdd,
                                const PaminsaBatchOutput& out) noexcept {
  PaminsaWorkspace ws;
  Status all = Status::ok;
  for (std::size_t n = 0; n < instants; ++n) {
    const PlatformMotion pm = motion_at(P, Pd, Pdd, n);
    WristMotion wm;
    wm.angles = Eigen::Map<const Vec3>(q + 3 * n);
    wm.rates = Eigen::Map<const Vec3>(qd + 3 * n);
    wm.accelerations = Eigen::Map<const Vec3>(qdd + 3 * n);
    Status s = paminsa_kinematics(model, pm, wm, ws);
    ShakingWrench sw;
    Vec3 D = Vec3::Zero(), Dd = Vec3::Zero();
    // the inputs are finite here (paminsa_kinematics checked them): a non-finite body state or
    // wrench is an overflow of finite input
    if (s == Status::ok) {
      s = paminsa_shaking_wrench(model, ws, sw);
      if (s == Status::non_finite_input) s = Status::out_of_range;
    }
    if (s == Status::ok) {
      s = paminsa_mechanism_momentum(model, ws, D, Dd);
      if (s == Status::non_finite_input) s = Status::out_of_range;
    }
    if (s != Status::ok) {
      ws = PaminsaWorkspace{};  // never NaN out: identity poses, zero motion
      sw = ShakingWrench{};
    }
    write_instant(ws, sw, n, out);
    if (out.D) Eigen::Map<Vec3>(out.D + 3 * n) = D;
    if (out.D_dot) Eigen::Map<Vec3>(out.D_dot + 3 * n) = Dd;
    if (out.wrist_angles) Eigen::Map<Vec3>(out.wrist_angles + 3 * n) = s == Status::ok ? wm.angles : Vec3::Zero();
    if (out.wrist_rates) Eigen::Map<Vec3>(out.wrist_rates + 3 * n) = s == Status::ok ? wm.rates : Vec3::Zero();
    if (out.wrist_accelerations)
      Eigen::Map<Vec3>(out.wrist_accelerations + 3 * n) = s == Status::ok ? wm.accelerations : Vec3::Zero();
    if (out.condition) out.condition[n] = 0.0;
    if (out.status) out.status[n] = static_cast<std::uint32_t>(s);
    all |= s;
  }
  return all;
}

Status paminsa_reactionless_run(const PaminsaModel& model, const ReactionlessWristConfig& config,
                                const Vec3& initial_wrist_angles, std::size_t steps,
                                const double* P, const double* Pd, const double* Pdd,
                                const PaminsaBatchOutput& out) {
  PaminsaController ctl(model, config, initial_wrist_angles);
  Status all = ctl.reset(motion_at(P, Pd, Pdd, 0), initial_wrist_angles);
  for (std::size_t n = 0; n <= steps; ++n) {
    const std::size_t j = 2 * n;
    const std::size_t jh = std::min(j + 1, 2 * steps), jn = std::min(j + 2, 2 * steps);
    const Status s = ctl.tick(motion_at(P, Pd, Pdd, j), motion_at(P, Pd, Pdd, jh),
                              motion_at(P, Pd, Pdd, jn));
    all |= s;
    write_instant(ctl.workspace(), ctl.wrench(), n, out);
    const WristCommand& c = ctl.wrist().command();
    if (out.D) Eigen::Map<Vec3>(out.D + 3 * n) = ctl.D();
    if (out.D_dot) Eigen::Map<Vec3>(out.D_dot + 3 * n) = ctl.D_dot();
    if (out.wrist_angles) Eigen::Map<Vec3>(out.wrist_angles + 3 * n) = c.angles;
    if (out.wrist_rates) Eigen::Map<Vec3>(out.wrist_rates + 3 * n) = c.rates;
    if (out.wrist_accelerations) Eigen::Map<Vec3>(out.wrist_accelerations + 3 * n) = c.accelerations;
    if (out.condition) out.condition[n] = c.condition_number;
    if (out.status) out.status[n] = static_cast<std::uint32_t>(s);
  }
  return all;
}

}  // namespace mechbal
