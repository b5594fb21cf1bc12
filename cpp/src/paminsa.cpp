#include "mechbal/paminsa.hpp"

#include <cmath>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

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

/// Value, first and second time derivative of a planar quantity.
struct Scalar3 {
  double v = 0.0, d = 0.0, dd = 0.0;
};

/// An angle by its cosine and sine (no atan2 in the tick: every use of an angle is through its
/// cosine and sine, which the vector gives directly; issue 6), and its first and second derivative.
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
  const double r = std::sqrt(r2);
  Angle3 out;
  out.c = w(0) / r;
  out.s = w(1) / r;
  out.d = cross2(w, wd) / r2;
  out.dd = cross2(w, wdd) / r2 - 2.0 * out.d * w.dot(wd) / r2;
  return out;
}

/// |w| and derivatives: rhod = w.wd/rho, rhodd = (|wd|^2 + w.wdd - rhod^2)/rho.
Scalar3 norm_of(const Vec2& w, const Vec2& wd, const Vec2& wdd) noexcept {
  Scalar3 out;
  out.v = w.norm();
  out.d = w.dot(wd) / out.v;
  out.dd = (wd.squaredNorm() + w.dot(wdd) - out.d * out.d) / out.v;
  return out;
}

/// Leg plane frame: X = B_h + s u + z e_z with u = (cos beta, sin beta, 0), n = e_z x u.
struct Plane {
  Vec3 origin, u, n;
  Angle3 beta;
};

/// In-plane point (s, z) with rates relative to the turning plane -> base frame:
/// Xd = sd u + s bd n + zd e_z;  Xdd = (sdd - s bd^2) u + (2 sd bd + s bdd) n + zdd e_z.
void to_base(const Plane& pl, const Point2& pt, Vec3& X, Vec3& Xd, Vec3& Xdd) noexcept {
  const double bd = pl.beta.d, bdd = pl.beta.dd;
  const double s = pt.p(0), z = pt.p(1), sd = pt.v(0), zd = pt.v(1), sdd = pt.a(0), zdd = pt.a(1);
  X = pl.origin + s * pl.u + z * Vec3::UnitZ();
  Xd = sd * pl.u + s * bd * pl.n + zd * Vec3::UnitZ();
  Xdd = (sdd - s * bd * bd) * pl.u + (2.0 * sd * bd + s * bdd) * pl.n + zdd * Vec3::UnitZ();
}

void point_body(const Plane& pl, const Point2& pt, BodyState& st) noexcept {
  to_base(pl, pt, st.com, st.com_velocity, st.com_acceleration);
  st.rotation.setIdentity();
  st.angular_velocity.setZero();
  st.angular_acceleration.setZero();
}

/// Pantograph link p1 -> p2 (COM at its middle), body X along the link, Y = plane normal n.
/// gamma = elevation of p1->p2 in the plane: R = [cos g u + sin g e_z, n, X x n],
/// w = bd e_z - gd n, wd = bdd e_z - gdd n + gd bd u.
void pantograph_link(const Plane& pl, const Point2& p1, const Point2& p2, BodyState& st) noexcept {
  Point2 mid;
  mid.p = 0.5 * (p1.p + p2.p);
  mid.v = 0.5 * (p1.v + p2.v);
  mid.a = 0.5 * (p1.a + p2.a);
  to_base(pl, mid, st.com, st.com_velocity, st.com_acceleration);
  const Angle3 g = angle_of(p2.p - p1.p, p2.v - p1.v, p2.a - p1.a);
  const Vec3 ex = g.c * pl.u + g.s * Vec3::UnitZ();
  st.rotation.col(0) = ex;
  st.rotation.col(1) = pl.n;
  st.rotation.col(2) = ex.cross(pl.n);
  st.angular_velocity = pl.beta.d * Vec3::UnitZ() - g.d * pl.n;
  st.angular_acceleration = pl.beta.dd * Vec3::UnitZ() - g.dd * pl.n + g.d * pl.beta.d * pl.u;
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
  out.alpha1 = alpha[0];
  out.alpha2 = alpha[1];
  out.alpha3 = alpha[2];
  out.z_B = p_.z_A + (P(2) - p_.length_CJ - p_.z_A) / k;  // vertical model: z_C - z_A = k (z_B - z_A)
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
  return Status::ok;
}

