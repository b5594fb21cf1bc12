#pragma once
// The PAMINSA tests' and benches' motion (test and bench support): a smooth 3-D platform motion
// around the nominal pose and a moving wrist, with exact rates and accelerations, so that every
// term of the kinematics is exercised, not just the paper's cycle.
#include <cmath>

#include "mechbal/papers/paminsa/paminsa.hpp"

namespace mechbal::test {

inline PlatformMotion platform_at(double t) noexcept {
  const Vec3 P0(0.48, 0.05, 0.6775), amp(0.04, 0.12, 0.03), om(3.0, 2.0, 5.0), ph(0.3, 1.1, 0.7);
  PlatformMotion m;
  for (int i = 0; i < 3; ++i) {
    const double a = om(i) * t + ph(i);
    m.position(i) = P0(i) + amp(i) * std::sin(a);
    m.velocity(i) = amp(i) * om(i) * std::cos(a);
    m.acceleration(i) = -amp(i) * om(i) * om(i) * std::sin(a);
  }
  return m;
}

inline WristMotion wrist_at(double t) noexcept {
  const Vec3 q0(0.4, 1.2, -0.5), amp(0.7, 0.5, 1.3), om(2.0, 3.0, 4.0);
  WristMotion w;
  for (int i = 0; i < 3; ++i) {
    w.angles(i) = q0(i) + amp(i) * std::sin(om(i) * t);
    w.rates(i) = amp(i) * om(i) * std::cos(om(i) * t);
    w.accelerations(i) = -amp(i) * om(i) * om(i) * std::sin(om(i) * t);
  }
  return w;
}

}  // namespace mechbal::test
