// Real-time contract: the single-instant functions allocate nothing (DESIGN.md).
#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "mechbal/kdl_chain.hpp"
#include "mechbal/rigid_body.hpp"
#include "mechbal/serial_chain.hpp"
#include "mechbal/trajectory.hpp"
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
  const ChainModel model = test::random_chain(rng, "RRPRRR");
  const int n = model.dof();
  ChainWorkspace ws(model);
  KdlChainDynamics kdl(model);
  const Eigen::VectorXd q = test::random_vector(rng, n, 1.0),
                        qd = test::random_vector(rng, n, 1.0),
                        qdd = test::random_vector(rng, n, 1.0);
  Eigen::VectorXd tau(n), c(n), g(n), qt(n), qdt(n), qddt(n);
  Eigen::MatrixXd M(n, n);
  RestToRestTrajectory traj(q, qd, 0.5, TimeLaw::quintic);
  ShakingWrench sw;
  BaseReaction br;
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
    EXPECT_EQ(chain_kinematics(model, qt, qdt, qddt, ws), Status::ok);
    EXPECT_EQ(shaking_wrench(model.bodies().data(), ws.states.data(), ws.states.size(), sw),
              Status::ok);
    EXPECT_EQ(base_reaction(model.bodies().data(), ws.states.data(), ws.states.size(),
                            model.gravity(), sw, br),
              Status::ok);
    EXPECT_EQ(kdl.inverse_dynamics(qt, qdt, qddt, tau, &F, &Mo), Status::ok);
    EXPECT_EQ(kdl.mass_matrix(qt, M), Status::ok);
    EXPECT_EQ(kdl.coriolis(qt, qdt, c), Status::ok);
    EXPECT_EQ(kdl.gravity(qt, g), Status::ok);
  }
  EXPECT_EQ(scope.count(), 0u);
}
