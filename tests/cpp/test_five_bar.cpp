// Planar 5R five-bar by the coupling-matrix method with a 4x4 A° (Coutinho & Hess Coelho):
// against the closed-form Lagrangian of the parallelogram five-bar written here independently,
// constant-diagonal after leg-wise static balancing over 1000 states, the decoupled controller
// equal to computed torque over it, singular poses give a status and no NaN, no allocation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "alloc_counter.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/papers/five_bar/five_bar.hpp"

using namespace mechbal;

namespace {

// The five-bar case (parallelogram: d = 0, b1 = a2, b2 = a1), unbalanced (mid-link CoMs).
FiveBarParameters parallelogram() {
  FiveBarParameters p;
  p.a1 = 0.3;
  p.a2 = 0.25;
  p.b1 = 0.25;
  p.b2 = 0.3;
  p.d = 0.0;
  p.mp1 = 3.0;
  p.mp2 = 2.5;
  p.md1 = 1.2;
  p.md2 = 1.5;
  p.mP = 0.5;
  p.cp1 = 0.15;
  p.cp2 = 0.125;
  p.cd1 = 0.125;
  p.cd2 = 0.15;
  p.Jp1 = 0.08;
  p.Jp2 = 0.06;
  p.Jd1 = 0.012;
  p.Jd2 = 0.018;
  return p;
}

// Leg-wise static balancing (eq 8 applied to each leg carrying its share mP1 of the end effector).
FiveBarParameters balanced(FiveBarParameters p, double mP1) {
  const double mP2 = p.mP - mP1;
  p.cd1 = -mP1 * p.b1 / p.md1;
  p.cd2 = -mP2 * p.b2 / p.md2;
  p.cp1 = -p.a1 * (p.md1 + mP1) / p.mp1;
  p.cp2 = -p.a2 * (p.md2 + mP2) / p.mp2;
  return p;
}

// Lagrangian of the parallelogram five-bar (distal 1 parallel to proximal 2, distal 2 to
// proximal 1, P = B1 + B2): M = [[k1, K c], [K c, k2]], c = cos(q2 - q1),
// v = K sin(q2 - q1) (-q2'^2, q1'^2), g = g (G1 cos q1, G2 cos q2).
struct Closed {
  Eigen::Matrix2d M;
  Eigen::Vector2d v, g;
};
Closed parallelogram_lagrangian(const FiveBarParameters& p, const Eigen::Vector2d& q,
                                const Eigen::Vector2d& qd) {
  const double k1 = p.Jp1 + p.mp1 * p.cp1 * p.cp1 + (p.md1 + p.mP) * p.a1 * p.a1 + p.Jd2 +
                    p.md2 * p.cd2 * p.cd2;
  const double k2 = p.Jp2 + p.mp2 * p.cp2 * p.cp2 + (p.md2 + p.mP) * p.a2 * p.a2 + p.Jd1 +
                    p.md1 * p.cd1 * p.cd1;
  const double K = p.md1 * p.a1 * p.cd1 + p.md2 * p.a2 * p.cd2 + p.mP * p.a1 * p.a2;
  const double c = std::cos(q(1) - q(0)), s = std::sin(q(1) - q(0));
  Closed r;
  r.M << k1, K * c, K * c, k2;
  r.v << -K * s * qd(1) * qd(1), K * s * qd(0) * qd(0);
  r.g << p.gravity * std::cos(q(0)) * (p.mp1 * p.cp1 + p.md1 * p.a1 + p.md2 * p.cd2 + p.mP * p.a1),
      p.gravity * std::cos(q(1)) * (p.mp2 * p.cp2 + p.md1 * p.cd1 + p.md2 * p.a2 + p.mP * p.a2);
  return r;
}

// Random state away from the flat configurations (|q2 - q1| in [0.25, pi - 0.25]).
void random_state(std::mt19937& rng, Eigen::Vector2d& q, Eigen::Vector2d& qd) {
  std::uniform_real_distribution<double> ang(-M_PI, M_PI), gap(0.25, M_PI - 0.25), rate(-2, 2);
  std::bernoulli_distribution sign(0.5);
  q(0) = ang(rng);
  q(1) = q(0) + (sign(rng) ? 1.0 : -1.0) * gap(rng);
  qd << rate(rng), rate(rng);
}

}  // namespace

