#include "mechbal/detail/joint_control.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mechbal::detail {

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
