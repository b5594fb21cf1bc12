// The general reactionless controller's tick (control/reactionless.hpp), issue 21:
//  - reactionless_wheel_{euler,rk4}: the reaction-wheel arm (tests/cpp/reaction_wheel_arm.hpp,
//    cases/reaction-wheel-arm.toml), wheel cancelling the moment about z: pose, the wheel's column
//    and the task momentum, the rate solve, the feed-forward, the predicted shaking wrench (and
//    RK4's three stages).
//  - reactionless_paminsa_{euler,rk4}: PAMINSA as data on the general model (38 bodies, 9 loops,
//    paminsa_general.hpp), the wrist joints balancing the moment: loop solve, projection, the
//    wrist's columns and the task momentum, controller and predicted shaking wrench of all bodies;
//    the closed form of the same tick is paminsa_tick_{euler,rk4} (bench_controllers.cpp): ratio
//    reactionless_paminsa_general_over_closed_form_*.
// Motions are periodic with period 2 pi s, sampled on the grid t_n = n 2 pi / kTicks (about 1 kHz),
// so the cycled ticks never jump. Each case checks at setup that the controller keeps the
// cancelled momentum on target (and aborts otherwise).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bench_registry.hpp"
#include "bench_support.hpp"
#include "mechbal/control/reactionless.hpp"
#include "paminsa_general.hpp"
#include "paminsa_motion.hpp"
#include "reaction_wheel_arm.hpp"

namespace mechbal::bench {
namespace {

constexpr int kTicks = 6284;  // t wraps at 2 pi: every motion below is 2 pi periodic
const double kDt = 2.0 * M_PI / kTicks;

struct TaskSample {
  Eigen::VectorXd q, v, a, qh, vh, qn, vn;
};

struct ReactionlessCase {
  std::unique_ptr<ReactionlessController> ctrl;
  std::vector<TaskSample> in;
  int k = 0;
  Status status = Status::ok;
};

Tick tick_of(std::shared_ptr<ReactionlessCase> s) {
  // setup check: the cancelled rows of the commanded momentum stay on target
  for (int n = 0; n < 200; ++n) {
    const TaskSample& x = s->in[static_cast<std::size_t>(n)];
    const Status st = s->ctrl->step(x.q, x.v, x.a, x.qh, x.vh, x.qn, x.vn);
    if (st != Status::ok) fail("reactionless bench: tick not ok", static_cast<double>(st));
    for (int row : s->ctrl->cancelled_rows()) {
      const double err = std::abs(s->ctrl->command().momentum(row) - s->ctrl->target()(row));
      if (!(err < 1e-9)) fail("reactionless bench: momentum off target", err);
    }
  }
  s->k = 200;
  return [s] {
    const TaskSample& x = s->in[static_cast<std::size_t>(s->k)];
    s->k = s->k + 1 == kTicks ? 0 : s->k + 1;
    s->status = s->ctrl->step(x.q, x.v, x.a, x.qh, x.vh, x.qn, x.vn);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(&s->ctrl->command());
    benchmark::ClobberMemory();
  };
}

/// The wheel arm's task motion: shoulder and elbow, 2 pi periodic.
void wheel_task(double t, Eigen::VectorXd& q, Eigen::VectorXd& v, Eigen::VectorXd& a) {
  const double amp[2] = {0.8, -1.1}, om[2] = {3.0, 4.0};
  for (int i = 0; i < 2; ++i) {
    q(i) = 0.2 + amp[i] * (1.0 - std::cos(om[i] * t));
    v(i) = amp[i] * om[i] * std::sin(om[i] * t);
    a(i) = amp[i] * om[i] * om[i] * std::cos(om[i] * t);
  }
}

Tick wheel_case(ReactionlessIntegrator integrator) {
  auto s = std::make_shared<ReactionlessCase>();
  ReactionlessConfig c;
  c.balancing_joints = {"wheel"};
  c.cancel = moment_z;
  c.integrator = integrator;
  c.rate_hz = 1.0 / kDt;
  s->ctrl = std::make_unique<ReactionlessController>(test::reaction_wheel_arm(), c, Eigen::Vector3d(0.2, 0.2, 0.0));
  Eigen::VectorXd a2(2);
  for (int n = 0; n < kTicks; ++n) {
    TaskSample x{Eigen::VectorXd(2), Eigen::VectorXd(2), Eigen::VectorXd(2), Eigen::VectorXd(2),
                 Eigen::VectorXd(2), Eigen::VectorXd(2), Eigen::VectorXd(2)};
    wheel_task(n * kDt, x.q, x.v, x.a);
    wheel_task((n + 0.5) * kDt, x.qh, x.vh, a2);
    wheel_task((n + 1) * kDt, x.qn, x.vn, a2);
    s->in.push_back(x);
  }
  return tick_of(s);
}

Tick paminsa_case(ReactionlessIntegrator integrator) {
  auto s = std::make_shared<ReactionlessCase>();
  const PaminsaModel closed{PaminsaParameters{}};
  const auto model = std::make_shared<const MechanismModel>(paminsa_description(closed));
  WristMotion w0;
  w0.angles = Vec3(M_PI / 2, M_PI / 2, M_PI / 2);  // as paminsa_tick_*
  const PlatformMotion p0 = test::platform_at(0.0);
  const ActuatedState s0 = actuated(closed, *model, p0, w0);
  ReactionlessConfig c;
  c.balancing_joints = {"wrist_phi", "wrist_theta", "wrist_psi"};
  c.integrator = integrator;
  c.rate_hz = 1.0 / kDt;
  Eigen::VectorXd v0 = s0.v;
  for (int j = 0; j < model->num_actuated(); ++j)  // the wrist at rest
    if (model->coordinate_name(model->actuated_coordinates()[static_cast<std::size_t>(j)]).rfind("wrist_", 0) == 0)
      v0(j) = 0.0;
  s->ctrl = std::make_unique<ReactionlessController>(model, c, s0.q, v0, initial_guess(closed, *model, p0, w0));
  const auto task = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd out(s->ctrl->num_task());
    for (int i = 0; i < s->ctrl->num_task(); ++i) out(i) = x(s->ctrl->task_joints()[static_cast<std::size_t>(i)]);
    return out;
  };
  for (int n = 0; n < kTicks; ++n) {
    const ActuatedState now = actuated(closed, *model, test::platform_at(n * kDt), w0);
    const ActuatedState half = actuated(closed, *model, test::platform_at((n + 0.5) * kDt), w0);
    const ActuatedState next = actuated(closed, *model, test::platform_at((n + 1) * kDt), w0);
    s->in.push_back({task(now.q), task(now.v), task(now.a), task(half.q), task(half.v), task(next.q), task(next.v)});
  }
  return tick_of(s);
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(reactionless_wheel_euler) { return wheel_case(mechbal::ReactionlessIntegrator::euler); }
MECHBAL_BENCH_CASE(reactionless_wheel_rk4) { return wheel_case(mechbal::ReactionlessIntegrator::rk4); }
MECHBAL_BENCH_CASE(reactionless_paminsa_euler) { return paminsa_case(mechbal::ReactionlessIntegrator::euler); }
MECHBAL_BENCH_CASE(reactionless_paminsa_rk4) { return paminsa_case(mechbal::ReactionlessIntegrator::rk4); }
