// Serial chains: own closed-form kinematics against finite differences; KDL's joint torques and
// base wrench against the rigid-body (momentum) computation on the same motion.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <limits>

#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/model/serial_chain.hpp"
#include "test_support.hpp"

using namespace mechbal;
using Eigen::VectorXd;

namespace {

// Log map of a rotation: the vector w with exp([w]) = R (small angles here).
Vec3 log_so3(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

struct ChainCase {
  const char* types;
  unsigned seed;
};

class ChainTest : public ::testing::TestWithParam<ChainCase> {};

}  // namespace

TEST_P(ChainTest, KinematicsMatchFiniteDifferences) {
  std::mt19937 rng(GetParam().seed);
  const ChainModel model = test::random_chain(rng, GetParam().types);
  const int n = model.dof();
  ChainWorkspace ws(model), wp(model), wm(model);
  const VectorXd q0 = test::random_vector(rng, n, 1.5), qd = test::random_vector(rng, n, 1.0),
                 qdd = test::random_vector(rng, n, 2.0);
  // q(t) = q0 + qd t + qdd t^2 / 2 around t = 0
  const double h = 1e-5;
  auto q_at = [&](double t) { VectorXd q = q0 + qd * t + 0.5 * qdd * t * t; return q; };
  auto qd_at = [&](double t) { VectorXd v = qd + qdd * t; return v; };
  ASSERT_EQ(chain_kinematics(model, q0, qd, qdd, ws), Status::ok);
  ASSERT_EQ(chain_kinematics(model, q_at(h), qd_at(h), qdd, wp), Status::ok);
  ASSERT_EQ(chain_kinematics(model, q_at(-h), qd_at(-h), qdd, wm), Status::ok);
  for (int i = 0; i < n; ++i) {
    const BodyState &s = ws.states[i], &sp = wp.states[i], &sm = wm.states[i];
    EXPECT_LT(((sp.com - sm.com) / (2 * h) - s.com_velocity).norm(), 1e-8) << "link " << i;
    EXPECT_LT(((sp.com_velocity - sm.com_velocity) / (2 * h) - s.com_acceleration).norm(), 1e-7)
        << "link " << i;
    // angular velocity: R(t+h) R(t-h)^T = exp(2h [w])
    const Vec3 w_fd = log_so3(sp.rotation * sm.rotation.transpose()) / (2 * h);
    EXPECT_LT((w_fd - s.angular_velocity).norm(), 1e-8) << "link " << i;
    EXPECT_LT(((sp.angular_velocity - sm.angular_velocity) / (2 * h) - s.angular_acceleration)
                  .norm(),
              1e-7)
        << "link " << i;
    EXPECT_LT((s.rotation.transpose() * s.rotation - Mat3::Identity()).norm(), 1e-12);
  }
}

TEST_P(ChainTest, KdlTorquesAndBaseWrenchMatchMomentumBalance) {
  std::mt19937 rng(GetParam().seed + 100);
  const ChainModel model = test::random_chain(rng, GetParam().types);
  const int n = model.dof();
  KdlChainDynamics kdl(model);
  ChainWorkspace ws(model);
  for (int trial = 0; trial < 10; ++trial) {
    const VectorXd q = test::random_vector(rng, n, 2.0), qd = test::random_vector(rng, n, 1.5),
                   qdd = test::random_vector(rng, n, 3.0);
    VectorXd tau(n);
    Vec3 F, M;
    ASSERT_EQ(kdl.inverse_dynamics(q, qd, qdd, tau, &F, &M), Status::ok);
    ASSERT_EQ(chain_kinematics(model, q, qd, qdd, ws), Status::ok);

    // Base wrench: support = dP/dt - m g, dH_O/dt - sum c x m g over all links.
    ShakingWrench sw;
    ASSERT_EQ(shaking_wrench(model.bodies().data(), ws.states.data(), n, sw), Status::ok);
    BaseReaction br;
    ASSERT_EQ(base_reaction(model.bodies().data(), ws.states.data(), n, model.gravity(), sw, br),
              Status::ok);
    const double fs = 1.0 + br.force.norm(), ms = 1.0 + br.moment.norm();
    EXPECT_LT((F - br.force).norm() / fs, 1e-9);
    EXPECT_LT((M - br.moment).norm() / ms, 1e-9);

    // Joint i carries the subtree i..n: tau_i = axis . (moment about the joint of the subtree's
    // momentum rate minus gravity) for revolute joints, axis . force for prismatic ones.
    for (int i = 0; i < n; ++i) {
      const JointSpec& j = model.joints()[i];
      const Eigen::Isometry3d Fprev = i == 0 ? model.base() : ws.frames[i - 1];
      const Eigen::Isometry3d P = Fprev * j.origin;
      const Vec3 z = P.linear() * j.axis;
      const Vec3 p = ws.frames[i].translation();
      Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
      for (int k = i; k < n; ++k) {
        const BodyState& s = ws.states[k];
        const RigidBody& b = model.bodies()[k];
        const Mat3 I = s.rotation * b.inertia_body * s.rotation.transpose();
        const Vec3 f = b.mass * (s.com_acceleration - model.gravity());
        force += f;
        moment += (s.com - p).cross(f) + I * s.angular_acceleration +
                  s.angular_velocity.cross(I * s.angular_velocity);
      }
      const double expected = j.type == JointType::revolute ? z.dot(moment) : z.dot(force);
      EXPECT_NEAR(tau(i), expected, 1e-9 * (1.0 + std::abs(expected))) << "joint " << i;
    }

    // Mass matrix, Coriolis and gravity terms reassemble the torque.
    Eigen::MatrixXd Mq(n, n);
    VectorXd c(n), g(n);
    ASSERT_EQ(kdl.mass_matrix(q, Mq), Status::ok);
    ASSERT_EQ(kdl.coriolis(q, qd, c), Status::ok);
    ASSERT_EQ(kdl.gravity(q, g), Status::ok);
    EXPECT_LT((Mq - Mq.transpose()).norm(), 1e-12 * Mq.norm());
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Mq).eigenvalues().minCoeff(), 0.0);
    EXPECT_LT((Mq * qdd + c + g - tau).norm(), 1e-9 * (1.0 + tau.norm()));
  }
}

