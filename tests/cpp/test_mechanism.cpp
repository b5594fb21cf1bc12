// The general mechanism model (model.hpp, data.hpp, algorithm/*.hpp): against KDL on serial
// chains (an independent engine), against a body-by-body sum of the momenta (test_support.hpp), against
// its own invariants on random trees, and the real-time contract (no allocation, statuses).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "alloc_counter.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/regressor.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/detail/tree.hpp"
#include "every_algorithm.hpp"
#include "test_support.hpp"

using namespace mechbal;

namespace {

/// A random rotation among the 24 that permute the axes with signs (exact zeros and ones).
Mat3 random_axis_permutation(std::mt19937& rng) {
  int order[3] = {0, 1, 2};
  std::shuffle(std::begin(order), std::end(order), rng);
  Mat3 R = Mat3::Zero();
  for (int c = 0; c < 3; ++c) R(order[c], c) = std::bernoulli_distribution(0.5)(rng) ? 1.0 : -1.0;
  if (R.determinant() < 0.0) R.col(2) = -R.col(2);
  return R;
}

/// A random tree: each joint's parent is a random earlier link; types from `types` (R, P, F);
/// 1-3 bodies per link; a gear coupling on the last joint when `gear`; a frame on every link.
/// `aligned`: the joints' placements turn the axes into one another (random_axis_permutation)
/// and their axes are +-x, +-y or +-z, as in models drawn at right angles, or (half of them) the
/// placement does not turn and the axis is z.
MechanismDescription random_tree_description(std::mt19937& rng, const std::string& types, bool gear = false,
                                             bool aligned = false) {
  MechanismDescription d;
  std::vector<std::string> links{d.root_name};
  for (std::size_t i = 0; i < types.size(); ++i) {
    const std::string parent = links[std::uniform_int_distribution<std::size_t>(0, links.size() - 1)(rng)];
    Joint j = test::random_joint(rng, "j" + std::to_string(i + 1), types[i], parent);
    if (aligned && std::bernoulli_distribution(0.5)(rng)) {  // (the other half: in line with the parent, along z)
      j.placement.linear() = random_axis_permutation(rng);
      j.axis = (std::bernoulli_distribution(0.5)(rng) ? 1.0 : -1.0) *
               Vec3::Unit(std::uniform_int_distribution<int>(0, 2)(rng));
    } else if (aligned) {
      j.placement.linear().setIdentity();
      j.axis = Vec3::UnitZ();
    }
    d.joints.push_back(j);
    const int nb = 1 + static_cast<int>(std::uniform_int_distribution<int>(0, 2)(rng));
    for (int b = 0; b < nb; ++b) d.bodies.push_back(test::random_link_body(rng, j.name + "_b" + std::to_string(b), j.name));
    d.frames.push_back(Frame{j.name + "_tool", j.name, test::random_pose(rng)});
    links.push_back(j.name);
  }
  if (gear) test::gear_last_joint(d);
  return d;
}

MechanismModel random_tree(std::mt19937& rng, const std::string& types, bool gear = false) {
  return MechanismModel(random_tree_description(rng, types, gear));
}

using test::rel;

}  // namespace

TEST(Mechanism, ChainMatchesKdl) {
  std::mt19937 rng(21);
  for (const char* types : {"RRRRRR", "RPRRPR", "R", "PP"}) {
    const MechanismModel model(test::random_chain(rng, types));
    ASSERT_TRUE(model.is_serial_chain());
    MechanismData data(model);
    KdlChainDynamics kdl(model);
    const int n = model.dof();
    for (int k = 0; k < 5; ++k) {
      const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.0),
                            a = test::random_vector(rng, n, 1.0);
      Eigen::VectorXd tau(n);
      Vec3 F, M;
      ASSERT_EQ(kdl.inverse_dynamics(q, v, a, tau, &F, &M), Status::ok);
      ASSERT_EQ(inverse_dynamics(model, data, q, v, a), Status::ok);
      EXPECT_LT(rel(data.joint_torque, tau), 1e-10) << types;
      Eigen::MatrixXd Mk(n, n);
      ASSERT_EQ(kdl.mass_matrix(q, Mk), Status::ok);
      ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
      EXPECT_LT(rel(data.mass_matrix, Mk), 1e-10) << types;
      // KDL's base support wrench is the base reaction of the moving links
      ASSERT_EQ(base_reaction(model, data, q, v, a), Status::ok);
      EXPECT_LT(rel(data.base_reaction.force, F), 1e-10);
      EXPECT_LT(rel(data.base_reaction.moment, M), 1e-10);
    }
  }
}

