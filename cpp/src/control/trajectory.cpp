#include "mechbal/control/trajectory.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mechbal {

LawValue evaluate_law(TimeLaw law, double u) noexcept {
  if (!(u > 0.0)) u = 0.0;  // also maps NaN to 0
  if (u > 1.0) u = 1.0;
  LawValue v;
  const double u2 = u * u, u3 = u2 * u;
  switch (law) {
    case TimeLaw::quintic:
      v.s = u3 * (10.0 - 15.0 * u + 6.0 * u2);
      v.ds = 30.0 * u2 * (1.0 - 2.0 * u + u2);
      v.dds = 60.0 * u * (1.0 - 3.0 * u + 2.0 * u2);
      break;
    case TimeLaw::cubic:
      v.s = 3.0 * u2 - 2.0 * u3;
      v.ds = 6.0 * u - 6.0 * u2;
      v.dds = 6.0 - 12.0 * u;
      break;
  }
  return v;
}

RestToRestTrajectory::RestToRestTrajectory(const Eigen::VectorXd& start, const Eigen::VectorXd& end,
                                           double duration, TimeLaw law)
    : start_(start), end_(end), duration_(duration), law_(law) {
  std::ostringstream msg;
  if (start.size() != end.size()) {
    msg << "trajectory.end has " << end.size() << " values but trajectory.start has "
        << start.size();
    throw std::invalid_argument(msg.str());
  }
  if (!start.allFinite()) throw std::invalid_argument("trajectory.start must be finite");
  if (!end.allFinite()) throw std::invalid_argument("trajectory.end must be finite");
  if (!std::isfinite(duration) || duration <= 0.0) {
    msg << "trajectory.duration must be a finite number > 0, got " << duration;
    throw std::invalid_argument(msg.str());
  }
  // the peak acceleration (at most 6 |end - start| / T^2, cubic law) must be finite, so that no
  // evaluate() can overflow (a duration of 5e-324 gives infinite rates)
  const double stroke = start.size() ? (end - start).cwiseAbs().maxCoeff() : 0.0;
  if (!std::isfinite(stroke) || !std::isfinite(6.0 * stroke / duration / duration)) {
    msg << "trajectory.duration " << duration << " is too short for a stroke of " << stroke
        << ": the accelerations overflow";
    throw std::invalid_argument(msg.str());
  }
}

Status RestToRestTrajectory::evaluate(double t, Eigen::Ref<Eigen::VectorXd> q,
                                      Eigen::Ref<Eigen::VectorXd> qd,
                                      Eigen::Ref<Eigen::VectorXd> qdd) const noexcept {
  if (q.size() != size() || qd.size() != size() || qdd.size() != size()) return Status::bad_size;
  Status status = Status::ok;
  if (!std::isfinite(t)) {
    status = Status::non_finite_input;
    t = 0.0;
  }
  const LawValue v = evaluate_law(law_, t / duration_);
  // On the closed interval [0, T] the law's one-sided values hold (the cubic law starts with a
  // non-zero acceleration); outside it the trajectory rests at its end points.
  const bool moving = t >= 0.0 && t <= duration_;
  q = start_ + v.s * (end_ - start_);
  qd = (moving ? v.ds / duration_ : 0.0) * (end_ - start_);
  qdd = (moving ? v.dds / (duration_ * duration_) : 0.0) * (end_ - start_);
  return status;
}

Status RestToRestTrajectory::evaluate_batch(const double* times, Eigen::Index n, double* q,
                                            double* qd, double* qdd) const noexcept {
  using VecMap = Eigen::Map<Eigen::VectorXd>;
  const Eigen::Index m = size();
  Status status = Status::ok;
  for (Eigen::Index k = 0; k < n; ++k) {
    VecMap qk(q + k * m, m), qdk(qd + k * m, m), qddk(qdd + k * m, m);
    status |= evaluate(times[k], qk, qdk, qddk);
  }
  return status;
}

}  // namespace mechbal
