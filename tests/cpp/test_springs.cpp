// Springs of the general model (model.hpp `Spring`, algorithm/springs.hpp): the generalised force
// against finite differences of the spring energy on random trees (fixed joints, prismatic joints,
// gear couplings, pulley ratios, counts, free lengths, preloads), anchor distances against named
// frames placed at the anchors, the springs inside the inverse dynamics and the support wrench,
// the validation messages, and the real-time contract (no allocation).
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "alloc_counter.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/algorithm/springs.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "test_support.hpp"

using namespace mechbal;

namespace {

/// A random tree (as test_mechanism.cpp's) with `springs` random springs between random links
/// (the base included), and with a frame at every anchor ("<spring>_a", "<spring>_b").
MechanismDescription random_tree_with_springs(std::mt19937& rng, const std::string& types, int springs,
                                              bool gear = true) {
  MechanismDescription d;
  std::uniform_real_distribution<double> u(-0.3, 0.3), pos(0.0, 1.0);
  std::vector<std::string> links{d.root_name};
  std::map<std::string, std::string> carrier{{d.root_name, d.root_name}};  // link after folding
  for (std::size_t i = 0; i < types.size(); ++i) {
    Joint j;
    j.name = "j" + std::to_string(i + 1);
    j.type = types[i] == 'P' ? JointType::prismatic : types[i] == 'F' ? JointType::fixed : JointType::revolute;
    j.parent = links[std::uniform_int_distribution<std::size_t>(0, links.size() - 1)(rng)];
    j.placement = test::random_pose(rng);
    j.axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    d.joints.push_back(j);
    carrier[j.name] = j.type == JointType::fixed ? carrier[j.parent] : j.name;
    const RigidBody rb = test::random_body(rng);
    d.bodies.push_back(Body{j.name + "_b", "link", j.name, rb.mass, Vec3(u(rng), u(rng), u(rng)), rb.inertia_body});
    links.push_back(j.name);
  }
  if (gear) test::gear_last_joint(d);
  std::uniform_int_distribution<std::size_t> pick(0, links.size() - 1);
  for (int s = 0; s < springs; ++s) {
    Spring sp;
    sp.name = "s" + std::to_string(s);
    sp.link_a = links[pick(rng)];
    do {
      sp.link_b = links[pick(rng)];
    } while (carrier[sp.link_b] == carrier[sp.link_a]);
    sp.anchor_a = Vec3(u(rng), u(rng), u(rng));
    sp.anchor_b = Vec3(u(rng), u(rng), u(rng));
    sp.rate = 100.0 + 900.0 * pos(rng);
    sp.free_length = s % 2 ? 0.0 : 0.2 * pos(rng);  // zero-free-length and real springs
    sp.preload = s % 2 ? 0.0 : 10.0 * pos(rng);
    sp.count = 1 + s % 3;
    sp.pulley_ratio = s % 3 == 2 ? 2.0 : 1.0 + pos(rng);
    d.springs.push_back(sp);
    Eigen::Isometry3d Ta = Eigen::Isometry3d::Identity(), Tb = Eigen::Isometry3d::Identity();
    Ta.translation() = sp.anchor_a;
    Tb.translation() = sp.anchor_b;
    d.frames.push_back(Frame{sp.name + "_a", sp.link_a, Ta});
    d.frames.push_back(Frame{sp.name + "_b", sp.link_b, Tb});
  }
  return d;
}

using test::rel;

/// Central differences (h = 1e-6) of a scalar function of q.
template <typename F>
Eigen::VectorXd gradient(const Eigen::VectorXd& q, F&& f) {
  Eigen::VectorXd g(q.size());
  const double h = 1e-6;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp(i) += h;
    qm(i) -= h;
    g(i) = (f(qp) - f(qm)) / (2 * h);
  }
  return g;
}

}  // namespace

TEST(Springs, TorqueIsTheGradientOfTheEnergy) {
  std::mt19937 rng(71);
  for (const char* types : {"RRR", "RPFRR", "RFRPRR", "PRRFRRR"}) {
    for (int trial = 0; trial < 4; ++trial) {
      const MechanismModel model(random_tree_with_springs(rng, types, 5));
      MechanismData data(model);
      const int n = model.dof();
      const Eigen::VectorXd q = test::random_vector(rng, n, 1.5);
      ASSERT_EQ(spring_torque(model, data, q), Status::ok);
      const Eigen::VectorXd K = data.spring_torque;
      ASSERT_GT(K.cwiseAbs().maxCoeff(), 1e-3);  // the springs do something here
      const Eigen::VectorXd fd = gradient(q, [&](const Eigen::VectorXd& x) {
        EXPECT_EQ(spring_state(model, data, x), Status::ok);
        return data.spring_energy;
      });
      EXPECT_LT(rel(K, fd), 1e-7) << types << "\nK  = " << K.transpose() << "\nfd = " << fd.transpose();
      // the tension is dV/dd: the energy of one spring against its length and tension
      ASSERT_EQ(spring_state(model, data, q), Status::ok);
      for (int s = 0; s < model.num_springs(); ++s) {
        const Spring& sp = model.spring(s);
        const double keq = sp.count * sp.rate / (sp.pulley_ratio * sp.pulley_ratio);
        const double x = data.spring_length(s) - sp.free_length;
        EXPECT_NEAR(data.spring_tension(s), sp.count * sp.preload / sp.pulley_ratio + keq * x, 1e-9);
      }
    }
  }
}