TEST(Mechanism, ShakingWrenchEqualsTheSumOverBodies) {
  std::mt19937 rng(22);
  for (int trial = 0; trial < 10; ++trial) {
    const MechanismModel model = random_tree(rng, "RRPFRRF", trial % 2 == 1);
    MechanismData data(model);
    const int n = model.dof();
    const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.0),
                          a = test::random_vector(rng, n, 1.0);
    ASSERT_EQ(forward_kinematics(model, data, q, v, a), Status::ok);
    const ShakingWrench per_body =
        test::body_set_wrench(data.body_inertias.data(), data.body_states.data(), data.body_states.size());
    ASSERT_EQ(shaking_wrench(model, data, q, v, a), Status::ok);
    EXPECT_LT(rel(data.shaking.force, per_body.force), 1e-12);
    EXPECT_LT(rel(data.shaking.moment, per_body.moment), 1e-12);
    EXPECT_LT(rel(data.shaking.linear_momentum, per_body.linear_momentum), 1e-12);
    EXPECT_LT(rel(data.shaking.angular_momentum, per_body.angular_momentum), 1e-12);
  }
}

// Links whose constant rotation permutes the axes (exact zeros and ones) take shortcuts in every
// pass (MechanismModel::local_rotation: products with R's zeros left out). Their results must be
// those of the general products: the same tree with each placement turned by 1e-13 rad (no exact
// zeros left: every link general, a different mechanism by 1e-13) agrees to 1e-11 in every
// algorithm that places links, runs a forward or a backward pass or accumulates composites.
TEST(Mechanism, AxisAlignedLinksAgreeWithTheGeneralProducts) {
  std::mt19937 rng(29);
  using K = MechanismModel::LocalRotation;
  int seen[5] = {0, 0, 0, 0, 0};
  for (int trial = 0; trial < 12; ++trial) {
    const MechanismDescription d = random_tree_description(rng, trial % 2 == 0 ? "RRPFRRPR" : "RFRRPRRF", trial % 3 == 0, true);
    MechanismDescription turned = d;
    for (Joint& j : turned.joints) j.placement.linear() = j.placement.linear() * Eigen::AngleAxisd(1e-13, Vec3(0.6, 0.0, 0.8)).toRotationMatrix();
    const MechanismModel model(d), general(turned);
    for (int l = 1; l < model.num_links(); ++l) {
      ASSERT_NE(model.local_rotation(l), K::general) << "link " << l;
      ASSERT_EQ(general.local_rotation(l), K::general) << "link " << l;
      ++seen[static_cast<int>(model.local_rotation(l))];
    }
    MechanismData data(model), other(general);
    const int n = model.dof();
    const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.0),
                          a = test::random_vector(rng, n, 1.0);
    ASSERT_EQ(inverse_dynamics(model, data, q, v, a), Status::ok);
    ASSERT_EQ(inverse_dynamics(general, other, q, v, a), Status::ok);
    EXPECT_LT(rel(data.joint_torque, other.joint_torque), 1e-11);
    ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
    ASSERT_EQ(mass_matrix(general, other, q), Status::ok);
    EXPECT_LT(rel(data.mass_matrix, other.mass_matrix), 1e-11);
    ASSERT_EQ(shaking_wrench(model, data, q, v, a), Status::ok);
    ASSERT_EQ(shaking_wrench(general, other, q, v, a), Status::ok);
    EXPECT_LT(rel(data.shaking.force, other.shaking.force), 1e-11);
    EXPECT_LT(rel(data.shaking.moment, other.shaking.moment), 1e-11);
    EXPECT_LT(rel(data.shaking.angular_momentum, other.shaking.angular_momentum), 1e-11);
    ASSERT_EQ(base_reaction(model, data, q, v, a), Status::ok);
    ASSERT_EQ(base_reaction(general, other, q, v, a), Status::ok);
    EXPECT_LT(rel(data.base_reaction.moment, other.base_reaction.moment), 1e-11);
    ASSERT_EQ(momentum_matrix(model, data, q), Status::ok);
    ASSERT_EQ(momentum_matrix(general, other, q), Status::ok);
    EXPECT_LT(rel(data.momentum_matrix, other.momentum_matrix), 1e-11);
    for (int f = 0; f < model.num_frames(); ++f) {
      ASSERT_EQ(frame_placement(model, data, q, f), Status::ok);
      ASSERT_EQ(frame_placement(general, other, q, f), Status::ok);
      const auto fs = static_cast<std::size_t>(f);
      EXPECT_LT((data.frame_placements[fs].matrix() - other.frame_placements[fs].matrix()).cwiseAbs().maxCoeff(), 1e-11)
          << f;
    }
  }
  // every shortcut taken: the links along x, y, z and the identity (prismatic and fixed joints)
  for (const K kind : {K::along_x, K::along_y, K::along_z, K::identity}) EXPECT_GT(seen[static_cast<int>(kind)], 0);
}

