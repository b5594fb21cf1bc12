#pragma once
// A pinocchio::Model built in C++ from mechbal's parsed URDF description, the way Pinocchio's URDF
// parser builds it (bench_urdf_pinocchio.cpp's file comment says why, and what is checked):
// shared by bench_urdf_pinocchio.cpp and bench_reactionless_pinocchio.cpp (the Panda). Only built
// with Pinocchio's headers.
#include <algorithm>
#include <map>
#include <pinocchio/multibody.hpp>
#include <string>
#include <vector>

#include "mechbal/model/model.hpp"

namespace mechbal::bench {

inline pinocchio::SE3 to_se3(const Eigen::Isometry3d& T) { return pinocchio::SE3(T.linear(), T.translation()); }

/// Pinocchio's model of the description (see the file comment), and G, o with Pinocchio's
/// joint positions = G q + o (q: mechbal's coordinates).
struct PinModel {
  pinocchio::Model model;
  Eigen::MatrixXd G;
  Eigen::VectorXd offset;
};

inline PinModel to_pinocchio(const MechanismModel& mech) {
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
  // mechbal's named frames as operational frames (same name, carried by the moving ancestor)
  for (int f = 0; f < mech.num_frames(); ++f) {
    const Frame& fr = mech.frame(f);
    const auto l = static_cast<std::size_t>(mech.frame_link(f));
    const pinocchio::JointIndex j = carrier[l];
    pm.addFrame(pinocchio::Frame(fr.name, j, to_se3(offset[l] * fr.placement), pinocchio::OP_FRAME), false);
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

}  // namespace mechbal::bench
