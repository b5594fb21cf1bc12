#pragma once
/// \file rnea.hpp
/// mechbal's own joint-space dynamics of a serial ChainModel: recursive Newton-Euler inverse
/// dynamics (Luh, Walker & Paul 1980; Featherstone 2008, "Rigid Body Dynamics Algorithms",
/// algorithm 5.1 written with 3-vectors instead of spatial 6-vectors) and the composite rigid body
/// algorithm for the mass matrix (Featherstone 2008, algorithm 6.2), on fixed-size Eigen types.
///
/// Why a second back end next to KdlChainDynamics: the real-time controllers (computed torque,
/// decoupled control) call inverse dynamics every tick; this one is several times faster than KDL
/// (bench/README.md) because everything constant is precomputed at construction:
///  - each link is re-expressed in a "joint-aligned" frame L_i = F_i A_i, A_i a constant rotation
///    with A_i e_z = axis_i, so that the joint is a rotation about (or translation along) local z;
///    the parent-to-child transform is then the constant C_i = A_{i-1}^T origin_i A_i followed by
///    Rz(q_i) (or Tz(q_i)): a rotation about z costs 4 multiplications, the motion subspace is e_z,
///    and the joint torque is the z component of the transmitted moment (or force);
///  - link inertia is stored about the link frame origin (parallel axis theorem, once) together
///    with the first moment m c, so no per-tick change of reference point is needed;
///  - transforms are a 3x3 rotation and a 3-vector, never 4x4 products; gravity enters as a base
///    acceleration -g (Luh et al.'s trick), which also makes the base support wrench fall out of the
///    backward pass.
/// Frame convention: serial_chain.hpp (F_i = F_{i-1} origin_i J_i(q_i), base folded into joint 1).
#include <Eigen/Core>
#include <vector>

#include "mechbal/dynamics.hpp"
#include "mechbal/rigid_body.hpp"
#include "mechbal/serial_chain.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

class RneChainDynamics final : public InverseDynamics {
 public:
  /// Precomputes the constant link data and allocates every per-link buffer (not real-time).
  explicit RneChainDynamics(const ChainModel& model);

  int dof() const noexcept override { return dof_; }

  /// InverseDynamics interface: tau = M(q) qdd + C(q, qd) qd + G(q).
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau) noexcept override {
    return inverse_dynamics(q, qd, qdd, tau, nullptr, nullptr);
  }

  /// As above; when `support_force`/`support_moment` are non-null they receive the wrench the base
  /// exerts on the chain (moment about the base origin, world frame, gravity included), as
  /// KdlChainDynamics does. Real-time: noexcept, allocation-free. Wrong sizes: Status::bad_size;
  /// non-finite input: Status::non_finite_input; outputs untouched in both cases. Finite input
  /// whose result overflows (every query of this class): Status::out_of_range, outputs zero.
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                          Vec3* support_moment) noexcept;

  /// Joint-space mass matrix M(q) by the composite rigid body algorithm (both triangles filled).
  Status mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q,
                     Eigen::Ref<Eigen::MatrixXd> M) noexcept;
  /// Gravity torques G(q) (RNE with qd = qdd = 0).
  Status gravity(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::VectorXd> g) noexcept;
  /// Bias torques C(q, qd) qd + G(q) (RNE with qdd = 0), Pinocchio's `nle`.
  Status bias(const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& qd, Eigen::Ref<Eigen::VectorXd> b) noexcept;
  /// Coriolis and centrifugal torques C(q, qd) qd alone (RNE with qdd = 0 and no gravity).
  Status coriolis(const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                  Eigen::Ref<Eigen::VectorXd> c) noexcept;

 private:
  /// Constant data of link i, in its joint-aligned frame L_i (see the file comment).
  struct Link {
    Mat3 rotation;        ///< C_R: L_i at q = 0 relative to L_{i-1}
    Vec3 translation;     ///< C_p: origin of L_i (at q = 0) in L_{i-1}
    double mass;
    Vec3 first_moment;    ///< m c, c the centre of mass in L_i
    Mat3 inertia_origin;  ///< inertia about L_i's origin, in L_i
    bool revolute;
  };
  /// Per-tick state of link i, in L_i.
  struct State {
    Mat3 rotation;     ///< L_i relative to L_{i-1} at the current q
    Vec3 translation;  ///< origin of L_i in L_{i-1} at the current q
    Vec3 w, alpha, acc;  ///< angular velocity, angular acceleration, origin acceleration
    Vec3 force, moment;  ///< wrench link i-1 exerts on link i (moment about L_i's origin)
  };

  /// Joint placements for q (fills State::rotation/translation).
  void place(const Eigen::Ref<const Eigen::VectorXd>& q) noexcept;
  /// Forward and backward passes; the template flags drop the terms a query does not need.
  template <bool Velocity, bool Acceleration, bool Gravity>
  void rne(const Eigen::Ref<const Eigen::VectorXd>& qd,
           const Eigen::Ref<const Eigen::VectorXd>& qdd, Eigen::Ref<Eigen::VectorXd> tau) noexcept;

  int dof_;
  Vec3 gravity_;
  std::vector<Link> links_;
  std::vector<State> states_;
  std::vector<Vec3> composite_h_;  ///< CRBA: composite first moment, per link
  std::vector<Mat3> composite_I_;  ///< CRBA: composite inertia about the origin, per link
  std::vector<double> composite_m_;
};

}  // namespace mechbal