// Right angles as a URDF gives them: rpy angles of +-pi/2 leave cos(pi/2) = 6e-17 where the zeros
// belong. Such a rotation is taken as the signed permutation it stands for (the model's joint
// placements, before fixed joints are folded): the tree built from rotations recomposed from their Euler angles (as a parser does)
// is bit for bit the tree built from the exact permutations, in its kinds and in every result. A
// real angle of 1e-14 rad is not rounding: that tree stays general.
TEST(Mechanism, RightAnglesWithinRoundingAreExact) {
  std::mt19937 rng(31);
  using K = MechanismModel::LocalRotation;
  int rounded = 0;  // placements whose recomposed rotation is not exactly the permutation
  for (int trial = 0; trial < 8; ++trial) {
    const MechanismDescription d = random_tree_description(rng, trial % 2 == 0 ? "RRPFRRPR" : "RFRRPRRF", trial % 3 == 0, true);
    MechanismDescription parsed = d, turned = d;
    for (std::size_t i = 0; i < d.joints.size(); ++i) {
      const Mat3 R = d.joints[i].placement.linear();
      const Vec3 e = R.eulerAngles(2, 1, 0);  // multiples of pi/2, rounded
      const Mat3 Rp = (Eigen::AngleAxisd(e(0), Vec3::UnitZ()) * Eigen::AngleAxisd(e(1), Vec3::UnitY()) *
                       Eigen::AngleAxisd(e(2), Vec3::UnitX())).toRotationMatrix();
      ASSERT_LT((Rp - R).cwiseAbs().maxCoeff(), 1e-15);
      rounded += Rp != R;
      parsed.joints[i].placement.linear() = Rp;
      turned.joints[i].placement.linear() = R * Eigen::AngleAxisd(1e-14, Vec3(0.0, 0.6, 0.8)).toRotationMatrix();
    }
    const MechanismModel exact(d), model(parsed), general(turned);
    for (int l = 1; l < model.num_links(); ++l) {
      ASSERT_EQ(model.local_rotation(l), exact.local_rotation(l)) << "link " << l;
      ASSERT_NE(model.local_rotation(l), K::general) << "link " << l;
      ASSERT_TRUE(model.placement(l).matrix() == exact.placement(l).matrix()) << "link " << l;
      ASSERT_TRUE(model.link_constants(l).rotation == exact.link_constants(l).rotation) << "link " << l;
      if (d.joints[static_cast<std::size_t>(l - 1)].placement.linear() != Mat3::Identity()) {
        EXPECT_EQ(general.local_rotation(l), K::general) << "link " << l;
      }
    }
    MechanismData a(exact), b(model);
    const int n = model.dof();
    const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.0),
                          acc = test::random_vector(rng, n, 1.0);
    ASSERT_EQ(inverse_dynamics(exact, a, q, v, acc), Status::ok);
    ASSERT_EQ(inverse_dynamics(model, b, q, v, acc), Status::ok);
    EXPECT_TRUE(a.joint_torque == b.joint_torque);
    ASSERT_EQ(mass_matrix(exact, a, q), Status::ok);
    ASSERT_EQ(mass_matrix(model, b, q), Status::ok);
    EXPECT_TRUE(a.mass_matrix == b.mass_matrix);
  }
  EXPECT_GT(rounded, 10);  // (the recomposition rounds: the test is not of exact input)
}

