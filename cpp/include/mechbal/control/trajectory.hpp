#pragma once
/// \file trajectory.hpp
/// Rest-to-rest polynomial time laws (Arakelian, Le Baron & Mottu 2011, eqs 10-13).
///
/// q(t) = q0 + (q1 - q0) s(t/T) with
///  - quintic:  s = 10 u^3 - 15 u^4 + 6 u^5 (zero velocity and acceleration at both ends; the
///    paper's run A, "theta = 5.2360 t^3 - 7.8540 t^4 + 3.1416 t^5" for a 0.5236 rad stroke);
///  - cubic:    s = 3 u^2 - 2 u^3 (eq 13), the law that minimises the energy integral of the
///    squared acceleration for a rest-to-rest motion (the paper's "minimum energy" law).
/// Outside [0, T] the trajectory holds its end point at rest.
#include <Eigen/Core>

#include "mechbal/status.hpp"

namespace mechbal {

enum class TimeLaw { quintic, cubic };

/// Normalised law s(u), s'(u), s''(u) for u in [0, 1] (clamped).
struct LawValue {
  double s = 0.0, ds = 0.0, dds = 0.0;
};
LawValue evaluate_law(TimeLaw law, double u) noexcept;

/// A rest-to-rest trajectory between two joint (or Cartesian) vectors.
class RestToRestTrajectory {
 public:
  /// Throws std::invalid_argument (naming the field) if sizes differ, T <= 0 or values are
  /// non-finite.
  RestToRestTrajectory(const Eigen::VectorXd& start, const Eigen::VectorXd& end, double duration,
                       TimeLaw law);

  Eigen::Index size() const noexcept { return start_.size(); }
  double duration() const noexcept { return duration_; }
  TimeLaw law() const noexcept { return law_; }
  const Eigen::VectorXd& start() const noexcept { return start_; }
  const Eigen::VectorXd& end() const noexcept { return end_; }

  /// Position, velocity and acceleration at time t. Allocation-free: outputs must already have
  /// size(); otherwise Status::bad_size and nothing is written. Non-finite t: non_finite_input and
  /// the start point at rest.
  Status evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd,
                  Eigen::Ref<Eigen::VectorXd> qdd) const noexcept;

  /// Batch: times (N,), outputs row-major (N, size()) arrays.
  Status evaluate_batch(const double* times, Eigen::Index n, double* q, double* qd,
                        double* qdd) const noexcept;

 private:
  Eigen::VectorXd start_, end_;
  double duration_;
  TimeLaw law_;
};

}  // namespace mechbal
