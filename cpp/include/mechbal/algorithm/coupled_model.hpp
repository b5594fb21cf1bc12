#pragma once
/// \file coupled_model.hpp
/// The coupling-matrix projection of Coutinho & Hess Coelho, "A new approach for designing
/// dynamic balanced serial mechanisms" (eqs 1-3, 11-13, 22-24, 32-34), for mechanisms whose
/// redundant-coordinate constraints are solved per tick (closed chains: A° is a matrix, not 1).
///
/// Subsystems k have their own models M_k p_k' + v_k + g_k = u_k. Stacked in the order
/// p = (p#, p°) (independent first, then dependent), with linear quasi-velocity constraints
///   A p = A# p# + A° p° = 0,
/// the coupling matrix and its bias are
///   C = [1; -(A°)^-1 A#],   p = C p#,   p' = C p#' + cbar,   cbar = [0; -(A°)^-1 (A' p)],
/// and, projecting with C^T (constraint forces do no work on admissible motions),
///   M' = C^T M# C,   v' = C^T (M# cbar + v#),   g' = C^T g#.
/// This is the C++ twin of mechbal.coupling.couple (Python), with fixed sizes.
///
/// Use per tick: (1) fill `a_independent` (A#) and `a_dependent` (A°), call factor(): it checks A° (reciprocal condition number sigma_min / sigma_max from a
/// fixed-size SVD) and computes C; (2) with the dependent rates p = C p# now known, fill the
/// subsystem terms (mass, velocity, gravity in p order) and `constraint_bias` = A' p; (3) call
/// project(). Everything is noexcept and allocation-free (fixed-size Eigen).
#include <Eigen/Core>
#include <Eigen/SVD>
#include <cmath>

#include "mechbal/status.hpp"

namespace mechbal {

template <int Independent, int Dependent>
class CoupledProjection {
 public:
  static constexpr int ni = Independent;
  static constexpr int nd = Dependent;
  static constexpr int np = Independent + Dependent;
  using MatP = Eigen::Matrix<double, np, np>;
  using VecP = Eigen::Matrix<double, np, 1>;
  using MatI = Eigen::Matrix<double, ni, ni>;
  using VecI = Eigen::Matrix<double, ni, 1>;
  using MatDI = Eigen::Matrix<double, nd, ni>;
  using MatD = Eigen::Matrix<double, nd, nd>;
  using VecD = Eigen::Matrix<double, nd, 1>;
  using MatPI = Eigen::Matrix<double, np, ni>;

  // ---- inputs, in the order p = (p#, p°) ----
  MatDI a_independent = MatDI::Zero();  ///< A# = dPbar/dp#
  MatD a_dependent = MatD::Zero();      ///< A° = dPbar/dp°
  MatP mass = MatP::Zero();             ///< M# (block diagonal in the subsystems' own p_k)
  VecP velocity = VecP::Zero();         ///< v#
  VecP gravity = VecP::Zero();          ///< g#
  VecD constraint_bias = VecD::Zero();  ///< A' p (time derivative of A, times p)

  // ---- outputs ----
  MatPI coupling = MatPI::Zero();  ///< C
  VecP coupling_bias = VecP::Zero();  ///< cbar
  MatI reduced_mass = MatI::Zero();   ///< M'
  VecI reduced_velocity = VecI::Zero();  ///< v'
  VecI reduced_gravity = VecI::Zero();   ///< g'
  double reciprocal_condition = 0.0;  ///< sigma_min(A°) / sigma_max(A°) at the last factor()

  /// SVD of A°; Status::singular (C untouched) when sigma_min / sigma_max < tolerance or A° is
  /// not finite, else C = [1; -(A°)^-1 A#].
  Status factor(double tolerance) noexcept {
    if (!a_dependent.allFinite() || !a_independent.allFinite()) {
      reciprocal_condition = 0.0;
      return Status::singular;
    }
    svd_.compute(a_dependent, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const auto& s = svd_.singularValues();
    const double smax = s(0), smin = s(nd - 1);
    reciprocal_condition = smax > 0.0 ? smin / smax : 0.0;
    if (!(reciprocal_condition >= tolerance)) return Status::singular;
    coupling.template topRows<ni>().setIdentity();
    coupling.template bottomRows<nd>().noalias() = -svd_.solve(a_independent);
    return Status::ok;
  }

  /// p = C p# (call after factor()).
  VecP rates(const VecI& independent_rates) const noexcept { return coupling * independent_rates; }

  /// p' = C p#'' + cbar (call after project()).
  VecP accelerations(const VecI& independent_accelerations) const noexcept {
    return coupling * independent_accelerations + coupling_bias;
  }

  /// cbar, M', v', g' from the subsystem terms and A' p (call after a successful factor()).
  void project() noexcept {
    coupling_bias.template topRows<ni>().setZero();
    coupling_bias.template bottomRows<nd>().noalias() = -svd_.solve(constraint_bias);
    const Eigen::Matrix<double, np, ni> MC = mass * coupling;
    reduced_mass.noalias() = coupling.transpose() * MC;
    const VecP h = mass * coupling_bias + velocity;
    reduced_velocity.noalias() = coupling.transpose() * h;
    reduced_gravity.noalias() = coupling.transpose() * gravity;
  }

 private:
  Eigen::JacobiSVD<MatD> svd_;
};

}  // namespace mechbal
