// Closed-form 2-DOF arm (Arakelian, Le Baron & Mottu 2011, eqs 14-31 corrected) against KDL and
// against invariants; computed-torque controller (eqs 2-6) real-time contract; closed loop vs eq 6.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "alloc_counter.hpp"
#include "mechbal/papers/arm2dof/arm2dof.hpp"
#include "mechbal/control/closed_loop.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/kdl_chain.hpp"

using namespace mechbal;

namespace {

Arm2DofParameters random_arm(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.2, 3.0), l(0.05, 0.6), c(-0.2, 0.3), i(0.0, 0.3);
  Arm2DofParameters a;
  a.m1 = u(rng);
  a.m2 = u(rng);
  a.l1 = l(rng);
  a.l_s1 = c(rng);
  a.l_s2 = c(rng);
  a.i_s1 = i(rng);
  a.i_s2 = i(rng);
  return a;
}

Arm2DofCounterweights random_cw(std::mt19937& rng) {
  std::uniform_real_distribution<double> m(0.0, 8.0), r(-0.1, 0.4);
  return {m(rng), m(rng), r(rng), r(rng)};
}

Vec2 rvec(std::mt19937& rng, double s) {
  std::uniform_real_distribution<double> u(-s, s);
  return Vec2(u(rng), u(rng));
}

const Eigen::Vector2d kStart(0.0, 1.1526), kEnd(0.5236, 1.6762);  // paper Sec. 4

}  // namespace

TEST(Arm2Dof, ClosedFormMatchesKdlOnRandomArmsAndStates) {
  std::mt19937 rng(11);
  for (int a = 0; a < 20; ++a) {
    const Arm2DofParameters arm = a == 0 ? Arm2DofParameters{} : random_arm(rng);
    const Arm2DofCounterweights cw = a % 2 ? random_cw(rng) : Arm2DofCounterweights{};
    Arm2DofDynamics closed(arm, cw);
    KdlChainDynamics kdl(arm2dof_chain_model(arm, cw));
    for (int k = 0; k < 20; ++k) {
      const Vec2 q = rvec(rng, 3.0), qd = rvec(rng, 2.0), qdd = rvec(rng, 5.0);
      Eigen::VectorXd t_kdl(2), t_cf(2);
      ASSERT_EQ(kdl.inverse_dynamics(q, qd, qdd, t_kdl), Status::ok);
      ASSERT_EQ(closed.inverse_dynamics(q, qd, qdd, t_cf), Status::ok);
      EXPECT_LT((t_kdl - t_cf).norm() / std::max(1.0, t_kdl.norm()), 1e-9) << a << " " << k;
      Eigen::MatrixXd M(2, 2);
      ASSERT_EQ(kdl.mass_matrix(q, M), Status::ok);
      EXPECT_LT((M - closed.mass_matrix(q)).norm() / M.norm(), 1e-9);
      Eigen::VectorXd g(2);
      ASSERT_EQ(kdl.gravity(q, g), Status::ok);
      EXPECT_LT((g - closed.gravity(q)).norm() / std::max(1.0, g.norm()), 1e-9);
    }
  }
}

TEST(Arm2Dof, MassMatrixSpdSkewSymmetryAndPotential) {
  std::mt19937 rng(3);
  for (int a = 0; a < 10; ++a) {
    Arm2DofDynamics d(random_arm(rng), random_cw(rng));
    for (int k = 0; k < 10; ++k) {
      const Vec2 q = rvec(rng, 3.0), qd = rvec(rng, 2.0);
      const Mat2 A = d.mass_matrix(q);
      EXPECT_EQ(A(0, 1), A(1, 0));
      EXPECT_GT(A(0, 0), 0.0);
      EXPECT_GT(A.determinant(), 0.0);
      // Adot - 2C skew-symmetric (Adot by central differences along qd)
      const double h = 1e-6;
      const Mat2 Adot = (d.mass_matrix(q + h * qd) - d.mass_matrix(q - h * qd)) / (2 * h);
      const Mat2 S = Adot - 2.0 * d.coriolis_matrix(q, qd);
      EXPECT_LT((S + S.transpose()).norm(), 1e-7 * (1.0 + A.norm()));
      // Q = dV/dq
      for (int j = 0; j < 2; ++j) {
        const Vec2 e = Vec2::Unit(j) * h;
        const double dV = (d.potential_energy(q + e) - d.potential_energy(q - e)) / (2 * h);
        EXPECT_NEAR(dV, d.gravity(q)(j), 1e-6 * (1.0 + d.gravity(q).norm()));
      }
      // forward dynamics inverts inverse dynamics
      const Vec2 qdd = rvec(rng, 5.0);
      EXPECT_LT((d.acceleration(q, qd, d.torque(q, qd, qdd)) - qdd).norm(), 1e-10);
    }
  }
}

