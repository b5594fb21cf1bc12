// Joint stops of the closed-loop simulator (ClosedLoopOptions::lower_limit / upper_limit) and
// simulate_passive (control/passive.hpp): a pendulum let go falls onto its stop and stays there
// (never beyond it, its rate removed: an inelastic stop), a double pendulum's stop takes the
// impact through the inverse mass matrix (the other joint's generalised momentum is kept across
// it), no stops leave the motion unchanged, and bad stops are refused naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/control/passive.hpp"

using namespace mechbal;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Links along x, hinges about -y: q > 0 lifts the link, gravity -z pulls q down.
MechanismModel pendulum(int links, double lower, double upper) {
  MechanismDescription d;
  std::string parent = d.root_name;
  for (int i = 0; i < links; ++i) {
    Joint j;
    j.name = "j" + std::to_string(i + 1);
    j.parent = parent;
    j.axis = Vec3(0.0, -1.0, 0.0);
    if (i > 0) j.placement.translation() = Vec3(0.5, 0.0, 0.0);
    if (i == links - 1) {
      j.lower = lower;
      j.upper = upper;
    }
    d.joints.push_back(j);
    Body b;
    b.name = j.name + "_link";
    b.link = j.name;
    b.mass = 1.0 + 0.3 * i;
    b.com = Vec3(0.3, 0.0, 0.0);
    b.inertia = Mat3::Identity() * 0.02;
    d.bodies.push_back(b);
    parent = j.name;
  }
  return MechanismModel(d);
}

ClosedLoopOptions options(int n, double lower, double upper, double duration) {
  ClosedLoopOptions o;
  o.dt = 1e-3;
  o.duration = duration;
  o.lower_limit = Eigen::VectorXd::Constant(n, -kInf);
  o.upper_limit = Eigen::VectorXd::Constant(n, kInf);
  o.lower_limit(n - 1) = lower;
  o.upper_limit(n - 1) = upper;
  return o;
}

}  // namespace

TEST(PassiveStops, PendulumRestsOnItsStop) {
  const double lower = -0.8;
  MechanismDynamics plant(pendulum(1, lower, 2.0));
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(1, 0.3), v0 = Eigen::VectorXd::Zero(1);
  const ClosedLoopLog log = simulate_passive(plant, q0, v0, options(1, lower, 2.0, 1.5));
  ASSERT_EQ(log.status, Status::ok);
  EXPECT_GT(log.stop_ticks, 100);
  EXPECT_GE(log.q.minCoeff(), lower);              // never beyond the stop
  EXPECT_EQ(log.q(log.q.rows() - 1, 0), lower);    // resting on it ...
  EXPECT_EQ(log.qd(log.qd.rows() - 1, 0), 0.0);    // ... at rest (inelastic: no bounce)
  // the free pendulum passes the same angle
  ClosedLoopOptions free = options(1, lower, 2.0, 1.5);
  free.lower_limit.resize(0);
  free.upper_limit.resize(0);
  const ClosedLoopLog passing = simulate_passive(plant, q0, v0, free);
  EXPECT_LT(passing.q.minCoeff(), lower - 0.5);
  EXPECT_EQ(passing.stop_ticks, 0);
}

TEST(PassiveStops, TheImpactGoesThroughTheInverseMassMatrix) {
  // joint 2 hits its stop while joint 1 swings: the stop's impulse acts on joint 2 only, so the
  // generalised momentum of joint 1, (M v)_1, is continuous across the impact step (up to the
  // smooth forces over one step), while joint 2's rate jumps to zero
  MechanismModel model = pendulum(2, -0.4, 2.0);
  MechanismDynamics plant(model);
  Eigen::VectorXd q0(2), v0(2);
  q0 << 0.2, 0.3;
  v0 << 0.0, -8.0;
  const ClosedLoopLog log = simulate_passive(plant, q0, v0, options(2, -0.4, 2.0, 0.3));
  ASSERT_EQ(log.status, Status::ok);
  ASSERT_GT(log.stop_ticks, 0);
  EXPECT_GE(log.q.col(1).minCoeff(), -0.4);
  int k = 0;
  while (log.q(k + 1, 1) > -0.4) ++k;   // step k ends on the stop
  Eigen::MatrixXd M0(2, 2), M1(2, 2);
  plant.mass_matrix(log.q.row(k).transpose(), M0);
  plant.mass_matrix(log.q.row(k + 1).transpose(), M1);
  const double p_before = (M0 * log.qd.row(k).transpose())(0);
  const double p_after = (M1 * log.qd.row(k + 1).transpose())(0);
  EXPECT_EQ(log.qd(k + 1, 1), 0.0);
  EXPECT_LT(log.qd(k, 1), -1.0);                        // a real impact
  EXPECT_NEAR(p_after, p_before, 0.02);   // gravity and Coriolis over one step: < 0.02
  // zeroing joint 2's rate alone (no impulse on joint 1) would change (M v)_1 by M_12 v_2
  EXPECT_GT(std::abs(M0(0, 1) * log.qd(k, 1)), 0.1);
}

TEST(PassiveStops, InfiniteStopsChangeNothing) {
  MechanismDynamics plant(pendulum(2, -kInf, kInf));
  Eigen::VectorXd q0(2), v0(2);
  q0 << 0.2, 0.3;
  v0 << 0.5, -1.0;
  ClosedLoopOptions with = options(2, -kInf, kInf, 0.5), without = with;
  without.lower_limit.resize(0);
  without.upper_limit.resize(0);
  const ClosedLoopLog a = simulate_passive(plant, q0, v0, with), b = simulate_passive(plant, q0, v0, without);
  EXPECT_EQ(a.stop_ticks, 0);
  EXPECT_EQ((a.q - b.q).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a.qd - b.qd).cwiseAbs().maxCoeff(), 0.0);
}

TEST(PassiveStops, BadStopsAreRefusedNamingTheField) {
  MechanismDynamics plant(pendulum(1, -1.0, 1.0));
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(1, 0.3), v0 = Eigen::VectorXd::Zero(1);
  auto message = [&](ClosedLoopOptions o, const Eigen::VectorXd& q) {
    try {
      simulate_passive(plant, q, v0, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  ClosedLoopOptions o = options(1, -1.0, 1.0, 0.1);
  o.upper_limit.resize(2);
  o.upper_limit.setConstant(1.0);
  EXPECT_NE(message(o, q0).find("lower_limit and upper_limit"), std::string::npos);
  o = options(1, 1.0, -1.0, 0.1);
  EXPECT_NE(message(o, q0).find("lower_limit <= upper_limit"), std::string::npos);
  o = options(1, std::nan(""), 1.0, 0.1);
  EXPECT_NE(message(o, q0).find("lower_limit <= upper_limit"), std::string::npos);
  o = options(1, -1.0, 0.2, 0.1);
  EXPECT_NE(message(o, q0).find("q0[0]"), std::string::npos);
}