TEST(FiveBar, EqualsTheParallelogramLagrangianForRandomParameters) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> f(0.7, 1.3), off(-0.2, 0.4);
  for (int design = 0; design < 5; ++design) {
    FiveBarParameters p = parallelogram();
    p.a1 *= f(rng);
    p.a2 *= f(rng);
    p.b1 = p.a2;
    p.b2 = p.a1;
    for (double* m : {&p.mp1, &p.mp2, &p.md1, &p.md2, &p.mP, &p.Jp1, &p.Jp2, &p.Jd1, &p.Jd2})
      *m *= f(rng);
    for (double* c : {&p.cp1, &p.cp2, &p.cd1, &p.cd2}) *c = off(rng);
    FiveBarDynamics dyn(p);
    Eigen::Matrix2d M;
    Eigen::Vector2d v, g, q, qd;
    for (int s = 0; s < 200; ++s) {
      random_state(rng, q, qd);
      ASSERT_EQ(dyn.evaluate(q, qd, M, v, g), Status::ok);
      const Closed ref = parallelogram_lagrangian(p, q, qd);
      const double sM = ref.M.cwiseAbs().maxCoeff();
      EXPECT_LT((M - ref.M).cwiseAbs().maxCoeff(), 1e-12 * sM);
      EXPECT_LT((v - ref.v).cwiseAbs().maxCoeff(), 1e-12 * sM * 4.0);
      EXPECT_LT((g - ref.g).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + ref.g.cwiseAbs().maxCoeff()));
    }
  }
}