TEST(Springs, LengthsAreTheDistancesBetweenFramesAtTheAnchors) {
  std::mt19937 rng(72);
  const MechanismModel model(random_tree_with_springs(rng, "RFRPFRR", 6));
  MechanismData data(model);
  const Eigen::VectorXd q = test::random_vector(rng, model.dof(), 1.5);
  ASSERT_EQ(forward_kinematics(model, data, q), Status::ok);
  ASSERT_EQ(spring_state(model, data, q), Status::ok);
  for (int s = 0; s < model.num_springs(); ++s) {
    const std::string& name = model.spring(s).name;
    const Vec3 pa = data.frame_placements[static_cast<std::size_t>(model.frame_index(name + "_a"))].translation();
    const Vec3 pb = data.frame_placements[static_cast<std::size_t>(model.frame_index(name + "_b"))].translation();
    EXPECT_NEAR(data.spring_length(s), (pb - pa).norm(), 1e-12) << name;
  }
}

TEST(Springs, InverseDynamicsStaticTorqueAndSupportIncludeTheSprings) {
  std::mt19937 rng(73);
  MechanismDescription d = random_tree_with_springs(rng, "RRPFRR", 4, false);
  const MechanismModel with(d);
  d.springs.clear();
  const MechanismModel without(d);
  MechanismData dw(with), dn(without);
  const int n = with.dof();
  const Eigen::VectorXd q = test::random_vector(rng, n, 1.5), v = test::random_vector(rng, n, 1.0),
                        a = test::random_vector(rng, n, 1.0);
  ASSERT_EQ(spring_torque(with, dw, q), Status::ok);
  const Eigen::VectorXd K = dw.spring_torque;
  ASSERT_EQ(inverse_dynamics(with, dw, q, v, a), Status::ok);
  ASSERT_EQ(inverse_dynamics(without, dn, q, v, a), Status::ok);
  EXPECT_LT(rel(dw.joint_torque, dn.joint_torque + K), 1e-12);
  const Eigen::VectorXd tau = dw.joint_torque;
  ASSERT_EQ(bias_torque(with, dw, q, v), Status::ok);
  ASSERT_EQ(inverse_dynamics(with, dw, q, v, Eigen::VectorXd::Zero(n)), Status::ok);
  EXPECT_LT(rel(dw.bias_torque, dw.joint_torque), 1e-12);
  ASSERT_EQ(static_torque(with, dw, q), Status::ok);
  ASSERT_EQ(gravity_torque(without, dn, q), Status::ok);
  EXPECT_LT(rel(dw.gravity_torque, dn.gravity_torque), 1e-12);  // gravity_torque stays gravity alone
  EXPECT_LT(rel(dw.static_torque, dn.gravity_torque + K), 1e-12);
  // static torque = dV/dq with V gravity plus springs
  const Eigen::VectorXd fd = gradient(q, [&](const Eigen::VectorXd& x) {
    EXPECT_EQ(potential_energy(with, dw, x), Status::ok);
    return dw.potential_energy;
  });
  ASSERT_EQ(static_torque(with, dw, q), Status::ok);
  EXPECT_LT(rel(dw.static_torque, fd), 1e-7);
  // the wrench the base exerts on the moving links (joints and springs anchored to it) is the
  // rate of momentum minus the weight (momentum theorem; no body on the base here)
  MechanismDynamics dyn(with);
  Eigen::VectorXd tau_dyn(n);
  Vec3 F, M;
  ASSERT_EQ(dyn.inverse_dynamics(q, v, a, tau_dyn, &F, &M), Status::ok);
  EXPECT_LT(rel(tau_dyn, tau), 1e-12);
  ASSERT_EQ(base_reaction(with, dw, q, v, a), Status::ok);
  EXPECT_LT(rel(F, dw.base_reaction.force), 1e-10);
  EXPECT_LT(rel(M, dw.base_reaction.moment), 1e-10);
  // forward dynamics inverts the inverse dynamics, springs included
  Eigen::VectorXd acc(n), s(n), g(n), c(n), b(n);
  ASSERT_EQ(dyn.forward_dynamics(q, v, tau, acc), Status::ok);
  EXPECT_LT(rel(acc, a), 1e-9);
  ASSERT_EQ(dyn.static_torque(q, s), Status::ok);
  ASSERT_EQ(dyn.gravity(q, g), Status::ok);
  ASSERT_EQ(dyn.coriolis(q, v, c), Status::ok);
  ASSERT_EQ(dyn.bias(q, v, b), Status::ok);
  EXPECT_LT(rel(s, g + K), 1e-12);
  EXPECT_LT(rel(b, c + s), 1e-12);
}

