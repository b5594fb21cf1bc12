// Pinocchio C++ (header-only, the `pin` wheel's headers) on the robots of bench_urdf.cpp: rnea,
// crba and computeCentroidalMomentumTimeVariation on UR5 and Panda.
//
// Pinocchio's own URDF parser is not used here: it is built on the wheel's urdfdom (cmeel prefix,
// other headers and ABI than Debian's urdfdom that mechbal links), and the two cannot live in one
// executable. The Pinocchio model is built in C++ from mechbal's parsed description the way
// Pinocchio's parser builds it: a joint per revolute/prismatic URDF joint, JointModelRX/RY/RZ
// (PX/PY/PZ) when the axis is a unit axis and the unaligned joint otherwise, placement = the URDF
// origin composed with the fixed joints above it, fixed-joint links' inertias appended to the
// nearest moving ancestor, mimic joints as independent joints (the parser's default, mimic =
// false: Panda has 9 joints there, 8 coordinates in mechbal). Setup checks that torques, mass
// matrix and momentum rate equal mechbal's to 1e-9 at every bench state (aborts otherwise);
// tests/python/test_urdf.py checks mechbal against pin.buildModelFromUrdf on the same files.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <map>
#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include "bench_urdf.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/model/data.hpp"

namespace mechbal::bench {
namespace {

pinocchio::SE3 to_se3(const Eigen::Isometry3d& T) { return pinocchio::SE3(T.linear(), T.translation()); }

/// Pinocchio's model of the description (see the file comment), and G, o with Pinocchio's
/// joint positions = G q + o (q: mechbal's coordinates).
struct PinModel {
  pinocchio::Model model;
  Eigen::MatrixXd G;
  Eigen::VectorXd offset;
};

PinModel to_pinocchio(const MechanismModel& mech) {
  PinModel out;
  pinocchio::Model& pm = out.model;
  const auto& joints = mech.description().joints;  // joint k moves link k + 1 (depth-first)
  const int nl = mech.num_links();
  std::vector<pinocchio::JointIndex> carrier(static_cast<std::size_t>(nl), 0);
  std::vector<Eigen::Isometry3d> offset(static_cast<std::size_t>(nl), Eigen::Isometry3d::Identity());
  std::map<std::string, int> pin_v;  // joint name -> Pinocchio v index
  for (int l = 1; l < nl; ++l) {
    const Joint& j = joints[static_cast<std::size_t>(l - 1)];
    const auto p = static_cast<std::size_t>(mech.parent(l));
    const Eigen::Isometry3d placement = offset[p] * j.placement;
    if (j.type == JointType::fixed) {
      carrier[static_cast<std::size_t>(l)] = carrier[p];
      offset[static_cast<std::size_t>(l)] = placement;
      continue;
    }
    const Vec3& a = j.axis;
    pinocchio::JointIndex id;
    const pinocchio::SE3 X = to_se3(placement);
    if (j.type == JointType::revolute) {
      if (a == Vec3::UnitX()) id = pm.addJoint(carrier[p], pinocchio::JointModelRX(), X, j.name);
      else if (a == Vec3::UnitY()) id = pm.addJoint(carrier[p], pinocchio::JointModelRY(), X, j.name);
      else if (a == Vec3::UnitZ()) id = pm.addJoint(carrier[p], pinocchio::JointModelRZ(), X, j.name);
      else id = pm.addJoint(carrier[p], pinocchio::JointModelRevoluteUnaligned(a), X, j.name);
    } else {
      if (a == Vec3::UnitX()) id = pm.addJoint(carrier[p], pinocchio::JointModelPX(), X, j.name);
      else if (a == Vec3::UnitY()) id = pm.addJoint(carrier[p], pinocchio::JointModelPY(), X, j.name);
      else if (a == Vec3::UnitZ()) id = pm.addJoint(carrier[p], pinocchio::JointModelPZ(), X, j.name);
      else id = pm.addJoint(carrier[p], pinocchio::JointModelPrismaticUnaligned(a), X, j.name);
    }
    carrier[static_cast<std::size_t>(l)] = id;
    pin_v[j.name] = pm.joints[id].idx_v();
  }
  for (int b = 0; b < mech.num_bodies(); ++b) {
    const Body& body = mech.body(b);
    const auto l = static_cast<std::size_t>(mech.body_link(b));
    pm.appendBodyToJoint(carrier[l], pinocchio::Inertia(body.mass, body.com, body.inertia), to_se3(offset[l]));
  }
  pm.gravity.linear(mech.gravity());
  out.G = Eigen::MatrixXd::Zero(pm.nv, mech.dof());
  out.offset = Eigen::VectorXd::Zero(pm.nv);
  const auto& names = mech.coordinate_names();
  auto coordinate = [&](const std::string& n) {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  for (const Joint& j : joints) {
    if (j.type == JointType::fixed) continue;
    const int iv = pin_v.at(j.name);
    if (j.mimic_joint.empty()) {
      out.G(iv, coordinate(j.name)) = 1.0;
    } else {
      out.G(iv, coordinate(j.mimic_joint)) = j.mimic_ratio;
      out.offset(iv) = j.mimic_offset;
    }
  }
  return out;
}

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

struct Pin : UrdfRobot {
  explicit Pin(const std::string& robot) : UrdfRobot(robot), pin(to_pinocchio(model)), data(pin.model) {
    for (int k = 0; k < JointStates::count; ++k) {
      const auto sk = static_cast<std::size_t>(k);
      q.push_back(pin.G * x.q[sk] + pin.offset);
      v.push_back(pin.G * x.qd[sk]);
      a.push_back(pin.G * x.qdd[sk]);
    }
    // the same numbers as mechbal's, at every bench state
    MechanismData md(model);
    double worst = 0.0;
    for (int k = 0; k < JointStates::count; ++k) {
      const auto sk = static_cast<std::size_t>(k);
      inverse_dynamics(model, md, x.q[sk], x.qd[sk], x.qdd[sk]);
      pinocchio::rnea(pin.model, data, q[sk], v[sk], a[sk]);
      worst = std::max(worst, rel(md.joint_torque, pin.G.transpose() * data.tau));
      mass_matrix(model, md, x.q[sk]);
      pinocchio::crba(pin.model, data, q[sk]);
      data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose().triangularView<Eigen::StrictlyLower>();
      worst = std::max(worst, rel(md.mass_matrix, pin.G.transpose() * data.M * pin.G));
      shaking_wrench(model, md, x.q[sk], x.qd[sk], x.qdd[sk]);
      pinocchio::computeCentroidalMomentumTimeVariation(pin.model, data, q[sk], v[sk], a[sk]);
      const Vec3 c = data.com[0], dP = data.dhg.linear();
      const Vec3 dH_O = data.dhg.angular() + c.cross(dP);
      worst = std::max(worst, rel(md.shaking.force, dP));
      worst = std::max(worst, rel(md.shaking.moment, dH_O));
    }
    if (!(worst < 1e-9)) {
      std::fprintf(stderr, "mechbal-bench: Pinocchio disagrees with mechbal on %s (relative %g)\n",
                   robot.c_str(), worst);
      std::abort();
    }
  }
  PinModel pin;
  pinocchio::Data data;
  std::vector<Eigen::VectorXd> q, v, a;
  int k = 0;
  std::size_t next() { return static_cast<std::size_t>(k = (k + 1) & (JointStates::count - 1)); }
};

Tick id_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::rnea(s->pin.model, s->data, s->q[k], s->v[k], s->a[k]);
    benchmark::DoNotOptimize(s->data.tau.data());
    benchmark::ClobberMemory();
  };
}

// crba fills the upper triangle; the lower one is copied so that the output equals mechbal's.
Tick mass_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::crba(s->pin.model, s->data, s->q[k]);
    s->data.M.triangularView<Eigen::StrictlyLower>() =
        s->data.M.transpose().triangularView<Eigen::StrictlyLower>();
    benchmark::DoNotOptimize(s->data.M.data());
    benchmark::ClobberMemory();
  };
}

Tick momentum_rate_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::computeCentroidalMomentumTimeVariation(s->pin.model, s->data, s->q[k], s->v[k], s->a[k]);
    benchmark::DoNotOptimize(s->data.dhg);
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(id_ur5_pinocchio) { return id_case("ur5"); }
MECHBAL_BENCH_CASE(mass_ur5_pinocchio) { return mass_case("ur5"); }
MECHBAL_BENCH_CASE(momentum_rate_ur5_pinocchio) { return momentum_rate_case("ur5"); }
MECHBAL_BENCH_CASE(id_panda_pinocchio) { return id_case("panda"); }
MECHBAL_BENCH_CASE(mass_panda_pinocchio) { return mass_case("panda"); }
MECHBAL_BENCH_CASE(momentum_rate_panda_pinocchio) { return momentum_rate_case("panda"); }
