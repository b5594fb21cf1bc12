// Real-time contract: the single-instant functions allocate nothing (docs/architecture.md).
#include <gtest/gtest.h>

#include <cmath>

#include "../../bench/paminsa_general.hpp"
#include "alloc_counter.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "paminsa_motion.hpp"
#include "mechbal/papers/arm2dof/arm2dof.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/control/trajectory.hpp"
#include "test_support.hpp"

using namespace mechbal;

TEST(Allocations, CounterSeesAnAllocation) {
  test::AllocationScope scope;
  std::vector<double> v(100);
  v[3] = 1.0;
  EXPECT_GE(scope.count(), 1u);  // proves the counter is live
  EXPECT_EQ(v[3], 1.0);
}

TEST(Allocations, SingleInstantFunctionsAllocateNothing) {
  std::mt19937 rng(5);
  const MechanismModel model(test::random_chain(rng, "RRPRRR"));
  const int n = model.dof();
  MechanismData ws(model);
  KdlChainDynamics kdl(model);
  const Eigen::VectorXd q = test::random_vector(rng, n, 1.0),
                        qd = test::random_vector(rng, n, 1.0),
                        qdd = test::random_vector(rng, n, 1.0);
  Eigen::VectorXd tau(n), c(n), g(n), qt(n), qdt(n), qddt(n);
  Eigen::MatrixXd M(n, n);
  RestToRestTrajectory traj(q, qd, 0.5, TimeLaw::quintic);
  Vec3 F, Mo;
  // warm up once (lazy initialisation inside libraries is allowed before the loop starts)
  kdl.inverse_dynamics(q, qd, qdd, tau, &F, &Mo);
  kdl.mass_matrix(q, M);
  kdl.coriolis(q, qd, c);
  kdl.gravity(q, g);

  test::AllocationScope scope;
  for (int tick = 0; tick < 100; ++tick) {
    const double t = tick * 1e-3;
    EXPECT_EQ(traj.evaluate(t, qt, qdt, qddt), Status::ok);
    EXPECT_EQ(forward_kinematics(model, ws, qt, qdt, qddt), Status::ok);
    EXPECT_EQ(shaking_wrench(model, ws, qt, qdt, qddt), Status::ok);
    EXPECT_EQ(base_reaction(model, ws, qt, qdt, qddt), Status::ok);
    EXPECT_EQ(kdl.inverse_dynamics(qt, qdt, qddt, tau, &F, &Mo), Status::ok);
    EXPECT_EQ(kdl.mass_matrix(qt, M), Status::ok);
    EXPECT_EQ(kdl.coriolis(qt, qdt, c), Status::ok);
    EXPECT_EQ(kdl.gravity(qt, g), Status::ok);
  }
  EXPECT_EQ(scope.count(), 0u);
}

