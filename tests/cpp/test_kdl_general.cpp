// KdlChainDynamics built from the general MechanismModel (kdl_chain.hpp): on random serial chains
// with several bodies per link (and bodies on the base), Orocos KDL is an independent engine for
// MechanismDynamics' inverse dynamics, base support wrench, mass matrix, gravity and Coriolis
// terms; a model that is not a chain is refused with the reason.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "test_support.hpp"

using namespace mechbal;

namespace {

/// A random serial chain in the general format: joint i's parent is joint i - 1; types from
/// `types` ('R', 'P'); 1-3 bodies on every link, one body on the base; a random gravity.
MechanismDescription random_chain_description(std::mt19937& rng, const std::string& types) {
  MechanismDescription d;
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  std::string parent = d.root_name;
  d.bodies.push_back(Body{"pedestal", "base", d.root_name, 3.0, Vec3(0.0, 0.0, 0.1), Mat3::Identity() * 0.01});
  for (std::size_t i = 0; i < types.size(); ++i) {
    Joint j;
    j.name = "j" + std::to_string(i + 1);
    j.type = types[i] == 'P' ? JointType::prismatic : JointType::revolute;
    j.parent = parent;
    j.placement = test::random_pose(rng);
    j.axis = Vec3(u(rng), u(rng), u(rng));  // not unit: the model normalises it
    d.joints.push_back(j);
    const int nb = 1 + std::uniform_int_distribution<int>(0, 2)(rng);
    for (int b = 0; b < nb; ++b) {
      const RigidBody rb = test::random_body(rng);
      d.bodies.push_back(Body{j.name + "_b" + std::to_string(b), b == 0 ? "link" : "counterweight", j.name,
                              rb.mass, Vec3(u(rng), u(rng), u(rng)), rb.inertia_body});
    }
    parent = j.name;
  }
  d.gravity = Vec3(u(rng), u(rng), -9.81 + u(rng));
  return d;
}

using test::rel;

std::string refusal(const MechanismDescription& d) {
  try {
    KdlChainDynamics kdl{MechanismModel(d)};
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(KdlGeneral, RandomChainsMatchMechanismDynamics) {
  std::mt19937 rng(91);
  for (const char* types : {"RRRRRR", "RPRRPR", "R", "P", "RRPRRRR"}) {
    for (int trial = 0; trial < 3; ++trial) {
      const MechanismModel model(random_chain_description(rng, types));
      ASSERT_TRUE(model.is_serial_chain()) << types;
      MechanismDynamics general(model);
      KdlChainDynamics kdl(model);
      const int n = model.dof();
      ASSERT_EQ(kdl.dof(), n);
      for (int k = 0; k < 5; ++k) {
        const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.5),
                              a = test::random_vector(rng, n, 1.5);
        Eigen::VectorXd tau_k(n), tau_g(n);
        Vec3 F_k, M_k, F_g, M_g;
        ASSERT_EQ(kdl.inverse_dynamics(q, v, a, tau_k, &F_k, &M_k), Status::ok);
        ASSERT_EQ(general.inverse_dynamics(q, v, a, tau_g, &F_g, &M_g), Status::ok);
        EXPECT_LT(rel(tau_g, tau_k), 1e-10) << types;
        EXPECT_LT(rel(F_g, F_k), 1e-10) << types;
        EXPECT_LT(rel(M_g, M_k), 1e-10) << types;

        Eigen::MatrixXd Mk(n, n), Mg(n, n);
        ASSERT_EQ(kdl.mass_matrix(q, Mk), Status::ok);
        ASSERT_EQ(general.mass_matrix(q, Mg), Status::ok);
        EXPECT_LT(rel(Mg, Mk), 1e-10) << types;

        Eigen::VectorXd gk(n), gg(n), ck(n), cg(n);
        ASSERT_EQ(kdl.gravity(q, gk), Status::ok);
        ASSERT_EQ(general.gravity(q, gg), Status::ok);
        EXPECT_LT(rel(gg, gk), 1e-10) << types;
        ASSERT_EQ(kdl.coriolis(q, v, ck), Status::ok);
        ASSERT_EQ(general.coriolis(q, v, cg), Status::ok);
        EXPECT_LT(rel(cg, ck), 1e-10) << types;
      }
    }
  }
}

TEST(KdlGeneral, BodiesOnALinkAreLumpedExactly) {
  // The same chain with each link's bodies given separately or as one lumped body: equal torques
  // through KDL (the lumping) and through the general model (which sums the bodies itself).
  std::mt19937 rng(92);
  const MechanismDescription split = random_chain_description(rng, "RRPR");
  MechanismDescription lumped = split;
  lumped.bodies.clear();
  for (const Joint& j : split.joints) {
    double m = 0.0;
    Vec3 h = Vec3::Zero();
    for (const Body& b : split.bodies)
      if (b.link == j.name) m += b.mass, h += b.mass * b.com;
    const Vec3 c = h / m;
    Mat3 I = Mat3::Zero();
    for (const Body& b : split.bodies) {
      if (b.link != j.name) continue;
      const Vec3 d = b.com - c;
      I += b.inertia + b.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
    }
    lumped.bodies.push_back(Body{j.name, "link", j.name, m, c, I});
  }
  KdlChainDynamics kdl_split{MechanismModel(split)};
  MechanismDynamics general_lumped{MechanismModel(lumped)};
  const Eigen::VectorXd q = test::random_vector(rng, 4, 2.0), v = test::random_vector(rng, 4, 1.0),
                        a = test::random_vector(rng, 4, 1.0);
  Eigen::VectorXd t1(4), t2(4);
  ASSERT_EQ(kdl_split.inverse_dynamics(q, v, a, t1), Status::ok);
  ASSERT_EQ(general_lumped.inverse_dynamics(q, v, a, t2), Status::ok);
  EXPECT_LT(rel(t1, t2), 1e-10);
}

TEST(KdlGeneral, ModelsThatAreNotChainsAreRefusedWithTheReason) {
  std::mt19937 rng(93);
  const MechanismDescription chain = random_chain_description(rng, "RRR");

  MechanismDescription tree = chain;
  tree.joints[2].parent = "j1";  // j3 hangs from j1 beside j2
  EXPECT_NE(refusal(tree).find("link 'j3' hangs from 'j1'"), std::string::npos) << refusal(tree);

  // a fixed joint is folded into its parent when the model is built: still a chain, accepted
  MechanismDescription fixed = chain;
  fixed.joints[1].type = JointType::fixed;
  EXPECT_TRUE(MechanismModel(fixed).is_serial_chain());
  EXPECT_EQ(refusal(fixed), "");

  MechanismDescription geared = chain;
  geared.joints[2].mimic_joint = "j1";
  geared.joints[2].mimic_ratio = -2.0;
  EXPECT_NE(refusal(geared).find("joint 'j3' is gear-coupled to 'j1'"), std::string::npos) << refusal(geared);

  MechanismDescription empty;
  empty.bodies.push_back(Body{"pedestal", "base", empty.root_name, 1.0, Vec3::Zero(), Mat3::Zero()});
  EXPECT_NE(refusal(empty).find("no joint"), std::string::npos) << refusal(empty);

  EXPECT_EQ(refusal(chain), "");
}
