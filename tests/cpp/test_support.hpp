#pragma once
// Shared helpers for the C++ tests: random rigid bodies, random serial chains, smooth motions.
#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/model/rigid_body.hpp"
#include <cstddef>
#include <string>

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

/// Momenta about O and their rates of `count` bodies given their states, summed body by body
/// with each inertia formed in the base frame, I = R J R^T (Briot & Arakelian 2009, eqs 1-4):
/// P = sum m v, H_O = sum (m c x v + I w), F = sum m a, M_O = sum (m c x a + I alpha + w x I w).
/// The tests' independent reference for the general algorithm/shaking_wrench and for PAMINSA's
/// closed forms; test_rigid_body.cpp checks it against finite differences of its momenta.
inline ShakingWrench body_set_wrench(const RigidBody* bodies, const BodyState* states,
                                     std::size_t count) {
  ShakingWrench w;
  for (std::size_t j = 0; j < count; ++j) {
    const RigidBody& b = bodies[j];
    const BodyState& s = states[j];
    const Mat3 I = s.rotation * b.inertia_body * s.rotation.transpose();
    w.linear_momentum += b.mass * s.com_velocity;
    w.angular_momentum += b.mass * s.com.cross(s.com_velocity) + I * s.angular_velocity;
    w.force += b.mass * s.com_acceleration;
    w.moment += b.mass * s.com.cross(s.com_acceleration) + I * s.angular_acceleration +
                s.angular_velocity.cross(I * s.angular_velocity);
  }
  return w;
}

inline Eigen::Isometry3d random_pose(std::mt19937& rng, double scale = 0.4) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  T.translation() = Vec3(u(rng), u(rng), u(rng));
  return T;
}

/// A joint of the random mechanisms: type 'P' prismatic, 'F' fixed, else revolute; a random
/// placement in its parent (random_pose) and a random unit axis. Draws in this order: the
/// placement, then the axis.
inline Joint random_joint(std::mt19937& rng, const std::string& name, char type, const std::string& parent) {
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  Joint j;
  j.name = name;
  j.type = type == 'P' ? JointType::prismatic : type == 'F' ? JointType::fixed : JointType::revolute;
  j.parent = parent;
  j.placement = random_pose(rng);
  j.axis = Vec3(u(rng), u(rng), u(rng)).normalized();
  return j;
}

/// A body of kind "link" named `name` on `link`: random mass and inertia (random_body), then a
/// random centre of mass within 0.3 m of the link frame's origin.
inline Body random_link_body(std::mt19937& rng, const std::string& name, const std::string& link) {
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const RigidBody b = random_body(rng);
  const Vec3 com(u(rng), u(rng), u(rng));
  return Body{name, "link", link, b.mass, com, b.inertia_body};
}

/// A random serial chain in the general format, one body per link (kind "link", named after its
/// joint); `types` pattern: 'R' revolute, 'P' prismatic. A random base pose is folded into the
/// first joint's placement; gravity (0, 0, -9.81).
inline MechanismDescription random_chain(std::mt19937& rng, const char* types) {
  MechanismDescription d;
  std::string parent = d.root_name;
  for (int i = 0; types[i]; ++i) {
    const Joint j = random_joint(rng, "j" + std::to_string(i + 1), types[i] == 'P' ? 'P' : 'R', parent);
    d.joints.push_back(j);
    d.bodies.push_back(random_link_body(rng, j.name, j.name));
    parent = j.name;
  }
  d.gravity = Vec3(0.0, 0.0, -9.81);
  d.joints.front().placement = random_pose(rng, 0.2) * d.joints.front().placement;
  return d;
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
