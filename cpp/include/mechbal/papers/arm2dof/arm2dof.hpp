#pragma once
/// \file arm2dof.hpp
/// Closed-form dynamics of the planar 2R arm of Arakelian, Le Baron & Mottu 2011 ("Torque
/// minimisation of the 2-DOF serial manipulators based on minimum energy consideration and optimum
/// mass redistribution", Mechatronics 21:310-314), Fig. 1, eqs 14-31, re-derived from the
/// Lagrangian, with optional point-mass counterweights on the link extensions.
///
/// Geometry. The arm moves in the vertical x-z plane of the base frame (z up, gravity (0,0,-g)).
/// theta1 = angle of link 1 (A -> B) from +x; theta2 = angle of link 2 relative to link 1 (the
/// paper's convention). Link 1: mass m1, centre of mass S1 at l_S1 from A on AB, inertia I_S1 about
/// S1 (so I_A = I_S1 + m1 l_S1^2, eq 16). Link 2: mass m2, S2 at l_S2 from B, inertia I_S2 about S2.
/// Counterweight 1 (mass m_CW1) sits on the extension of link 1 beyond A at r_CW1 from A;
/// counterweight 2 (m_CW2) on the extension of link 2 beyond B at r_CW2 from B (the only placement
/// that reproduces the signs of eqs 25-31). As a rotation about the base -y axis lifts +x towards
/// +z, the equivalent serial chain has both joint axes along -y (see arm2dof_chain_model).
///
/// The dynamics depend only on the five lumped parameters of Arm2DofLumped (plus l1 and g):
///   A11 = j1 + j2 + M2 l1^2 + 2 l1 s2 cos q2,  A12 = j2 + l1 s2 cos q2,  A22 = j2
///   C   = h [[-qd2, -(qd1 + qd2)], [qd1, 0]],  h = l1 s2 sin q2   (Adot - 2C skew-symmetric)
///   Q1  = g (s1 + M2 l1) cos q1 + g s2 cos(q1 + q2),  Q2 = g s2 cos(q1 + q2)
/// which are eqs 14-22 (bare arm) and 23-31 (counterweight torques, added linearly).
///
/// A fast path of the general model: the same arm with links and counterweights as separate bodies
/// is `mechbal.papers.arm2dof_mechanism`; tests/python/test_papers.py checks torques, mass matrix
/// and gravity against MechanismDynamics to 1e-12 relative along the paper's trajectories.
///
/// Corrections to the printed paper (proofs: tests/python/test_arm2dof.py, sympy Lagrangian):
///  - eqs 14 and 23: the term -k32 theta2dot^2 must read -k32 theta2dot^2 sin(theta2);
///  - eq 16 / text: "l_A" is I_A, the inertia of link 1 about A; eq 18: 1/2 (I_S2 + m2 l_S2^2)
///    (printed m2 I_S2^2); eq 19: "I_52 + m2 l_52^2" is I_S2 + m2 l_S2^2; eq 22: p2 = m2 g l_S2
///    (printed l_c2); Sec. 4 data "l_S1 = 0.15, l_S2 = 0.1 kgm^2" are I_S1, I_S2 (about S1, S2).
#include <Eigen/Core>

#include "mechbal/control/dynamics.hpp"
#include "mechbal/model/serial_chain.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

/// Bare arm of Fig. 1 (SI units). Defaults: the paper's Sec. 4 data.
struct Arm2DofParameters {
  double m1 = 2.5;     ///< link 1 mass [kg]
  double m2 = 2.0;     ///< link 2 mass [kg]
  double l1 = 0.4;     ///< |AB| [m]
  double l_s1 = 0.1;   ///< |A S1| along A->B [m]
  double l_s2 = 0.1;   ///< |B S2| along link 2 [m]
  double i_s1 = 0.15;  ///< inertia of link 1 about S1 [kg m^2]
  double i_s2 = 0.1;   ///< inertia of link 2 about S2 [kg m^2]
  double g = 9.81;     ///< gravity magnitude [m/s^2], acting along -z
};

