// PAMINSA kinematics and the reactionless wrist: invariants (finite differences, momentum),
// round trips, status handling and the real-time contract.
#include <gtest/gtest.h>

#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "alloc_counter.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/papers/paminsa/reactionless_wrist.hpp"
#include "paminsa_motion.hpp"
#include "test_support.hpp"

using namespace mechbal;
using Idx = PaminsaBodyIndex;

namespace {

using test::platform_at;
using test::wrist_at;

Vec3 vee(const Mat3& S) {
  return 0.5 * Vec3(S(2, 1) - S(1, 2), S(0, 2) - S(2, 0), S(1, 0) - S(0, 1));
}

// Corrected closed forms of Briot & Arakelian 2009, eqs 11, 14-16 (re-derived in the test from the
// mass coefficients of the leg; see closed_form_counterweights in python/mechbal/papers/paminsa.py).
PaminsaParameters force_balanced_parameters() {
  PaminsaParameters p;
  const double k = p.k;
  const auto& m = p.link_mass;
  const double cp2 = k * (m[0] + m[2]) / 2.0 + (k - 2.0) * m[1] / 2.0 - m[3] / 2.0 - m[7];
  const double cp1 = (k - 1.0) * (p.platform_mass / 3.0 + m[0] / 2.0 + m[1] / (2.0 * k)) -
                     (m[2] + m[3]) / 2.0 - (m[1] + m[3] + 2.0 * m[7] + 2.0 * cp2) / (2.0 * k);
  const double cp3 = -m[4] / p.cp3_ratio;
  const double mc2 = p.platform_mass / 3.0 + m[0] / 2.0 +
                     (2 * m[1] + m[3] + 2 * m[5] + 2 * m[6] + 2 * m[7] + 2 * cp2) / (2.0 * k);
  for (int i = 0; i < 3; ++i) {
    p.counterweights.at_A[i] = cp1;
    p.counterweights.at_F[i] = cp2;
    p.counterweights.at_L[i] = cp3;
  }
  p.counterweights.vertical = 3.0 * mc2;
  return p;
}

}  // namespace

TEST(Paminsa, BodyMotionMatchesFiniteDifferences) {
  const PaminsaModel model(PaminsaParameters{});
  const double h = 1e-6;
  for (double t : {0.0, 0.37, 1.21}) {
    PaminsaWorkspace a, b, c;
    ASSERT_EQ(paminsa_kinematics(model, platform_at(t - h), wrist_at(t - h), a), Status::ok);
    ASSERT_EQ(paminsa_kinematics(model, platform_at(t), wrist_at(t), b), Status::ok);
    ASSERT_EQ(paminsa_kinematics(model, platform_at(t + h), wrist_at(t + h), c), Status::ok);
    for (std::size_t j = 0; j < Idx::count; ++j) {
      const BodyState &m = a.states[j], &s = b.states[j], &p = c.states[j];
      const std::string name = PaminsaModel::body_name(j);
      const Vec3 v_fd = (p.com - m.com) / (2 * h);
      const Vec3 a_fd = (p.com_velocity - m.com_velocity) / (2 * h);
      const Vec3 w_fd = vee((p.rotation - m.rotation) / (2 * h) * s.rotation.transpose());
      const Vec3 wd_fd = (p.angular_velocity - m.angular_velocity) / (2 * h);
      EXPECT_LT((v_fd - s.com_velocity).norm(), 1e-7 * (1 + s.com_velocity.norm())) << name;
      EXPECT_LT((a_fd - s.com_acceleration).norm(), 1e-6 * (1 + s.com_acceleration.norm())) << name;
      EXPECT_LT((w_fd - s.angular_velocity).norm(), 1e-7 * (1 + s.angular_velocity.norm())) << name;
      EXPECT_LT((wd_fd - s.angular_acceleration).norm(), 1e-6 * (1 + s.angular_acceleration.norm()))
          << name;
      EXPECT_LT((s.rotation.transpose() * s.rotation - Mat3::Identity()).norm(), 1e-12) << name;
      EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12) << name;
    }
  }
}