// The shortcuts themselves, against the dense products they stand for, on rotations of each kind
// (R = C R_z(q), C a signed permutation taking z to the axis k; the identity), to round-off.
TEST(Mechanism, RotationShortcutsAreTheDenseProducts) {
  std::mt19937 rng(31);
  using K = MechanismModel::LocalRotation;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto check = [&](auto kind, const Mat3& R) {
    constexpr K k = decltype(kind)::value;
    const Vec3 v(u(rng), u(rng), u(rng));
    Mat3 S = Mat3::Random();
    S = (S * S.transpose()).eval();
    S = (0.5 * (S + S.transpose())).eval();  // (exactly symmetric, as a composite inertia)
    const Mat3 P = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    Mat3 PR;
    detail::times_local<k>(P, R, PR);
    const double tol = 4.0 * std::numeric_limits<double>::epsilon();
    EXPECT_LT((detail::to_child<k>(R, v) - R.transpose() * v).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((detail::to_parent<k>(R, v) - R * v).cwiseAbs().maxCoeff(), tol);
    EXPECT_LT((PR - P * R).cwiseAbs().maxCoeff(), tol);
    const Mat3 rotated = detail::rotate_symmetric_as<k>(R, S);
    EXPECT_LT((rotated - R * S * R.transpose()).cwiseAbs().maxCoeff(), tol * S.norm());
    EXPECT_EQ(rotated, rotated.transpose());  // exactly symmetric, as rotate_symmetric's
  };
  for (int trial = 0; trial < 50; ++trial) {
    Mat3 C = random_axis_permutation(rng);
    const double q = 3.0 * u(rng);
    const Mat3 R = C * Eigen::AngleAxisd(q, Vec3::UnitZ()).toRotationMatrix();
    Eigen::Index axis = 0;
    C.col(2).cwiseAbs().maxCoeff(&axis);
    if (axis == 0) check(std::integral_constant<K, K::along_x>{}, R);
    if (axis == 1) check(std::integral_constant<K, K::along_y>{}, R);
    if (axis == 2) check(std::integral_constant<K, K::along_z>{}, R);
    check(std::integral_constant<K, K::general>{}, Mat3(Eigen::Quaterniond::UnitRandom().toRotationMatrix()));
  }
  check(std::integral_constant<K, K::identity>{}, Mat3::Identity());
}

// A chain long enough that its per-link buffers take the large-buffer path (2 MiB and more:
// 2 MiB-aligned, marked for huge pages): the buffers are aligned, and the centre of mass summed
// while the links are placed equals the body-by-body sum over forward kinematics' body states.
TEST(Mechanism, BigChainBuffersAndFusedCentreOfMass) {
  std::mt19937 rng(4242);
  const std::string types(6000, 'R');
  const MechanismModel model(test::random_chain(rng, types.c_str()));
  MechanismData data(model);
  ASSERT_GE(data.work.size() * sizeof(MechanismData::LinkWork), std::size_t{2} << 20);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(data.work.data()) % (std::uintptr_t{2} << 20), 0u);
  const MechanismData copy = data;  // copies through the same allocator
  EXPECT_EQ(copy.work.size(), data.work.size());
  const Eigen::VectorXd q = test::random_vector(rng, model.dof(), 0.3);
  ASSERT_EQ(forward_kinematics(model, data, q), Status::ok);
  Vec3 mc = Vec3::Zero();
  double m = 0.0;
  for (std::size_t b = 0; b < data.body_states.size(); ++b) {
    mc += data.body_inertias[b].mass * data.body_states[b].com;
    m += data.body_inertias[b].mass;
  }
  ASSERT_EQ(center_of_mass(model, data, q), Status::ok);
  EXPECT_NEAR(data.mass, m, 1e-9 * m);
  EXPECT_LT(rel(data.center_of_mass, Vec3(mc / m)), 1e-10);
}

