#include "mechbal/control/detail/joint_control.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace mechbal::detail {

void check_torque_limit(const Eigen::VectorXd& limit, const char* field, Eigen::Index n,
                        Eigen::VectorXd& out) {
  if (limit.size() == 0) {  // undeclared: no limit
    out = Eigen::VectorXd::Constant(n, no_limit);
    return;
  }
  check_positive_vector(limit, field, n, true);
  out = limit;
}

void check_positive_vector(const Eigen::VectorXd& v, const char* field, Eigen::Index n,
                           bool allow_inf) {
  std::ostringstream msg;
  if (v.size() != n) {
    msg << field << " must have " << n << " values (got " << v.size() << ")";
    throw std::invalid_argument(msg.str());
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double x = v(i);
    const bool ok = allow_inf ? (x > 0.0 && !std::isnan(x)) : (std::isfinite(x) && x > 0.0);
    if (!ok) {
      msg << field << "[" << i << "] must be " << (allow_inf ? "> 0" : "finite and > 0")
          << " (got " << x << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

}  // namespace mechbal::detail

namespace mechbal {

void validate_joint_input_range(const JointInputRange& r, const char* field) {
  const std::pair<const char*, double> bounds[] = {{"max_position", r.max_position},
                                                  {"max_speed", r.max_speed},
                                                  {"max_acceleration", r.max_acceleration}};
  for (const auto& b : bounds) {
    if (std::isnan(b.second) || b.second <= 0.0) {
      std::ostringstream msg;
      msg << field << "." << b.first << " must be > 0 (+inf: no limit) (got " << b.second << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

}  // namespace mechbal