TEST(Paminsa, LegGeometryInvariantsHold) {
  const PaminsaModel model(PaminsaParameters{});
  const PaminsaParameters& p = model.parameters();
  PaminsaWorkspace ws;
  for (double t : {0.0, 0.5, 0.9}) {
    const PlatformMotion pm = platform_at(t);
    ASSERT_EQ(paminsa_mechanism_kinematics(model, pm, ws), Status::ok);
    for (int i = 0; i < 3; ++i) {
      const auto& pt = ws.leg_points[i];  // A, B, C, D, E, F
      const Vec3 &A = pt[0], &B = pt[1], &C = pt[2], &D = pt[3], &E = pt[4], &F = pt[5];
      EXPECT_NEAR((E - A).norm(), p.length_AE, 1e-12);
      EXPECT_NEAR((E - C).norm(), p.length_CE, 1e-12);
      EXPECT_NEAR((D - F).norm(), p.length_DF, 1e-12);
      EXPECT_NEAR((F - A).norm(), p.length_AF, 1e-12);
      EXPECT_NEAR((D - E).norm(), p.length_CE / p.k, 1e-12);
      EXPECT_NEAR((B - F).norm(), p.length_DF / p.k, 1e-12);
      EXPECT_LT(((B - A).cross(C - A)).norm(), 1e-12);                          // A, B, C collinear
      EXPECT_LT((B.head<2>() - model.slider_line()[i]).norm(), 1e-12);        // B on its vertical
      EXPECT_NEAR(A(2), p.z_A, 1e-12);                                         // A in its plane
      EXPECT_LT((C - pm.position - model.platform_joint_offset()[i]).norm(), 1e-12);  // C attached
    }
  }
}

TEST(Paminsa, InverseKinematicsRoundTripsThroughForwardSolve) {
  const PaminsaModel model(PaminsaParameters{});
  for (double t = 0.0; t < 3.0; t += 0.1) {
    const Vec3 P = platform_at(t).position;
    PaminsaActuators act;
    ASSERT_EQ(model.inverse_kinematics(P, act), Status::ok);
    Vec3 back;
    ASSERT_EQ(model.forward_kinematics(act.alpha1, act.alpha3, act.z_B, back), Status::ok);
    EXPECT_LT((back - P).norm(), 1e-12);
    // legs 1 and 2 are the parallel pair: the passive guide stays parallel to the actuated one
    EXPECT_NEAR(act.alpha2, act.alpha1, 1e-12);
  }
  Vec3 P;
  EXPECT_EQ(model.forward_kinematics(std::nan(""), 0.0, 0.0, P), Status::non_finite_input);
}

