#pragma once
// PAMINSA on the general model, built in C++ for the benchmarks: the same tree, bodies, frames,
// gear couplings and loop closures as mechbal.papers.paminsa.paminsa_mechanism (its docstring
// explains every joint). The C++ case reader (mechbal/io/case.hpp) reads the paper's
// paminsa-linkage.toml as well; this header is a direct transcription of the generator instead, so
// that the closed form and the general model of a benchmark come from one PaminsaModel's
// parameters and derived layout (balanced or not, as its counterweights are) with no file to find;
// bench_loops.cpp checks at setup that it moves exactly as the closed form (every body's momentum
// and the shaking wrench to 1e-9 relative along the bench trajectory) and aborts otherwise, so the
// bench cannot time a model that drifted from the Python one.
#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mechbal/model/model.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"

namespace mechbal::bench {

inline Eigen::Isometry3d paminsa_pose(const Vec3& xyz, const Mat3& R = Mat3::Identity()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = xyz;
  return T;
}

/// The general-model description of PAMINSA (mechbal.papers.paminsa, balanced or not as the
/// model's counterweights are). Actuated: leg1_guide, leg3_guide (M_1, M_3), leg1_slider (M_v),
/// the three wrist joints.
inline MechanismDescription paminsa_description(const PaminsaModel& model) {
  const PaminsaParameters& p = model.parameters();
  const double k = p.k;
  const auto& cw = p.counterweights;
  Mat3 column, pantograph, in_plane;
  column << 0, 0, -1, 0, 1, 0, 1, 0, 0;      // columns (e_z, e_y, -e_x)
  pantograph << 0, 0, 1, 0, 1, 0, -1, 0, 0;  // columns (u, n, e_z) in the column frame
  in_plane << 1, 0, 0, 0, 0, 1, 0, -1, 0;    // z along the link's y (the leg plane's normal)
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ(), minus_n(0, -1, 0), o = Vec3::Zero();
  const double x_D = -(k - 1.0) / k * p.length_DF, x_F = p.length_DF / k;
  const double x_E = -p.length_CE / k, x_C = p.length_CE * (k - 1.0) / k;
  const auto R = JointType::revolute, P = JointType::prismatic;
  const auto joint = [](std::string name, JointType type, std::string parent, Eigen::Isometry3d T, Vec3 axis) {
    Joint j;
    j.name = std::move(name);
    j.type = type;
    j.parent = std::move(parent);
    j.placement = T;
    j.axis = axis;
    return j;
  };
  const auto body = [](std::string name, std::string link, double mass, double x, const Mat3& I, const char* kind) {
    return Body{std::move(name), kind, std::move(link), mass, Vec3(x, 0.0, 0.0), I};
  };
  const auto diag = [](const Vec3& v) { return Mat3(v.asDiagonal()); };

  MechanismDescription d;
  d.gravity = Vec3(0.0, 0.0, -9.81);
  d.joints = {joint("platform_x", P, "base", paminsa_pose(o), ex), joint("platform_y", P, "platform_x", paminsa_pose(o), ey),
              joint("platform_z", P, "platform_y", paminsa_pose(o), ez), joint("wrist_phi", R, "platform_z", paminsa_pose(o), ez),
              joint("wrist_theta", R, "wrist_phi", paminsa_pose(o), ex), joint("wrist_psi", R, "wrist_theta", paminsa_pose(o), ez)};
  std::vector<Body> bodies(PaminsaBodyIndex::count);
  bodies[PaminsaBodyIndex::platform] = body("platform", "platform_z", p.platform_mass, 0.0, Mat3::Zero(), "payload");
  const char* wrist_links[3] = {"wrist_phi", "wrist_theta", "wrist_psi"};
  for (std::size_t w = 0; w < 3; ++w) {
    bodies[PaminsaBodyIndex::wrist(w)] =
        body("wrist" + std::to_string(w + 1), wrist_links[w], 0.0, 0.0, diag(p.wrist_inertia[w]), "link");
  }
  const char* link_names[8] = {"link1_EC", "link2_DF", "link3_AE", "link4_AF", "link5_guide", "link6_BG",
                               "link7_slider", "link8_atF"};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string L = "leg" + std::to_string(i + 1);
    const Eigen::Vector2d& Bh = model.slider_line()[i];
    const Eigen::Vector2d& Mh = model.guide_pivot()[i];
    Joint slider = joint(L + "_slider", P, "base", paminsa_pose(Vec3(Bh(0), Bh(1), 0.0)), ez);
    if (i > 0) slider.mimic_joint = "leg1_slider";  // one linear actuator M_v for the three sliders
    d.joints.push_back(slider);
    d.joints.push_back(joint(L + "_column", R, L + "_slider", paminsa_pose(o, column), ex));
    d.joints.push_back(joint(L + "_link2", R, L + "_column", paminsa_pose(o, pantograph), minus_n));
    d.joints.push_back(joint(L + "_link1", R, L + "_link2", paminsa_pose(Vec3(x_D, 0, 0)), minus_n));
    d.joints.push_back(joint(L + "_link3", R, L + "_link1", paminsa_pose(Vec3(x_E, 0, 0)), minus_n));
    d.joints.push_back(joint(L + "_link4", R, L + "_link2", paminsa_pose(Vec3(x_F, 0, 0)), minus_n));
    d.joints.push_back(joint(L + "_guide", R, "base", paminsa_pose(Vec3(Mh(0), Mh(1), p.z_A)), ez));
    d.joints.push_back(joint(L + "_stroke", P, L + "_guide", paminsa_pose(o), ex));
    const std::pair<const char*, double> on[8] = {{"_link1", 0.5 * (x_E + x_C)}, {"_link2", 0.5 * (x_D + x_F)},
                                                  {"_link3", -0.5 * p.length_AE}, {"_link4", -0.5 * p.length_AF},
                                                  {"_guide", p.length_MS5},       {"_column", 0.5 * p.length_BG},
                                                  {"_slider", 0.0},               {"_link2", x_F}};
    for (std::size_t j = 0; j < 8; ++j) {
      bodies[PaminsaBodyIndex::leg(i, j)] = body(L + "." + link_names[j], L + on[j].first, p.link_mass[j], on[j].second,
                                                 diag(p.link_inertia[j]), "link");
    }
    bodies[PaminsaBodyIndex::cp1(i)] = body(L + ".CP1_atA", L + "_link3", cw.at_A[i], -p.length_AE, Mat3::Zero(), "counterweight");
    bodies[PaminsaBodyIndex::cp2(i)] = body(L + ".CP2_atF", L + "_link2", cw.at_F[i], x_F, Mat3::Zero(), "counterweight");
    bodies[PaminsaBodyIndex::cp3(i)] = body(L + ".CP3_atL", L + "_guide", cw.at_L[i], p.cp3_ratio * p.length_MS5,
                                            Mat3::Zero(), "counterweight");
    d.frames.push_back(Frame{L + "_A_link3", L + "_link3", paminsa_pose(Vec3(-p.length_AE, 0, 0), in_plane)});
    d.frames.push_back(Frame{L + "_A_link4", L + "_link4", paminsa_pose(Vec3(-p.length_AF, 0, 0))});
    d.frames.push_back(Frame{L + "_A_guide", L + "_stroke", paminsa_pose(o)});
    d.frames.push_back(Frame{L + "_C_link1", L + "_link1", paminsa_pose(Vec3(x_C, 0, 0))});
    d.frames.push_back(Frame{L + "_C_platform", "platform_z", paminsa_pose(model.platform_joint_offset()[i])});
    d.loops.push_back(LoopConstraint{L + "_parallelogram", LoopType::planar_point, L + "_A_link3", L + "_A_link4"});
    d.loops.push_back(LoopConstraint{L + "_guide", LoopType::point, L + "_A_link3", L + "_A_guide"});
    d.loops.push_back(LoopConstraint{L + "_platform", LoopType::point, L + "_C_link1", L + "_C_platform"});
  }
  const Eigen::Vector2d& v = model.vertical_mass_xy();
  Joint vertical = joint("vertical_counter_mass", P, "base", paminsa_pose(Vec3(v(0), v(1), 0.0)), ez);
  vertical.mimic_joint = "leg1_slider";  // moves as -z_P: z = z0 - (z_P - z_P0), z_P = z_A + k (z_B - z_A) + l_CJ
  vertical.mimic_ratio = -k;
  vertical.mimic_offset = p.vertical_mass_z0 + p.nominal_platform(2) + (k - 1.0) * p.z_A - p.length_CJ;
  d.joints.push_back(vertical);
  bodies[PaminsaBodyIndex::vertical_mass] = body("vertical_counter_mass", "vertical_counter_mass", cw.vertical, 0.0,
                                                 Mat3::Zero(), "counterweight");
  d.bodies = std::move(bodies);
  d.actuated = {"leg1_guide", "leg3_guide", "leg1_slider", "wrist_phi", "wrist_theta", "wrist_psi"};
  return d;
}

