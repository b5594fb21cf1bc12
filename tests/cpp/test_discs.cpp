// Serial arms with counter-rotating discs (Coutinho & Hess Coelho): the balanced planar 3R has a
// constant diagonal mass matrix equal to the closed forms of eq 16 and no velocity/gravity terms;
// DecoupledJointController equals ComputedTorque over the balanced model; real-time contract.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "alloc_counter.hpp"
#include "mechbal/computed_torque.hpp"
#include "mechbal/decoupled_control.hpp"
#include "mechbal/disc_arm.hpp"

using namespace mechbal;

namespace {

// Planar 3R of the discs-3r case: vertical y-z plane, axes x, link frames y along the link.
struct Planar3R {
  double l1 = 0.4, l2 = 0.3, m1 = 6.0, m2 = 3.0, m3 = 1.0;
  double J1 = 0.25, J2 = 0.06, J3 = 0.005, J4 = 0.002, J5 = 0.024, J6 = 0.001, J7 = 0.004;
};

JointSpec link(const char* name, double offset, double m, double lg, double Jx) {
  JointSpec j;
  j.name = name;
  j.origin = Eigen::Isometry3d(Eigen::Translation3d(0.0, offset, 0.0));
  j.axis = Vec3::UnitX();
  j.link.mass = m;
  j.link.inertia_body = Vec3(Jx, 0.6 * Jx, 0.6 * Jx).asDiagonal();  // thin plate, physical
  j.com = Vec3(0.0, lg, 0.0);
  return j;
}

DiscSpec disc(int carrier, int joint, double ratio, double J) {
  DiscSpec d;
  d.carrier = carrier;
  d.joint = joint;
  d.ratio = ratio;
  d.inertia = Vec3(J, J / 2, J / 2);
  return d;
}

// eqs 8, 14 (static and dynamic balancing) written here from the paper, independently of Python.
DiscArmDynamics balanced(const Planar3R& p, double beta_scale = 1.0) {
  const double lg1 = -p.l1 * (p.m2 + p.m3) / p.m1, lg2 = -p.l2 * p.m3 / p.m2;
  const double X = p.J2 + p.J3 + p.J4 + p.J6 + p.J7 + p.m3 * p.l2 * p.l2 +
                   p.m3 * p.m3 * p.l2 * p.l2 / p.m2;
  const double beta = -X / p.J5 * beta_scale, gamma = -(p.J3 + p.J6) / p.J7;
  ChainModel chain({link("j1", 0.0, p.m1, lg1, p.J1), link("j2", p.l1, p.m2, lg2, p.J2),
                    link("j3", p.l2, p.m3, 0.0, p.J3)});
  return DiscArmDynamics(chain, {disc(0, 1, 1.0, p.J4), disc(0, 1, beta, p.J5),
                                 disc(1, 2, 1.0, p.J6), disc(1, 2, gamma, p.J7)});
}

Eigen::Vector3d k_eq16(const Planar3R& p) {
  const double X = p.J2 + p.J3 + p.J4 + p.J6 + p.J7 + p.m3 * p.l2 * p.l2 +
                   p.m3 * p.m3 * p.l2 * p.l2 / p.m2;
  const double k1 = p.J1 + p.J2 + p.J3 + p.J4 + p.J5 + p.J6 + p.J7 + p.m2 * p.l1 * p.l1 +
                    p.m3 * (p.l1 * p.l1 + p.l2 * p.l2) +
                    p.l1 * p.l1 * (p.m2 + p.m3) * (p.m2 + p.m3) / p.m1 +
                    p.l2 * p.l2 * p.m3 * p.m3 / p.m2;
  const double k2 = X * (X + p.J5) / p.J5;
  const double k3 = (p.J3 + p.J6) * (p.J3 + p.J6 + p.J7) / p.J7;
  return {k1, k2, k3};
}

}  // namespace

TEST(DiscArm, BalancedPlanar3RIsDiagonalConstantAndFree) {
  Planar3R p;
  DiscArmDynamics dyn = balanced(p);
  const Eigen::Vector3d k = k_eq16(p);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ang(-M_PI, M_PI), rate(-2.0, 2.0);
  Eigen::MatrixXd M(3, 3);
  Eigen::VectorXd v(3), g(3), q(3), qd(3);
  for (int s = 0; s < 200; ++s) {
    for (int i = 0; i < 3; ++i) {
      q(i) = ang(rng);
      qd(i) = rate(rng);
    }
    ASSERT_EQ(dyn.evaluate(q, qd, M, v, g), Status::ok);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(M(i, i), k(i), 1e-12 * k(i));
      for (int j = 0; j < 3; ++j)
        if (i != j) EXPECT_LT(std::abs(M(i, j)), 1e-12 * k.minCoeff());
    }
    EXPECT_LT(v.norm(), 1e-12);
    EXPECT_LT(g.norm(), 1e-12);
  }
}

