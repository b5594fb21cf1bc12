// RneChainDynamics (mechbal's own recursive Newton-Euler + CRBA) against KDL, an independent
// implementation, plus invariants that hold whatever the implementation: tau = M qdd + bias,
// M symmetric positive definite, a pendulum in closed form, the real-time contract.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "alloc_counter.hpp"
#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/control/rnea.hpp"
#include "test_support.hpp"

using namespace mechbal;

namespace {

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

class RneVsKdl : public ::testing::TestWithParam<std::pair<const char*, unsigned>> {};

TEST_P(RneVsKdl, TorquesWrenchMassMatrixGravityCoriolisAgree) {
  const auto [types, seed] = GetParam();
  std::mt19937 rng(seed);
  const ChainModel model = test::random_chain(rng, types);
  const int n = model.dof();
  RneChainDynamics rne(model);
  KdlChainDynamics kdl(model);
  ASSERT_EQ(rne.dof(), n);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd q = test::random_vector(rng, n, 2.0),
                          qd = test::random_vector(rng, n, 1.5),
                          qdd = test::random_vector(rng, n, 3.0);
    Eigen::VectorXd tau_r(n), tau_k(n);
    Vec3 F_r, M_r, F_k, M_k;
    ASSERT_EQ(rne.inverse_dynamics(q, qd, qdd, tau_r, &F_r, &M_r), Status::ok);
    ASSERT_EQ(kdl.inverse_dynamics(q, qd, qdd, tau_k, &F_k, &M_k), Status::ok);
    EXPECT_LT(rel(tau_r, tau_k), 1e-9) << tau_r.transpose() << "\n" << tau_k.transpose();
    EXPECT_LT(rel(F_r, F_k), 1e-9) << F_r.transpose() << " vs " << F_k.transpose();
    EXPECT_LT(rel(M_r, M_k), 1e-9) << M_r.transpose() << " vs " << M_k.transpose();

    Eigen::MatrixXd M_rm(n, n), M_km(n, n);
    ASSERT_EQ(rne.mass_matrix(q, M_rm), Status::ok);
    ASSERT_EQ(kdl.mass_matrix(q, M_km), Status::ok);
    EXPECT_LT(rel(M_rm, M_km), 1e-9) << M_rm << "\n\n" << M_km;

    Eigen::VectorXd g_r(n), g_k(n), c_r(n), c_k(n), b_r(n);
    ASSERT_EQ(rne.gravity(q, g_r), Status::ok);
    ASSERT_EQ(kdl.gravity(q, g_k), Status::ok);
    EXPECT_LT(rel(g_r, g_k), 1e-9);
    ASSERT_EQ(rne.coriolis(q, qd, c_r), Status::ok);
    ASSERT_EQ(kdl.coriolis(q, qd, c_k), Status::ok);
    EXPECT_LT(rel(c_r, c_k), 1e-9);
    ASSERT_EQ(rne.bias(q, qd, b_r), Status::ok);
    EXPECT_LT(rel(b_r, c_k + g_k), 1e-9);

    // invariants within mechbal itself: tau = M qdd + bias; M symmetric positive definite
    EXPECT_LT(rel(M_rm * qdd + b_r, tau_r), 1e-9);
    EXPECT_LT((M_rm - M_rm.transpose()).norm(), 1e-12 * M_rm.norm());
    Eigen::LLT<Eigen::MatrixXd> llt(M_rm);
    EXPECT_EQ(llt.info(), Eigen::Success);
  }
}

INSTANTIATE_TEST_SUITE_P(RandomChains, RneVsKdl,
                         ::testing::Values(std::make_pair("RRR", 11u), std::make_pair("RPR", 12u),
                                           std::make_pair("RRRRRR", 13u),
                                           std::make_pair("PRRPRR", 14u),
                                           std::make_pair("RRRRRRR", 15u),
                                           std::make_pair("RRPRRRP", 16u)));

