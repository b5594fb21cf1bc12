// Serial arms with counter-rotating discs (Coutinho & Hess Coelho) on the general model (discs are
// gear-coupled links, tests/cpp/disc_arms.hpp): the balanced planar 3R has a constant diagonal mass
// matrix equal to the closed forms of eq 16 and no velocity/gravity terms;
// DecoupledJointController equals ComputedTorque over the balanced model; real-time contract.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "alloc_counter.hpp"
#include "disc_arms.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"

using namespace mechbal;
using test::Planar3R;

TEST(DiscArm, BalancedPlanar3RIsDiagonalConstantAndFree) {
  const Planar3R p;
  const MechanismModel model = test::balanced_planar_3r(p);
  ASSERT_EQ(model.dof(), 3);  // the discs follow their joints: no coordinates of their own
  MechanismData data(model);
  const Eigen::Vector3d k = test::planar_3r_k(p);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ang(-M_PI, M_PI), rate(-2.0, 2.0);
  Eigen::VectorXd q(3), qd(3);
  for (int s = 0; s < 200; ++s) {
    for (int i = 0; i < 3; ++i) {
      q(i) = ang(rng);
      qd(i) = rate(rng);
    }
    ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
    const Eigen::MatrixXd& M = data.mass_matrix;
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(M(i, i), k(i), 1e-12 * k(i));
      for (int j = 0; j < 3; ++j)
        if (i != j) EXPECT_LT(std::abs(M(i, j)), 1e-12 * k.minCoeff());
    }
    ASSERT_EQ(bias_torque(model, data, q, qd), Status::ok);  // C(q, qd) qd + G(q)
    EXPECT_LT(data.bias_torque.norm(), 1e-12);
  }
}

TEST(DiscArm, MassMatrixSymmetricPositiveDefiniteAndGearRatioRecouples) {
  const Planar3R p;
  const MechanismModel model = test::balanced_planar_3r(p, 1.05);  // +5 % gear ratio error
  MechanismData data(model);
  const Eigen::Vector3d q(0.3, -1.1, 2.0);
  ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
  const Eigen::MatrixXd& M = data.mass_matrix;
  EXPECT_LT((M - M.transpose()).norm(), 1e-14);
  EXPECT_GT(M.selfadjointView<Eigen::Lower>().eigenvalues().minCoeff(), 0.0);
  // D'12 = D12 + J4 + beta J5 + J6 + J7 = 0.05 * beta_nominal * J5 (eq 13): linear in the error.
  EXPECT_NEAR(M(0, 1), -0.05 * p.X(), 1e-12);
}

TEST(DecoupledControl, EqualsComputedTorqueOnTheBalancedModelAndAllocatesNothing) {
  const Planar3R p;
  MechanismDynamics dyn(test::balanced_planar_3r(p));
  const Eigen::Vector3d k = test::planar_3r_k(p);
  const Eigen::Vector3d kp(100.0, 120.0, 150.0), kd(20.0, 22.0, 25.0);
  ComputedTorque ct(dyn, kp, kd);
  DecoupledJointController dc(k, kp, kd);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::VectorXd q(3), qd(3), qdes(3), qddes(3), qdddes(3), t1(3), t2(3);
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