TEST(DiscArm, MassMatrixSymmetricPositiveDefiniteAndGearRatioRecouples) {
  Planar3R p;
  DiscArmDynamics dyn = balanced(p, 1.05);  // +5 % gear ratio error
  Eigen::MatrixXd M(3, 3);
  Eigen::VectorXd v(3), g(3), q(3), qd(3);
  q << 0.3, -1.1, 2.0;
  qd << 0.5, 1.0, -1.0;
  ASSERT_EQ(dyn.evaluate(q, qd, M, v, g), Status::ok);
  EXPECT_LT((M - M.transpose()).norm(), 1e-14);
  EXPECT_GT(M.selfadjointView<Eigen::Lower>().eigenvalues().minCoeff(), 0.0);
  // D'12 = D12 + J4 + beta J5 + J6 + J7 = 0.05 * beta_nominal * J5 (eq 13): linear in the error.
  const double X = p.J2 + p.J3 + p.J4 + p.J6 + p.J7 + p.m3 * p.l2 * p.l2 +
                   p.m3 * p.m3 * p.l2 * p.l2 / p.m2;
  EXPECT_NEAR(M(0, 1), -0.05 * X, 1e-12);
}

TEST(DiscArm, RejectsBadDiscs) {
  Planar3R p;
  ChainModel chain({link("j1", 0.0, p.m1, 0.1, p.J1), link("j2", p.l1, p.m2, 0.1, p.J2)});
  DiscSpec d = disc(0, 1, 1.0, 0.01);
  d.carrier = 2;
  EXPECT_THROW(DiscArmDynamics(chain, {d}), std::invalid_argument);
  d = disc(0, 1, std::nan(""), 0.01);
  try {
    DiscArmDynamics bad(chain, {disc(0, 1, 1.0, 0.01), d});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("discs[1].ratio"), std::string::npos) << e.what();
  }
  d = disc(0, 1, 1.0, 0.01);
  d.inertia = Vec3(0.01, 0.001, 0.001);  // violates the triangle inequality
  EXPECT_THROW(DiscArmDynamics(chain, {d}), std::invalid_argument);
}

TEST(DecoupledControl, EqualsComputedTorqueOnTheBalancedModelAndAllocatesNothing) {
  Planar3R p;
  DiscArmDynamics dyn = balanced(p);
  const Eigen::Vector3d k = k_eq16(p);
  const Eigen::Vector3d kp(100.0, 120.0, 150.0), kd(20.0, 22.0, 25.0);
  ComputedTorque ct(dyn, kp, kd);
  DecoupledJointController dc(k, kp, kd);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::VectorXd q(3), qd(3), qdes(3), qddes(3), qdddes(3), t1(3), t2(3), v(3), g(3);
  Eigen::MatrixXd Mm(3, 3);
  test::AllocationScope scope;
  for (int s = 0; s < 500; ++s) {
    for (int i = 0; i < 3; ++i) {
      q(i) = 3 * u(rng);
      qd(i) = u(rng);
      qdes(i) = 3 * u(rng);
      qddes(i) = u(rng);
      qdddes(i) = 5 * u(rng);
    }
    ASSERT_EQ(ct.step(q, qd, qdes, qddes, qdddes, t1), Status::ok);
    ASSERT_EQ(dc.step(q, qd, qdes, qddes, qdddes, t2), Status::ok);
    EXPECT_LT((t1 - t2).norm(), 1e-11 * (1.0 + t1.norm()));
    ASSERT_EQ(dyn.evaluate(q, qd, Mm, v, g), Status::ok);
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(DecoupledControl, NonFiniteInputHoldsLastCommandAndLimitsSaturate) {
  const Eigen::Vector3d k(1.0, 2.0, 0.5), kp(100, 100, 100), kd(20, 20, 20);
  DecoupledJointController dc(k, kp, kd, Eigen::Vector3d(5.0, 5.0, 5.0));
  Eigen::VectorXd z = Eigen::VectorXd::Zero(3), q(3), tau(3), good(3);
  q << 0.01, -0.02, 0.0;
  ASSERT_EQ(dc.step(q, z, z, z, z, tau), Status::ok);
  good = tau;
  EXPECT_NEAR(tau(1), 2.0 * 100 * 0.02, 1e-12);
  Eigen::VectorXd nan = z;
  nan(2) = std::numeric_limits<double>::quiet_NaN();
  test::AllocationScope scope;
  EXPECT_EQ(dc.step(q, nan, z, z, z, tau), Status::non_finite_input);
  EXPECT_EQ(tau, good);
  EXPECT_EQ(dc.step(q, z, z, z, nan, tau), Status::non_finite_input);
  EXPECT_EQ(tau, good);
  Eigen::VectorXd big = Eigen::VectorXd::Constant(3, 1e308);
  EXPECT_EQ(dc.step(q, z, z, z, big, tau), Status::out_of_range);  // absurd, finite
  EXPECT_EQ(tau, good);
  Eigen::VectorXd far = Eigen::VectorXd::Constant(3, 10.0);
  EXPECT_EQ(dc.step(q, z, far, z, z, tau), Status::saturated);
  EXPECT_DOUBLE_EQ(tau(0), 5.0);
  Eigen::VectorXd two(2);
  EXPECT_EQ(dc.step(two, z, z, z, z, tau), Status::bad_size);
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_THROW(DecoupledJointController(Eigen::Vector3d(1, -1, 1), kp, kd), std::invalid_argument);
  EXPECT_THROW(DecoupledJointController(k, Eigen::Vector2d(1, 1), kd), std::invalid_argument);
}
