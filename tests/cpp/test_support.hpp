#pragma once
// Shared helpers for the C++ tests: random rigid bodies, random serial chains, smooth motions.
#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "mechbal/model/model.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/model/serial_chain.hpp"

namespace mechbal::test {

inline RigidBody random_body(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.1, 2.0);
  RigidBody b;
  b.mass = u(rng);
  // principal moments satisfying the triangle inequality, random principal axes
  const double a = u(rng), c = u(rng);
  const Vec3 p(a, c, std::abs(a - c) + 0.5 * (a + c - std::abs(a - c)));  // |a-c| <= p3 <= a+c
  const Mat3 Q = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  b.inertia_body = Q * p.asDiagonal() * Q.transpose() * 0.05;
  return b;
}

inline Eigen::Isometry3d random_pose(std::mt19937& rng, double scale = 0.4) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  T.translation() = Vec3(u(rng), u(rng), u(rng));
  return T;
}

/// A random chain; `types` pattern: 'R' revolute, 'P' prismatic.
inline ChainModel random_chain(std::mt19937& rng, const char* types) {
  std::vector<JointSpec> joints;
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int i = 0; types[i]; ++i) {
    JointSpec j;
    j.name = "j" + std::to_string(i + 1);
    j.type = types[i] == 'P' ? JointType::prismatic : JointType::revolute;
    j.origin = random_pose(rng);
    j.axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    j.link = random_body(rng);
    j.com = Vec3(u(rng), u(rng), u(rng));
    joints.push_back(j);
  }
  return ChainModel(joints, Vec3(0.0, 0.0, -9.81), random_pose(rng, 0.2));
}

inline Eigen::VectorXd random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

/// max |a - b| relative to max(1, max |b|).
inline double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

/// A gear coupling (mimic) on the last moving joint of a random tree: it follows the first other
/// moving joint, q = -1.7 q_master + 0.3.
inline void gear_last_joint(MechanismDescription& d) {
  for (auto it = d.joints.rbegin(); it != d.joints.rend(); ++it) {
    if (it->type == JointType::fixed) continue;
    for (const auto& m : d.joints) {
      if (m.name != it->name && m.type != JointType::fixed) {
        it->mimic_joint = m.name;
        it->mimic_ratio = -1.7;
        it->mimic_offset = 0.3;
        break;
      }
    }
    break;
  }
}

}  // namespace mechbal::test
