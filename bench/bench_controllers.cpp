// The balancing controllers' real-time ticks: the reactionless wrist alone (build N, solve
// N qdot_w = H_target - D, feed-forward, integrate; Euler and RK4) and the whole PAMINSA tick
// (closed-form kinematics of the 35 mechanism bodies, D and dD/dt, the wrist step, the wrist
// links' motion and the shaking wrench of all 38 bodies), both at 1 kHz; and the PAMINSA
// kinematics + shaking wrench of one instant with a prescribed wrist motion.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench_registry.hpp"
#include "bench_support.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/papers/paminsa/reactionless_wrist.hpp"
#include "paminsa_motion.hpp"

namespace mechbal::bench {
namespace {

using test::platform_at;
using test::wrist_at;

constexpr double kDt = 1e-3;  // 1 kHz
constexpr int kTicks = 1024;  // a precomputed stretch of trajectory, cycled through (power of 2)

const Vec3 kWristStart(M_PI / 2, M_PI / 2, M_PI / 2);  // away from the z-x-z gimbal lock

// ---------------------------------------------------------------------------- wrist alone
struct WristInputs {
  Vec3 D, D_dot, D_half, D_next;
};

struct WristCase {
  WristCase(const PaminsaModel& model, WristIntegrator integrator, const Vec3& H_target)
      : wrist(model.wrist_inertia(), config(integrator), kWristStart, H_target) {}
  static ReactionlessWristConfig config(WristIntegrator integrator) {
    ReactionlessWristConfig c;
    c.integrator = integrator;
    return c;
  }
  ReactionlessWrist wrist;
  std::vector<WristInputs> in;
  Status status = Status::ok;
  int k = 0;
};

Vec3 mechanism_D(const PaminsaModel& model, const PlatformMotion& m, Vec3* D_dot = nullptr) {
  PaminsaWorkspace ws;
  Vec3 D, Dd;
  if (paminsa_mechanism_kinematics(model, m, ws) != Status::ok ||
      paminsa_mechanism_momentum(model, ws, D, Dd) != Status::ok)
    fail("PAMINSA bench trajectory is not reachable", m.position.norm());
  if (D_dot) *D_dot = Dd;
  return D;
}

Tick wrist_case(WristIntegrator integrator) {
  const PaminsaModel model{PaminsaParameters{}};
  PlatformMotion rest = platform_at(0.0);
  rest.velocity.setZero();
  rest.acceleration.setZero();
  auto s = std::make_shared<WristCase>(model, integrator, mechanism_D(model, rest));
  // D(t) of the PAMINSA mechanism along the trajectory (precomputed: only the wrist is timed)
  for (int n = 0; n < kTicks; ++n) {
    const double t = n * kDt;
    WristInputs w;
    w.D = mechanism_D(model, platform_at(t), &w.D_dot);
    w.D_half = mechanism_D(model, platform_at(t + kDt / 2));
    w.D_next = mechanism_D(model, platform_at(t + kDt));
    s->in.push_back(w);
  }
  // check at setup: the commanded rates satisfy eq 25, N(q_n) qdot_n = H_target - D(t_n)
  for (int n = 0; n < 64; ++n) {
    const WristInputs& w = s->in[static_cast<std::size_t>(n)];
    const Vec3 q = s->wrist.angles();
    if (s->wrist.step(w.D, w.D_dot, w.D_half, w.D_next) != Status::ok)
      fail("reactionless wrist tick did not return ok on the bench trajectory", n);
    const Vec3 H = wrist_momentum_matrix(model.wrist_inertia(), q) * s->wrist.command().rates;
    const Vec3 want = s->wrist.target_momentum() - w.D;
    const double rel = (H - want).norm() / std::max(1.0, want.norm());
    if (!(rel < 1e-9)) fail("reactionless wrist: N qdot != H_target - D (relative)", rel);
  }
  s->wrist.reset(kWristStart, s->wrist.target_momentum());
  return [s] {
    const WristInputs& w = s->in[static_cast<std::size_t>(s->k)];
    s->k = (s->k + 1) & (kTicks - 1);
    s->status = s->wrist.step(w.D, w.D_dot, w.D_half, w.D_next);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(&s->wrist.command());
    benchmark::ClobberMemory();
  };
}

// ---------------------------------------------------------------------------- whole PAMINSA tick
struct PlatformInputs {
  PlatformMotion now, half, next;
};

struct PaminsaCase {
  PaminsaCase(WristIntegrator integrator)
      : ctl(PaminsaModel{PaminsaParameters{}}, WristCase::config(integrator), kWristStart) {}
  PaminsaController ctl;
  std::vector<PlatformInputs> in;
  Status status = Status::ok;
  int k = 0;
};

Tick paminsa_case(WristIntegrator integrator) {
  auto s = std::make_shared<PaminsaCase>(integrator);
  PlatformMotion rest = platform_at(0.0);
  rest.velocity.setZero();
  rest.acceleration.setZero();
  if (s->ctl.reset(rest, kWristStart) != Status::ok) fail("PAMINSA reset failed", 0.0);
  for (int n = 0; n < kTicks; ++n) {
    const double t = n * kDt;
    s->in.push_back({platform_at(t), platform_at(t + kDt / 2), platform_at(t + kDt)});
  }
  // check at setup: the total angular momentum about O of all 38 bodies stays at H_target and
  // the shaking moment dH/dt is cancelled at the tick (Briot & Arakelian 2009, eqs 21, 25)
  for (int n = 0; n < 64; ++n) {
    const PlatformInputs& p = s->in[static_cast<std::size_t>(n)];
    if (s->ctl.tick(p.now, p.half, p.next) != Status::ok)
      fail("PAMINSA tick did not return ok on the bench trajectory", n);
    const Vec3& H = s->ctl.wrench().angular_momentum;
    const Vec3& target = s->ctl.wrist().target_momentum();
    const double rel = (H - target).norm() / std::max(1.0, target.norm());
    if (!(rel < 1e-9)) fail("PAMINSA tick: total angular momentum != H_target (relative)", rel);
    const double m = s->ctl.wrench().moment.norm() / (1.0 + s->ctl.D_dot().norm());
    if (!(m < 1e-9)) fail("PAMINSA tick: shaking moment not cancelled (relative)", m);
  }
  s->ctl.reset(rest, kWristStart);
  return [s] {
    const PlatformInputs& p = s->in[static_cast<std::size_t>(s->k)];
    s->k = (s->k + 1) & (kTicks - 1);
    s->status = s->ctl.tick(p.now, p.half, p.next);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(&s->ctl.wrench());
    benchmark::ClobberMemory();
  };
}

// ---------------------------------------------------------------------------- PAMINSA wrench
// Closed-form kinematics of all 38 bodies with a prescribed wrist motion + the shaking wrench
// (what paminsa_kinematics_batch does per instant). Checked at setup against finite differences
// of the total momenta (the wrench is their time derivative, Briot & Arakelian 2009, eqs 1-4).
struct WrenchCase {
  PaminsaModel model{PaminsaParameters{}};
  PaminsaWorkspace ws;
  ShakingWrench out;
  std::vector<PlatformMotion> platform;
  std::vector<WristMotion> wrist;
  Status status = Status::ok;
  int k = 0;
};

Tick paminsa_wrench_case() {
  auto s = std::make_shared<WrenchCase>();
  for (int n = 0; n < kTicks; ++n) {
    s->platform.push_back(platform_at(n * kDt));
    s->wrist.push_back(wrist_at(n * kDt));
  }
  const auto wrench_at = [&](double t) {
    PaminsaWorkspace ws;
    ShakingWrench w;
    if (paminsa_kinematics(s->model, platform_at(t), wrist_at(t), ws) != Status::ok ||
        paminsa_shaking_wrench(s->model, ws, w) != Status::ok)
      fail("PAMINSA bench trajectory is not reachable", t);
    return w;
  };
  const double t = 0.3, h = 1e-5;
  const ShakingWrench a = wrench_at(t - h), b = wrench_at(t), c = wrench_at(t + h);
  const Vec3 dH = (c.angular_momentum - a.angular_momentum) / (2 * h);
  const double rel = (dH - b.moment).norm() / std::max(1.0, b.moment.norm());
  if (!(rel < 1e-6)) fail("PAMINSA wrench: moment != dH/dt (relative)", rel);
  return [s] {
    const std::size_t k = static_cast<std::size_t>(s->k);
    s->k = (s->k + 1) & (kTicks - 1);
    s->status = paminsa_kinematics(s->model, s->platform[k], s->wrist[k], s->ws);
    s->status |= paminsa_shaking_wrench(s->model, s->ws, s->out);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(&s->out);
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(wrist_euler) { return wrist_case(mechbal::WristIntegrator::euler); }
MECHBAL_BENCH_CASE(wrist_rk4) { return wrist_case(mechbal::WristIntegrator::rk4); }
MECHBAL_BENCH_CASE(paminsa_tick_euler) { return paminsa_case(mechbal::WristIntegrator::euler); }
MECHBAL_BENCH_CASE(paminsa_tick_rk4) { return paminsa_case(mechbal::WristIntegrator::rk4); }
MECHBAL_BENCH_CASE(paminsa_wrench) { return paminsa_wrench_case(); }
