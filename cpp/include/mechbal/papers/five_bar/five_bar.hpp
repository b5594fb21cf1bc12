#pragma once
/// \file five_bar.hpp
/// Planar 5R five-bar evaluated per control tick by the coupling-matrix method (Coutinho & Hess
/// Coelho, "A new approach for designing dynamic balanced serial mechanisms", eqs 1-3 and 12,
/// with a 4x4 A°; the paper names the 5R in its abstract but prints no model: derivation in
/// docs/discs_derivation.md section 5). The C++ twin of mechbal.sizing.discs.fivebar_model.
///
/// Geometry: vertical y-z plane, joint axes x, z up, gravity (0, 0, -g). Leg i (i = 1, 2) is a
/// serial 2R arm with base A_1 = 0, A_2 = (0, d, 0): proximal link of length a_i at absolute angle
/// theta_i (actuated, measured from +y), distal link of length b_i at relative angle theta_i2; the
/// distal tips meet at the end effector P (point mass m_P). Centres of mass on the link lines at
/// cp_i (proximal, from A_i) and cd_i (distal, from the elbow B_i); Jp_i, Jd_i: central inertia
/// about the joint axis.
///
/// Subsystems: leg 1 (theta_1, theta_12), leg 2 (theta_2, theta_22) with the closed-form 2R
/// models of eq 7/9 type (M, v, g), and P with M = m_P 1, v = 0, g = (0, m_P g). Constraints:
/// v_P - J_tip,i qd_leg,i = 0 (four rows). With p# = (theta_1', theta_2') and
/// p° = (theta_12', theta_22', v_Py, v_Pz), A° (4x4) is singular exactly when the distal links are
/// aligned (type-2 singularity): evaluate() then returns Status::singular and leaves its outputs
/// untouched. Passive angles: closed-form circle intersection, in the assembly mode nearest the
/// parallelogram point B_1 + (B_2 - A_2) (as in Python); |B_2 - B_1| outside [|b_1 - b_2|,
/// b_1 + b_2] (cannot be assembled) is also Status::singular.
#include <Eigen/Core>

#include "mechbal/algorithm/coupled_model.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

struct FiveBarParameters {
  double a1 = 0.0, a2 = 0.0;    ///< proximal lengths [m]
  double b1 = 0.0, b2 = 0.0;    ///< distal lengths [m]
  double d = 0.0;               ///< base-joint spacing along y [m]
  double mp1 = 0.0, mp2 = 0.0;  ///< proximal masses [kg]
  double md1 = 0.0, md2 = 0.0;  ///< distal masses [kg]
  double mP = 0.0;              ///< end-effector point mass [kg]
  double cp1 = 0.0, cp2 = 0.0;  ///< proximal CoM positions along the link (from A_i) [m]
  double cd1 = 0.0, cd2 = 0.0;  ///< distal CoM positions along the link (from B_i) [m]
  double Jp1 = 0.0, Jp2 = 0.0;  ///< proximal central inertia about x [kg m^2]
  double Jd1 = 0.0, Jd2 = 0.0;  ///< distal central inertia about x [kg m^2]
  double gravity = 9.81;        ///< |g| along -z [m/s^2]
};

/// Angles, rates and accelerations of the four joints (theta_1, theta_12, theta_2, theta_22) and
/// the end effector, from the coupling: p = C p#, p' = C p#'' + cbar.
struct FiveBarMotion {
  Eigen::Vector4d angles = Eigen::Vector4d::Zero();  ///< (theta_1, theta_12, theta_2, theta_22)
  Eigen::Vector4d rates = Eigen::Vector4d::Zero();
  Eigen::Vector4d accelerations = Eigen::Vector4d::Zero();
  Eigen::Vector2d end_effector = Eigen::Vector2d::Zero();  ///< P (y, z)
  Eigen::Vector2d end_effector_velocity = Eigen::Vector2d::Zero();
  Eigen::Vector2d end_effector_acceleration = Eigen::Vector2d::Zero();
};

class FiveBarDynamics final : public InverseDynamics {
 public:
  using Projection = CoupledProjection<2, 4>;

  /// Throws std::invalid_argument naming the field and value ("five_bar.a1 must be > 0 (got
  /// -0.3)"): lengths > 0, d >= 0, masses and inertias >= 0, everything finite,
  /// singular_tolerance in (0, 1).
  explicit FiveBarDynamics(const FiveBarParameters& parameters, double singular_tolerance = 1e-6);

  int dof() const noexcept override { return 2; }
  const FiveBarParameters& parameters() const noexcept { return p_; }
  double singular_tolerance() const noexcept { return tol_; }

  /// M' (2x2), v', g' at (q, qd) = ((theta_1, theta_2), rates). Real-time: noexcept,
  /// allocation-free. Non-finite input: non_finite_input; singular or unassemblable pose:
  /// singular; outputs untouched in both cases.
  Status evaluate(const Eigen::Vector2d& q, const Eigen::Vector2d& qd, Eigen::Matrix2d& mass,
                  Eigen::Vector2d& velocity_terms, Eigen::Vector2d& gravity_terms) noexcept;

  /// Every joint's angle, rate and acceleration and the end effector's motion (same contract).
  Status motion(const Eigen::Vector2d& q, const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                FiveBarMotion& out) noexcept;

  /// tau = M' qdd + v' + g'. Sizes must be 2 (else bad_size); singular pose: Status::singular and
  /// tau untouched (ComputedTorque then holds its last command).
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau) noexcept override;

  /// sigma_min / sigma_max of A° at the last evaluation (0 when not assembled).
  double reciprocal_condition() const noexcept { return proj_.reciprocal_condition; }

 private:
  Status compute(const Eigen::Vector2d& q, const Eigen::Vector2d& qd) noexcept;

  FiveBarParameters p_;
  double tol_;
  Projection proj_;
  Eigen::Vector4d angles_ = Eigen::Vector4d::Zero();
  Eigen::Vector4d rates_ = Eigen::Vector4d::Zero();
  Eigen::Vector2d tip_ = Eigen::Vector2d::Zero();
};

}  // namespace mechbal
