// The C++ case-format reader (io/case.hpp) and make_controller (control/factory.hpp): the three
// joint forms (origin, mdh, dh) of a planar 2R arm against its closed-form mass matrix and gravity
// torque, the built-in closed cases, the errors naming the field, [control] and the controllers.
// Parity with the Python reader is tested in tests/python/test_io_parity.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

#include "alloc_counter.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/control/factory.hpp"
#include "mechbal/io/case.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/control/reactionless.hpp"

using namespace mechbal;

namespace {

constexpr double l1 = 0.7, l2 = 0.45, m1 = 2.5, m2 = 1.25, g0 = 9.81;

/// A vertical planar 2R arm (joints about z, gravity along -y) with point masses at the link
/// ends, in one of the three joint forms.
std::string arm(const std::string& form) {
  std::string s = "[mechanism]\ngravity = [0.0, -9.81, 0.0]\n";
  if (form == "origin") {
    s += "[[mechanism.joints]]\nname = \"a\"\nlink = {mass = 2.5, com = [0.7, 0.0, 0.0], inertia = [0, 0, 0]}\n";
    s += "[[mechanism.joints]]\nname = \"b\"\norigin = {xyz = [0.7, 0, 0]}\n"
         "link = {mass = 1.25, com = [0.45, 0.0, 0.0], inertia = [0, 0, 0]}\n";
  } else if (form == "mdh") {
    s += "[[mechanism.joints]]\nname = \"a\"\nmdh = {a = 0.0, alpha = 0.0}\n"
         "link = {mass = 2.5, com = [0.7, 0.0, 0.0], inertia = [0, 0, 0]}\n";
    s += "[[mechanism.joints]]\nname = \"b\"\nmdh = {a = 0.7, alpha = 0.0}\n"
         "link = {mass = 1.25, com = [0.45, 0.0, 0.0], inertia = [0, 0, 0]}\n";
  } else {  // standard DH: the link frame is at the link's far end
    s += "[[mechanism.joints]]\nname = \"a\"\ndh = {a = 0.7, alpha = 0.0}\n"
         "link = {mass = 2.5, com = [0.0, 0.0, 0.0], inertia = [0, 0, 0]}\n";
    s += "[[mechanism.joints]]\nname = \"b\"\ndh = {a = 0.45, alpha = 0.0}\n"
         "link = {mass = 1.25, com = [0.0, 0.0, 0.0], inertia = [0, 0, 0]}\n";
  }
  return s;
}

std::string field_of(const std::string& toml) {
  try {
    mechanism_from_string(toml);
  } catch (const ConfigError& e) {
    return e.field();
  }
  return "(accepted)";
}

std::string message_of(const std::string& toml) {
  try {
    case_from_string(toml);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

const std::string cases_dir = MECHBAL_SOURCE_DIR "/python/mechbal/cases/";
const std::string papers_dir = MECHBAL_SOURCE_DIR "/python/mechbal/papers/";
// a paper's case file read by the general reader: absent when the paper's folder is deleted
bool paper_case_exists(const std::string& rel) { return std::ifstream(papers_dir + rel).good(); }

}  // namespace

TEST(CaseReader, ThreeJointFormsGiveTheClosedFormArm) {
  for (const char* form : {"origin", "mdh", "dh"}) {
    SCOPED_TRACE(form);
    const MechanismModel model = mechanism_from_string(arm(form));
    ASSERT_EQ(model.dof(), 2);
    MechanismData data(model);
    for (double q1 : {-1.1, 0.3, 2.0}) {
      for (double q2 : {-2.5, 0.0, 0.8}) {
        const Eigen::Vector2d q(q1, q2);
        ASSERT_EQ(mass_matrix(model, data, q), Status::ok);
        const double c2 = std::cos(q2);
        Eigen::Matrix2d M;
        M(0, 0) = m1 * l1 * l1 + m2 * (l1 * l1 + l2 * l2 + 2 * l1 * l2 * c2);
        M(0, 1) = M(1, 0) = m2 * (l2 * l2 + l1 * l2 * c2);
        M(1, 1) = m2 * l2 * l2;
        EXPECT_LT((data.mass_matrix - M).cwiseAbs().maxCoeff(), 1e-12);
        ASSERT_EQ(gravity_torque(model, data, q), Status::ok);
        const Eigen::VectorXd& gq = data.gravity_torque;
        const Eigen::Vector2d g((m1 + m2) * g0 * l1 * std::cos(q1) + m2 * g0 * l2 * std::cos(q1 + q2),
                                m2 * g0 * l2 * std::cos(q1 + q2));
        EXPECT_LT((gq - g).cwiseAbs().maxCoeff(), 1e-12);
      }
    }
  }
}

TEST(CaseReader, BuiltInClosedCases) {
  const MechanismModel fb = load_mechanism(cases_dir + "four-bar.toml");
  EXPECT_TRUE(fb.is_closed());
  EXPECT_EQ(fb.num_actuated(), 1);
  if (!paper_case_exists("paminsa/cases/paminsa-linkage.toml")) GTEST_SKIP() << "PAMINSA's folder is deleted";
  const LoadedCase p = load_case(papers_dir + "paminsa/cases/paminsa-linkage.toml");
  EXPECT_EQ(p.name, "paminsa-linkage");
  EXPECT_EQ(p.model.num_bodies(), 38);
  EXPECT_EQ(p.model.num_loops(), 9);
  EXPECT_EQ(p.model.num_actuated(), 6);
  ASSERT_TRUE(p.trajectory.present);
  EXPECT_EQ(p.trajectory.start.size(), 6u);
  EXPECT_EQ(p.trajectory.initial_guess.size(), static_cast<std::size_t>(p.model.dof()));
  EXPECT_EQ(p.control.kind, ControlKind::none);
}

TEST(CaseReader, ErrorsNameTheField) {
  const std::string ok = arm("origin");
  EXPECT_EQ(field_of(ok), "(accepted)");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = ok;
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  EXPECT_EQ(field_of(with("mass = 1.25", "mass = -1.25")), "mechanism.joints[1].link.mass");
  EXPECT_EQ(field_of(with("mass = 1.25", "mass = nan")), "mechanism.joints[1].link.mass");
  EXPECT_EQ(field_of(with("mass = 1.25", "mass = true")), "mechanism.joints[1].link.mass");
  EXPECT_EQ(field_of(with("mass = 1.25, ", "")), "mechanism.joints[1].link.mass");
  EXPECT_EQ(field_of(with("origin =", "orign =")), "mechanism.joints[1].orign");
  EXPECT_EQ(field_of(with("xyz = [0.7, 0, 0]", "xyz = [0.7, 0]")), "mechanism.joints[1].origin.xyz");
  EXPECT_EQ(field_of(with("xyz = [0.7, 0, 0]", "xyz = [0.7, 0, 1e13]")), "mechanism.joints[1].origin.xyz[2]");
  EXPECT_EQ(field_of(with("name = \"b\"", "name = \"b\"\nparent = \"c\"")), "mechanism.joints[1].parent");
  EXPECT_EQ(field_of(with("inertia = [0, 0, 0]}\n[[mechanism.joints]]", "inertia = [1, 1, 3]}\n[[mechanism.joints]]")),
            "mechanism.joints[0].link.inertia");
  EXPECT_EQ(field_of("[case]\nname = \"x\"\n"), "mechanism");
  EXPECT_EQ(field_of("[mechanism\n"), "string");  // not TOML: the source is named
  const std::string msg = message_of(with("mass = 1.25", "mass = -1.25"));
  EXPECT_NE(msg.find("mechanism.joints[1].link.mass: must be >= 0 (got -1.25)"), std::string::npos) << msg;
  EXPECT_NE(message_of(with("origin =", "orgin =")).find("did you mean"), std::string::npos);
}

TEST(CaseReader, ControlTable) {
  const std::string base = arm("origin");
  const LoadedCase c = case_from_string(base + "[control]\nkind = \"computed_torque\"\nkp = [100, 100]\nkd = [20, 20]\n");
  EXPECT_EQ(c.control.kind, ControlKind::computed_torque);
  EXPECT_EQ(c.control.rate_hz, 1000.0);
  EXPECT_NE(message_of(base + "[control]\nkind = \"computed_torque\"\nkp = [100]\nkd = [20, 20]\n").find("control.kp: must have 2 values"),
            std::string::npos);
  EXPECT_NE(message_of(base + "[control]\nkind = \"computed_torque\"\nkp = [1, 1]\nkd = [2, 2]\nk = [1, 1]\n")
                .find("control.k: is only for kind = 'decoupled'"),
            std::string::npos);
  EXPECT_NE(message_of(base + "[control]\nkind = \"computed\"\n").find("control.kind: must be one of"), std::string::npos);
  EXPECT_NE(message_of(base + "[control]\nkind = \"decoupled\"\nkp = [1, 1]\nkd = [0, 1]\n").find("control.kd[0]: must be > 0"),
            std::string::npos);
  const LoadedCase r = case_from_string(base + "[control]\nkind = \"reactionless\"\nbalancing_joints = [\"b\"]\n"
                                               "cancel = [\"moment_z\"]\nintegrator = \"euler\"\n");
  EXPECT_EQ(r.control.balancing_joints, std::vector<std::string>{"b"});
  EXPECT_EQ(r.control.cancel, std::vector<std::string>{"moment_z"});
  EXPECT_EQ(r.control.integrator, "euler");
  EXPECT_NE(message_of(base + "[control]\nkind = \"reactionless\"\nbalancing_joints = [\"c\"]\n").find("control.balancing_joints[0]"),
            std::string::npos);
  // every field of the reactionless table, and the defaults of the Python reader's schema.Control
  EXPECT_EQ(r.control.damping, 1e-2);
  EXPECT_TRUE(std::isinf(r.control.max_rate));  // no hidden limit: none unless declared
  EXPECT_TRUE(std::isinf(r.control.max_speed));
  EXPECT_EQ(r.control.tolerance.residual, 1e-6);
  EXPECT_EQ(r.control.tolerance.joint, 1e-2);
  EXPECT_EQ(r.control.home_gain, 0.0);
  EXPECT_TRUE(r.control.kp.empty() && r.control.task_frame.empty());
  const LoadedCase full = case_from_string(
      base + "[[mechanism.frames]]\nname = \"tip\"\nlink = \"b\"\n[control]\nkind = \"reactionless\"\n"
             "balancing_joints = [\"a\"]\ncancel = [\"both\", \"moment_x\"]\nintegrator = \"rk4\"\nrate_hz = 500\n"
             "damping = 0.25\nmax_rate = 7\nhome_gain = 0.5\nlimit_gain = 2\ntask_frame = \"tip\"\nkp = [1, 2]\n"
             "kd = [3, 4]\ntorque_limit = [5, 6]\nmax_speed = 9\ntolerance = { residual = 1e-3, joint = 0.5 }\n");
  EXPECT_EQ(full.control.max_speed, 9.0);
  EXPECT_EQ(full.control.tolerance.residual, 1e-3);
  EXPECT_EQ(full.control.tolerance.joint, 0.5);
  EXPECT_EQ(full.control.tolerance.floor, 1e-9);
  EXPECT_EQ(full.control.cancel, (std::vector<std::string>{"both", "moment_x"}));
  EXPECT_EQ(full.control.rate_hz, 500.0);
  EXPECT_EQ(full.control.damping, 0.25);
  EXPECT_EQ(full.control.max_rate, 7.0);
  EXPECT_EQ(full.control.home_gain, 0.5);
  EXPECT_EQ(full.control.limit_gain, 2.0);
  EXPECT_EQ(full.control.task_frame, "tip");
  EXPECT_EQ(full.control.kp, (std::vector<double>{1, 2}));
  EXPECT_EQ(full.control.torque_limit, (std::vector<double>{5, 6}));
  const std::string rl = base + "[control]\nkind = \"reactionless\"\nbalancing_joints = [\"b\"]\n";
  const std::pair<std::string, std::string> refused[] = {
      {"damping = 1", "control.damping: must be < 1 (got 1)"},
      {"damping = 0", "control.damping: must be > 0 (got 0)"},
      {"max_rate = -1.0", "control.max_rate: must be > 0 (got -1.0)"},
      {"max_speed = 0", "control.max_speed: must be > 0 (got 0)"},
      {"tolerance = { residual = 0 }", "control.tolerance.residual: must be > 0 (got 0)"},
      {"tolerance = { resid = 1 }", "control.tolerance.resid"},
      {"home_gain = nan", "control.home_gain: must be finite"},
      {"limit_gain = \"1\"", "control.limit_gain: must be a number"},
      {"cancel = []", "control.cancel: must have at least 1 values"},
      {"cancel = [\"torque\"]", "control.cancel[0]: must be one of"},
      {"integrator = \"rk45\"", "control.integrator: must be one of euler, rk4 (did you mean 'rk4'?)"},
      {"task_frame = \"tool\"", "control.task_frame: is not a frame of the mechanism"},
      {"kp = [1, 1]", "control.kd: is required with kp"},
      {"kd = [1, 1]", "control.kp: is required with kd"},
      {"kp = [1]\nkd = [1]", "control.kp: must have 2 values"},
      {"k = [1, 1]", "control.k: is only for kind = 'decoupled'"},
      {"rate = 1000", "control.rate: unknown key (did you mean 'rate_hz'?)"},
  };
  for (const auto& [line, expected] : refused) {
    EXPECT_EQ(message_of(rl + line + "\n").rfind(expected, 0), 0u) << line << ": " << message_of(rl + line + "\n");
  }
  EXPECT_EQ(message_of(base + "[control]\nkind = \"reactionless\"\n").rfind("control.balancing_joints: is required", 0), 0u);
  EXPECT_EQ(message_of(base + "[control]\nkind = \"reactionless\"\nbalancing_joints = [\"b\", \"b\"]\n")
                .rfind("control.balancing_joints[1]: is listed twice", 0),
            0u);
  EXPECT_EQ(message_of(base + "[control]\nkind = \"computed_torque\"\nkp = [1, 1]\nkd = [1, 1]\ndamping = 0.1\n")
                .rfind("control.damping: is only for kind = 'reactionless'", 0),
            0u);
  // make_controller builds a joint controller: the reactionless one needs its computed-torque stage
  try {
    make_controller(r.model, r.control);
    ADD_FAILURE() << "reactionless built without kp, kd";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("control.kp: is required to build a joint controller", 0), 0u) << e.what();
  }
  EXPECT_THROW(make_controller(full.model, full.control), std::invalid_argument);  // task_frame: make_task_controller
  EXPECT_NE(make_reactionless_controller(r.model, r.control), nullptr);
  EXPECT_THROW(make_task_controller(r.model, r.control), std::invalid_argument);
}

TEST(MakeController, ComputedTorqueIsTheInverseDynamicsOnTrack) {
  const LoadedCase c = case_from_string(arm("mdh") + "[control]\nkind = \"computed_torque\"\nkp = [100, 100]\nkd = [20, 20]\n");
  auto controller = make_controller(c.model, c.control);
  ASSERT_EQ(controller->dof(), 2);
  const Eigen::Vector2d q(0.3, -0.7), qd(0.5, -0.2), qdd(1.0, 2.0);
  Eigen::Vector2d tau;
  ASSERT_EQ(controller->step(q, qd, q, qd, qdd, tau), Status::ok);
  MechanismData data(c.model);
  ASSERT_EQ(inverse_dynamics(c.model, data, q, qd, qdd), Status::ok);
  EXPECT_LT((tau - data.joint_torque).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(MakeController, DecoupledTakesTheBalancedDiagonal) {
  // a rotor about the vertical: M = Izz, constant, and no gravity torque
  const std::string rotor =
      "[mechanism]\n[[mechanism.joints]]\nname = \"r\"\nlink = {mass = 3.0, inertia = [0.2, 0.2, 0.35]}\n"
      "[control]\nkind = \"decoupled\"\nkp = [50]\nkd = [10]\n";
  const LoadedCase c = case_from_string(rotor);
  auto controller = make_controller(c.model, c.control);
  Eigen::VectorXd q(1), qd(1), qdd(1), tau(1);
  q << 0.1;
  qd << 0.0;
  qdd << 2.0;
  ASSERT_EQ(controller->step(q, qd, q, qd, qdd, tau), Status::ok);
  EXPECT_NEAR(tau[0], 0.35 * 2.0, 1e-12);
  // the 2R arm's mass matrix is not diagonal: decoupled needs k then
  const LoadedCase a = case_from_string(arm("origin") + "[control]\nkind = \"decoupled\"\nkp = [1, 1]\nkd = [1, 1]\n");
  EXPECT_THROW(make_controller(a.model, a.control), std::invalid_argument);
}

TEST(MakeController, MadeControllersStepWithoutAllocating) {
  // the closed PAMINSA under computed torque (loops solved every tick) and a decoupled rotor
  if (!paper_case_exists("paminsa/cases/paminsa-linkage.toml")) GTEST_SKIP() << "PAMINSA's folder is deleted";
  const LoadedCase p = load_case(papers_dir + "paminsa/cases/paminsa-linkage.toml");
  ControlConfig config;
  config.kind = ControlKind::computed_torque;
  config.kp.assign(6, 400.0);
  config.kd.assign(6, 40.0);
  const Eigen::VectorXd guess = Eigen::Map<const Eigen::VectorXd>(p.trajectory.initial_guess.data(), p.model.dof());
  auto ct = make_controller(p.model, config, guess);
  const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(p.trajectory.start.data(), 6);
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(6);
  Eigen::VectorXd tau(6), bad = q;
  bad[0] = std::nan("");
  ASSERT_EQ(ct->step(q, z, q, z, z, tau), Status::ok);  // first tick: assembles from the guess
  // the case's motion, sampled before counting
  const RestToRestTrajectory motion(q, Eigen::Map<const Eigen::VectorXd>(p.trajectory.end.data(), 6),
                                    p.trajectory.duration, p.trajectory.law);
  Eigen::MatrixXd Q(6, 50), V(6, 50), A(6, 50);
  for (int k = 0; k < 50; ++k) {
    Eigen::VectorXd qk(6), vk(6), ak(6);
    motion.evaluate(p.trajectory.duration * k / 49.0, qk, vk, ak);
    Q.col(k) = qk, V.col(k) = vk, A.col(k) = ak;
  }
  int ok = 0;
  {
    test::AllocationScope scope;
    for (int k = 0; k < 50; ++k) {
      ok += ct->step(Q.col(k), V.col(k), Q.col(k), V.col(k), A.col(k), tau) == Status::ok;
      ct->step(bad, z, q, z, z, tau);  // held output, status
    }
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_EQ(ok, 50);
  EXPECT_TRUE(tau.allFinite());
}

namespace {

/// The reaction-wheel arm's case file with its [control] table, plus the computed-torque stage.
LoadedCase wheel_arm_with_gains() {
  std::string text;
  {
    std::ifstream in(cases_dir + "reaction-wheel-arm.toml");
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  return case_from_string(text + "kp = [400.0, 400.0, 400.0]\nkd = [40.0, 40.0, 40.0]\n"
                                 "torque_limit = [50.0, 50.0, 50.0]\n");
}

}  // namespace

TEST(MakeController, ReactionlessTicksAsOneBuiltDirectly) {
  const LoadedCase c = wheel_arm_with_gains();
  ASSERT_EQ(c.control.kind, ControlKind::reactionless);
  const Eigen::VectorXd q0 = Eigen::Map<const Eigen::VectorXd>(c.trajectory.start.data(), 3);
  auto made = make_controller(c.model, c.control, Eigen::VectorXd(), q0);
  ASSERT_EQ(made->dof(), 3);
  // the same controller written out by hand
  ReactionlessConfig config;
  config.balancing_joints = {"wheel"};
  config.cancel = moment_z;
  config.integrator = ReactionlessIntegrator::rk4;
  config.rate_hz = 1000.0;
  config.damping = 1e-3;
  const Eigen::VectorXd kp = Eigen::VectorXd::Constant(3, 400.0), kd = Eigen::VectorXd::Constant(3, 40.0);
  ReactionlessJointController direct(std::make_shared<const MechanismModel>(c.model), config, q0, kp, kd,
                                     Eigen::VectorXd::Constant(3, 50.0));
  // and the motion command alone
  auto made_motion = make_reactionless_controller(c.model, c.control, q0);
  ReactionlessController direct_motion(c.model, config, q0);

  Eigen::VectorXd end = Eigen::Map<const Eigen::VectorXd>(c.trajectory.end.data(), 3);
  end[2] = q0[2];  // a balancing joint's end is ignored
  const RestToRestTrajectory motion(q0, end, c.trajectory.duration, c.trajectory.law);
  const int ticks = 2000;
  Eigen::MatrixXd Q(3, ticks), V(3, ticks), A(3, ticks);
  for (int k = 0; k < ticks; ++k) {
    Eigen::VectorXd qk(3), vk(3), ak(3);
    motion.evaluate(k * 1e-3, qk, vk, ak);
    Q.col(k) = qk, V.col(k) = vk, A.col(k) = ak;
  }
  const Eigen::VectorXd q_meas_offset = Eigen::Vector3d(1e-4, -2e-4, 3e-4);
  Eigen::VectorXd tau_made(3), tau_direct(3);
  double worst_tau = 0.0, worst_motion = 0.0, peak_moment_z = 0.0, peak_moment_z_held = 0.0;
  std::size_t allocations = 0;
  int ok = 0;
  MechanismData data(c.model);
  const auto& made_command = static_cast<const ReactionlessJointController&>(*made).reactionless().command();
  Eigen::VectorXd q = Q.col(0), v = V.col(0);
  for (int k = 0; k < ticks; ++k) {
    // the measured state: the last command tracked with a small error (the wheel moves as commanded)
    if (k > 0) q = made_command.q + q_meas_offset, v = made_command.v;
    Status s1, s2, s3, s4;
    {
      test::AllocationScope scope;
      s1 = made->step(q, v, Q.col(k), V.col(k), A.col(k), tau_made);
      s3 = made_motion->step_euler(Q.col(k).head(2), V.col(k).head(2), A.col(k).head(2));
      allocations += scope.count();
    }
    s2 = direct.step(q, v, Q.col(k), V.col(k), A.col(k), tau_direct);
    s4 = direct_motion.step_euler(Q.col(k).head(2), V.col(k).head(2), A.col(k).head(2));
    EXPECT_EQ(s1, s2);
    EXPECT_EQ(s3, s4);
    ok += s1 == Status::ok && s3 == Status::ok;
    worst_tau = std::max(worst_tau, (tau_made - tau_direct).cwiseAbs().maxCoeff());
    const ReactionlessCommand& a = made_motion->command();
    const ReactionlessCommand& b = direct_motion.command();
    worst_motion = std::max({worst_motion, (a.q - b.q).cwiseAbs().maxCoeff(), (a.v - b.v).cwiseAbs().maxCoeff(),
                             (a.a - b.a).cwiseAbs().maxCoeff(), (a.shaking_moment - b.shaking_moment).cwiseAbs().maxCoeff()});
    // the reactionless command cancels the shaking moment about z; the arm with the wheel held does not
    peak_moment_z = std::max(peak_moment_z, std::abs(made_command.shaking_moment.z()));
    ASSERT_EQ(shaking_wrench(c.model, data, Q.col(k), V.col(k), A.col(k)), Status::ok);
    peak_moment_z_held = std::max(peak_moment_z_held, std::abs(data.shaking.moment.z()));
  }
  std::printf("factory vs direct over %d ticks: |tau| %.3g, command %.3g; moment_z peak %.3g (held %.3g)\n", ticks,
              worst_tau, worst_motion, peak_moment_z, peak_moment_z_held);
  EXPECT_EQ(ok, ticks);
  EXPECT_LE(worst_tau, 1e-12);
  EXPECT_LE(worst_motion, 1e-12);
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(peak_moment_z_held, 0.1);
  EXPECT_LT(peak_moment_z, 1e-9 * peak_moment_z_held);
}

TEST(MakeController, TaskControllerTicksAsOneBuiltDirectly) {
  // a redundant planar 3R arm following its tip in x, y, minimising the moment about z
  const std::string text =
      "[mechanism]\ngravity = [0.0, 0.0, -9.81]\n"
      "[[mechanism.joints]]\nname = \"j1\"\nlink = {mass = 1.0, com = [0.2, 0, 0], inertia = [0.001, 0.01, 0.01]}\n"
      "[[mechanism.joints]]\nname = \"j2\"\norigin = {xyz = [0.4, 0, 0]}\n"
      "link = {mass = 0.8, com = [0.15, 0, 0], inertia = [0.001, 0.008, 0.008]}\n"
      "[[mechanism.joints]]\nname = \"j3\"\norigin = {xyz = [0.3, 0, 0]}\n"
      "link = {mass = 0.5, com = [0.1, 0, 0], inertia = [0.001, 0.004, 0.004]}\n"
      "[[mechanism.frames]]\nname = \"tip\"\nlink = \"j3\"\norigin = {xyz = [0.2, 0, 0]}\n"
      "[control]\nkind = \"reactionless\"\ncancel = [\"moment_z\"]\n"
      "integrator = \"euler\"\ntask_frame = \"tip\"\n";
  const LoadedCase c = case_from_string(text);
  const Eigen::VectorXd q0 = Eigen::Vector3d(0.3, 0.8, -0.6);
  auto made = make_task_controller(c.model, c.control, q0);
  TaskSpaceConfig config;
  config.frame = "tip";
  config.cancel = moment_z;
  config.integrator = ReactionlessIntegrator::euler;
  ReactionlessTaskController direct(std::make_shared<const MechanismModel>(c.model), config, q0);
  double worst = 0.0;
  std::size_t allocations = 0;
  for (int k = 0; k < 500; ++k) {
    Vec6 twist = Vec6::Zero();
    twist[0] = 0.05 * std::sin(2e-3 * k);
    twist[1] = 0.04 * std::cos(3e-3 * k);
    Status s;
    {
      test::AllocationScope scope;
      s = made->step(twist, twist, twist);
      allocations += scope.count();
    }
    EXPECT_EQ(s, direct.step(twist, twist, twist));
    worst = std::max({worst, (made->q() - direct.q()).cwiseAbs().maxCoeff(),
                      (made->v() - direct.v()).cwiseAbs().maxCoeff()});
  }
  EXPECT_LE(worst, 1e-12);
  EXPECT_EQ(allocations, 0u);
}

TEST(CaseReader, ConstantSpeedTrajectory) {
  const std::string base = arm("origin") + "[case]\nname = \"arm\"\nkind = \"mechanism\"\n";
  const LoadedCase c = case_from_string(base + "[trajectory]\nlaw = \"constant_speed\"\nstart = [0.1, 0.2]\n"
                                               "rpm = 30\nrevolutions = 2\nsamples = 11\n");
  ASSERT_TRUE(c.trajectory.constant_speed);
  ASSERT_EQ(c.trajectory.speed.size(), 2u);
  EXPECT_DOUBLE_EQ(c.trajectory.speed[0], M_PI);  // 30 rpm, one number for both joints
  EXPECT_DOUBLE_EQ(c.trajectory.speed[1], M_PI);
  EXPECT_DOUBLE_EQ(c.trajectory.duration, 4.0);   // two turns at pi rad/s
  const LoadedCase d = case_from_string(base + "[trajectory]\nlaw = \"constant_speed\"\nstart = [0.1, 0.2]\n"
                                               "speed = [1.0, -2.0]\nduration = 0.5\n");
  EXPECT_EQ(d.trajectory.speed, (std::vector<double>{1.0, -2.0}));
  EXPECT_DOUBLE_EQ(d.trajectory.duration, 0.5);
  auto refused = [&](const std::string& table, const std::string& field) {
    const std::string msg = message_of(base + "[trajectory]\n" + table);
    EXPECT_EQ(msg.rfind(field + ": ", 0), 0u) << msg;
  };
  refused("law = \"constant_speed\"\nstart = [0, 0]\nspeed = 1.0\nrpm = 2.0\nduration = 1.0\n", "trajectory.rpm");
  refused("law = \"constant_speed\"\nstart = [0, 0]\nduration = 1.0\n", "trajectory.speed");
  refused("law = \"constant_speed\"\nstart = [0, 0]\nrpm = 60\n", "trajectory.duration");
  refused("law = \"constant_speed\"\nstart = [0, 0]\nrpm = 60\nend = [1, 1]\nduration = 1.0\n", "trajectory.end");
  refused("law = \"constant_speed\"\nstart = [0, 0]\nrpm = 0\nrevolutions = 1\n", "trajectory.revolutions");
  refused("law = \"constant_speed\"\nstart = [0, 0]\nspeed = [1, 2, 3]\nduration = 1.0\n", "trajectory.speed");
  refused("start = [0, 0]\nend = [1, 1]\nduration = 1.0\nrpm = 60\n", "trajectory.rpm");
  refused("start = [0, 0]\nend = [1, 1]\nduration = 1.0\nbranch = \"open\"\n", "trajectory.branch");  // no loop
}

TEST(CaseReader, MinShakingIsRefusedByItsLaw) {
  // a planned motion (Python's mechbal.plan) is not run as another law: refused at trajectory.law,
  // with or without its own keys (which would otherwise read as unknown ones)
  const std::string base = arm("origin") + "[case]\nname = \"arm\"\nkind = \"mechanism\"\n[trajectory]\n";
  for (const std::string extra : {"", "objective = \"force_rms\"\ncontrol_points = 10\n"}) {
    const std::string msg =
        message_of(base + "law = \"min_shaking\"\nstart = [0, 0]\nend = [1, 1]\nduration = 1.0\n" + extra);
    EXPECT_EQ(msg.rfind("trajectory.law: 'min_shaking' is a motion planned by the Python layer", 0), 0u) << msg;
    EXPECT_NE(msg.find("(got 'min_shaking')"), std::string::npos) << msg;
  }
  // the built-in case that plans one
  try {
    load_case(cases_dir + "four-bar-min-shaking.toml");
    ADD_FAILURE() << "four-bar-min-shaking.toml accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "trajectory.law");
  }
}

TEST(CaseReader, PlanarIzzIsALamina) {
  // the 2R arm turns about z: izz alone is accepted and is the lamina diag(izz/2, izz/2, izz)
  const std::string planar = "[mechanism]\n[[mechanism.joints]]\nname = \"a\"\nlink = {mass = 1.0, izz = 0.4}\n"
                             "[[mechanism.joints]]\nname = \"b\"\norigin = {xyz = [0.7, 0, 0]}\naxis = [0, 0, -1]\n"
                             "link = {mass = 1.0, com = [0.2, 0, 0], izz = 0.2}\n";
  const MechanismModel m = mechanism_from_string(planar);
  EXPECT_TRUE(m.description().bodies[0].inertia.isApprox(Eigen::Vector3d(0.2, 0.2, 0.4).asDiagonal().toDenseMatrix()));
  // a joint about x makes it spatial: refused, naming the field
  std::string spatial = planar;
  spatial.replace(spatial.find("axis = [0, 0, -1]"), 17, "axis = [1, 0, 0] ");
  EXPECT_EQ(field_of(spatial), "mechanism.joints[0].link.izz");
  std::string both = planar;
  both.replace(both.find("izz = 0.4"), 9, "izz = 0.4, inertia = [1, 1, 1]");
  EXPECT_EQ(field_of(both), "mechanism.joints[0].link.izz");
}

TEST(MakeController, TaskRowsHaveOneNameTableForEveryCaller) {
  // make_task_controller and the Python ReactionlessTaskController read task_rows through
  // task_rows_mask: the same bits and the same messages, only the field named differs
  EXPECT_EQ(task_rows_mask({"linear", "w_z"}), cancel_force | moment_z);
  EXPECT_EQ(task_rows_mask({"all"}, "task_rows"), cancel_both);
  EXPECT_EQ(task_rows_mask({"v_x", "v_y", "angular"}), force_x | force_y | cancel_moment);
  const auto message = [](const std::vector<std::string>& rows, const std::string& field) {
    try {
      task_rows_mask(rows, field);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({"all", "lineal"}, "control.task_rows"),
            "control.task_rows[1]: 'lineal' is not a twist component (all, linear, angular, v_x, v_y, v_z, w_x, "
            "w_y, w_z)");
  EXPECT_EQ(message({}, "task_rows"), "task_rows: must name at least one twist component");
}

TEST(MakeController, PassiveCommandsZeroWithoutAllocating) {
  const LoadedCase c = case_from_string(arm("origin") + "[control]\nkind = \"passive\"\nrate_hz = 500\n");
  EXPECT_EQ(c.control.kind, ControlKind::passive);
  EXPECT_EQ(std::string(control_kind_name(c.control.kind)), "passive");
  auto passive = make_controller(c.model, c.control);
  ASSERT_EQ(passive->dof(), 2);
  Eigen::Vector2d q(0.3, -0.7), qd(0.5, -0.2), tau(1.0, 1.0), bad(std::nan(""), 0.0);
  {
    test::AllocationScope scope;
    EXPECT_EQ(passive->step(q, qd, q, qd, qd, tau), Status::ok);
    EXPECT_EQ(passive->step(bad, qd, q, qd, qd, tau), Status::non_finite_input);
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_EQ(tau, Eigen::Vector2d::Zero());
  EXPECT_NE(message_of(arm("origin") + "[control]\nkind = \"passive\"\nkp = [1, 1]\n").find("control.kp: is not for kind = 'passive'"),
            std::string::npos);
}

// ---- issue 40: names, bounded work, one verdict for both readers, the task controller's start ----

TEST(Names, TheCharacterSetOfNames) {
  EXPECT_EQ(name_problem("shoulder_lift"), "");
  EXPECT_EQ(name_problem("bras épaule --> x <y> & \"z\""), "");  // printable: the writers escape it
  EXPECT_EQ(name_problem(""), "must not be empty");
  EXPECT_NE(name_problem(std::string("a\x01", 2)).find("U+0001"), std::string::npos);
  EXPECT_NE(name_problem(std::string("a\0b", 3)).find("U+0000"), std::string::npos);
  EXPECT_NE(name_problem("a\x7f").find("U+007F"), std::string::npos);
  EXPECT_NE(name_problem("a\xc2\x85").find("U+0085"), std::string::npos);      // C1 control
  EXPECT_NE(name_problem("a\xef\xbf\xbe").find("U+FFFE"), std::string::npos);  // noncharacter
  EXPECT_NE(name_problem("a\xed\xa0\x80").find("U+D800"), std::string::npos);  // a surrogate
  EXPECT_EQ(name_problem("a\xff"), "is not valid UTF-8");
  EXPECT_EQ(name_problem("a\xc0\xaf"), "is not valid UTF-8");  // overlong '/'
  EXPECT_EQ(name_problem(std::string(256, 'x')), "");
  EXPECT_NE(name_problem(std::string(257, 'x')).find("at most 256"), std::string::npos);
  // the model refuses it whoever builds it (URDF reader, Python constructors): the field named
  MechanismDescription d;
  Joint j;
  j.name = std::string("j\n1");
  j.parent = "base";
  d.joints.push_back(j);
  try {
    MechanismModel m(d);
    ADD_FAILURE() << "a name with a line feed was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("joints[0].name must not contain the character U+000A"), std::string::npos)
        << e.what();
  }
  // and the case reader at the boundary, naming the field
  const std::string bad = "[mechanism]\n[[mechanism.joints]]\nname = \"a\\u0001b\"\nlink = {mass = 1.0, com = [0.1, 0, 0]}\n";
  EXPECT_EQ(field_of(bad), "mechanism.joints[0].name");
}

TEST(CaseReader, TextEntryPointsHaveTheFileSizeLimit) {
  // a document past 4 MiB is refused before it is parsed, as the file API refuses the file
  std::string big = arm("origin") + "# " + std::string(4u * 1024u * 1024u, 'x') + "\n";
  for (int api = 0; api < 2; ++api) {
    try {
      if (api == 0) (void)case_from_string(big, "big.toml");
      else (void)mechanism_from_string(big, "big.toml");
      ADD_FAILURE() << "a document of " << big.size() << " bytes was read";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.field(), "big.toml");
      EXPECT_NE(std::string(e.what()).find("4194304 bytes"), std::string::npos) << e.what();
    }
  }
}

TEST(CaseReader, MisspelledTablesAreErrors) {
  const std::string base = arm("origin") + "[case]\nname = \"arm\"\nkind = \"mechanism\"\n";
  EXPECT_EQ(message_of(base + "[contrl]\nkind = \"passive\"\n"), "contrl: unknown table (did you mean 'control'?)");
  EXPECT_EQ(message_of(base + "[trajectry]\nlaw = \"quintic\"\n"),
            "trajectry: unknown table (did you mean 'trajectory'?)");
  EXPECT_NE(message_of(base + "extra = 1\n").find("extra: unknown key"), std::string::npos);
  EXPECT_EQ(message_of(base + "[control]\nkind = \"passive\"\n"), "(accepted)");
}

TEST(CaseReader, TheTickLimitIsChecked) {
  const std::string base = arm("origin") + "[case]\nname = \"arm\"\nkind = \"mechanism\"\n"
                           "[trajectory]\nlaw = \"quintic\"\nstart = [0.0, 0.0]\nend = [1.0, 1.0]\n";
  EXPECT_EQ(message_of(base + "duration = 2.0\n[control]\nkind = \"passive\"\nrate_hz = 500000.0\n"), "(accepted)");
  EXPECT_EQ(message_of(base + "duration = 2.0\n[control]\nkind = \"passive\"\nrate_hz = 1000000.0\n"),
            "control.rate_hz: duration x rate_hz must be <= 1000000 ticks (a run of 2.0 s) (got 2000000.0)");
  EXPECT_EQ(message_of(base + "duration = 100000.0\n[control]\nkind = \"computed_torque\"\nkp = [1, 1]\nkd = [1, 1]\n"),
            "control.rate_hz: duration x rate_hz must be <= 1000000 ticks (a run of 100000.0 s) (got 100000000.0)");
}

TEST(ReactionlessTask, TheStartIsValidated) {
  const std::string text =
      "[mechanism]\ngravity = [0.0, 0.0, -9.81]\n"
      "[[mechanism.joints]]\nname = \"j1\"\nlimits = {lower = -2.0, upper = 2.0}\n"
      "link = {mass = 1.0, com = [0.2, 0, 0], inertia = [0.001, 0.01, 0.01]}\n"
      "[[mechanism.joints]]\nname = \"j2\"\norigin = {xyz = [0.4, 0, 0]}\n"
      "link = {mass = 0.8, com = [0.15, 0, 0], inertia = [0.001, 0.008, 0.008]}\n"
      "[[mechanism.joints]]\nname = \"j3\"\norigin = {xyz = [0.3, 0, 0]}\n"
      "link = {mass = 0.5, com = [0.1, 0, 0], inertia = [0.001, 0.004, 0.004]}\n"
      "[[mechanism.frames]]\nname = \"tip\"\nlink = \"j3\"\norigin = {xyz = [0.2, 0, 0]}\n";
  const auto model = std::make_shared<const MechanismModel>(mechanism_from_string(text));
  TaskSpaceConfig config;
  config.frame = "tip";
  config.cancel = moment_z;
  config.task_rows = 3u;  // v_x, v_y
  EXPECT_NO_THROW(ReactionlessTaskController(model, config, Eigen::Vector3d(0.3, 0.8, -0.6)));
  // j3 declares no limit: any finite start is within it
  EXPECT_NO_THROW(ReactionlessTaskController(model, config, Eigen::Vector3d(0.3, 0.8, 1e300)));
  for (const Eigen::Vector3d& q0 : {Eigen::Vector3d(2.5, 0.0, 0.0), Eigen::Vector3d(1e300, 0.0, 0.0),
                                    Eigen::Vector3d(-1e300, 0.0, 0.0)}) {
    try {
      ReactionlessTaskController c(model, config, q0);
      ADD_FAILURE() << "the start " << q0.transpose() << " outside j1's limits was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("q0[0] (j1)"), std::string::npos) << e.what();
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ReactionlessTaskController(model, config, Eigen::Vector3d(nan, 0.0, 0.0)), std::invalid_argument);
}