TEST(FiveBar, BalancedParallelogramIsConstantDiagonalOver1000States) {
  const FiveBarParameters p = balanced(parallelogram(), 0.25);
  FiveBarDynamics dyn(p);
  const Closed ref = parallelogram_lagrangian(p, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero());
  const Eigen::Vector2d k = ref.M.diagonal();
  ASSERT_LT(std::abs(ref.M(0, 1)), 1e-15 * k.minCoeff());  // K = 0 by the leg-wise balancing
  std::mt19937 rng(11);
  Eigen::Matrix2d M;
  Eigen::Vector2d v, g, q, qd;
  double worst_off = 0.0, worst_diag = 0.0, worst_v = 0.0, worst_g = 0.0;
  for (int s = 0; s < 1000; ++s) {
    random_state(rng, q, qd);
    ASSERT_EQ(dyn.evaluate(q, qd, M, v, g), Status::ok);
    worst_off = std::max(worst_off, std::abs(M(0, 1)) / k.minCoeff());
    worst_diag = std::max(worst_diag, (M.diagonal() - k).cwiseQuotient(k).cwiseAbs().maxCoeff());
    worst_v = std::max(worst_v, v.cwiseAbs().maxCoeff());
    worst_g = std::max(worst_g, g.cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst_off, 1e-12);
  EXPECT_LT(worst_diag, 1e-12);
  EXPECT_LT(worst_v, 1e-12);
  EXPECT_LT(worst_g, 1e-12);
  // the unbalanced five-bar is coupled and gravity-loaded (this test can fail)
  FiveBarDynamics raw(parallelogram());
  q << 0.3, 1.9;
  qd << 1.0, -1.0;
  ASSERT_EQ(raw.evaluate(q, qd, M, v, g), Status::ok);
  EXPECT_GT(std::abs(M(0, 1)), 1e-2 * M.diagonal().minCoeff());
  EXPECT_GT(g.cwiseAbs().maxCoeff(), 1.0);
}

TEST(FiveBar, GeneralFiveBarMassMatrixIsSymmetricPositiveDefinite) {
  FiveBarParameters p = balanced(parallelogram(), 0.25);
  p.d = 0.12;
  p.b1 = 0.32;
  p.b2 = 0.34;
  FiveBarDynamics dyn(p);
  Eigen::Matrix2d M;
  Eigen::Vector2d v, g, q(0.7, 2.2), qd(0.4, -0.8);
  ASSERT_EQ(dyn.evaluate(q, qd, M, v, g), Status::ok);
  EXPECT_LT(std::abs(M(0, 1) - M(1, 0)), 1e-14 * M.norm());
  EXPECT_GT(M.selfadjointView<Eigen::Lower>().eigenvalues().minCoeff(), 0.0);
  EXPECT_GT(dyn.reciprocal_condition(), 1e-3);
}

TEST(FiveBar, SingularAndUnassemblablePosesGiveAStatusAndNoNaN) {
  FiveBarDynamics dyn(parallelogram());
  Eigen::Matrix2d M = Eigen::Matrix2d::Constant(7.0);
  Eigen::Vector2d v = Eigen::Vector2d::Constant(7.0), g = v, qd(1.0, -0.5);
  test::AllocationScope scope;
  // folded (q1 = q2) and stretched (q2 = q1 + pi): distal links aligned, A° singular
  for (const Eigen::Vector2d q : {Eigen::Vector2d(0.4, 0.4), Eigen::Vector2d(0.4, 0.4 + M_PI)}) {
    EXPECT_EQ(dyn.evaluate(q, qd, M, v, g), Status::singular) << q.transpose();
    EXPECT_EQ(M, Eigen::Matrix2d::Constant(7.0));
    EXPECT_EQ(v, Eigen::Vector2d::Constant(7.0));
    EXPECT_LT(dyn.reciprocal_condition(), 1e-6);
  }
  // just off the fold: still regular, finite
  EXPECT_EQ(dyn.evaluate(Eigen::Vector2d(0.4, 0.45), qd, M, v, g), Status::ok);
  EXPECT_TRUE(M.allFinite() && v.allFinite() && g.allFinite());
  const Eigen::Vector2d nan(std::numeric_limits<double>::quiet_NaN(), 0.0);
  EXPECT_EQ(dyn.evaluate(nan, qd, M, v, g), Status::non_finite_input);
  EXPECT_EQ(scope.count(), 0u);
  // a general five-bar that cannot close: elbows farther apart than b1 + b2
  FiveBarParameters p = parallelogram();
  p.d = 0.5;
  p.b1 = p.b2 = 0.1;
  FiveBarDynamics open(p);
  EXPECT_EQ(open.evaluate(Eigen::Vector2d(M_PI, 0.0), qd, M, v, g), Status::singular);
  EXPECT_TRUE(M.allFinite());
  // computed torque through a singular pose holds its last command, never NaN
  ComputedTorque ct(dyn, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
  Eigen::VectorXd q(2), qdv(2), z = Eigen::VectorXd::Zero(2), tau(2), good(2);
  q << 0.4, 1.4;
  qdv << 0.1, 0.2;
  ASSERT_EQ(ct.step(q, qdv, q, z, z, tau), Status::ok);
  good = tau;
  q << 0.4, 0.4;
  EXPECT_TRUE(has(ct.step(q, qdv, q, z, z, tau), Status::singular));
  EXPECT_EQ(tau, good);
}

TEST(FiveBar, DecoupledControlEqualsComputedTorqueOnTheBalancedModelAndAllocatesNothing) {
  const FiveBarParameters p = balanced(parallelogram(), 0.25);
  FiveBarDynamics dyn(p);
  const Eigen::Vector2d k =
      parallelogram_lagrangian(p, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()).M.diagonal();
  const Eigen::Vector2d kp(100.0, 120.0), kd(20.0, 22.0);
  ComputedTorque ct(dyn, kp, kd);
  DecoupledJointController dc(k, kp, kd);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::VectorXd q(2), qd(2), qdes(2), qddes(2), qdddes(2), t1(2), t2(2);
  Eigen::Vector2d qq, qqd;
  FiveBarMotion mo;
  test::AllocationScope scope;
  for (int s = 0; s < 500; ++s) {
    random_state(rng, qq, qqd);
    q = qq;
    qd = qqd;
    for (int i = 0; i < 2; ++i) {
      qdes(i) = q(i) + 0.1 * u(rng);
      qddes(i) = u(rng);
      qdddes(i) = 5 * u(rng);
    }
    ASSERT_EQ(ct.step(q, qd, qdes, qddes, qdddes, t1), Status::ok);
    ASSERT_EQ(dc.step(q, qd, qdes, qddes, qdddes, t2), Status::ok);
    EXPECT_LT((t1 - t2).norm(), 1e-11 * (1.0 + t1.norm()));
    ASSERT_EQ(dyn.motion(qq, qqd, Eigen::Vector2d(qdddes), mo), Status::ok);
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(FiveBar, MotionClosesTheLoop) {
  // the end effector reached through leg 1 and through leg 2 agrees in position, velocity and
  // (by finite differences along a path) acceleration
  FiveBarParameters p = balanced(parallelogram(), 0.25);
  p.d = 0.12;
  p.b1 = 0.32;
  p.b2 = 0.34;
  FiveBarDynamics dyn(p);
  auto tip = [&](const FiveBarMotion& m, int leg) {
    const double a = leg == 0 ? p.a1 : p.a2, b = leg == 0 ? p.b1 : p.b2;
    const double base = leg == 0 ? 0.0 : p.d;
    const double t1 = m.angles(2 * leg), t12 = t1 + m.angles(2 * leg + 1);
    return Eigen::Vector2d(base + a * std::cos(t1) + b * std::cos(t12),
                           a * std::sin(t1) + b * std::sin(t12));
  };
  const Eigen::Vector2d q0(0.7, 2.2), qd(0.4, -0.8), qdd(1.5, 0.3);
  FiveBarMotion m0, mp, mm;
  ASSERT_EQ(dyn.motion(q0, qd, qdd, m0), Status::ok);
  EXPECT_LT((tip(m0, 0) - m0.end_effector).norm(), 1e-13);
  EXPECT_LT((tip(m0, 1) - m0.end_effector).norm(), 1e-13);
  const double h = 1e-5;
  ASSERT_EQ(dyn.motion(q0 + h * qd + 0.5 * h * h * qdd, qd + h * qdd, qdd, mp), Status::ok);
  ASSERT_EQ(dyn.motion(q0 - h * qd + 0.5 * h * h * qdd, qd - h * qdd, qdd, mm), Status::ok);
  EXPECT_LT(((mp.angles - mm.angles) / (2 * h) - m0.rates).norm(), 1e-7);
  EXPECT_LT(((mp.rates - mm.rates) / (2 * h) - m0.accelerations).norm(), 1e-6);
  EXPECT_LT(((mp.end_effector - mm.end_effector) / (2 * h) - m0.end_effector_velocity).norm(), 1e-7);
  EXPECT_LT(((mp.end_effector_velocity - mm.end_effector_velocity) / (2 * h) -
             m0.end_effector_acceleration).norm(), 1e-6);
}

TEST(FiveBar, RejectsBadParametersNamingTheField) {
  FiveBarParameters p = parallelogram();
  p.a1 = -0.3;
  try {
    FiveBarDynamics bad(p);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("five_bar.a1"), std::string::npos) << e.what();
  }
  p = parallelogram();
  p.cd2 = std::nan("");
  EXPECT_THROW(FiveBarDynamics{p}, std::invalid_argument);
  EXPECT_THROW(FiveBarDynamics(parallelogram(), 0.0), std::invalid_argument);
}
