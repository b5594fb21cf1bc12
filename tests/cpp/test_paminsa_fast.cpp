// The real-time fast paths of issue 6 against the general code they replace in the tick:
// the closed-form momentum of the PAMINSA mechanism (leg structure) against shaking_wrench over the
// bodies' states, and the reactionless wrist's frame-2 N / cond-free RK4 stages against the
// general N(q) and rates().
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/papers/paminsa/reactionless_wrist.hpp"
#include "test_support.hpp"

using namespace mechbal;
using Idx = PaminsaBodyIndex;

namespace {

double rel_err(const Vec3& a, const Vec3& b) { return (a - b).norm() / (1.0 + b.norm()); }

// principal moments that satisfy the triangle inequality, all different (Jy != Jz exercises every
// term of the pantograph links' I w)
Vec3 random_principal(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(0.2, 1.0);
  const double a = u(rng), b = u(rng);
  const double c = std::abs(a - b) + (a + b - std::abs(a - b)) * u(rng);  // |a-b| <= c <= a+b
  return scale * Vec3(a, b, c);
}

PaminsaParameters random_parameters(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  PaminsaParameters p;
  p.platform_mass = 1.0 + 5.0 * u(rng);
  for (int j = 0; j < 8; ++j) {
    p.link_mass[j] = 0.05 + 1.5 * u(rng);
    p.link_inertia[j] = random_principal(rng, 0.05);
  }
  for (int i = 0; i < 3; ++i) {
    p.counterweights.at_A[i] = 3.0 * u(rng);
    p.counterweights.at_F[i] = 3.0 * u(rng);
    p.counterweights.at_L[i] = 3.0 * u(rng);
  }
  p.counterweights.vertical = 10.0 * u(rng);
  p.cp3_ratio = -1.0 - u(rng);
  return p;
}

PlatformMotion random_motion(std::mt19937& rng, const Vec3& nominal) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PlatformMotion m;
  m.position = nominal + Vec3(0.05 * u(rng), 0.1 * u(rng), 0.04 * u(rng));
  m.velocity = Vec3(u(rng), u(rng), u(rng));
  m.acceleration = 10.0 * Vec3(u(rng), u(rng), u(rng));
  return m;
}

}  // namespace

TEST(PaminsaFast, ClosedFormMechanismWrenchEqualsBodyByBodySum) {
  std::mt19937 rng(7);
  int checked = 0;
  for (int model_trial = 0; model_trial < 20; ++model_trial) {
    const PaminsaModel model(model_trial == 0 ? PaminsaParameters{} : random_parameters(rng));
    PaminsaWorkspace ws;
    for (int trial = 0; trial < 50; ++trial) {
      const PlatformMotion pm = random_motion(rng, model.parameters().nominal_platform);
      ASSERT_EQ(paminsa_mechanism_kinematics(model, pm, ws), Status::ok);
      ShakingWrench fast;
      const ShakingWrench ref =
          test::body_set_wrench(model.bodies().data(), ws.states.data(), Idx::mechanism_count);
      ASSERT_EQ(paminsa_mechanism_wrench(model, pm, fast), Status::ok);
      EXPECT_LT(rel_err(fast.linear_momentum, ref.linear_momentum), 1e-12);
      EXPECT_LT(rel_err(fast.angular_momentum, ref.angular_momentum), 1e-12);
      EXPECT_LT(rel_err(fast.force, ref.force), 1e-12);
      EXPECT_LT(rel_err(fast.moment, ref.moment), 1e-12);
      Vec3 D;
      ASSERT_EQ(paminsa_mechanism_angular_momentum(model, pm, D), Status::ok);
      EXPECT_LT(rel_err(D, ref.angular_momentum), 1e-12);
      EXPECT_GT(ref.moment.norm(), 1e-3);  // not a trivial comparison
      ++checked;
    }
  }
  EXPECT_EQ(checked, 1000);
}

TEST(PaminsaFast, ClosedFormWrenchStatusesMatchTheKinematics) {
  const PaminsaModel model(PaminsaParameters{});
  ShakingWrench w;
  w.force = Vec3(1.0, 2.0, 3.0);
  PlatformMotion bad;
  bad.position = model.parameters().nominal_platform;
  bad.velocity(2) = std::nan("");
  EXPECT_EQ(paminsa_mechanism_wrench(model, bad, w), Status::non_finite_input);
  EXPECT_EQ(w.force, Vec3(1.0, 2.0, 3.0));  // untouched
  Vec3 D(4.0, 5.0, 6.0);
  EXPECT_EQ(paminsa_mechanism_angular_momentum(model, bad, D), Status::non_finite_input);
  PlatformMotion far;
  far.position = model.parameters().nominal_platform + Vec3(0.0, 0.0, 5.0);  // legs cannot reach
  PaminsaWorkspace ws;
  EXPECT_EQ(paminsa_mechanism_wrench(model, far, w), paminsa_mechanism_kinematics(model, far, ws));
  EXPECT_EQ(paminsa_mechanism_angular_momentum(model, far, D), Status::singular);
  EXPECT_EQ(D, Vec3(4.0, 5.0, 6.0));
}

