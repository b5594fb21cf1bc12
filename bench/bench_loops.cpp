// Closed loops on the general model (issue 10, "Performance"): one tick of the general path where
// the papers have closed forms.
//  - paminsa_general_wrench: PAMINSA as 38 bodies on a tree with 9 loop closures (22 passive
//    coordinates, 24 closure equations; paminsa_general.hpp): closed_motion (position solve
//    warm-started from the last tick, v = C v#, a = C a# + c) from the paper's actuators (M_1, M_3,
//    M_v) and the wrist, then shaking_wrench (momenta and their rates about O) of every body.
//    Same platform and wrist motion as paminsa_wrench (the closed form of the same quantities):
//    ratio paminsa_general_over_closed_form.
//  - four_bar_tick: closed_inverse_dynamics of a four-bar (position solve, projection, tree
//    inverse dynamics, tau# = C^T tau; the test's four-bar, tests/cpp/test_loops.cpp).
// Ticks run back and forth along 1024 precomputed instants at 1 kHz (no jump for the warm start).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench_registry.hpp"
#include "bench_support.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "paminsa_general.hpp"
#include "paminsa_motion.hpp"

namespace mechbal::bench {
namespace {

using test::platform_at;
using test::wrist_at;

constexpr double kDt = 1e-3;
constexpr int kTicks = 1024;

// ---------------------------------------------------------------------------- PAMINSA general
struct PaminsaGeneralCase {
  PaminsaModel closed{PaminsaParameters{}};
  MechanismModel model{paminsa_description(closed)};
  MechanismData data{model};
  std::vector<ActuatedState> in;
  Eigen::VectorXd q;
  PingPong<kTicks> order;
  Status status = Status::ok;
};

Tick paminsa_general_case() {
  auto s = std::make_shared<PaminsaGeneralCase>();
  for (int n = 0; n < kTicks; ++n) s->in.push_back(actuated(s->closed, s->model, platform_at(n * kDt), wrist_at(n * kDt)));
  // check at setup, at 64 consecutive ticks: the general path's momenta and shaking wrench equal
  // the closed form's (paminsa_kinematics + paminsa_shaking_wrench of the 38 bodies) to 1e-9
  s->q = initial_guess(s->closed, s->model, platform_at(0.0), wrist_at(0.0));
  PaminsaWorkspace ws;
  for (int n = 0; n < 64; ++n) {
    const ActuatedState& a = s->in[static_cast<std::size_t>(n)];
    if (closed_shaking_wrench(s->model, s->data, a.q, a.v, a.a, s->q) != Status::ok)
      fail("PAMINSA general model: closed_shaking_wrench failed on the bench trajectory", n);
    ShakingWrench w;
    if (paminsa_kinematics(s->closed, platform_at(n * kDt), wrist_at(n * kDt), ws) != Status::ok ||
        paminsa_shaking_wrench(s->closed, ws, w) != Status::ok)
      fail("PAMINSA closed form failed on the bench trajectory", n);
    const ShakingWrench& g = s->data.shaking;
    const double rel = std::max({(g.force - w.force).norm() / std::max(1.0, w.force.norm()),
                                 (g.moment - w.moment).norm() / std::max(1.0, w.moment.norm()),
                                 (g.linear_momentum - w.linear_momentum).norm() / std::max(1.0, w.linear_momentum.norm()),
                                 (g.angular_momentum - w.angular_momentum).norm() / std::max(1.0, w.angular_momentum.norm())});
    if (!(rel < 1e-9)) fail("PAMINSA general model != closed form (relative)", rel);
  }
  s->q = initial_guess(s->closed, s->model, platform_at(0.0), wrist_at(0.0));
  return [s] {
    const ActuatedState& a = s->in[s->order.next()];
    s->status = closed_shaking_wrench(s->model, s->data, a.q, a.v, a.a, s->q);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(&s->data.shaking);
    benchmark::ClobberMemory();
  };
}

// ---------------------------------------------------------------------------- four-bar
Eigen::Isometry3d at(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Vec3(x, 0.0, 0.0);
  return T;
}

}  // namespace

/// The four-bar of tests/cpp/test_loops.cpp (also bench_loops_pinocchio.cpp's).
MechanismModel bench_four_bar() {
  const auto rod = [](const std::string& name, double mass, double length) {
    return Body{name, "link", name, mass, Vec3(0.5 * length, 0.01, 0.0),
                Mat3(Vec3(1e-4, mass * length * length / 12.0, mass * length * length / 12.0).asDiagonal())};
  };
  MechanismDescription d;
  d.gravity = Vec3(0.0, -9.81, 0.0);
  d.joints = {Joint{"crank", JointType::revolute, "base"}, Joint{"coupler", JointType::revolute, "crank", at(0.2)},
              Joint{"rocker", JointType::revolute, "base", at(0.45)}};
  d.bodies = {rod("crank", 0.8, 0.2), rod("coupler", 1.5, 0.5), rod("rocker", 1.1, 0.4)};
  d.frames = {Frame{"coupler_tip", "coupler", at(0.5)}, Frame{"rocker_tip", "rocker", at(0.4)}};
  d.loops = {LoopConstraint{"tip", LoopType::point, "coupler_tip", "rocker_tip"}};
  d.actuated = {"crank"};
  return MechanismModel(d);
}

namespace {

struct FourBarCase {
  MechanismModel model{bench_four_bar()};
  MechanismData data{model};
  std::vector<ActuatedState> in;
  Eigen::VectorXd q = (Eigen::VectorXd(3) << 1.0, -0.6, 1.75).finished();
  PingPong<kTicks> order;
  Status status = Status::ok;
};

Tick four_bar_case() {
  auto s = std::make_shared<FourBarCase>();
  for (int n = 0; n < kTicks; ++n) {  // the crank swings 1.0 +- 0.4 rad at 2 rad/s
    const double t = n * kDt;
    s->in.push_back({Eigen::VectorXd::Constant(1, 1.0 + 0.4 * std::sin(2.0 * t)),
                     Eigen::VectorXd::Constant(1, 0.8 * std::cos(2.0 * t)),
                     Eigen::VectorXd::Constant(1, -1.6 * std::sin(2.0 * t))});
  }
  // check at setup: the loop closes and forward dynamics of the actuated force gives back a#
  for (int n = 0; n < 64; ++n) {
    const ActuatedState& a = s->in[static_cast<std::size_t>(n)];
    if (closed_inverse_dynamics(s->model, s->data, a.q, a.v, a.a, s->q) != Status::ok)
      fail("four-bar: closed_inverse_dynamics failed", n);
    if (!(s->data.loop_residual_norm < 1e-12)) fail("four-bar: loop not closed", s->data.loop_residual_norm);
    const Eigen::VectorXd tau = s->data.actuated_force;
    if (closed_forward_dynamics(s->model, s->data, a.q, a.v, tau, s->q) != Status::ok)
      fail("four-bar: closed_forward_dynamics failed", n);
    const double err = (s->data.actuated_acceleration - a.a).cwiseAbs().maxCoeff();
    if (!(err < 1e-9)) fail("four-bar: forward dynamics does not invert inverse dynamics", err);
  }
  s->q << 1.0, -0.6, 1.75;
  return [s] {
    const ActuatedState& a = s->in[s->order.next()];
    s->status = closed_inverse_dynamics(s->model, s->data, a.q, a.v, a.a, s->q);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(s->data.actuated_force.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(paminsa_general_wrench) { return paminsa_general_case(); }
MECHBAL_BENCH_CASE(four_bar_tick) { return four_bar_case(); }