TEST(Arm2Dof, PowerBalanceAlongATrajectory) {
  // d(T + V)/dt = qd . tau along any motion: integrate the free arm with a torque and compare.
  Arm2DofDynamics d(Arm2DofParameters{}, Arm2DofCounterweights{7.4, 2.0, 0.25, 0.19});
  Vec2 q(0.3, -0.4), qd(1.0, -0.5);
  const double dt = 1e-4;
  double work = 0.0;
  const double E0 = d.kinetic_energy(q, qd) + d.potential_energy(q);
  for (int k = 0; k < 5000; ++k) {  // RK4, torque sin(t) constant per step is not needed: tau(t)
    auto tau = [](double t) { return Vec2(2.0 * std::sin(3 * t), -std::cos(2 * t)); };
    auto f = [&](double t, const Vec2& x, const Vec2& v, Vec2& dx, Vec2& dv, double& dw) {
      dx = v;
      dv = d.acceleration(x, v, tau(t));
      dw = v.dot(tau(t));
    };
    const double t = k * dt;
    Vec2 a1, b1, a2, b2, a3, b3, a4, b4;
    double w1, w2, w3, w4;
    f(t, q, qd, a1, b1, w1);
    f(t + dt / 2, q + dt / 2 * a1, qd + dt / 2 * b1, a2, b2, w2);
    f(t + dt / 2, q + dt / 2 * a2, qd + dt / 2 * b2, a3, b3, w3);
    f(t + dt, q + dt * a3, qd + dt * b3, a4, b4, w4);
    q += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    qd += dt / 6 * (b1 + 2 * b2 + 2 * b3 + b4);
    work += dt / 6 * (w1 + 2 * w2 + 2 * w3 + w4);
  }
  const double E1 = d.kinetic_energy(q, qd) + d.potential_energy(q);
  EXPECT_NEAR(E1 - E0, work, 1e-9 * (1.0 + std::abs(work)));
}

TEST(Arm2Dof, BadParametersNameTheField) {
  Arm2DofParameters a;
  a.m1 = -1.0;
  try {
    Arm2DofDynamics d(a);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("arm.m1"), std::string::npos);
  }
  Arm2DofCounterweights cw;
  cw.r_cw2 = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Arm2DofDynamics(Arm2DofParameters{}, cw), std::invalid_argument);
  Arm2DofLumped p = arm2dof_lumped(Arm2DofParameters{});
  p.s2 = 10.0;  // first moment impossible for the inertia: mass matrix indefinite
  EXPECT_THROW(Arm2DofDynamics{p}, std::invalid_argument);
}