INSTANTIATE_TEST_SUITE_P(RandomChains, ChainTest,
                         ::testing::Values(ChainCase{"RRR", 1}, ChainCase{"RPR", 2},
                                           ChainCase{"RRRRRR", 3}, ChainCase{"PRRPRR", 4},
                                           ChainCase{"RRRRRRR", 5}),
                         [](const ::testing::TestParamInfo<ChainCase>& info) {
                           return std::string(info.param.types);
                         });

TEST(ChainModel, BadInputNamesTheJointAndField) {
  std::vector<JointSpec> joints(2);
  joints[0].name = "shoulder";
  joints[0].link.mass = 1.0;
  joints[0].link.inertia_body = Mat3::Identity() * 0.01;
  joints[1] = joints[0];
  joints[1].name = "elbow";
  joints[1].axis = Vec3::Zero();
  try {
    ChainModel m(joints);
    FAIL() << "zero axis accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("joints[1] (elbow).axis"), std::string::npos) << e.what();
  }
  joints[1].axis = Vec3::UnitZ();
  joints[1].link.mass = std::numeric_limits<double>::quiet_NaN();
  try {
    ChainModel m(joints);
    FAIL() << "NaN mass accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("joints[1] (elbow).link.mass"), std::string::npos)
        << e.what();
  }
}

TEST(ChainKinematics, BadSizeAndNonFiniteGiveStatus) {
  std::mt19937 rng(3);
  const ChainModel model = test::random_chain(rng, "RR");
  ChainWorkspace ws(model);
  VectorXd q = VectorXd::Zero(3), ok = VectorXd::Zero(2);
  EXPECT_EQ(chain_kinematics(model, q, ok, ok, ws), Status::bad_size);
  ok(0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(chain_kinematics(model, ok, VectorXd::Zero(2), VectorXd::Zero(2), ws),
            Status::non_finite_input);
  KdlChainDynamics kdl(model);
  VectorXd tau(2);
  EXPECT_EQ(kdl.inverse_dynamics(ok, VectorXd::Zero(2), VectorXd::Zero(2), tau),
            Status::non_finite_input);
}
