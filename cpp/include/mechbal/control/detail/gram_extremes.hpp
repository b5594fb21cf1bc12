#pragma once
/// \file detail/gram_extremes.hpp
/// Internal, for tests: the reactionless controllers' damping decision and reported condition
/// (control/reactionless.hpp) on a given K, through the same code their ticks run. Defined in
/// cpp/src/control/reactionless.cpp; not real-time (it allocates and throws), not part of the
/// controllers' API.
#include <Eigen/Core>

namespace mechbal::detail {

/// The extreme eigenvalues of a reactionless solve's Gram matrix (K K^T when K has fewer rows
/// than columns, else K^T K) as the controllers compute them for the damping decision at
/// max_condition (damped iff lmax / lmin > max_condition^2) and, when `reported`, for the
/// reported condition sqrt(lmax / lmin); `iterated`: Eigen's iterative eigensolver was needed
/// (otherwise the closed forms and K's minors settled both). For tests (it allocates):
/// std::invalid_argument when K is not finite or has more than 6 rows or columns.
struct GramExtremes {
  double lmin = 0.0, lmax = 0.0;
  bool iterated = false;
};
GramExtremes gram_extremes(const Eigen::MatrixXd& K, double max_condition, bool reported);

}  // namespace mechbal::detail
