#pragma once
/// \file detail/saturation.hpp
/// Shared by the joint controllers: clip a command to symmetric per-joint limits.
#include <Eigen/Core>

#include "mechbal/status.hpp"

namespace mechbal::detail {

/// Clips x(i) to [-limit(i), limit(i)] for the first n entries (limits may be +infinity).
/// Returns Status::saturated when any entry was clipped, Status::ok otherwise. noexcept, no
/// allocation.
template <typename Command, typename Limit>
inline Status clip_to_limits(Eigen::DenseBase<Command>& x, const Eigen::DenseBase<Limit>& limit,
                             Eigen::Index n) noexcept {
  Status status = Status::ok;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (x(i) > limit(i)) {
      x(i) = limit(i);
      status = Status::saturated;
    } else if (x(i) < -limit(i)) {
      x(i) = -limit(i);
      status = Status::saturated;
    }
  }
  return status;
}

}  // namespace mechbal::detail
