#pragma once
/// \file serial_chain.hpp
/// Serial kinematic chains: an immutable model (joints and link inertias) and allocation-free
/// forward kinematics that give every link's pose, centre-of-mass velocity/acceleration, angular
/// velocity and angular acceleration in the base frame, ready for `shaking_wrench`.
///
/// Frames: F_0 = base; for joint i (1-based) F_i = F_{i-1} * origin_i * J_i(q_i), where origin_i is
/// the constant transform from the previous link frame to the joint frame at q = 0 and J_i is a
/// rotation about (revolute) or translation along (prismatic) the unit `axis`, expressed in the
/// joint frame. Link i is rigidly attached to F_i; its centre of mass and inertia are given in F_i.
/// Modified (Craig) DH maps directly: origin = Rx(alpha) Tx(a) Tz(d) Rz(theta0), axis = z.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "mechbal/model/joint_type.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

struct JointSpec {
  std::string name;
  JointType type = JointType::revolute;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  Vec3 axis = Vec3::UnitZ();
  RigidBody link;            ///< mass and inertia about the link's centre of mass, in F_i
  Vec3 com = Vec3::Zero();   ///< centre of mass of link i in F_i
};

/// Immutable chain model. The constructor validates every field and throws std::invalid_argument
/// naming the joint and field on bad input (not real-time).
class ChainModel {
 public:
  explicit ChainModel(std::vector<JointSpec> joints, const Vec3& gravity = Vec3(0.0, 0.0, -9.81),
                      const Eigen::Isometry3d& base = Eigen::Isometry3d::Identity());

  int dof() const noexcept { return static_cast<int>(joints_.size()); }
  const std::vector<JointSpec>& joints() const noexcept { return joints_; }
  const JointSpec& joint(int i) const { return joints_.at(static_cast<std::size_t>(i)); }
  const Vec3& gravity() const noexcept { return gravity_; }
  const Eigen::Isometry3d& base() const noexcept { return base_; }
  /// Link mass properties, one per joint, in joint order (for shaking_wrench).
  const std::vector<RigidBody>& bodies() const noexcept { return bodies_; }

 private:
  std::vector<JointSpec> joints_;
  std::vector<RigidBody> bodies_;
  Vec3 gravity_;
  Eigen::Isometry3d base_;
};

/// Buffers for chain kinematics, allocated once from the model.
struct ChainWorkspace {
  explicit ChainWorkspace(const ChainModel& model);
  std::vector<Eigen::Isometry3d> frames;  ///< F_i in the base frame, i = 1..n (index i-1)
  std::vector<BodyState> states;          ///< each link's motion, in the base frame
};

/// Forward position/velocity/acceleration kinematics of every link (closed-form recursion).
/// Allocation-free, noexcept. Sizes must equal model.dof() (else Status::bad_size, nothing
/// written); non-finite input gives Status::non_finite_input and leaves the workspace untouched;
/// finite input whose motion overflows gives Status::out_of_range and resets the workspace to
/// rest (identity frames, zero motion).
Status chain_kinematics(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                        const Eigen::Ref<const Eigen::VectorXd>& qd,
                        const Eigen::Ref<const Eigen::VectorXd>& qdd,
                        ChainWorkspace& ws) noexcept;

/// The chain as a general MechanismDescription: joint i named as in the chain (or "joint<i>"),
/// parent the previous joint, the base transform folded into the first placement, each link's
/// inertia a body of kind "link" named after its joint. Not real-time.
MechanismDescription chain_description(const ChainModel& model);

/// Scales `axis` to unit length without overflow (by its largest component first). False, axis
/// untouched, when it is not finite or its norm is below 1e-12.
bool normalize_axis(Vec3& axis) noexcept;

/// Modified (Craig 1989) DH origin: Rx(alpha) Tx(a) Tz(d) Rz(theta).
Eigen::Isometry3d modified_dh_origin(double a, double alpha, double d, double theta);

}  // namespace mechbal