TEST(Rne, PendulumInClosedForm) {
  // A point-ish pendulum swinging about the base y axis: tau = (I_yy + m l^2) qdd + m g l sin(q)
  // (centre of mass at l along x from the pivot, q = 0 horizontal... here com along -z: hanging).
  const double m = 1.7, l = 0.45, Iyy = 0.02, g = 9.81;
  JointSpec j;
  j.type = JointType::revolute;
  j.axis = Vec3::UnitY();
  j.link.mass = m;
  j.link.inertia_body = Vec3(0.03, Iyy, 0.01).asDiagonal();
  j.com = Vec3(0.0, 0.0, -l);
  const ChainModel model({j});
  RneChainDynamics rne(model);
  for (double q : {0.0, 0.3, -1.1, 2.5}) {
    const double qd = 0.7, qdd = -1.3;
    Eigen::VectorXd tau(1);
    Vec3 F, M;
    ASSERT_EQ(rne.inverse_dynamics(Eigen::VectorXd::Constant(1, q), Eigen::VectorXd::Constant(1, qd),
                                   Eigen::VectorXd::Constant(1, qdd), tau, &F, &M),
              Status::ok);
    // rotation about +y by q moves the bob (0,0,-l) to (-l sin q, 0, -l cos q): gravity torque
    // about +y is r x (0,0,-m g) . y = m g l sin q ... with the sign of (r_z F_x - r_x F_z).
    const double expected = (Iyy + m * l * l) * qdd + m * g * l * std::sin(q);
    EXPECT_NEAR(tau(0), expected, 1e-12);
    // support force: weight plus m a_G, a_G of the bob
    const Vec3 r(-l * std::sin(q), 0.0, -l * std::cos(q));
    const Vec3 w(0.0, qd, 0.0), alpha(0.0, qdd, 0.0);
    const Vec3 aG = alpha.cross(r) + w.cross(w.cross(r));
    EXPECT_LT((F - (m * aG - m * Vec3(0, 0, -g))).norm(), 1e-12);
  }
}

TEST(Rne, RealTimeContract) {
  std::mt19937 rng(21);
  const ChainModel model = test::random_chain(rng, "RRPRRRR");
  const int n = model.dof();
  RneChainDynamics rne(model);
  const Eigen::VectorXd q = test::random_vector(rng, n, 1.0), qd = test::random_vector(rng, n, 1.0),
                        qdd = test::random_vector(rng, n, 1.0);
  Eigen::VectorXd tau = Eigen::VectorXd::Constant(n, 7.0), out(n);
  Eigen::MatrixXd M(n, n);
  Vec3 F, Mo;
  {
    test::AllocationScope scope;
    for (int k = 0; k < 100; ++k) {
      EXPECT_EQ(rne.inverse_dynamics(q, qd, qdd, tau, &F, &Mo), Status::ok);
      EXPECT_EQ(rne.inverse_dynamics(q, qd, qdd, tau), Status::ok);
      EXPECT_EQ(rne.mass_matrix(q, M), Status::ok);
      EXPECT_EQ(rne.gravity(q, out), Status::ok);
      EXPECT_EQ(rne.bias(q, qd, out), Status::ok);
      EXPECT_EQ(rne.coriolis(q, qd, out), Status::ok);
    }
    EXPECT_EQ(scope.count(), 0u);
  }
  {
    // compiles only if the tick is declared noexcept (C++17: noexcept is part of the type)
    using CRef = const Eigen::Ref<const Eigen::VectorXd>&;
    using Tick = Status (RneChainDynamics::*)(CRef, CRef, CRef, Eigen::Ref<Eigen::VectorXd>,
                                              Vec3*, Vec3*) noexcept;
    const Tick tick = &RneChainDynamics::inverse_dynamics;
    EXPECT_NE(tick, nullptr);
  }

  // non-finite input: status, output untouched
  const Eigen::VectorXd held = tau;
  Eigen::VectorXd bad = qd;
  bad(3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(rne.inverse_dynamics(q, bad, qdd, tau), Status::non_finite_input);
  EXPECT_EQ(tau, held);
  bad = q;
  bad(0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(rne.mass_matrix(bad, M), Status::non_finite_input);
  EXPECT_EQ(rne.gravity(bad, out), Status::non_finite_input);
  // wrong size: status, output untouched
  Eigen::VectorXd short_q = q.head(n - 1);
  EXPECT_EQ(rne.inverse_dynamics(short_q, qd, qdd, tau), Status::bad_size);
  EXPECT_EQ(tau, held);
  Eigen::MatrixXd M_small(n - 1, n - 1);
  EXPECT_EQ(rne.mass_matrix(q, M_small), Status::bad_size);
}

TEST(Rne, ThroughTheInterface) {
  std::mt19937 rng(3);
  const ChainModel model = test::random_chain(rng, "RRR");
  RneChainDynamics rne(model);
  KdlChainDynamics kdl(model);
  InverseDynamics* backends[] = {&rne, &kdl};
  const Eigen::VectorXd q = test::random_vector(rng, 3, 1.0), qd = test::random_vector(rng, 3, 1.0),
                        qdd = test::random_vector(rng, 3, 1.0);
  Eigen::VectorXd t0(3), t1(3);
  ASSERT_EQ(backends[0]->inverse_dynamics(q, qd, qdd, t0), Status::ok);
  ASSERT_EQ(backends[1]->inverse_dynamics(q, qd, qdd, t1), Status::ok);
  EXPECT_LT(rel(t0, t1), 1e-9);
}

}  // namespace