TEST(Paminsa, ModelValidationNamesTheField) {
  auto expect_field = [](PaminsaParameters p, const std::string& field) {
    try {
      PaminsaModel m(p);
      ADD_FAILURE() << "no exception for " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  PaminsaParameters p;
  p.k = 1.0;
  expect_field(p, "k");
  p = PaminsaParameters{};
  p.link_mass[3] = -1.0;
  expect_field(p, "link_mass[3]");
  p = PaminsaParameters{};
  p.length_AF = 0.3;
  expect_field(p, "length_AF");
  p = PaminsaParameters{};
  p.counterweights.at_F[2] = std::nan("");
  expect_field(p, "counterweights.at_F[2]");
  p = PaminsaParameters{};
  p.wrist_inertia[1] = Vec3(1.0, 0.1, 0.1);  // violates the triangle inequality
  expect_field(p, "wrist_inertia[1]");
  p = PaminsaParameters{};
  p.nominal_rho = 0.6;  // the pantograph cannot close
  expect_field(p, "nominal_platform");
}

TEST(Paminsa, NonFiniteInputLeavesWorkspaceUntouched) {
  const PaminsaModel model(PaminsaParameters{});
  PaminsaWorkspace ws;
  ASSERT_EQ(paminsa_kinematics(model, platform_at(0.2), wrist_at(0.2), ws), Status::ok);
  const Vec3 before = ws.states[5].com;
  PlatformMotion bad = platform_at(0.3);
  bad.acceleration(1) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(paminsa_kinematics(model, bad, wrist_at(0.3), ws), Status::non_finite_input);
  EXPECT_EQ(ws.states[5].com, before);
}

TEST(Paminsa, MechanismMomentumDerivativeMatchesFiniteDifferences) {
  const PaminsaModel model(force_balanced_parameters());
  const double h = 1e-6;
  PaminsaWorkspace ws;
  Vec3 Dm, Dp, D, Dd, unused;
  for (double t : {0.1, 0.8}) {
    paminsa_mechanism_kinematics(model, platform_at(t - h), ws);
    paminsa_mechanism_momentum(model, ws, Dm, unused);
    paminsa_mechanism_kinematics(model, platform_at(t + h), ws);
    paminsa_mechanism_momentum(model, ws, Dp, unused);
    paminsa_mechanism_kinematics(model, platform_at(t), ws);
    ASSERT_EQ(paminsa_mechanism_momentum(model, ws, D, Dd), Status::ok);
    EXPECT_LT(((Dp - Dm) / (2 * h) - Dd).norm(), 1e-6 * (1 + Dd.norm()));
  }
}

TEST(Paminsa, CorrectedCounterweightsCancelTheShakingForce) {
  const PaminsaModel bal(force_balanced_parameters());
  const PaminsaModel unbal(PaminsaParameters{});
  PaminsaWorkspace ws;
  ShakingWrench sw;
  double peak_unbal = 0.0, peak_bal = 0.0;
  for (double t = 0.0; t < 2.0; t += 0.05) {
    // PAMINSA's own sum over its 38 bodies equals the tests' independent body-by-body sum
    for (const PaminsaModel* model : {&unbal, &bal}) {
      ASSERT_EQ(paminsa_kinematics(*model, platform_at(t), wrist_at(t), ws), Status::ok);
      ASSERT_EQ(paminsa_shaking_wrench(*model, ws, sw), Status::ok);
      const ShakingWrench ref = test::body_set_wrench(model->bodies().data(), ws.states.data(), Idx::count);
      EXPECT_LT((sw.force - ref.force).norm(), 1e-12 * (1.0 + ref.force.norm()));
      EXPECT_LT((sw.moment - ref.moment).norm(), 1e-12 * (1.0 + ref.moment.norm()));
      EXPECT_LT((sw.angular_momentum - ref.angular_momentum).norm(), 1e-12 * (1.0 + ref.angular_momentum.norm()));
      double& peak = model == &unbal ? peak_unbal : peak_bal;
      peak = std::max(peak, sw.force.norm());
    }
  }
  EXPECT_GT(peak_unbal, 1.0);
  EXPECT_LT(peak_bal, 1e-10 * peak_unbal);
}

// ---------------------------------------------------------------------------- wrist
TEST(ReactionlessWrist, MomentumMatrixEqualsBodyByBodyAngularMomentum) {
  const WristInertias J{Mat3(Vec3(0.019, 0.337, 0.2).asDiagonal()),
                        Mat3(Vec3(0.039, 2.63, 2.6).asDiagonal()),
                        Mat3(Vec3(0.088, 3.35, 3.3).asDiagonal())};
  for (double t : {0.0, 0.3, 0.77}) {
    const WristMotion w = wrist_at(t);
    WristLinkMotion lm;
    wrist_link_motion(w.angles, w.rates, w.accelerations, lm);
    Vec3 H = Vec3::Zero(), Hdot = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const Mat3 I = lm.rotation[k] * J[k] * lm.rotation[k].transpose();
      H += I * lm.angular_velocity[k];
      Hdot += I * lm.angular_acceleration[k] +
              lm.angular_velocity[k].cross(I * lm.angular_velocity[k]);
    }
    const Mat3 N = wrist_momentum_matrix(J, w.angles);
    EXPECT_LT((N * w.rates - H).norm(), 1e-13 * (1 + H.norm()));
    EXPECT_LT((N * w.accelerations + wrist_momentum_bias(J, w.angles, w.rates) - Hdot).norm(),
              1e-12 * (1 + Hdot.norm()));
    // and d/dt(N qdot) by central differences
    const double h = 1e-6;
    const WristMotion a = wrist_at(t - h), b = wrist_at(t + h);
    const Vec3 fd = (wrist_momentum_matrix(J, b.angles) * b.rates -
                     wrist_momentum_matrix(J, a.angles) * a.rates) / (2 * h);
    EXPECT_LT((fd - Hdot).norm(), 1e-6 * (1 + Hdot.norm()));
  }
}

TEST(ReactionlessWrist, SingularOnlyAtThetaZeroOrPi) {
  const PaminsaParameters p;
  const WristInertias J{Mat3(p.wrist_inertia[0].asDiagonal()), Mat3(p.wrist_inertia[1].asDiagonal()),
                        Mat3(p.wrist_inertia[2].asDiagonal())};
  EXPECT_LT(std::abs(wrist_momentum_matrix(J, Vec3(0.3, 0.0, 1.0)).determinant()), 1e-14);
  EXPECT_LT(std::abs(wrist_momentum_matrix(J, Vec3(-1.0, M_PI, 0.2)).determinant()), 1e-12);
  EXPECT_GT(std::abs(wrist_momentum_matrix(J, Vec3(0.3, 1.0, 1.0)).determinant()), 1e-3);
}

namespace {
ReactionlessWrist make_wrist(WristIntegrator integ, double max_rate, const Vec3& q0) {
  const PaminsaParameters p;
  ReactionlessWristConfig c;
  c.integrator = integ;
  c.max_rate = max_rate;
  const WristInertias J{Mat3(p.wrist_inertia[0].asDiagonal()), Mat3(p.wrist_inertia[1].asDiagonal()),
                        Mat3(p.wrist_inertia[2].asDiagonal())};
  return ReactionlessWrist(J, c, q0, Vec3::Zero());
}
}  // namespace

TEST(ReactionlessWrist, RatesCancelTheMomentumAndEulerIntegrates) {
  ReactionlessWrist w = make_wrist(WristIntegrator::euler, 1e9, Vec3(M_PI / 2, M_PI / 2, M_PI / 2));
  const Vec3 D(0.8, -0.2, 0.3), Dd(1.0, 0.5, -2.0);
  const Vec3 q0 = w.angles();
  ASSERT_EQ(w.step_euler(D, Dd), Status::ok);
  const WristCommand& c = w.command();
  const Mat3 N = wrist_momentum_matrix(w.inertia_body(), q0);
  EXPECT_LT((N * c.rates + D).norm(), 1e-12);  // total momentum = target (0)
  EXPECT_LT((N * c.accelerations + wrist_momentum_bias(w.inertia_body(), q0, c.rates) + Dd).norm(),
            1e-12);
  EXPECT_LT((c.next_angles - (q0 + 1e-3 * c.rates)).norm(), 1e-15);
  EXPECT_EQ(c.angles, q0);
  EXPECT_GT(c.condition_number, 1.0);
  EXPECT_LT(c.condition_number, 10.0);
}

TEST(ReactionlessWrist, Rk4TracksTheMomentumBetterThanEuler) {
  // D(t) = D1 sin(t): integrate over 0.5 s, then compare N(q) qdot with -D at the end.
  const Vec3 D1(1.5, -0.4, 0.6);
  double err[2];
  int idx = 0;
  for (WristIntegrator integ : {WristIntegrator::euler, WristIntegrator::rk4}) {
    ReactionlessWrist w = make_wrist(integ, 1e9, Vec3(M_PI / 2, M_PI / 2, M_PI / 2));
    const double dt = w.dt();
    // exact solution reference: one very fine RK4 run
    ReactionlessWrist ref = make_wrist(WristIntegrator::rk4, 1e9, Vec3(M_PI / 2, M_PI / 2, M_PI / 2));
    for (int n = 0; n < 500; ++n) {
      const double t = n * dt;
      w.step(D1 * std::sin(t), D1 * std::cos(t), D1 * std::sin(t + dt / 2), D1 * std::sin(t + dt));
    }
    ReactionlessWristConfig fine = ref.config();
    fine.rate_hz = 20000.0;
    ReactionlessWrist r(ref.inertia_body(), fine, Vec3(M_PI / 2, M_PI / 2, M_PI / 2), Vec3::Zero());
    for (int n = 0; n < 10000; ++n) {
      const double t = n * r.dt();
      r.step(D1 * std::sin(t), D1 * std::cos(t), D1 * std::sin(t + r.dt() / 2),
             D1 * std::sin(t + r.dt()));
    }
    err[idx++] = (w.angles() - r.angles()).norm();
  }
  EXPECT_LT(err[1], 1e-3 * err[0]);
  EXPECT_LT(err[0], 1e-2);
}

TEST(ReactionlessWrist, NonFiniteInputHoldsTheLastCommand) {
  ReactionlessWrist w = make_wrist(WristIntegrator::rk4, 1e9, Vec3(0.2, 1.0, 0.3));
  const Vec3 D(0.1, 0.2, 0.3), Dd(0.0, 0.0, 1.0);
  ASSERT_EQ(w.step(D, Dd, D, D), Status::ok);
  const Vec3 held = w.angles();
  const Vec3 bad(0.0, std::nan(""), 0.0);
  EXPECT_EQ(w.step(bad, Dd, D, D), Status::non_finite_input);
  EXPECT_EQ(w.command().angles, held);
  EXPECT_EQ(w.command().next_angles, held);
  EXPECT_TRUE(w.command().rates.allFinite() && w.command().accelerations.allFinite());
  EXPECT_EQ(w.angles(), held);
  EXPECT_EQ(w.step(D, Dd, D, Vec3::Constant(INFINITY)), Status::non_finite_input);
  EXPECT_EQ(w.angles(), held);
}

TEST(ReactionlessWrist, NearSingularStartIsDampedAndFinite) {
  ReactionlessWrist w = make_wrist(WristIntegrator::euler, 1e9, Vec3(0.0, 1e-9, 0.0));
  const Status s = w.step_euler(Vec3(1.0, 0.5, 0.2), Vec3(0.3, 0.0, 0.0));
  EXPECT_TRUE(has(s, Status::singular));
  EXPECT_TRUE(w.command().rates.allFinite());
  EXPECT_TRUE(w.command().accelerations.allFinite());
  EXPECT_TRUE(w.angles().allFinite());
  EXPECT_GT(w.command().condition_number, 1e4);
  EXPECT_TRUE(std::isfinite(w.command().condition_number));
  // damping bounds the rate by |rhs| / (2 lambda)
  EXPECT_LT(w.command().rates.norm(), 1e4);
  // exactly singular too
  ReactionlessWrist z = make_wrist(WristIntegrator::rk4, 1e9, Vec3::Zero());
  EXPECT_TRUE(has(z.step(Vec3(1.0, 0.0, 0.0), Vec3::Zero(), Vec3(1.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0)),
                  Status::singular));
  EXPECT_TRUE(z.angles().allFinite());
}

TEST(ReactionlessWrist, RateLimitSaturates) {
  ReactionlessWrist free = make_wrist(WristIntegrator::euler, 1e9, Vec3(M_PI / 2, M_PI / 2, M_PI / 2));
  ReactionlessWrist lim = make_wrist(WristIntegrator::euler, 0.1, Vec3(M_PI / 2, M_PI / 2, M_PI / 2));
  const Vec3 D(3.0, 0.1, 1.0);
  EXPECT_EQ(free.step_euler(D, Vec3::Zero()), Status::ok);
  ASSERT_GT(free.command().rates.cwiseAbs().maxCoeff(), 0.1);
  EXPECT_EQ(lim.step_euler(D, Vec3::Zero()), Status::saturated);
  EXPECT_NEAR(lim.command().rates.cwiseAbs().maxCoeff(), 0.1, 1e-15);
  // direction kept
  EXPECT_LT((lim.command().rates.normalized() - free.command().rates.normalized()).norm(), 1e-12);
}

// The tick's fast path (closed-form eigenvalues of N^T N for cond(N), cofactor inverse) against a
// full JacobiSVD of N over many well- and ill-conditioned poses: same condition number, same rates
// and feed-forward (N qddot = -Ddot - bias) as solving with the SVD.
TEST(ReactionlessWrist, FastSolveAgreesWithTheSvd) {
  const PaminsaModel model(PaminsaParameters{});
  const WristInertias& J = model.wrist_inertia();
  ReactionlessWristConfig c;
  c.max_condition = 1e4;
  c.max_rate = 1e9;  // the solve, not the limits
  c.max_acceleration = 1e12;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int singular = 0, regular = 0;
  for (int trial = 0; trial < 400; ++trial) {
    // every 4th pose near the gimbal lock theta = 0 (ill-conditioned: the SVD path)
    const double theta = trial % 4 == 0 ? 1e-6 * u(rng) : u(rng);
    const Vec3 q(u(rng), theta, u(rng));
    const Vec3 D(u(rng), u(rng), u(rng)), Dd(u(rng), u(rng), u(rng));
    ReactionlessWrist w(J, c, q, Vec3::Zero());
    const Status st = w.step_euler(D, Dd);
    const Mat3 N = wrist_momentum_matrix(J, q);
    Eigen::JacobiSVD<Mat3> svd(N, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Vec3 s = svd.singularValues();
    const double cond = s(0) / s(2);
    if (cond > c.max_condition) {
      ++singular;
      EXPECT_TRUE(has(st, Status::singular));
      // the closed-form damped least squares (normal equations) equals the SVD form
      // sum_i s_i (u_i . b) / (s_i^2 + lambda^2) v_i, lambda = damping s_max
      const double lambda = c.damping * s(0);
      const Vec3 b = svd.matrixU().transpose() * (-D);
      Vec3 y;
      for (int i = 0; i < 3; ++i) y(i) = s(i) * b(i) / (s(i) * s(i) + lambda * lambda);
      const Vec3 dls = svd.matrixV() * y;
      EXPECT_LT((w.command().rates - dls).norm(), 1e-9 * (1.0 + dls.norm()));
      // the reported cond(N) of a singular N is accurate too (from |det N|, not eigenvalues)
      if (cond < 1e10) EXPECT_NEAR(w.command().condition_number / cond, 1.0, 1e-5);
      continue;
    }
    ++regular;
    ASSERT_EQ(st, Status::ok);
    EXPECT_NEAR(w.command().condition_number / cond, 1.0, 1e-6);
    const Vec3 rates = svd.solve(-D);
    EXPECT_LT((w.command().rates - rates).norm(), 1e-10 * (1.0 + rates.norm()) * cond);
    const Vec3 qdd = svd.solve(-Dd - wrist_momentum_bias(J, q, w.command().rates));
    EXPECT_LT((w.command().accelerations - qdd).norm(), 1e-10 * (1.0 + qdd.norm()) * cond);
  }
  EXPECT_GT(singular, 50);
  EXPECT_GT(regular, 200);
}

TEST(ReactionlessWrist, ConfigValidationNamesTheField) {
  const PaminsaParameters p;
  const WristInertias J{Mat3::Identity(), Mat3::Identity(), Mat3::Identity()};
  ReactionlessWristConfig c;
  c.rate_hz = 0.0;
  try {
    ReactionlessWrist w(J, c, Vec3::Zero(), Vec3::Zero());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rate_hz"), std::string::npos);
  }
  c = ReactionlessWristConfig{};
  c.max_rate = -1.0;
  EXPECT_THROW(ReactionlessWrist(J, c, Vec3::Zero(), Vec3::Zero()), std::invalid_argument);
}

// ---------------------------------------------------------------------------- controller
TEST(PaminsaController, FullyBalancedTickCancelsForceAndMoment) {
  const PaminsaModel model(force_balanced_parameters());
  for (WristIntegrator integ : {WristIntegrator::euler, WristIntegrator::rk4}) {
    ReactionlessWristConfig c;
    c.integrator = integ;
    const Vec3 q0(M_PI / 2, M_PI / 2, M_PI / 2);
    PaminsaController ctl(model, c, q0);
    PlatformMotion rest = platform_at(0.0);
    rest.velocity.setZero();
    rest.acceleration.setZero();
    ASSERT_EQ(ctl.reset(rest, q0), Status::ok);
    const double dt = 1e-3;
    for (int n = 0; n < 200; ++n) {
      const double t = n * dt;
      ASSERT_EQ(ctl.tick(platform_at(t), platform_at(t + dt / 2), platform_at(t + dt)), Status::ok);
      // closed form at the tick: the wrist's rates and feed-forward accelerations cancel dH/dt
      EXPECT_LT(ctl.wrench().force.norm(), 1e-9);
      EXPECT_LT(ctl.wrench().moment.norm(), 1e-9 * (1 + ctl.D_dot().norm()));
    }
    EXPECT_GT(ctl.D_dot().norm(), 0.1);  // the moment that was cancelled is not trivial
  }
}

TEST(PaminsaController, TickAllocatesNothingAndHoldsOnBadInput) {
  const PaminsaModel model(force_balanced_parameters());
  ReactionlessWristConfig c;
  c.integrator = WristIntegrator::rk4;
  const Vec3 q0(M_PI / 2, M_PI / 2, M_PI / 2);
  PaminsaController ctl(model, c, q0);
  ReactionlessWrist w = make_wrist(WristIntegrator::rk4, 5.0, q0);
  ctl.reset(platform_at(0.0), q0);
  test::AllocationScope scope;
  for (int n = 0; n < 100; ++n) {
    const double t = n * 1e-3;
    EXPECT_EQ(ctl.tick(platform_at(t), platform_at(t + 5e-4), platform_at(t + 1e-3)), Status::ok);
    w.step(Vec3(0.1, 0.2, 0.3) * t, Vec3(0.1, 0.2, 0.3), Vec3(0.1, 0.2, 0.3) * t,
           Vec3(0.1, 0.2, 0.3) * t);
  }
  PlatformMotion bad = platform_at(0.2);
  bad.position(0) = std::nan("");
  const Vec3 held = ctl.wrist().angles();
  EXPECT_TRUE(has(ctl.tick(bad, platform_at(0.2), platform_at(0.2)), Status::non_finite_input));
  EXPECT_EQ(ctl.wrist().angles(), held);
  EXPECT_EQ(scope.count(), 0u);
}