TEST(ComputedTorque, TickAllocatesNothingWithEitherBackEnd) {
  Arm2DofDynamics closed(Arm2DofParameters{});
  KdlChainDynamics kdl(arm2dof_chain_model(Arm2DofParameters{}));
  const Eigen::Vector2d kp(100, 100), kd(20, 20);
  ComputedTorque c1(closed, kp, kd), c2(kdl, kp, kd, Eigen::Vector2d(50, 5));
  RestToRestTrajectory traj(kStart, kEnd, 1.0, TimeLaw::cubic);
  Eigen::VectorXd q = kStart, qd = Eigen::VectorXd::Zero(2), qdes(2), qddes(2), qdddes(2), t1(2),
                  t2(2);
  c2.step(q, qd, kStart, qd, qd, t2);  // warm up
  test::AllocationScope scope;
  for (int k = 0; k < 1000; ++k) {
    traj.evaluate(k * 1e-3, qdes, qddes, qdddes);
    const Status s1 = c1.step(q, qd, qdes, qddes, qdddes, t1);
    const Status s2 = c2.step(q, qd, qdes, qddes, qdddes, t2);
    EXPECT_EQ(s1, Status::ok);
    EXPECT_FALSE(has(s2, Status::non_finite_input));
    EXPECT_LT((t1 - t2).norm(), 1e-9 * (1 + t1.norm()) + (has(s2, Status::saturated) ? 1e9 : 0));
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(ComputedTorque, NonFiniteInputHoldsTheLastCommand) {
  Arm2DofDynamics model(Arm2DofParameters{});
  ComputedTorque c(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
  Eigen::VectorXd q = kStart, z = Eigen::VectorXd::Zero(2), tau(2), bad = kStart;
  tau.setConstant(123.0);
  bad(1) = std::numeric_limits<double>::quiet_NaN();
  // before any good tick the safe output is zero
  EXPECT_EQ(c.step(bad, z, kStart, z, z, tau), Status::non_finite_input);
  EXPECT_EQ(tau, Eigen::VectorXd::Zero(2));
  ASSERT_EQ(c.step(q, z, kEnd, z, z, tau), Status::ok);
  const Eigen::VectorXd good = tau;
  EXPECT_GT(good.norm(), 1.0);
  Eigen::VectorXd inf = z;
  inf(0) = std::numeric_limits<double>::infinity();
  test::AllocationScope scope;
  EXPECT_EQ(c.step(q, inf, kEnd, z, z, tau), Status::non_finite_input);
  EXPECT_EQ(tau, good);
  EXPECT_EQ(c.step(q, z, bad, z, z, tau), Status::non_finite_input);
  EXPECT_EQ(tau, good);
  EXPECT_EQ(c.step(q, z, kEnd, z, inf, tau), Status::non_finite_input);
  EXPECT_EQ(tau, good);
  EXPECT_TRUE(tau.allFinite());
  Eigen::VectorXd three(3);
  EXPECT_EQ(c.step(q, z, kEnd, z, z, three.head(3)), Status::bad_size);
  EXPECT_EQ(scope.count(), 0u);
}

TEST(ComputedTorque, SaturatesWithAStatusAndRejectsBadGains) {
  Arm2DofDynamics model(Arm2DofParameters{});
  ComputedTorque c(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20),
                   Eigen::Vector2d(1.0, std::numeric_limits<double>::infinity()));
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2), tau(2);
  EXPECT_EQ(c.step(kStart, z, kEnd, z, z, tau), Status::saturated);
  EXPECT_DOUBLE_EQ(std::abs(tau(0)), 1.0);
  EXPECT_THROW(ComputedTorque(model, Eigen::Vector2d(100, -1), Eigen::Vector2d(20, 20)),
               std::invalid_argument);
  EXPECT_THROW(ComputedTorque(model, Eigen::Vector3d(1, 1, 1), Eigen::Vector2d(20, 20)),
               std::invalid_argument);
  EXPECT_THROW(ComputedTorque(model, Eigen::Vector2d(1, 1), Eigen::Vector2d(20, 20),
                              Eigen::Vector2d(0.0, 1.0)),
               std::invalid_argument);
}

namespace {

double max_deviation_from_eq6(const ClosedLoopLog& log, const Eigen::Vector2d& e0, double kp,
                              double kd) {
  double dev = 0.0;
  for (int k = 0; k < log.t.size(); ++k)
    for (int j = 0; j < 2; ++j) {
      const double e = log.q_des(k, j) - log.q(k, j);
      dev = std::max(dev, std::abs(e - pd_error_analytic(e0(j), 0.0, kp, kd, log.t(k))));
    }
  return dev;
}

}  // namespace

TEST(ClosedLoop, ExactModelErrorFollowsEq6) {
  // Arakelian et al. 2011 eq 6: with A_hat = A, C_hat = C, Q_hat = Q, e'' + Kd e' + Kp e = 0.
  const Arm2DofParameters arm;
  for (const auto& cw : {Arm2DofCounterweights{}, Arm2DofCounterweights{7.4, 2.0, 0.2509, 0.1913}}) {
    Arm2DofDynamics plant(arm, cw), model(arm, cw);
    KdlChainDynamics kdl(arm2dof_chain_model(arm, cw));
    for (InverseDynamics* back_end : {static_cast<InverseDynamics*>(&model),
                                      static_cast<InverseDynamics*>(&kdl)}) {
      ComputedTorque ctrl(*back_end, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
      RestToRestTrajectory traj(kStart, kEnd, 1.0, TimeLaw::cubic);
      const Eigen::Vector2d e0(0.05, -0.03);
      ClosedLoopOptions opt;
      opt.duration = 2.0;
      opt.sampling = ControlSampling::every_rk4_stage;
      const ClosedLoopLog log = simulate_computed_torque(plant, ctrl, traj, kStart - e0,
                                                         Eigen::Vector2d::Zero(), opt);
      EXPECT_EQ(log.status, Status::ok);
      EXPECT_EQ(log.steps_completed, 2000);
      EXPECT_LT(max_deviation_from_eq6(log, e0, 100, 20), 1e-6);
      // the error really moved (not a trivially zero-error run)
      EXPECT_NEAR(log.q_des(0, 0) - log.q(0, 0), 0.05, 1e-15);
    }
  }
}

TEST(ClosedLoop, ZeroOrderHoldDepartsFromEq6AtFirstOrderInDt) {
  // A 1 kHz digital controller holds the torque over the period: the error departs from eq 6 by
  // O(dt). Halving dt must halve the departure (first order), which proves it is the hold and not
  // a modelling error.
  const Arm2DofParameters arm;
  Arm2DofDynamics plant(arm), model(arm);
  RestToRestTrajectory traj(kStart, kEnd, 1.0, TimeLaw::cubic);
  const Eigen::Vector2d e0(0.05, -0.03);
  double dev[2];
  for (int i = 0; i < 2; ++i) {
    ComputedTorque ctrl(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
    ClosedLoopOptions opt;
    opt.dt = i == 0 ? 1e-3 : 5e-4;
    opt.duration = 2.0;
    const ClosedLoopLog log = simulate_computed_torque(plant, ctrl, traj, kStart - e0,
                                                       Eigen::Vector2d::Zero(), opt);
    dev[i] = max_deviation_from_eq6(log, e0, 100, 20);
  }
  EXPECT_GT(dev[0], 1e-5);
  EXPECT_LT(dev[0], 1e-3);
  EXPECT_NEAR(dev[0] / dev[1], 2.0, 0.2);
}

TEST(ClosedLoop, PerturbedModelAndTorqueLimits) {
  Arm2DofParameters arm, wrong;
  wrong.m1 *= 1.2;
  wrong.m2 *= 0.8;
  wrong.i_s1 *= 1.2;
  wrong.i_s2 *= 0.8;
  Arm2DofDynamics plant(arm), model(wrong);
  RestToRestTrajectory traj(kStart, kEnd, 1.0, TimeLaw::cubic);
  ClosedLoopOptions opt;
  opt.duration = 2.0;
  ComputedTorque ctrl(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
  const ClosedLoopLog log =
      simulate_computed_torque(plant, ctrl, traj, kStart, Eigen::Vector2d::Zero(), opt);
  const double err = (log.q_des - log.q).cwiseAbs().maxCoeff();
  EXPECT_GT(err, 1e-3);  // a wrong model leaves an error eq 6 does not predict
  EXPECT_LT(err, 0.2);   // but the loop stays stable
  ComputedTorque limited(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20),
                         Eigen::Vector2d(5.0, 5.0));
  const ClosedLoopLog sat =
      simulate_computed_torque(plant, limited, traj, kStart, Eigen::Vector2d::Zero(), opt);
  EXPECT_TRUE(has(sat.status, Status::saturated));
  EXPECT_GT(sat.saturated_ticks, 0);
  EXPECT_LE(sat.tau.cwiseAbs().maxCoeff(), 5.0);
}

TEST(ClosedLoop, SampledDesiredMotionEqualsTheTrajectoryAndTickStatusesAddUp) {
  // The same quintic, given as samples every dt/2, drives the same loop to the same state (the
  // path any Python trajectory takes); tick_status ORs to status and counts the saturated ticks.
  const Arm2DofParameters arm;
  Arm2DofDynamics plant(arm), model(arm);
  RestToRestTrajectory traj(kStart, kEnd, 1.0, TimeLaw::quintic);
  ClosedLoopOptions opt;
  opt.duration = 1.0;
  opt.sampling = ControlSampling::every_rk4_stage;
  const int steps = 1000;
  SampledMotion desired;
  desired.q.resize(2 * steps + 1, 2);
  desired.qd.resize(2 * steps + 1, 2);
  desired.qdd.resize(2 * steps + 1, 2);
  for (int j = 0; j <= 2 * steps; ++j) {
    Eigen::Vector2d q, qd, qdd;
    traj.evaluate(j * 0.5e-3, q, qd, qdd);
    desired.q.row(j) = q.transpose();
    desired.qd.row(j) = qd.transpose();
    desired.qdd.row(j) = qdd.transpose();
  }
  const Eigen::Vector2d q0 = kStart - Eigen::Vector2d(0.02, -0.01);
  ComputedTorque a(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
  ComputedTorque b(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
  const ClosedLoopLog from_traj = simulate_closed_loop(plant, a, traj, q0, Eigen::Vector2d::Zero(), opt);
  const ClosedLoopLog from_samples =
      simulate_closed_loop(plant, b, desired, q0, Eigen::Vector2d::Zero(), opt);
  EXPECT_EQ(from_samples.status, Status::ok);
  EXPECT_LT((from_traj.q - from_samples.q).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(from_samples.tick_status.size(), steps + 1);
  EXPECT_EQ(from_samples.tick_status.maxCoeff(), 0u);

  SampledMotion short_desired = desired;
  short_desired.q.conservativeResize(steps, 2);
  EXPECT_THROW(simulate_closed_loop(plant, b, short_desired, q0, Eigen::Vector2d::Zero(), opt),
               std::invalid_argument);

  ComputedTorque limited(model, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20),
                         Eigen::Vector2d(5.0, 5.0));
  opt.sampling = ControlSampling::zero_order_hold;
  const ClosedLoopLog sat = simulate_closed_loop(plant, limited, traj, kStart, Eigen::Vector2d::Zero(), opt);
  std::uint32_t all = 0;
  int saturated = 0;
  for (int k = 0; k < sat.tick_status.size(); ++k) {
    all |= sat.tick_status(k);
    saturated += (sat.tick_status(k) & static_cast<std::uint32_t>(Status::saturated)) != 0;
  }
  EXPECT_EQ(all, static_cast<std::uint32_t>(sat.status));
  EXPECT_EQ(saturated, sat.saturated_ticks);
  EXPECT_GT(saturated, 0);
}

TEST(ClosedLoop, PdErrorAnalyticSolvesEq6) {
  for (double kd : {5.0, 20.0, 40.0}) {
    const double kp = 100.0, h = 1e-4;
    for (double t : {0.05, 0.3, 1.0}) {
      auto e = [&](double s) { return pd_error_analytic(0.1, -0.4, kp, kd, s); };
      const double edd = (e(t + h) - 2 * e(t) + e(t - h)) / (h * h);
      const double ed = (e(t + h) - e(t - h)) / (2 * h);
      EXPECT_NEAR(edd + kd * ed + kp * e(t), 0.0, 1e-5);
    }
    EXPECT_DOUBLE_EQ(pd_error_analytic(0.1, -0.4, kp, kd, 0.0), 0.1);
  }
}