TEST(Mechanism, BaseReactionCountsTheMovingBodiesOnly) {
  // Bodies on the root and on links fixed to it are the base's own: the base reaction (on the
  // moving mechanism) is the same with or without them; the support reaction adds their weight
  // and its moment about O. Against the body-by-body sum over the moving bodies (an independent
  // sum, test_support.hpp) minus their weight.
  std::mt19937 rng(24);
  for (int trial = 0; trial < 6; ++trial) {
    MechanismDescription d;
    d.joints.push_back(Joint{"mount", JointType::fixed, d.root_name, test::random_pose(rng)});
    d.joints.push_back(Joint{"j1", JointType::revolute, "mount", test::random_pose(rng), Vec3::UnitZ()});
    d.joints.push_back(Joint{"j2", JointType::prismatic, "j1", test::random_pose(rng), Vec3::UnitX()});
    d.joints.push_back(Joint{"tool", JointType::fixed, "j2", test::random_pose(rng)});
    for (const char* link : {"j1", "j2", "tool"}) {
      const RigidBody rb = test::random_body(rng);
      d.bodies.push_back(Body{std::string(link) + "_b", "link", link, rb.mass, test::random_vector(rng, 3, 0.2),
                              rb.inertia_body});
    }
    const MechanismModel moving(d);
    MechanismDescription with = d;
    with.bodies.push_back(Body{"base_link", "link", d.root_name, 4.0, Vec3(0.1, -0.2, 0.3), Mat3::Identity()});
    with.bodies.push_back(Body{"mount_b", "link", "mount", 2.5, Vec3(-0.3, 0.1, 0.2), Mat3::Identity()});
    const MechanismModel model(with);
    MechanismData d0(moving), d1(model);
    const Eigen::VectorXd q = test::random_vector(rng, 2, 2.0), v = test::random_vector(rng, 2, 1.0),
                          a = test::random_vector(rng, 2, 1.0);
    ASSERT_EQ(base_reaction(moving, d0, q, v, a), Status::ok);
    ASSERT_EQ(base_reaction(model, d1, q, v, a), Status::ok);
    EXPECT_LT(rel(d1.base_reaction.force, d0.base_reaction.force), 1e-13);
    EXPECT_LT(rel(d1.base_reaction.moment, d0.base_reaction.moment), 1e-13);
    EXPECT_LT(rel(d0.support_reaction.force, d0.base_reaction.force), 1e-15);
    const Vec3 g = model.gravity();
    ASSERT_EQ(forward_kinematics(model, d1, q, v, a), Status::ok);
    // the still bodies' weight: 4 kg at its com in O, 2.5 kg at the mount's com in O
    const auto idx = [&](const char* n) { return static_cast<std::size_t>(model.body_index(n)); };
    const Vec3 c_base = d1.body_states[idx("base_link")].com;
    const Vec3 c_mount = d1.body_states[idx("mount_b")].com;
    EXPECT_LT((c_base - Vec3(0.1, -0.2, 0.3)).norm(), 1e-15);
    EXPECT_LT(rel(d1.support_reaction.force - d1.base_reaction.force, Vec3(-6.5 * g)), 1e-13);
    EXPECT_LT(rel(d1.support_reaction.moment - d1.base_reaction.moment,
                  Vec3(-c_base.cross(4.0 * g) - c_mount.cross(2.5 * g))), 1e-12);
    // independent: the body-by-body sum over the three moving bodies, minus their weight
    std::vector<RigidBody> inertias;
    std::vector<BodyState> states;
    Vec3 weight = Vec3::Zero(), weight_moment = Vec3::Zero();
    for (const char* n : {"j1_b", "j2_b", "tool_b"}) {
      inertias.push_back(d1.body_inertias[idx(n)]);
      states.push_back(d1.body_states[idx(n)]);
      weight += inertias.back().mass * g;
      weight_moment += states.back().com.cross(inertias.back().mass * g);
    }
    const ShakingWrench sw = test::body_set_wrench(inertias.data(), states.data(), 3);
    EXPECT_LT(rel(d1.base_reaction.force, sw.force - weight), 1e-12);
    EXPECT_LT(rel(d1.base_reaction.moment, sw.moment - weight_moment), 1e-12);
  }
}

TEST(Mechanism, VirtualPowerAndMomentumMatrix) {
  // tau . v = dT/dt + dV/dt with T = v^T M v / 2: checks the dynamics against the mass matrix along
  // a motion by finite differences of the energy; and A(q) v equals the momenta.
  std::mt19937 rng(23);
  for (int trial = 0; trial < 10; ++trial) {
    const MechanismModel model = random_tree(rng, "RRPRFR", trial % 2 == 0);
    MechanismData data(model);
    const int n = model.dof();
    const Eigen::VectorXd q0 = test::random_vector(rng, n, 2.0), v0 = test::random_vector(rng, n, 1.0),
                          a0 = test::random_vector(rng, n, 1.0);
    auto energy = [&](double t) {
      const Eigen::VectorXd q = q0 + v0 * t + 0.5 * a0 * t * t, v = v0 + a0 * t;
      mass_matrix(model, data, q);
      center_of_mass(model, data, q);
      return 0.5 * v.dot(data.mass_matrix * v) - data.mass * model.gravity().dot(data.center_of_mass);
    };
    const double h = 1e-5;
    const double power = (energy(h) - energy(-h)) / (2 * h);
    ASSERT_EQ(inverse_dynamics(model, data, q0, v0, a0), Status::ok);
    EXPECT_NEAR(data.joint_torque.dot(v0), power, 1e-6 * std::max(1.0, std::abs(power)));
    ASSERT_EQ(momentum_matrix(model, data, q0), Status::ok);
    const Eigen::Matrix<double, 6, 1> h6 = data.momentum_matrix * v0;
    ASSERT_EQ(momentum(model, data, q0, v0), Status::ok);
    EXPECT_LT(rel(h6.head<3>(), data.shaking.linear_momentum), 1e-12);
    EXPECT_LT(rel(h6.tail<3>(), data.shaking.angular_momentum), 1e-12);
  }
}