/// Point-mass counterweights of eqs 25-31 on the link extensions beyond A and beyond B.
/// Radii are signed distances from the joint (a negative radius puts the mass on the link side).
struct Arm2DofCounterweights {
  double m_cw1 = 0.0;  ///< [kg]
  double m_cw2 = 0.0;  ///< [kg]
  double r_cw1 = 0.0;  ///< from A, beyond A [m]
  double r_cw2 = 0.0;  ///< from B, beyond B [m]
};

/// Minimal parameter set of a planar 2R arm.
struct Arm2DofLumped {
  double j1 = 0.0;  ///< inertia about A of the link-1 bodies [kg m^2]: I_A (+ m_CW1 r_CW1^2)
  double s1 = 0.0;  ///< first moment of the link-1 bodies about A along AB [kg m]: m1 l_S1 (- m_CW1 r_CW1)
  double M2 = 0.0;  ///< mass of the link-2 bodies [kg]: m2 (+ m_CW2)
  double s2 = 0.0;  ///< first moment of the link-2 bodies about B [kg m]: m2 l_S2 (- m_CW2 r_CW2)
  double j2 = 0.0;  ///< inertia about B of the link-2 bodies [kg m^2]: I_S2 + m2 l_S2^2 (+ m_CW2 r_CW2^2)
  double l1 = 0.0;  ///< |AB| [m]
  double g = 9.81;  ///< [m/s^2]
};

/// Validates (std::invalid_argument naming the field and value: "arm.m1 must be ...") and lumps.
Arm2DofLumped arm2dof_lumped(const Arm2DofParameters& arm,
                             const Arm2DofCounterweights& cw = Arm2DofCounterweights{});

/// The same arm (and counterweights, merged into the link bodies) as a ChainModel for KDL:
/// joint 1 at the origin, joint 2 at (l1, 0, 0) of link frame 1, both axes along -y, link
/// centres of mass on the local +x axis, counterweights at (-r, 0, 0), gravity (0, 0, -g).
/// Link inertias are slender-rod-like tensors diag(0, I, I) about the centre of mass.
ChainModel arm2dof_chain_model(const Arm2DofParameters& arm,
                               const Arm2DofCounterweights& cw = Arm2DofCounterweights{});


/// Closed-form 2-DOF dynamics, eq 1: tau = A(q) qdd + C(q, qd) qd + Q(q) (eqs 14-31 corrected).
/// Immutable after construction; every method is noexcept and allocation-free.
class Arm2DofDynamics final : public InverseDynamics, public ForwardDynamics {
 public:
  explicit Arm2DofDynamics(const Arm2DofParameters& arm,
                           const Arm2DofCounterweights& cw = Arm2DofCounterweights{});
  /// From lumped parameters (validated: j1, j2 > 0, M2 >= 0, l1 > 0, A positive definite).
  explicit Arm2DofDynamics(const Arm2DofLumped& lumped);

  int dof() const noexcept override { return 2; }
  const Arm2DofLumped& lumped() const noexcept { return p_; }

  Mat2 mass_matrix(const Vec2& q) const noexcept;
  Mat2 coriolis_matrix(const Vec2& q, const Vec2& qd) const noexcept;
  Vec2 gravity(const Vec2& q) const noexcept;
  Vec2 torque(const Vec2& q, const Vec2& qd, const Vec2& qdd) const noexcept;
  Vec2 acceleration(const Vec2& q, const Vec2& qd, const Vec2& tau) const noexcept;
  double kinetic_energy(const Vec2& q, const Vec2& qd) const noexcept;
  /// V = g [(s1 + M2 l1) sin q1 + s2 sin(q1 + q2)], zero with both links horizontal at A's height.
  double potential_energy(const Vec2& q) const noexcept;

  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau) noexcept override;
  Status forward_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& tau,
                          Eigen::Ref<Eigen::VectorXd> qdd) noexcept override;

 private:
  Arm2DofLumped p_;
};

}  // namespace mechbal