// Issue 14: the paths that reject input (out_of_range holds, overflow checks) and the wrist's
// closed-form damped least squares at the singularity are reachable from a tick: no allocation.
TEST(Allocations, RejectionAndSingularPathsAllocateNothing) {
  std::mt19937 rng(8);
  const MechanismModel model(test::random_chain(rng, "RRPR"));
  const int n = model.dof();
  MechanismData ws(model);
  KdlChainDynamics kdl(model);
  MechanismDynamics rne(model);
  Arm2DofDynamics arm(Arm2DofParameters{});
  const JointInputRange declared{1e3, 1e2, 1e4};  // no limit unless declared: declare one to reject
  ComputedTorque ct(arm, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20), Eigen::VectorXd(), declared);
  DecoupledJointController dc(Eigen::Vector2d(1, 2), Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20),
                              Eigen::VectorXd(), declared);
  const PaminsaModel paminsa(PaminsaParameters{});
  ReactionlessWristConfig rk4;
  rk4.integrator = WristIntegrator::rk4;
  PaminsaController pc(paminsa, rk4, Vec3(M_PI / 2, M_PI / 2, M_PI / 2));
  ReactionlessWrist singular_wrist(paminsa.wrist_inertia(), rk4, Vec3::Zero(), Vec3::Zero());
  PlatformMotion rest;
  rest.position = paminsa.parameters().nominal_platform;
  ASSERT_EQ(pc.reset(rest, Vec3(M_PI / 2, M_PI / 2, M_PI / 2)), Status::ok);
  PlatformMotion fast = rest, far = rest;
  fast.velocity = Vec3(50.0, 0.0, 0.0);  // beyond PlatformLimits::max_speed
  far.position = Vec3(5.0, 5.0, 0.6);    // unreachable
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(n, 0.3), huge = Eigen::VectorXd::Constant(n, 1e200);
  Eigen::VectorXd tau(n), c(n), tau2(2);
  Eigen::MatrixXd M(n, n);
  const Eigen::Vector2d z2 = Eigen::Vector2d::Zero(), absurd(1e6, 0.0);
  Vec3 F, Mo;
  kdl.inverse_dynamics(q, q, q, tau, &F, &Mo);  // warm up
  kdl.coriolis(q, q, c);

  test::AllocationScope scope;
  for (int tick = 0; tick < 50; ++tick) {
    EXPECT_EQ(forward_kinematics(model, ws, q, huge, q), Status::out_of_range);
    EXPECT_EQ(shaking_wrench(model, ws, q, q, q), Status::ok);
    EXPECT_EQ(rne.inverse_dynamics(q, huge, q, tau, &F, &Mo), Status::out_of_range);
    EXPECT_EQ(rne.mass_matrix(q, M), Status::ok);
    EXPECT_EQ(kdl.inverse_dynamics(q, huge, q, tau, &F, &Mo), Status::out_of_range);
    EXPECT_EQ(kdl.coriolis(q, huge, c), Status::out_of_range);
    EXPECT_EQ(ct.step(z2, z2, absurd, z2, z2, tau2), Status::out_of_range);
    EXPECT_EQ(dc.step(z2, absurd, z2, z2, z2, tau2), Status::out_of_range);
    EXPECT_TRUE(has(singular_wrist.step(Vec3(1.0, 0.5, 0.2), Vec3::Zero(), Vec3(1.0, 0.5, 0.2),
                                        Vec3(1.0, 0.5, 0.2)),
                    Status::singular));
    singular_wrist.reset(Vec3::Zero(), Vec3::Zero());
    EXPECT_EQ(singular_wrist.step(Vec3::Constant(1e5), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()),
              Status::out_of_range);
    EXPECT_EQ(pc.tick(fast, fast, fast), Status::out_of_range);
    EXPECT_EQ(pc.tick(far, far, far), Status::singular);
  }
  EXPECT_EQ(scope.count(), 0u);
}

// The general PAMINSA tick (closed_shaking_wrench: position solve, projection, shaking wrench of
// the closed motion), at 1 kHz and after jumps of 50 ms (Newton iterates): no allocation.
TEST(Allocations, ClosedShakingWrenchAllocatesNothing) {
  const PaminsaModel closed(PaminsaParameters{});
  const MechanismModel model(bench::paminsa_description(closed));
  MechanismData data(model);
  Eigen::VectorXd q = bench::initial_guess(closed, model, test::platform_at(0.0), test::wrist_at(0.0));
  std::vector<bench::ActuatedState> in;
  for (int k = 0; k < 60; ++k) {
    const double t = k < 30 ? 1e-3 * k : 0.05 * k;
    in.push_back(bench::actuated(closed, model, test::platform_at(t), test::wrist_at(t)));
  }
  test::AllocationScope scope;
  for (const auto& s : in) EXPECT_EQ(closed_shaking_wrench(model, data, s.q, s.v, s.a, q), Status::ok);
  EXPECT_EQ(scope.count(), 0u);
}