// The placement pass skips the links whose joint did not move since they were placed, and the
// composite inertias keep the subtrees whose placements did not change (detail/tree.hpp): every
// algorithm, called in any order at poses where only some joints moved (none, one, a subtree, all),
// gives bit for bit what a fresh MechanismData gives at the same pose.
TEST(Mechanism, IncrementalPlacementIsBitForBitAFreshPlacement) {
  std::mt19937 rng(29);
  for (int trial = 0; trial < 12; ++trial) {
    const MechanismModel model = random_tree(rng, trial % 3 == 0 ? "RRPRFRRP" : "RPRRRFR", trial % 2 == 0);
    MechanismData data(model);
    data.reserve_mass_matrix();
    const int n = model.dof();
    Eigen::VectorXd q = test::random_vector(rng, n, 2.0);
    for (int call = 0; call < 60; ++call) {
      // move none, one or several coordinates (sometimes back to an earlier value)
      const int moves = std::uniform_int_distribution<int>(0, n)(rng);
      for (int m = 0; m < moves; ++m) {
        const int c = std::uniform_int_distribution<int>(0, n - 1)(rng);
        q(c) = call % 7 == 3 ? 0.0 : std::uniform_real_distribution<double>(-2.0, 2.0)(rng);
      }
      const Eigen::VectorXd v = test::random_vector(rng, n, 1.0), a = test::random_vector(rng, n, 1.0);
      MechanismData fresh(model);
      fresh.reserve_mass_matrix();
      const int which = std::uniform_int_distribution<int>(0, 6)(rng);
      const auto same = [&](const auto& x, const auto& y, const char* what) {
        EXPECT_TRUE((x.array() == y.array()).all()) << what << " trial " << trial << " call " << call;
      };
      switch (which) {
        case 0:
          ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
          ASSERT_EQ(mass_matrix(model, fresh, q), Status::ok);
          same(data.mass_matrix, fresh.mass_matrix, "mass_matrix");
          break;
        case 1:
          ASSERT_EQ(momentum_matrix(model, data, q), Status::ok);
          ASSERT_EQ(momentum_matrix(model, fresh, q), Status::ok);
          same(data.momentum_matrix, fresh.momentum_matrix, "momentum_matrix");
          break;
        case 2:
          ASSERT_EQ(shaking_wrench(model, data, q, v, a), Status::ok);
          ASSERT_EQ(shaking_wrench(model, fresh, q, v, a), Status::ok);
          same(data.shaking.force, fresh.shaking.force, "shaking force");
          same(data.shaking.moment, fresh.shaking.moment, "shaking moment");
          same(data.shaking.angular_momentum, fresh.shaking.angular_momentum, "angular momentum");
          break;
        case 3:
          ASSERT_EQ(inverse_dynamics(model, data, q, v, a), Status::ok);
          ASSERT_EQ(inverse_dynamics(model, fresh, q, v, a), Status::ok);
          same(data.joint_torque, fresh.joint_torque, "inverse_dynamics");
          break;
        case 4:
          ASSERT_EQ(gravity_torque(model, data, q), Status::ok);
          ASSERT_EQ(gravity_torque(model, fresh, q), Status::ok);
          same(data.gravity_torque, fresh.gravity_torque, "gravity_torque");
          break;
        case 5: {
          const int f = std::uniform_int_distribution<int>(0, model.num_frames() - 1)(rng);
          ASSERT_EQ(frame_jacobian(model, data, q, f), Status::ok);
          ASSERT_EQ(frame_jacobian(model, fresh, q, f), Status::ok);
          same(data.frame_jacobian, fresh.frame_jacobian, "frame_jacobian");
          break;
        }
        default:
          ASSERT_EQ(forward_kinematics(model, data, q, v, a), Status::ok);
          ASSERT_EQ(forward_kinematics(model, fresh, q, v, a), Status::ok);
          for (std::size_t l = 0; l < data.link_position.size(); ++l) {
            same(data.link_position[l], fresh.link_position[l], "link_position");
            same(data.link_rotation[l], fresh.link_rotation[l], "link_rotation");
            same(data.link_acceleration[l], fresh.link_acceleration[l], "link_acceleration");
          }
          break;
      }
    }
  }
}