// N is built in link 2's frame: check it against the body-by-body angular momentum with full
// (non-diagonal, rotated) inertia tensors, and the feed-forward against wrist_momentum_bias.
TEST(ReactionlessWristFast, FrameTwoMomentumMatrixWithGeneralInertias) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int solved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    WristInertias J;
    for (auto& Jk : J) {
      const Mat3 R = Eigen::AngleAxisd(u(rng), Vec3(u(rng), u(rng), u(rng)).normalized())
                         .toRotationMatrix();
      Jk = R * Mat3(random_principal(rng, 1.0).asDiagonal()) * R.transpose();
    }
    const Vec3 q(u(rng), u(rng), u(rng)), qd(u(rng), u(rng), u(rng));
    WristLinkMotion lm;
    wrist_link_motion(q, qd, Vec3::Zero(), lm);
    Vec3 H = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
      H += lm.rotation[k] * J[k] * lm.rotation[k].transpose() * lm.angular_velocity[k];
    EXPECT_LT(rel_err(wrist_momentum_matrix(J, q) * qd, H), 1e-13);

    // the Euler tick's feed-forward solves N qdd = -Ddot - bias with the general bias
    ReactionlessWristConfig c;
    c.max_condition = 1e6;
    const Vec3 D(u(rng), u(rng), u(rng)), Dd(u(rng), u(rng), u(rng));
    ReactionlessWrist w(J, c, q, Vec3::Zero());
    if (w.step_euler(D, Dd) != Status::ok) continue;
    const Mat3 N = wrist_momentum_matrix(J, q);
    const double cond = w.command().condition_number;
    // residuals relative to the size of the terms (the rates grow with cond(N))
    const Vec3 bias = wrist_momentum_bias(J, q, w.command().rates);
    const double scale = 1.0 + D.norm() + N.norm() * w.command().rates.norm();
    EXPECT_LT((N * w.command().rates + D).norm(), 1e-13 * cond * scale);
    const double scale_dd = 1.0 + Dd.norm() + bias.norm() + N.norm() * w.command().accelerations.norm();
    EXPECT_LT((N * w.command().accelerations + bias + Dd).norm(), 1e-13 * cond * scale_dd)
        << "cond " << cond << " bias " << bias.norm() << " qdd " << w.command().accelerations.norm();
    ++solved;
  }
  EXPECT_GT(solved, 150);
}

// The RK4 stages skip cond(N) (an upper bound decides the fast solve): the tick must equal RK4
// written with the public rates() (full closed-form cond + SVD fallback), same status, including
// stages near the gimbal lock and with the rate limit.
TEST(ReactionlessWristFast, Rk4StagesEqualRk4OverTheGeneralRates) {
  const PaminsaParameters p;
  const WristInertias J_diag{Mat3(p.wrist_inertia[0].asDiagonal()),
                             Mat3(p.wrist_inertia[1].asDiagonal()),
                             Mat3(p.wrist_inertia[2].asDiagonal())};
  // the same links with their principal axes turned (the stages' general, non-diagonal path)
  WristInertias J_rot;
  for (int k = 0; k < 3; ++k) {
    const Mat3 R = Eigen::AngleAxisd(0.3 + k, Vec3(1.0, -2.0, 0.5 * k).normalized()).toRotationMatrix();
    J_rot[k] = R * J_diag[k] * R.transpose();
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int singular = 0, saturated = 0, regular = 0;
  for (int trial = 0; trial < 1200; ++trial) {
    const WristInertias& J = trial < 600 ? J_diag : J_rot;
    ReactionlessWristConfig c;
    c.integrator = WristIntegrator::rk4;
    c.rate_hz = trial % 2 ? 1000.0 : 20.0;  // large steps move the stages far from q_n
    c.max_rate = trial % 5 == 0 ? 2.0 : 1e9;
    c.max_acceleration = 1e12;  // the reference below has no feed-forward limit
    // a third of the poses close to the gimbal lock theta = 0 (cond near and above the limit)
    const double theta = trial % 3 == 0 ? 1e-4 * u(rng) : u(rng);
    const Vec3 q(u(rng), theta, u(rng)), target(u(rng), u(rng), u(rng));
    const Vec3 D(u(rng), u(rng), u(rng)), Dd(u(rng), u(rng), u(rng));
    const Vec3 Dh = D + 0.01 * Dd, Dn = D + 0.02 * Dd;
    ReactionlessWrist w(J, c, q, target);
    const Status st = w.step(D, Dd, Dh, Dn);

    const double dt = 1.0 / c.rate_hz;
    double cond = 0.0, unused = 0.0;
    Vec3 k1, k2, k3, k4;
    Status ref = w.rates(q, D, k1, cond);
    ref |= w.rates(q + 0.5 * dt * k1, Dh, k2, unused);
    ref |= w.rates(q + 0.5 * dt * k2, Dh, k3, unused);
    ref |= w.rates(q + dt * k3, Dn, k4, unused);
    const Vec3 next = q + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    EXPECT_EQ(st, ref) << "trial " << trial;
    EXPECT_LT((w.command().rates - k1).norm(), 1e-9 * (1.0 + k1.norm()));
    EXPECT_LT((w.command().next_angles - next).norm(), 1e-9 * (1.0 + next.norm()))
        << "trial " << trial;
    EXPECT_NEAR(w.command().condition_number / cond, 1.0, 1e-6);
    singular += has(st, Status::singular);
    saturated += has(st, Status::saturated);
    regular += st == Status::ok;
  }
  EXPECT_GT(singular, 60);
  EXPECT_GT(saturated, 60);
  EXPECT_GT(regular, 400);
}
