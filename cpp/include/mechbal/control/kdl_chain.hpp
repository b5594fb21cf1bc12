#pragma once
/// \file kdl_chain.hpp
/// Inverse dynamics of a serial chain through Orocos KDL, wrapped so that a tick allocates nothing.
///
/// KDL's `ChainIdSolver_RNE` gives joint torques; `ChainDynParam` the mass matrix, Coriolis and
/// gravity terms. The wrench the chain transmits to its base is obtained from the same RNE pass by
/// prepending six motionless virtual joints at the base origin (translations along x, y, z, then
/// rotations about x, y, z): their generalised forces are exactly the support force and the support
/// moment about O that the base exerts on the chain (gravity included).
///
/// Built from the general MechanismModel when that is a serial chain (`model.is_serial_chain()`):
/// KDL is then an independent engine beside MechanismDynamics on the same description, and its
/// check (tests/cpp/test_kdl_general.cpp).
#include <Eigen/Core>
#include <memory>

#include "mechbal/control/dynamics.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

class KdlChainDynamics;
/// Instantiated in kdl_chain.cpp only (its vtable and typeinfo: see SupportWrenchDynamics).
extern template class SupportWrenchDynamics<KdlChainDynamics>;

class KdlChainDynamics final : public SupportWrenchDynamics<KdlChainDynamics> {
 public:
  /// From the general model when it is a serial chain: joint k moves link k + 1 whose parent is
  /// link k, every joint revolute or prismatic with its own coordinate (no fixed joint, no gear
  /// coupling). The bodies on each link are lumped into one rigid body (same mass, first moment
  /// and inertia); bodies on the base do not move and are left out, as in MechanismDynamics'
  /// support wrench. Throws std::invalid_argument naming the link or joint that makes the model
  /// not a chain ("KdlChainDynamics: joint 'wrist' is fixed ..."). Not real-time.
  explicit KdlChainDynamics(const MechanismModel& model);
  ~KdlChainDynamics();
  KdlChainDynamics(const KdlChainDynamics&) = delete;
  KdlChainDynamics& operator=(const KdlChainDynamics&) = delete;

  int dof() const noexcept override { return dof_; }

  /// InverseDynamics interface: joint torques only (SupportWrenchDynamics).
  using SupportWrenchDynamics<KdlChainDynamics>::inverse_dynamics;

  /// tau = M(q) qdd + C(q, qd) qd + G(q). When `support_force`/`support_moment` are non-null
  /// they receive the wrench the base exerts on the chain (moment about the base origin).
  /// Every query: wrong sizes Status::bad_size, non-finite input Status::non_finite_input, KDL
  /// failure Status::solver_error, a result that overflowed Status::out_of_range; the outputs are
  /// untouched unless Status::ok.
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                          Vec3* support_moment) noexcept;
  Status mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q,
                     Eigen::Ref<Eigen::MatrixXd> M) noexcept;
  Status coriolis(const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                  Eigen::Ref<Eigen::VectorXd> c) noexcept;
  Status gravity(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::VectorXd> g) noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int dof_;
};

}  // namespace mechbal
