#pragma once
/// \file disc_arm.hpp
/// Serial arm carrying counter-rotating discs, evaluated per control tick: Coutinho & Hess Coelho,
/// "A new approach for designing dynamic balanced serial mechanisms" (modular modelling with
/// redundant coordinates), eqs 1-3 and 10-13 / 20-24 / 31-34.
///
/// The model is the coupling-matrix form of the paper, specialised to serial arms:
/// every link is a Newton-Euler subsystem with quasi-velocities (v_G, omega) in the base frame,
/// M_b = diag(m 1, I_w), v_b = (0, omega x I_w omega), g_b = (-m g, 0); every disc is a subsystem
/// with its body-frame angular velocity, M_d = diag(J_x, J_y, J_z), v_d = omega_d x M_d omega_d
/// (Euler; the paper's eq 20 writes v_d = 0, correction C5 of docs/discs_derivation.md), g_d = 0.
/// The constraints p_k - J_k(q) qd = 0 have A° = 1 and A# = -J_k, so the coupling matrix is
/// C = [1; J_1; ...; J_K] and, with the bias (dJ/dt qd) c_k of each subsystem,
///   M'(q) = sum_k J_k^T M_k J_k,   v'(q, qd) = sum_k J_k^T (M_k c_k + v_k),   g'(q) = sum_k J_k^T g_k
/// (M' = C^T M# C, v' = C^T (M# cbar + v#), g' = C^T g#). This generic evaluator, rather than
/// closed forms per mechanism, serves the planar 3R, the spatial 3R and the SCARA alike, balanced
/// or not, and any perturbed as-built parameter set (sensitivity), with no new derivation to get
/// wrong; the closed forms stay in Python and in the tests as an independent check.
/// (The 5R five-bar has a non-identity 4x4 A°, solved per tick: mechbal::FiveBarDynamics over the
/// general mechbal::CoupledProjection, five_bar.hpp and coupled_model.hpp.)
///
/// Since the general model (model.hpp) has gear couplings, these arms are data on it: each disc a
/// link on a revolute joint whose angle is `ratio * q[joint]` (mimic), built by
/// `mechbal.papers.discs` and evaluated by MechanismDynamics, which is what the Python runner and
/// sizing now use. This evaluator agrees with it to ~1e-15 (tests/python/test_papers.py) and is
/// not a fast path: its inverse dynamics costs about twice MechanismDynamics' on the same arm. It
/// stays for its remaining users (bench_decoupled.cpp, tests/cpp/test_discs.cpp, the bindings)
/// until they move to MechanismDynamics.
///
/// Disc convention: disc d is carried by link `carrier`, spins about `axis` (unit, carrier frame)
/// through the carrier's frame origin, at relative angle ratio * q[joint] (gears/belts). Its mass
/// is lumped into the carrier link; the disc subsystem carries only its central inertia
/// diag(J_x, J_y, J_z) in the disc frame (x = spin axis when axis = (1, 0, 0)).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "mechbal/dynamics.hpp"
#include "mechbal/serial_chain.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

struct DiscSpec {
  std::string name;
  int carrier = 0;             ///< index of the link that carries the disc (0-based)
  int joint = 0;               ///< index of the joint whose rate drives it (0-based)
  Vec3 axis = Vec3::UnitX();   ///< spin axis in the carrier's frame (normalised on construction)
  double ratio = 1.0;          ///< disc rate relative to the carrier = ratio * qd[joint]
  Vec3 inertia = Vec3::Zero(); ///< principal central inertia in the disc frame [kg m^2]
};

/// Serial arm with discs: M'(q), v'(q, qd), g'(q) and inverse dynamics, allocation-free.
class DiscArmDynamics final : public InverseDynamics {
 public:
  static constexpr int max_dof = 8;
  using MatN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_dof, max_dof>;
  using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_dof, 1>;
  using Jac = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, max_dof>;

  /// Throws std::invalid_argument naming the disc and field ("discs[1].ratio must be finite
  /// (got nan)") on bad input; chain.dof() must be in [1, max_dof].
  DiscArmDynamics(ChainModel chain, std::vector<DiscSpec> discs);

  int dof() const noexcept override { return chain_.dof(); }
  const ChainModel& chain() const noexcept { return chain_; }
  const std::vector<DiscSpec>& discs() const noexcept { return discs_; }

  /// M' (dof x dof), v' and g' (dof) at (q, qd). Real-time: noexcept, allocation-free.
  /// Wrong sizes: bad_size, outputs untouched; non-finite input: non_finite_input, untouched.
  Status evaluate(const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& qd, Eigen::Ref<Eigen::MatrixXd> mass,
                  Eigen::Ref<Eigen::VectorXd> velocity_terms,
                  Eigen::Ref<Eigen::VectorXd> gravity_terms) noexcept;

  /// tau = M'(q) qdd + v'(q, qd) + g'(q).
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau) noexcept override;

 private:
  Status compute(const Eigen::Ref<const Eigen::VectorXd>& q,
               const Eigen::Ref<const Eigen::VectorXd>& qd) noexcept;

  ChainModel chain_;
  std::vector<DiscSpec> discs_;
  ChainWorkspace ws_;
  VecN zero_;
  MatN M_;
  VecN v_, g_;
};

}  // namespace mechbal