struct ActuatedState {
  Eigen::VectorXd q, v, a;
};

/// The actuated joints' motion for a platform and wrist motion (the closed form's inverse
/// kinematics and its derivatives; mechbal.papers.paminsa.paminsa_actuated_motion): alpha_i is the
/// angle of A_h,i - M_i, A_h,i = (k B_h,i - C_h,i)/(k - 1); z_B = z_A + (z_P - l_CJ - z_A)/k.
inline ActuatedState actuated(const PaminsaModel& pm, const MechanismModel& model, const PlatformMotion& m,
                       const WristMotion& w) {
  const PaminsaParameters& p = pm.parameters();
  const double k = p.k;
  double q[3][3];  // alpha1, alpha3, z_B: value, rate, acceleration
  for (int leg : {0, 2}) {
    const Eigen::Vector2d Ah = (k * pm.slider_line()[leg] - (m.position + pm.platform_joint_offset()[leg]).head<2>()) / (k - 1.0);
    const Eigen::Vector2d g = Ah - pm.guide_pivot()[leg], gd = -m.velocity.head<2>() / (k - 1.0),
                          gdd = -m.acceleration.head<2>() / (k - 1.0);
    const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a(0) * b(1) - a(1) * b(0); };
    const double r2 = g.squaredNorm(), ad = cross(g, gd) / r2;
    double* out = q[leg == 0 ? 0 : 1];
    out[0] = std::atan2(g(1), g(0));
    out[1] = ad;
    out[2] = (cross(g, gdd) - 2.0 * ad * g.dot(gd)) / r2;
  }
  q[2][0] = p.z_A + (m.position(2) - p.length_CJ - p.z_A) / k;
  q[2][1] = m.velocity(2) / k;
  q[2][2] = m.acceleration(2) / k;
  ActuatedState s{Eigen::VectorXd(model.num_actuated()), Eigen::VectorXd(model.num_actuated()),
                  Eigen::VectorXd(model.num_actuated())};
  for (int i = 0; i < model.num_actuated(); ++i) {
    const std::string& name = model.coordinate_name(model.actuated_coordinates()[static_cast<std::size_t>(i)]);
    const int wrist = name == "wrist_phi" ? 0 : name == "wrist_theta" ? 1 : name == "wrist_psi" ? 2 : -1;
    const int act = name == "leg1_guide" ? 0 : name == "leg3_guide" ? 1 : name == "leg1_slider" ? 2 : -1;
    if (wrist >= 0) {
      s.q(i) = w.angles(wrist);
      s.v(i) = w.rates(wrist);
      s.a(i) = w.accelerations(wrist);
    } else if (act >= 0) {
      s.q(i) = q[act][0];
      s.v(i) = q[act][1];
      s.a(i) = q[act][2];
    } else {
      throw std::invalid_argument("PAMINSA general model: unexpected actuated joint " + name);
    }
  }
  return s;
}

