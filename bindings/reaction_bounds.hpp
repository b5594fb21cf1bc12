#pragma once
// Whether the base and support reactions of an instant are surely finite once its shaking wrench
// is (finite momenta and rates), from bounds on the model: the shaking-wrench calls that are not
// asked for the reactions compute them (base_reaction) only when these bounds cannot tell, so that
// they accept exactly the instants the reactions' path accepts.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"

namespace mechbal::pyb {

class ReactionBounds {
 public:
  explicit ReactionBounds(const MechanismModel& model) {
    for (int l = 0; l < model.num_links(); ++l) {
      mass_ += std::abs(model.link_constants(l).mass);
      first_moments_ += model.link_constants(l).first_moment.lpNorm<1>();
    }
    gravity_ = model.gravity().cwiseAbs().maxCoeff();
  }

  /// After shaking_wrench on `data`: whether base_reaction (F - m g and M - (m c) x g over some or
  /// all links) surely gives finite reactions: |m c|_inf <= B = mass * reach + sum |m c_link|_1
  /// (reach: the largest |coordinate| of a link origin; |R x|_inf <= |x|_1), so
  /// |(m c - m c_still) x g|_inf <= 4 B |g|_inf. Otherwise the caller computes them.
  bool surely_finite(const MechanismData& data) const noexcept {
    constexpr double kSafe = 1e306;
    const auto& s = data.shaking;
    if (s.force.cwiseAbs().maxCoeff() > kSafe || s.moment.cwiseAbs().maxCoeff() > kSafe) return false;
    double reach = 0.0;
    for (const auto& w : data.work) reach = std::max(reach, w.world_position.cwiseAbs().maxCoeff());
    if (!(reach <= kSafe)) return false;  // (NaN too)
    return mass_ * gravity_ <= kSafe && 4.0 * (mass_ * reach + first_moments_) * gravity_ <= kSafe;
  }

 private:
  double mass_ = 0.0, first_moments_ = 0.0, gravity_ = 0.0;
};

}  // namespace mechbal::pyb