// The mass matrix's backward pass (a subtree's momenta carried together, the gear couplings
// applied pair by pair) against the dense projection G^T M_joint G of the same tree with every
// joint free, and against the inverse dynamics' columns (M e_c = ID(q, 0, e_c) - ID(q, 0, 0), an
// independent recursion), on random trees with several gear couplings (on the same path as their
// master, on another branch, one following another), fixed joints and massless links.
TEST(Mechanism, MassMatrixIsTheDenseGearProjection) {
  std::mt19937 rng(27);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    MechanismDescription d;
    std::vector<std::string> links{d.root_name}, moving;
    const char* types = trial % 2 ? "RRPRFRRRPRRFRR" : "RPRRRRFRRRRRRR";
    for (int i = 0; types[i]; ++i) {
      Joint j;
      j.name = "j" + std::to_string(i + 1);
      j.type = types[i] == 'P' ? JointType::prismatic : types[i] == 'F' ? JointType::fixed : JointType::revolute;
      j.parent = links[std::uniform_int_distribution<std::size_t>(0, links.size() - 1)(rng)];
      j.placement = test::random_pose(rng);
      j.axis = Vec3(u(rng), u(rng), u(rng)).normalized();
      // every fourth moving joint follows an earlier one (possibly itself a follower)
      if (j.type != JointType::fixed && !moving.empty() && moving.size() % 4 == 3) {
        j.mimic_joint = moving[std::uniform_int_distribution<std::size_t>(0, moving.size() - 1)(rng)];
        j.mimic_ratio = std::uniform_real_distribution<double>(-2.0, 2.0)(rng);
        j.mimic_offset = u(rng);
      }
      d.joints.push_back(j);
      if (j.type != JointType::fixed) moving.push_back(j.name);
      if ((i + trial) % 5 != 4) {  // otherwise a massless link
        const RigidBody rb = test::random_body(rng);
        d.bodies.push_back(Body{j.name + "_b", "link", j.name, rb.mass, Vec3(u(rng), u(rng), u(rng)), rb.inertia_body});
      }
      links.push_back(j.name);
    }
    const MechanismModel model(d);
    MechanismDescription free = d;
    for (auto& j : free.joints) j.mimic_joint.clear();
    const MechanismModel free_model(free);
    ASSERT_EQ(free_model.num_links(), model.num_links());
    const int n = model.dof(), nf = free_model.dof();
    ASSERT_LT(n, nf);
    MechanismData data(model), free_data(free_model);
    for (int k = 0; k < 4; ++k) {
      const Eigen::VectorXd q = test::random_vector(rng, n, 2.0);
      Eigen::MatrixXd G = Eigen::MatrixXd::Zero(nf, n);
      Eigen::VectorXd qf(nf);
      for (int l = 1; l < model.num_links(); ++l) {
        const int c = model.coordinate(l), cf = free_model.coordinate(l);
        if (c < 0) continue;
        G(cf, c) = model.coordinate_ratio(l);
        qf(cf) = model.coordinate_ratio(l) * q(c) + model.coordinate_offset(l);
      }
      ASSERT_EQ(mass_matrix(free_model, free_data, qf), Status::ok);
      const Eigen::MatrixXd dense = G.transpose() * free_data.mass_matrix * G;
      ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
      const Eigen::MatrixXd M = data.mass_matrix;
      EXPECT_LT(rel(M, dense), 1e-13) << trial;
      EXPECT_EQ(M, M.transpose());
      Eigen::MatrixXd columns(n, n);
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
      ASSERT_EQ(inverse_dynamics(model, data, q, zero, zero), Status::ok);
      const Eigen::VectorXd bias = data.joint_torque;
      for (int c = 0; c < n; ++c) {
        ASSERT_EQ(inverse_dynamics(model, data, q, zero, Eigen::VectorXd::Unit(n, c)), Status::ok);
        columns.col(c) = data.joint_torque - bias;
      }
      EXPECT_LT(rel(M, columns), 1e-12) << trial;
    }
  }
}

TEST(Mechanism, AlgorithmsAllocateNothing) {
  std::mt19937 rng(24);
  const MechanismModel model = random_tree(rng, "RRPFRRRF", true);
  MechanismData data(model);
  const int n = model.dof();
  const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.0),
                        a = test::random_vector(rng, n, 1.0);
  EXPECT_EQ(test::allocations_of_every_algorithm(model, data, q, v, a, 1), 0u);
}