TEST(Springs, AlgorithmsAllocateNothing) {
  std::mt19937 rng(74);
  const MechanismModel model(random_tree_with_springs(rng, "RRPFRRRF", 6));
  MechanismData data(model);
  MechanismDynamics dyn(model);
  const int n = model.dof();
  const Eigen::VectorXd q = test::random_vector(rng, n, 2.0), v = test::random_vector(rng, n, 1.0),
                        a = test::random_vector(rng, n, 1.0);
  Eigen::VectorXd tau(n), acc(n);
  dyn.inverse_dynamics(q, v, a, tau);  // warm up
  test::AllocationScope scope;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(spring_state(model, data, q), Status::ok);
    EXPECT_EQ(spring_torque(model, data, q), Status::ok);
    EXPECT_EQ(static_torque(model, data, q), Status::ok);
    EXPECT_EQ(potential_energy(model, data, q), Status::ok);
    EXPECT_EQ(inverse_dynamics(model, data, q, v, a), Status::ok);
    EXPECT_EQ(bias_torque(model, data, q, v), Status::ok);
    EXPECT_EQ(dyn.inverse_dynamics(q, v, a, tau), Status::ok);
    EXPECT_EQ(dyn.forward_dynamics(q, v, tau, acc), Status::ok);
    EXPECT_EQ(dyn.static_torque(q, acc), Status::ok);
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(Springs, BadInputGivesAStatusAndWritesNothing) {
  std::mt19937 rng(75);
  const MechanismModel model(random_tree_with_springs(rng, "RRR", 2));
  MechanismData data(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(model.dof(), 0.1);
  Eigen::VectorXd nan = q;
  nan(0) = std::numeric_limits<double>::quiet_NaN();
  ASSERT_EQ(spring_torque(model, data, q), Status::ok);
  const Eigen::VectorXd before = data.spring_torque, lengths = data.spring_length;
  EXPECT_EQ(spring_torque(model, data, nan), Status::non_finite_input);
  EXPECT_EQ(spring_state(model, data, Eigen::VectorXd::Zero(1)), Status::bad_size);
  EXPECT_EQ(data.spring_torque, before);
  EXPECT_EQ(data.spring_length, lengths);
  // a data built for the same tree without springs does not fit
  MechanismDescription d = model.description();
  d.springs.clear();
  MechanismData other(MechanismModel{d});
  EXPECT_EQ(spring_torque(model, other, q), Status::bad_size);
}

TEST(Springs, ConstructionErrorsNameTheField) {
  MechanismDescription d;
  Joint a;
  a.name = "shoulder";
  a.parent = "base";
  Joint tool;
  tool.name = "tool";
  tool.type = JointType::fixed;
  tool.parent = "shoulder";
  d.joints = {a, tool};
  Spring s;
  s.name = "lift";
  s.link_a = "base";
  s.link_b = "sholder";
  s.rate = 100.0;
  d.springs = {s};
  auto message = [&]() -> std::string {
    try {
      MechanismModel m(d);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(message(), "springs[0] (lift).link_b: no link named 'sholder' (did you mean 'shoulder'?)");
  d.springs[0].link_b = "shoulder";
  d.springs[0].rate = -5.0;
  EXPECT_EQ(message(), "springs[0] (lift).rate: must be >= 0 [N/m], got -5");
  d.springs[0].rate = 5.0;
  d.springs[0].pulley_ratio = 0.0;
  EXPECT_EQ(message(), "springs[0] (lift).pulley_ratio: must be > 0, got 0");
  d.springs[0].pulley_ratio = 1.0;
  d.springs[0].count = 0;
  EXPECT_EQ(message(), "springs[0] (lift).count: must be >= 1, got 0");
  d.springs[0].count = 1;
  d.springs[0].link_a = "tool";  // welded to the shoulder: the same link once folded
  EXPECT_NE(message().find("springs[0] (lift).link_b: both anchors are on the same link ('shoulder'"), std::string::npos);
  d.springs[0].link_a = "base";
  d.springs.push_back(d.springs[0]);
  EXPECT_EQ(message(), "springs[1] (lift).name is used by two springs");
  d.springs.pop_back();
  EXPECT_EQ(message(), "accepted");
}
