#pragma once
/// \file rigid_body.hpp
/// Rigid bodies, their motion, momenta and the shaking wrench of a set of bodies.
///
/// Briot & Arakelian 2009, eqs 1-4: the shaking force is F = sum_j m_j a_Gj and the shaking moment
/// about the base origin O is M_O = sum_j (dI_j/dt w_j + I_j dw_j/dt + m_j OG_j x a_Gj), i.e. the
/// time derivatives of the linear momentum P = sum m v_G and of the angular momentum about O,
/// H_O = sum (m OG x v_G + I_j w_j), with I_j = R_j I_body R_j^T expressed in the base frame.
/// (dI/dt w = w x (I w) because dI/dt = [w]x I - I [w]x and [w]x w = 0.)
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "mechbal/status.hpp"

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

/// Momenta and their time derivatives about the base origin O.
struct ShakingWrench {
  Vec3 linear_momentum = Vec3::Zero();   ///< P = sum m v_G            [kg m/s]
  Vec3 angular_momentum = Vec3::Zero();  ///< H_O = sum (m OG x v_G + I w) [kg m^2/s]
  Vec3 force = Vec3::Zero();             ///< shaking force F = dP/dt (eq 1)          [N]
  Vec3 moment = Vec3::Zero();            ///< shaking moment M_O = dH_O/dt (eqs 2-4) [N m]
};

/// Throws std::invalid_argument naming `field` when mass < 0, is non-finite, or the inertia is not
/// symmetric positive semi-definite (including the triangle inequality of principal moments).
/// Construction-time only (not real-time).
void validate_rigid_body(const RigidBody& body, const char* field);

/// Momenta, shaking force and shaking moment about O of `count` bodies at one instant.
/// Allocation-free and noexcept. Non-finite input gives Status::non_finite_input and a zero wrench;
/// finite input whose sums overflow gives Status::out_of_range and a zero wrench.
Status shaking_wrench(const RigidBody* bodies, const BodyState* states, std::size_t count,
                      ShakingWrench& out) noexcept;

/// Wrench the base must exert on the mechanism (support reaction) under gravity `gravity`
/// (e.g. (0,0,-9.81)): force = dP/dt - m_total g, moment about O = dH_O/dt - sum OG x m g.
/// The mechanism pushes on its base with the opposite wrench.
struct BaseReaction {
  Vec3 force = Vec3::Zero();
  Vec3 moment = Vec3::Zero();
};
Status base_reaction(const RigidBody* bodies, const BodyState* states, std::size_t count,
                     const Vec3& gravity, const ShakingWrench& inertial, BaseReaction& out) noexcept;

/// Batch over `instants` instants for `count` bodies, struct-of-arrays, C-contiguous row-major:
/// com, com_velocity, com_acceleration, angular_velocity, angular_acceleration: (N, B, 3);
/// rotation: (N, B, 3, 3) body->base. Outputs (N, 3) each, and the status of each instant (N,);
/// any may be null. An instant with non-finite input (non_finite_input) or an overflowing wrench
/// (out_of_range) gets zeros. Returns the OR of the per-instant statuses.
struct BodyTrajectoryView {
  std::size_t instants = 0;
  std::size_t count = 0;
  const double* com = nullptr;
  const double* com_velocity = nullptr;
  const double* com_acceleration = nullptr;
  const double* rotation = nullptr;
  const double* angular_velocity = nullptr;
  const double* angular_acceleration = nullptr;
};
Status shaking_wrench_batch(const RigidBody* bodies, const BodyTrajectoryView& motion,
                            double* force, double* moment, double* linear_momentum,
                            double* angular_momentum,
                            std::uint32_t* status_per_instant = nullptr) noexcept;

}  // namespace mechbal