// frame_placement (one frame from the link placements) is the frame forward_kinematics places,
// to the last bit, and accepts and refuses the same instants.
TEST(Mechanism, FramePlacementIsTheKinematicsFrame) {
  std::mt19937 rng(26);
  const MechanismModel model = random_tree(rng, "RPRFRRPR", true);
  MechanismData one(model), all(model);
  const int n = model.dof();
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = test::random_vector(rng, n, 3.0);
    ASSERT_EQ(forward_kinematics(model, all, q), Status::ok);
    for (int f = 0; f < model.num_frames(); ++f) {
      ASSERT_EQ(frame_placement(model, one, q, f), Status::ok);
      EXPECT_EQ(one.frame_placements[static_cast<std::size_t>(f)].matrix(),
                all.frame_placements[static_cast<std::size_t>(f)].matrix());
    }
  }
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q(1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(frame_placement(model, one, q, 0), Status::non_finite_input);
  // huge coordinates: a prismatic joint's placement overflows; the same verdict as the kinematics
  int refused = 0;
  for (int i = 0; i < n; ++i) {
    for (double x : {std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(), 1e308}) {
      q.setConstant(0.2);
      q(i) = x;
      if (i + 1 < n) q(i + 1) = x;
      const Status s = forward_kinematics(model, all, q);
      refused += s == Status::out_of_range;
      for (int f = 0; f < model.num_frames(); ++f) EXPECT_EQ(frame_placement(model, one, q, f), s);
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_EQ(frame_placement(model, one, Eigen::VectorXd::Zero(n), model.num_frames()), Status::bad_size);
  EXPECT_EQ(frame_placement(model, one, Eigen::VectorXd::Zero(n), -1), Status::bad_size);
}

TEST(Mechanism, BadInputGivesAStatusAndWritesNothing) {
  std::mt19937 rng(25);
  const MechanismModel model = random_tree(rng, "RRR");
  const MechanismModel other = random_tree(rng, "RRRR");
  MechanismData data(model), wrong(other);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(3, 0.1);
  Eigen::VectorXd nan = q;
  nan(1) = std::numeric_limits<double>::quiet_NaN();
  ASSERT_EQ(inverse_dynamics(model, data, q, q, q), Status::ok);
  const Eigen::VectorXd before = data.joint_torque;
  EXPECT_EQ(inverse_dynamics(model, data, nan, q, q), Status::non_finite_input);
  EXPECT_EQ(inverse_dynamics(model, data, q, Eigen::VectorXd::Zero(2), q), Status::bad_size);
  EXPECT_EQ(inverse_dynamics(model, wrong, q, q, q), Status::bad_size);
  EXPECT_EQ(frame_jacobian(model, data, q, 7), Status::bad_size);
  EXPECT_EQ(data.joint_torque, before);
}

TEST(Mechanism, ConstructionErrorsNameTheField) {
  MechanismDescription d;
  Joint a;
  a.name = "shoulder";
  a.parent = "base";
  Joint b;
  b.name = "elbow";
  b.parent = "sholder";
  d.joints = {a, b};
  try {
    MechanismModel m(d);
    FAIL() << "accepted an unknown parent";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "joints[1] (elbow).parent: no link named 'sholder' (did you mean 'shoulder'?)");
  }
  d.joints[1].parent = "shoulder";
  d.joints[1].lower = 1.0;
  d.joints[1].upper = -1.0;
  EXPECT_THROW(MechanismModel{d}, std::invalid_argument);
}

// detail::all_finite (every input and result check) against Eigen's allFinite on the values at the
// edges of the double range, in contiguous vectors and matrices and in strided blocks.
TEST(Mechanism, AllFiniteAgreesWithEigenAtTheEdges) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const double values[] = {0.0, -0.0, 1.0, -1.0, std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::min(), std::numeric_limits<double>::denorm_min(),
                           -std::numeric_limits<double>::denorm_min(), 1e308, inf, -inf, nan, -nan};
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(values)) - 1);
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::MatrixXd m(5, 7);
    for (Eigen::Index k = 0; k < m.size(); ++k) m.data()[k] = trial % 3 == 0 ? values[pick(rng) % 10] : values[pick(rng)];
    EXPECT_EQ(detail::all_finite(m), m.allFinite());
    const Eigen::VectorXd v = m.col(trial % 7);
    EXPECT_EQ(detail::all_finite(v), v.allFinite());
    const Eigen::Ref<const Eigen::VectorXd> r(v);
    EXPECT_EQ(detail::all_finite(r), v.allFinite());
    EXPECT_EQ(detail::all_finite(m.block(1, 2, 3, 4)), m.block(1, 2, 3, 4).allFinite());  // strided
    EXPECT_EQ(detail::all_finite(m.row(trial % 5)), m.row(trial % 5).allFinite());
    const Vec3 f = m.col(0).head<3>();
    EXPECT_EQ(detail::all_finite(f), f.allFinite());
  }
}
