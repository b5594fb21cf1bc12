// The reactionless controller of control/reactionless.hpp written over Pinocchio, on the same
// reaction-wheel arm and task motion as reactionless_wheel_{euler,rk4} (bench_reactionless.cpp):
// computeCentroidalMap gives A_G (momentum about the centre of mass); about O, H_O = H_G + c x P,
// so A_O = [A_lin; A_ang + c x A_lin]. Each tick: the rate solve of the cancelled rows (the same
// normal-equation solve as mechbal's), the feed-forward from computeCentroidalMapTimeVariation
// (dh_G/dt = A_G a + dA_G v, moved to O: dH_O/dt = dH_G/dt + c x dP/dt), the predicted wrench, and
// Euler or RK4 (three more centroidal maps). Setup checks it against mechbal's controller.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/multibody.hpp>
#include <vector>

#include "bench_registry.hpp"
#include "mechbal/control/reactionless.hpp"
#include "reaction_wheel_arm.hpp"

namespace mechbal::bench {
namespace {

constexpr int kTicks = 6284;
const double kDt = 2.0 * M_PI / kTicks;

[[noreturn]] void fail(const char* what, double value) {
  std::fprintf(stderr, "mechbal-bench: %s (%g)\n", what, value);
  std::abort();
}

/// The wheel arm as a Pinocchio model (three RZ joints).
pinocchio::Model wheel_arm_pinocchio(const MechanismModel& m) {
  pinocchio::Model model;
  pinocchio::JointIndex parent = 0;
  const auto& d = m.description();
  for (std::size_t i = 0; i < d.joints.size(); ++i) {
    const Joint& j = d.joints[i];
    const pinocchio::SE3 placement(j.placement.linear(), j.placement.translation());
    const auto id = model.addJoint(parent, pinocchio::JointModelRZ(), placement, j.name);
    const Body& b = d.bodies[i];
    model.appendBodyToJoint(id, pinocchio::Inertia(b.mass, b.com, b.inertia), pinocchio::SE3::Identity());
    parent = id;
  }
  return model;
}

void wheel_task(double t, Eigen::Vector2d& q, Eigen::Vector2d& v, Eigen::Vector2d& a) {
  const double amp[2] = {0.8, -1.1}, om[2] = {3.0, 4.0};
  for (int i = 0; i < 2; ++i) {
    q(i) = 0.2 + amp[i] * (1.0 - std::cos(om[i] * t));
    v(i) = amp[i] * om[i] * std::sin(om[i] * t);
    a(i) = amp[i] * om[i] * om[i] * std::cos(om[i] * t);
  }
}

inline Mat3 skew(const Vec3& c) {
  Mat3 S;
  S << 0, -c(2), c(1), c(2), 0, -c(0), -c(1), c(0), 0;
  return S;
}

/// The controller over Pinocchio: task joints 0, 1; balancing joint 2; cancelled row 5 (moment z).
struct PinocchioReactionless {
  explicit PinocchioReactionless(const pinocchio::Model& m) : model(m), data(m) {}
  pinocchio::Model model;
  pinocchio::Data data;
  Eigen::Vector3d q = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(), a = Eigen::Vector3d::Zero();
  double target = 0.0, wheel = 0.0, wheel_rate = 0.0, wheel_acc = 0.0;
  Eigen::Matrix<double, 6, 3> AO;
  Eigen::Matrix<double, 6, 1> predicted;
  double dt = kDt;
  static constexpr double damping = 1e-2, max_condition = 1e4;

