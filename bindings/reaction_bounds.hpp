#pragma once
// When the shaking wrench alone decides an instant: Mechanism.shaking_wrench accepts an instant
// when base_reaction accepts it (the shaking wrench and the base and support reactions finite), so
// that the same instants are accepted whichever reaction the caller reads. These bounds say, after
// shaking_wrench, when the reactions surely are finite; only otherwise is base_reaction computed.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"

namespace mechbal::pyb {

struct ReactionBounds {
  explicit ReactionBounds(const MechanismModel& model) noexcept {
    for (int l = 0; l < model.num_links(); ++l) {
      mass += std::abs(model.link_constants(l).mass);
      first_moments += model.link_constants(l).first_moment.lpNorm<1>();
    }
    gravity = model.gravity().cwiseAbs().maxCoeff();
  }

  /// After shaking_wrench (finite momenta and rates): whether the base and support reactions
  /// (base_reaction: F - m g and M - (m c) x g over some or all links) surely are finite, from
  /// bounds: |m c|_inf <= B = mass * reach + sum |m c_link|_1 (reach: the largest |coordinate| of
  /// a link origin; |R x|_inf <= |x|_1), so |(m c - m c_still) x g|_inf <= 4 B |g|_inf.
  bool surely_finite(const MechanismData& data) const noexcept {
    constexpr double kSafe = 1e306;
    const auto& s = data.shaking;
    if (s.force.cwiseAbs().maxCoeff() > kSafe || s.moment.cwiseAbs().maxCoeff() > kSafe) return false;
    double reach = 0.0;
    for (const auto& w : data.work) reach = std::max(reach, w.world_position.cwiseAbs().maxCoeff());
    if (!(reach <= kSafe)) return false;  // (NaN too)
    return mass * gravity <= kSafe && 4.0 * (mass * reach + first_moments) * gravity <= kSafe;
  }

  double mass = 0.0, first_moments = 0.0, gravity = 0.0;
};

}  // namespace mechbal::pyb
