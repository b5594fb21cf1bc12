#include <gtest/gtest.h>

#include <limits>

#include "mechbal/control/trajectory.hpp"

using namespace mechbal;

class LawTest : public ::testing::TestWithParam<TimeLaw> {};

TEST_P(LawTest, DerivativesMatchFiniteDifferencesAndBoundaryConditions) {
  const TimeLaw law = GetParam();
  const double h = 1e-6;
  for (double u = 0.05; u < 0.96; u += 0.05) {
    const LawValue v = evaluate_law(law, u), p = evaluate_law(law, u + h),
                   m = evaluate_law(law, u - h);
    EXPECT_NEAR((p.s - m.s) / (2 * h), v.ds, 1e-8);
    EXPECT_NEAR((p.ds - m.ds) / (2 * h), v.dds, 1e-7);
  }
  EXPECT_EQ(evaluate_law(law, 0.0).s, 0.0);
  EXPECT_NEAR(evaluate_law(law, 1.0).s, 1.0, 1e-15);
  EXPECT_NEAR(evaluate_law(law, 0.0).ds, 0.0, 1e-15);
  EXPECT_NEAR(evaluate_law(law, 1.0).ds, 0.0, 1e-15);
}

INSTANTIATE_TEST_SUITE_P(Laws, LawTest, ::testing::Values(TimeLaw::quintic, TimeLaw::cubic),
                         [](const ::testing::TestParamInfo<TimeLaw>& info) {
                           return std::string(info.param == TimeLaw::quintic ? "quintic" : "cubic");
                         });

TEST(Trajectory, CubicHasLessAccelerationEnergyThanQuintic) {
  // Arakelian et al. 2011 eq 13: the cubic law minimises int qdd^2 dt among rest-to-rest laws.
  double e_cubic = 0.0, e_quintic = 0.0;
  const int N = 100000;
  for (int k = 0; k < N; ++k) {
    const double u = (k + 0.5) / N;
    e_cubic += std::pow(evaluate_law(TimeLaw::cubic, u).dds, 2) / N;
    e_quintic += std::pow(evaluate_law(TimeLaw::quintic, u).dds, 2) / N;
  }
  EXPECT_NEAR(e_cubic, 12.0, 1e-6);         // int_0^1 (6 - 12u)^2 du = 12
  EXPECT_NEAR(e_quintic, 120.0 / 7.0, 1e-6);  // int_0^1 (60u - 180u^2 + 120u^3)^2 du
  EXPECT_LT(e_cubic, e_quintic);
}

TEST(Trajectory, PaperQuinticCoefficients) {
  // Run A of Arakelian et al. 2011: theta = 5.2360 t^3 - 7.8540 t^4 + 3.1416 t^5, T = 1 s.
  Eigen::VectorXd a(1), b(1);
  a << 0.0;
  b << 0.5236;
  RestToRestTrajectory traj(a, b, 1.0, TimeLaw::quintic);
  Eigen::VectorXd q(1), qd(1), qdd(1);
  for (double t = 0.0; t <= 1.0; t += 0.125) {
    ASSERT_EQ(traj.evaluate(t, q, qd, qdd), Status::ok);
    EXPECT_NEAR(q(0), 5.2360 * t * t * t - 7.8540 * t * t * t * t + 3.1416 * std::pow(t, 5), 1e-4);
  }
}

TEST(Trajectory, BadInput) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(2), b = Eigen::VectorXd::Ones(3);
  EXPECT_THROW(RestToRestTrajectory(a, b, 1.0, TimeLaw::cubic), std::invalid_argument);
  EXPECT_THROW(RestToRestTrajectory(a, a, 0.0, TimeLaw::cubic), std::invalid_argument);
  RestToRestTrajectory traj(a, Eigen::VectorXd::Ones(2), 1.0, TimeLaw::cubic);
  Eigen::VectorXd q(2), qd(2), qdd(2), wrong(3);
  EXPECT_EQ(traj.evaluate(0.5, wrong, qd, qdd), Status::bad_size);
  EXPECT_EQ(traj.evaluate(std::numeric_limits<double>::quiet_NaN(), q, qd, qdd),
            Status::non_finite_input);
  EXPECT_TRUE(q.allFinite());
}
