#pragma once
// The reaction-wheel arm (test and bench support): a planar two-link arm (shoulder and elbow
// about z) carrying an actuated reaction wheel (about z) on its forearm, the numbers of
// python/mechbal/cases/reaction-wheel-arm.toml.
#include <Eigen/Geometry>
#include <string>

#include "mechbal/model/model.hpp"

namespace mechbal::test {

inline MechanismModel reaction_wheel_arm() {
  const auto joint = [](const char* name, const char* parent, double x) {
    Joint j;
    j.name = name;
    j.parent = parent;
    j.placement = Eigen::Isometry3d::Identity();
    j.placement.translation() = Vec3(x, 0.0, 0.0);
    j.axis = Vec3::UnitZ();
    return j;
  };
  const auto diag = [](double x, double y, double z) { return Mat3(Vec3(x, y, z).asDiagonal()); };
  MechanismDescription d;
  d.joints = {joint("shoulder", "base", 0.0), joint("elbow", "shoulder", 0.5), joint("wheel", "elbow", 0.3)};
  d.bodies = {Body{"shoulder", "link", "shoulder", 2.0, Vec3(0.25, 0, 0), diag(0.002, 0.04, 0.04)},
              Body{"elbow", "link", "elbow", 1.5, Vec3(0.2, 0, 0), diag(0.001, 0.02, 0.02)},
              Body{"wheel", "link", "wheel", 2.0, Vec3::Zero(), diag(0.05, 0.05, 0.1)}};
  return MechanismModel(d);
}

}  // namespace mechbal::test
