#pragma once
// The Panda reactionless case shared by bench_reactionless_panda.cpp (mechbal) and
// bench_urdf_pinocchio.cpp (the same controller over Pinocchio): the tool frame, its twist, the
// home pose, the configuration, and mechbal's controller as the setup reference.
#include <cmath>
#include <memory>
#include <vector>

#include "bench_urdf.hpp"
#include "mechbal/control/reactionless.hpp"

namespace mechbal::bench::panda_reactionless {

inline constexpr int kTicks = 6284;  // the twist is 2 pi periodic: t_n = n 2 pi / kTicks (about 1 kHz)
inline const double kDt = 2.0 * M_PI / kTicks;
inline const char* const kFrame = "panda_hand_tcp";

/// A 0.1 m circle in the horizontal plane at 1 rad/s (the tool's linear velocity).
inline Vec6 twist_at(double t) {
  Vec6 x = Vec6::Zero();
  x(0) = -0.1 * std::sin(t);
  x(1) = 0.1 * std::cos(t);
  return x;
}

inline Eigen::VectorXd home(int dof) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(dof);
  q.head<7>() << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
  if (dof > 7) q(7) = 0.02;
  return q;
}

inline TaskSpaceConfig config(ReactionlessIntegrator integrator) {
  TaskSpaceConfig c;
  c.frame = kFrame;
  c.task_rows = cancel_force;  // rows 0-2 of [v; w]: the tool's linear velocity
  c.cancel = cancel_moment;    // angular momentum about O
  c.integrator = integrator;
  c.rate_hz = 1.0 / kDt;
  return c;
}

struct TwistSamples {
  std::vector<Vec6> now, half, next;
  TwistSamples() {
    for (int n = 0; n < kTicks; ++n) {
      now.push_back(twist_at(n * kDt));
      half.push_back(twist_at((n + 0.5) * kDt));
      next.push_back(twist_at((n + 1) * kDt));
    }
  }
};

inline std::unique_ptr<ReactionlessTaskController> mechbal_controller(ReactionlessIntegrator integrator) {
  UrdfRobot panda("panda");
  auto model = std::make_shared<const MechanismModel>(std::move(panda.model));
  return std::make_unique<ReactionlessTaskController>(model, config(integrator), home(model->dof()));
}

}  // namespace mechbal::bench::panda_reactionless