// ------------------------------------------------------------------------------ kinematics
Status paminsa_mechanism_kinematics(const PaminsaModel& model, const PlatformMotion& pm,
                                    PaminsaWorkspace& ws) noexcept {
  if (!finite(pm)) return Status::non_finite_input;
  const PaminsaParameters& p = model.parameters();
  const double k = p.k;
  const Vec3& P = pm.position;
  const Vec3& Pd = pm.velocity;
  const Vec3& Pdd = pm.acceleration;

  // leg-plane data first (so that an unreachable pose leaves the workspace untouched)
  Plane plane[3];
  Point2 A[3], C[3], E[3];
  Angle3 alpha[3];
  Vec2 AhArr[3];
  for (int i = 0; i < 3; ++i) {
    const Vec2& Bh = model.slider_line()[i];
    const Vec3 Cb = P + model.platform_joint_offset()[i];
    const Vec2 Ah = (k * Bh - Cb.head<2>()) / (k - 1.0);
    const Vec2 Ahd = -Pd.head<2>() / (k - 1.0);
    const Vec2 Ahdd = -Pdd.head<2>() / (k - 1.0);
    AhArr[i] = Ah;
    const Vec2 w = Ah - Bh;
    if (!(w.norm() > 1e-9)) return Status::singular;
    plane[i].beta = angle_of(w, Ahd, Ahdd);
    const Scalar3 rho = norm_of(w, Ahd, Ahdd);
    const double cb = plane[i].beta.c, sb = plane[i].beta.s;
    plane[i].origin = Vec3(Bh(0), Bh(1), 0.0);
    plane[i].u = Vec3(cb, sb, 0.0);
    plane[i].n = Vec3(-sb, cb, 0.0);
    // in-plane (s, z): A = (rho, z_A), C = (-(k-1) rho, z_C)
    A[i].p = Vec2(rho.v, p.z_A);
    A[i].v = Vec2(rho.d, 0.0);
    A[i].a = Vec2(rho.dd, 0.0);
    C[i].p = Vec2(-(k - 1.0) * rho.v, Cb(2));
    C[i].v = Vec2(-(k - 1.0) * rho.d, Pd(2));
    C[i].a = Vec2(-(k - 1.0) * rho.dd, Pdd(2));
    // elbow E: |E - A| = l_AE, |E - C| = l_CE (circle intersection, A6)
    const Vec2 dv = C[i].p - A[i].p;
    const double L = dv.norm();
    if (!(L > 1e-9)) return Status::singular;
    const Vec2 dh = dv / L;
    const double along = (p.length_AE * p.length_AE - p.length_CE * p.length_CE + L * L) / (2.0 * L);
    const double h2 = p.length_AE * p.length_AE - along * along;
    if (!(h2 > 1e-12)) return Status::singular;
    E[i].p = A[i].p + along * dh + p.elbow * std::sqrt(h2) * Vec2(dh(1), -dh(0));
    // rates from the constraint rows (E-A).(Ed-Ad) = 0, (E-C).(Ed-Cd) = 0 and their derivative
    Eigen::Matrix2d Jc;
    Jc.row(0) = (E[i].p - A[i].p).transpose();
    Jc.row(1) = (E[i].p - C[i].p).transpose();
    const double det = Jc.determinant();
    if (!(std::abs(det) > 1e-12)) return Status::singular;
    const Eigen::Matrix2d Jinv = Jc.inverse();
    E[i].v = Jinv * Vec2(Jc.row(0).dot(A[i].v), Jc.row(1).dot(C[i].v));
    const Vec2 rA = E[i].v - A[i].v, rC = E[i].v - C[i].v;
    E[i].a = Jinv * Vec2(Jc.row(0).dot(A[i].a) - rA.squaredNorm(),
                         Jc.row(1).dot(C[i].a) - rC.squaredNorm());
    alpha[i] = angle_of(Ah - model.guide_pivot()[i], Ahd, Ahdd);
  }

  // platform (translates only: yaw locked by the parallel legs, tilt by the pantographs)
  BodyState& pl = ws.states[Idx::platform];
  pl.com = P;
  pl.com_velocity = Pd;
  pl.com_acceleration = Pdd;
  pl.rotation.setIdentity();
  pl.angular_velocity.setZero();
  pl.angular_acceleration.setZero();

  const double ik = 1.0 / k;
  for (int i = 0; i < 3; ++i) {
    // D = E + (C-E)/k, F = A + (C-E)/k, B = ((k-1) A + C)/k
    const Point2 Dp = affine(E[i], 1.0 - ik, C[i], ik, A[i], 0.0);
    const Point2 Fp = affine(A[i], 1.0, C[i], ik, E[i], -ik);
    const Point2 Bp = affine(A[i], 1.0 - ik, C[i], ik, E[i], 0.0);
    const Plane& pn = plane[i];
    pantograph_link(pn, E[i], C[i], ws.states[Idx::leg(i, 0)]);  // link 1, E-C
    pantograph_link(pn, Dp, Fp, ws.states[Idx::leg(i, 1)]);      // link 2, D-F
    pantograph_link(pn, A[i], E[i], ws.states[Idx::leg(i, 2)]);  // link 3, A-E
    pantograph_link(pn, A[i], Fp, ws.states[Idx::leg(i, 3)]);    // link 4, A-F

    // link 5: turns about the vertical through M_i; COM S5 at l_MS5 along M_i -> A_i
    const Angle3& al = alpha[i];
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
    point_body(pn, A[i], ws.states[Idx::cp1(i)]);   // CP1 at A_i
    point_body(pn, Fp, ws.states[Idx::cp2(i)]);     // CP2 at F_i
    BodyState& l = ws.states[Idx::cp3(i)];          // CP3 at L_i: M_iL_i = r M_iS_5i
    on_guide(p.cp3_ratio * p.length_MS5, l);
    l.rotation.setIdentity();
    l.angular_velocity.setZero();
    l.angular_acceleration.setZero();

    // base-frame points A..F
    const Point2* pts[6] = {&A[i], &Bp, &C[i], &Dp, &E[i], &Fp};
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
  return Status::ok;
}

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

Status paminsa_mechanism_momentum(const PaminsaModel& model, const PaminsaWorkspace& ws, Vec3& D,
                                  Vec3& D_dot) noexcept {
  ShakingWrench sw;
  const Status s =
      shaking_wrench(model.bodies().data(), ws.states.data(), Idx::mechanism_count, sw);
  if (s != Status::ok) return s;
  D = sw.angular_momentum;
  D_dot = sw.moment;
  return Status::ok;
}

// ------------------------------------------------------------------------------ controller
namespace {

/// D only (eq 19), without dD/dt: what the RK4 stages need at t + dt/2 and t + dt. Same sum as
/// shaking_wrench's angular momentum, H = sum (m OG x v_G + R J R^T w), with R (J (R^T w))
/// (three matrix-vector products instead of forming R J R^T).
Status mechanism_angular_momentum(const PaminsaModel& model, const PaminsaWorkspace& ws,
                                  Vec3& D) noexcept {
  Vec3 H = Vec3::Zero();
  for (std::size_t j = 0; j < Idx::mechanism_count; ++j) {
    const RigidBody& b = model.bodies()[j];
    const BodyState& st = ws.states[j];
    H.noalias() += b.mass * st.com.cross(st.com_velocity);
    if (b.inertia_body.isZero(0.0)) continue;  // point mass
    H.noalias() += st.rotation * (b.inertia_body * (st.rotation.transpose() * st.angular_velocity));
  }
  if (!H.allFinite()) return Status::non_finite_input;
  D = H;
  return Status::ok;
}

}  // namespace

PaminsaController::PaminsaController(const PaminsaModel& model,
                                     const ReactionlessWristConfig& config,
                                     const Vec3& initial_wrist_angles)
    : model_(model), wrist_(model.wrist_inertia(), config, initial_wrist_angles, Vec3::Zero()) {}

Status PaminsaController::reset(const PlatformMotion& initial, const Vec3& wrist_angles) noexcept {
  Status s = paminsa_mechanism_kinematics(model_, initial, ws_);
  if (s != Status::ok) return s;
  Vec3 D, Dd;
  s = paminsa_mechanism_momentum(model_, ws_, D, Dd);
  if (s != Status::ok) return s;
  return wrist_.reset(wrist_angles, D);  // wrist at rest: H_target = D(t0)
}

Status PaminsaController::tick(const PlatformMotion& now, const PlatformMotion& half,
                               const PlatformMotion& next) noexcept {
  const bool rk4 = wrist_.config().integrator == WristIntegrator::rk4;
  Vec3 D_half = Vec3::Zero(), D_next = Vec3::Zero();
  Status s = Status::ok;
  if (rk4) {
    s = paminsa_mechanism_kinematics(model_, half, ws_);
    if (s == Status::ok) s = mechanism_angular_momentum(model_, ws_, D_half);
    if (s == Status::ok) s = paminsa_mechanism_kinematics(model_, next, ws_);
    if (s == Status::ok) s = mechanism_angular_momentum(model_, ws_, D_next);
  }
  // the 35 mechanism bodies' momenta and wrench once: D, dD/dt, and the wrench's first 35 terms
  ShakingWrench mechanism;
  if (s == Status::ok) s = paminsa_mechanism_kinematics(model_, now, ws_);
  if (s == Status::ok)
    s = shaking_wrench(model_.bodies().data(), ws_.states.data(), Idx::mechanism_count, mechanism);
  if (s != Status::ok) {
    // hold: the wrist sees a non-finite input and keeps its angles
    const Vec3 nan = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    wrist_.step(nan, nan, nan, nan);
    return s | Status::non_finite_input;
  }
  D_ = mechanism.angular_momentum;  // eq 19
  D_dot_ = mechanism.moment;
  const Status ws = wrist_.step(D_, D_dot_, D_half, D_next);
  const WristCommand& c = wrist_.command();
  WristMotion wm{c.angles, c.rates, c.accelerations};
  paminsa_wrist_kinematics(model_, now, wm, ws_);
  // all 38 bodies = the mechanism's sums + the three wrist links' (not re-summed from scratch)
  ShakingWrench wrist;
  shaking_wrench(model_.bodies().data() + Idx::wrist(0), ws_.states.data() + Idx::wrist(0), 3,
                 wrist);
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
    if (s == Status::ok) s = shaking_wrench(model.bodies().data(), ws.states.data(), Idx::count, sw);
    if (s == Status::ok) s = paminsa_mechanism_momentum(model, ws, D, Dd);
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