  /// A_O at (q_t, wheel), the rows of the cancelled components
  void map(const Eigen::Vector2d& qt, double qb) {
    q << qt, qb;
    pinocchio::computeCentroidalMap(model, data, q);
    AO = data.Ag;
    AO.bottomRows<3>() += skew(data.com[0]) * data.Ag.topRows<3>();
  }
  /// the same (normal-equation) solve as mechbal's for one balancing joint and one row
  double rate(const Eigen::Vector2d& vt) const {
    const double kb = AO(5, 2), r = target - AO(5, 0) * vt(0) - AO(5, 1) * vt(1);
    const double g = kb * kb;
    return g > 0.0 ? r / kb : 0.0;  // 1x1: cond = 1
  }
  void step(const Eigen::Vector2d& qt, const Eigen::Vector2d& vt, const Eigen::Vector2d& at, const Eigen::Vector2d& qh,
            const Eigen::Vector2d& vh, const Eigen::Vector2d& qn, const Eigen::Vector2d& vn, bool rk4) {
    map(qt, wheel);
    const double k1 = rate(vt);
    v << vt, k1;
    pinocchio::computeCentroidalMapTimeVariation(model, data, q, v);
    // dh_G/dt = A_G a + dA_G v; bias about O: [dAg v]_lin, [dAg v]_ang + c x [dAg v]_lin
    Eigen::Matrix<double, 6, 1> bias = data.dAg * v;
    bias.tail<3>() += data.com[0].cross(bias.head<3>());
    const double rhs = -AO(5, 0) * at(0) - AO(5, 1) * at(1) - bias(5);
    wheel_acc = rhs / AO(5, 2);
    a << at, wheel_acc;
    predicted = AO * a + bias;
    wheel_rate = k1;
    if (rk4) {
      map(qh, wheel + 0.5 * dt * k1);
      const double k2 = rate(vh);
      map(qh, wheel + 0.5 * dt * k2);
      const double k3 = rate(vh);
      map(qn, wheel + dt * k3);
      const double k4 = rate(vn);
      wheel += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    } else {
      wheel += dt * k1;
    }
  }
};

struct PinCase {
  std::unique_ptr<PinocchioReactionless> ctrl;
  std::vector<std::array<Eigen::Vector2d, 7>> in;
  bool rk4 = false;
  int k = 0;
};

Tick pinocchio_wheel_case(bool rk4) {
  auto s = std::make_shared<PinCase>();
  const MechanismModel arm = test::reaction_wheel_arm();
  s->ctrl = std::make_unique<PinocchioReactionless>(wheel_arm_pinocchio(arm));
  s->rk4 = rk4;
  s->ctrl->wheel = 0.0;
  for (int n = 0; n < kTicks; ++n) {
    std::array<Eigen::Vector2d, 7> x;
    Eigen::Vector2d unused;
    wheel_task(n * kDt, x[0], x[1], x[2]);
    wheel_task((n + 0.5) * kDt, x[3], x[4], unused);
    wheel_task((n + 1) * kDt, x[5], x[6], unused);
    s->in.push_back(x);
  }
  // target: the momentum at the start (the task at t = 0 is at rest: zero)
  s->ctrl->target = 0.0;
  // setup check against mechbal's controller on the same arm and motion
  ReactionlessConfig c;
  c.balancing_joints = {"wheel"};
  c.cancel = moment_z;
  c.integrator = rk4 ? ReactionlessIntegrator::rk4 : ReactionlessIntegrator::euler;
  c.rate_hz = 1.0 / kDt;
  ReactionlessController ref(arm, c, Eigen::Vector3d(0.2, 0.2, 0.0));
  for (int n = 0; n < 300; ++n) {
    const auto& x = s->in[static_cast<std::size_t>(n)];
    ref.step(x[0], x[1], x[2], x[3], x[4], x[5], x[6]);
    s->ctrl->step(x[0], x[1], x[2], x[3], x[4], x[5], x[6], rk4);
    const double err = std::abs(ref.command().v(2) - s->ctrl->wheel_rate) +
                       std::abs(ref.command().a(2) - s->ctrl->wheel_acc) +
                       std::abs(ref.balancing_state()(0) - s->ctrl->wheel) +
                       (ref.command().shaking_moment - s->ctrl->predicted.tail<3>()).norm();
    if (!(err < 1e-8)) fail("reactionless over Pinocchio != mechbal's controller", err);
  }
  s->k = 300;
  return [s] {
    const auto& x = s->in[static_cast<std::size_t>(s->k)];
    s->k = s->k + 1 == kTicks ? 0 : s->k + 1;
    s->ctrl->step(x[0], x[1], x[2], x[3], x[4], x[5], x[6], s->rk4);
    benchmark::DoNotOptimize(s->ctrl->wheel);
    benchmark::DoNotOptimize(s->ctrl->predicted.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

MECHBAL_BENCH_CASE(reactionless_wheel_euler_pinocchio) { return mechbal::bench::pinocchio_wheel_case(false); }
MECHBAL_BENCH_CASE(reactionless_wheel_rk4_pinocchio) { return mechbal::bench::pinocchio_wheel_case(true); }
