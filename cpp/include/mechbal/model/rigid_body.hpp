#pragma once
/// \file rigid_body.hpp
/// A rigid body's mass properties and its motion at one instant: the model's body data
/// (MechanismModel's bodies, MechanismData::body_inertias and body_states).
///
/// The shaking wrench of a mechanism (the rates of its momenta about O, Briot & Arakelian 2009,
/// eqs 1-4) is algorithm/shaking_wrench.hpp over the model; the result types it fills are in
/// model/data.hpp.
#include <Eigen/Core>

namespace mechbal {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Mass properties of one rigid body: mass [kg] and inertia tensor about its centre of mass,
/// expressed in the body frame [kg m^2]. Plain data; validate with `validate_rigid_body`.
struct RigidBody {
  double mass = 0.0;
  Mat3 inertia_body = Mat3::Zero();
};

/// Motion of one rigid body at one instant, everything in the base frame (SI units):
/// centre-of-mass position/velocity/acceleration, rotation body->base, angular velocity and
/// angular acceleration.
struct BodyState {
  Vec3 com = Vec3::Zero();
  Vec3 com_velocity = Vec3::Zero();
  Vec3 com_acceleration = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
  Vec3 angular_velocity = Vec3::Zero();
  Vec3 angular_acceleration = Vec3::Zero();
};

/// Throws std::invalid_argument naming `field` when mass < 0, is non-finite, or the inertia is not
/// symmetric positive semi-definite (including the triangle inequality of principal moments).
/// Construction-time only (not real-time).
void validate_rigid_body(const RigidBody& body, const char* field);

}  // namespace mechbal