/// Every coordinate at platform position P from the closed form's leg points (the assembly mode).
inline Eigen::VectorXd initial_guess(const PaminsaModel& pm, const MechanismModel& model, const PlatformMotion& m,
                              const WristMotion& w) {
  PaminsaWorkspace ws;
  if (paminsa_mechanism_kinematics(pm, m, ws) != Status::ok) throw std::invalid_argument("PAMINSA general model: platform pose unreachable");
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.dof());
  const auto set = [&](const std::string& name, double value) {
    for (int c = 0; c < model.dof(); ++c)
      if (model.coordinate_name(c) == name) q(c) = value;
  };
  set("platform_x", m.position(0));
  set("platform_y", m.position(1));
  set("platform_z", m.position(2));
  set("wrist_phi", w.angles(0));
  set("wrist_theta", w.angles(1));
  set("wrist_psi", w.angles(2));
  for (int i = 0; i < 3; ++i) {
    const auto& pts = ws.leg_points[static_cast<std::size_t>(i)];  // A, B, C, D, E, F
    const Vec3 &A = pts[0], &B = pts[1], &C = pts[2], &D = pts[3], &E = pts[4], &F = pts[5];
    const Eigen::Vector2d u = (A - B).head<2>().normalized();
    const auto elevation = [&](const Vec3& d) { return std::atan2(d(2), d.head<2>().dot(u)); };
    const double g_df = elevation(F - D), g_ec = elevation(C - E), g_ae = elevation(E - A);
    const Eigen::Vector2d g = A.head<2>() - pm.guide_pivot()[static_cast<std::size_t>(i)];
    const std::string L = "leg" + std::to_string(i + 1);
    set(L + "_slider", B(2));
    set(L + "_column", std::atan2(u(1), u(0)));
    set(L + "_link2", g_df);
    set(L + "_link1", g_ec - g_df);
    set(L + "_link3", g_ae - g_ec);
    set(L + "_link4", g_ec - g_df);
    set(L + "_guide", std::atan2(g(1), g(0)));
    set(L + "_stroke", g.norm());
  }
  return q;
}

}  // namespace mechbal::bench
