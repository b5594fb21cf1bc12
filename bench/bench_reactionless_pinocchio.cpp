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
#include <map>
#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/constrained-dynamics.hpp>
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/multibody.hpp>
#include <vector>

#include "bench_registry.hpp"
#include "bench_support.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/control/reactionless.hpp"
#include "mechbal/model/data.hpp"
#include "reaction_wheel_arm.hpp"

namespace mechbal::bench {
namespace {

constexpr int kTicks = 6284;
const double kDt = 2.0 * M_PI / kTicks;

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

// ============================================================================ closed-loop anchor
// A closed-loop anchor (issue 26): the four-bar of bench_loops.cpp in Pinocchio's constrained
// dynamics (constraintDynamics: a CONTACT_3D constraint between the coupler's and the rocker's tips,
// the proximal solver), against mechbal's closed_forward_dynamics on the same mechanism and the
// same instants.
//  - closed_forward_four_bar_mechbal: closed_forward_dynamics from the actuated state (crank angle,
//    rate, torque): the position solve of the two passive angles (warm-started from the last tick),
//    the projection v = C v#, a = C a# + c, the reduced mass matrix C^T M C and the bias, the solve
//    for a#, and the motion of all three joints (data.closed_acceleration).
//  - closed_forward_four_bar_pinocchio: constraintDynamics from the full state (all three angles and
//    rates, which mechbal's position solve produced: Pinocchio has no position solve), torque on the
//    crank: crba, the Delassus matrix of the constraint, the proximal Cholesky solve, ddq of all
//    three joints. The z row of the point constraint is identically zero (planar mechanism): the
//    proximal damping mu handles it, as Pinocchio's documentation advises for redundant rows.
// So mechbal's tick does strictly more (it also closes the loop from the crank angle alone).
// Setup checks that both give the same accelerations of the three joints (1e-8) at 64 instants.
// (In this translation unit to compile Pinocchio's headers once for both.)
namespace mechbal::bench {
MechanismModel bench_four_bar();  // bench_loops.cpp
namespace four_bar_anchor {
namespace {

constexpr double kDt = 1e-3;
constexpr int kTicks = 1024;

/// The crank's state and torque along a swing; the torque holds the crank against gravity with a
/// periodic excess, so that the accelerations are of the order of the bench's other motions.
struct Instant {
  Eigen::VectorXd qa, va, tau;
};

std::vector<Instant> crank_instants() {
  std::vector<Instant> out;
  for (int n = 0; n < kTicks; ++n) {
    const double t = n * kDt;
    out.push_back({Eigen::VectorXd::Constant(1, 1.0 + 0.4 * std::sin(2.0 * t)),
                   Eigen::VectorXd::Constant(1, 0.8 * std::cos(2.0 * t)),
                   Eigen::VectorXd::Constant(1, 2.0 + 1.5 * std::sin(3.0 * t))});
  }
  return out;
}

const Eigen::VectorXd kStart = (Eigen::VectorXd(3) << 1.0, -0.6, 1.75).finished();

struct MechCase {
  MechanismModel model{bench_four_bar()};
  MechanismData data{model};
  std::vector<Instant> in = crank_instants();
  Eigen::VectorXd q = kStart;
  PingPong<kTicks> order;
  Status status = Status::ok;
};

using ConstraintModels = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(pinocchio::RigidConstraintModel);
using ConstraintDatas = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(pinocchio::RigidConstraintData);

/// The four-bar as a Pinocchio model: three RZ joints (crank and rocker on the base, coupler on
/// the crank), the bodies of mechbal's description, the loop as a CONTACT_3D constraint between the
/// frames of the tips (placements relative to the coupler's and the rocker's joint frames).
struct PinCase {
  explicit PinCase(const MechanismModel& m) {
    const auto& d = m.description();
    std::vector<pinocchio::JointIndex> id;
    std::map<std::string, pinocchio::JointIndex> of_link;  // a link is named by the joint moving it
    for (std::size_t i = 0; i < d.joints.size(); ++i) {
      const Joint& j = d.joints[i];
      if (j.type != JointType::revolute || j.axis != Vec3::UnitZ()) fail("four-bar: expected RZ joints", 0);
      const pinocchio::JointIndex parent = j.parent == d.root_name ? 0 : of_link.at(j.parent);
      id.push_back(model.addJoint(parent, pinocchio::JointModelRZ(),
                                  pinocchio::SE3(j.placement.linear(), j.placement.translation()), j.name));
      of_link[j.name] = id.back();
      const Body& b = d.bodies[i];
      model.appendBodyToJoint(id.back(), pinocchio::Inertia(b.mass, b.com, b.inertia), pinocchio::SE3::Identity());
    }
    model.gravity.linear(m.gravity());
    const auto tip = [&](const std::string& frame) {
      for (const Frame& f : d.frames)
        if (f.name == frame) return std::make_pair(of_link.at(f.link),
                                                   pinocchio::SE3(f.placement.linear(), f.placement.translation()));
      fail("four-bar: frame not found", 0);
    };
    const LoopConstraint& loop = d.loops.front();
    const auto a = tip(loop.frame_a), b = tip(loop.frame_b);
    constraints.emplace_back(pinocchio::CONTACT_3D, model, a.first, a.second, b.first, b.second, pinocchio::LOCAL);
    data = std::make_unique<pinocchio::Data>(model);
    for (const auto& c : constraints) constraint_data.emplace_back(c);
    pinocchio::initConstraintDynamics(model, *data, constraints, constraint_data);
  }
  pinocchio::Model model;
  std::unique_ptr<pinocchio::Data> data;
  ConstraintModels constraints;
  ConstraintDatas constraint_data;
  pinocchio::ProximalSettings settings{1e-12, 1e-12, 3};
  std::vector<Eigen::VectorXd> q, v, tau;  // full state of each instant (from mechbal's solve)
  PingPong<kTicks> order;
};

Tick mechbal_case() {
  auto s = std::make_shared<MechCase>();
  for (int n = 0; n < 64; ++n) {
    const Instant& x = s->in[static_cast<std::size_t>(n)];
    if (closed_forward_dynamics(s->model, s->data, x.qa, x.va, x.tau, s->q) != Status::ok)
      fail("four-bar: closed_forward_dynamics failed", n);
  }
  s->q = kStart;
  return [s] {
    const Instant& x = s->in[s->order.next()];
    s->status = closed_forward_dynamics(s->model, s->data, x.qa, x.va, x.tau, s->q);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(s->data.closed_acceleration.data());
    benchmark::ClobberMemory();
  };
}

Tick pinocchio_case() {
  MechCase m;
  auto s = std::make_shared<PinCase>(m.model);
  double worst = 0.0;
  for (int n = 0; n < kTicks; ++n) {
    const Instant& x = m.in[static_cast<std::size_t>(n)];
    if (closed_forward_dynamics(m.model, m.data, x.qa, x.va, x.tau, m.q) != Status::ok)
      fail("four-bar: closed_forward_dynamics failed", n);
    // mechbal's coordinates are Pinocchio's (three RZ joints in the same order); tau on the crank
    s->q.push_back(m.data.closed_position);
    s->v.push_back(m.data.closed_velocity);
    Eigen::VectorXd tau = Eigen::VectorXd::Zero(3);
    tau(m.model.actuated_coordinates().front()) = x.tau(0);
    s->tau.push_back(tau);
    if (n < 64) {
      pinocchio::constraintDynamics(s->model, *s->data, s->q.back(), s->v.back(), s->tau.back(), s->constraints,
                                    s->constraint_data, s->settings);
      worst = std::max(worst, (s->data->ddq - m.data.closed_acceleration).cwiseAbs().maxCoeff() /
                                  std::max(1.0, m.data.closed_acceleration.cwiseAbs().maxCoeff()));
    }
  }
  if (!(worst < 1e-8)) fail("four-bar: Pinocchio's constraintDynamics != mechbal's closed_forward_dynamics", worst);
  return [s] {
    const std::size_t k = s->order.next();
    pinocchio::constraintDynamics(s->model, *s->data, s->q[k], s->v[k], s->tau[k], s->constraints,
                                  s->constraint_data, s->settings);
    benchmark::DoNotOptimize(s->data->ddq.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace four_bar_anchor
}  // namespace mechbal::bench

MECHBAL_BENCH_CASE(closed_forward_four_bar_mechbal) { return mechbal::bench::four_bar_anchor::mechbal_case(); }
MECHBAL_BENCH_CASE(closed_forward_four_bar_pinocchio) { return mechbal::bench::four_bar_anchor::pinocchio_case(); }
