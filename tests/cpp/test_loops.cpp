// Closed loops on the general model (algorithm/loops.hpp) from C++: a four-bar and a five-bar built
// here, the closure after the position solve, the coupling matrix C and the acceleration bias c
// against finite differences of solved positions, and the real-time contract (no heap allocation
// per tick in the solve, the projection and the projected dynamics).
#include <gtest/gtest.h>

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <random>

#include "../../bench/paminsa_general.hpp"
#include "alloc_counter.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/detail/placed.hpp"
#include "mechbal/detail/tree.hpp"
#include "paminsa_motion.hpp"
#include "test_support.hpp"

using namespace mechbal;

namespace {

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Vec3(x, y, z);
  return T;
}

Body rod(const std::string& name, const std::string& link, double mass, double length) {
  // a slender rod along the link's x, centre of mass at its middle
  return Body{name, "link", link, mass, Vec3(0.5 * length, 0.01, 0.0),
              Mat3(Vec3(1e-4, mass * length * length / 12.0, mass * length * length / 12.0).asDiagonal())};
}

/// Crank (0.2 m) about z at O, coupler (`coupler` m), rocker (0.4 m) about z at (0.45, 0, 0); the
/// coupler and rocker tips closed by a loop of `type`; gravity along -y (the plane of motion); crank
/// actuated.
MechanismModel four_bar(LoopType type, double coupler = 0.5) {
  MechanismDescription d;
  d.gravity = Vec3(0.0, -9.81, 0.0);
  d.joints = {Joint{"crank", JointType::revolute, "base"}, Joint{"coupler", JointType::revolute, "crank", at(0.2, 0, 0)},
              Joint{"rocker", JointType::revolute, "base", at(0.45, 0, 0)}};
  d.bodies = {rod("crank", "crank", 0.8, 0.2), rod("coupler", "coupler", 1.5, coupler), rod("rocker", "rocker", 1.1, 0.4)};
  d.frames = {Frame{"coupler_tip", "coupler", at(coupler, 0, 0)}, Frame{"rocker_tip", "rocker", at(0.4, 0, 0)}};
  d.loops = {LoopConstraint{"tip", type, "coupler_tip", "rocker_tip"}};
  d.actuated = {"crank"};
  return MechanismModel(d);
}

/// Planar 5R: proximal links (0.3 m) at (0, 0) and (0.25, 0), distal links (0.45 m) meeting at a
/// point; both proximal joints actuated.
MechanismModel five_bar() {
  MechanismDescription d;
  d.gravity = Vec3(0.0, -9.81, 0.0);
  d.joints = {Joint{"p1", JointType::revolute, "base"}, Joint{"d1", JointType::revolute, "p1", at(0.3, 0, 0)},
              Joint{"p2", JointType::revolute, "base", at(0.25, 0, 0)},
              Joint{"d2", JointType::revolute, "p2", at(0.3, 0, 0)}};
  d.bodies = {rod("p1", "p1", 1.0, 0.3), rod("d1", "d1", 0.7, 0.45), rod("p2", "p2", 1.0, 0.3),
              rod("d2", "d2", 0.7, 0.45)};
  d.frames = {Frame{"tip1", "d1", at(0.45, 0, 0)}, Frame{"tip2", "d2", at(0.45, 0, 0)}};
  d.loops = {LoopConstraint{"tip", LoopType::point, "tip1", "tip2"}};
  d.actuated = {"p1", "p2"};
  return MechanismModel(d);
}

/// The four-bar (point loop) carrying a two-joint arm on its coupler and a slide on the base, all
/// three actuated and outside the loop: C's columns of these are unit vectors, the projection
/// solves for the crank's column only (MechanismData::loop_actuated_columns).
MechanismModel four_bar_with_arm() {
  MechanismDescription d;
  d.gravity = Vec3(0.0, -9.81, 0.0);
  Eigen::Isometry3d tilted = at(0.25, 0.02, 0);
  tilted.linear() = Eigen::AngleAxisd(0.4, Vec3(1.0, 0.3, 0.0).normalized()).toRotationMatrix();
  Joint slide{"slide", JointType::prismatic, "base", at(0, 0, 0.3)};
  slide.axis = Vec3(0.0, 1.0, 0.0);
  d.joints = {Joint{"crank", JointType::revolute, "base"}, Joint{"coupler", JointType::revolute, "crank", at(0.2, 0, 0)},
              Joint{"wrist", JointType::revolute, "coupler", tilted}, Joint{"tool", JointType::revolute, "wrist", at(0.1, 0, 0)},
              Joint{"rocker", JointType::revolute, "base", at(0.45, 0, 0)}, slide};
  d.bodies = {rod("crank", "crank", 0.8, 0.2), rod("coupler", "coupler", 1.5, 0.5), rod("rocker", "rocker", 1.1, 0.4),
              rod("wrist", "wrist", 0.3, 0.1), rod("tool", "tool", 0.2, 0.15), rod("slide", "slide", 0.5, 0.1)};
  d.frames = {Frame{"coupler_tip", "coupler", at(0.5, 0, 0)}, Frame{"rocker_tip", "rocker", at(0.4, 0, 0)}};
  d.loops = {LoopConstraint{"tip", LoopType::point, "coupler_tip", "rocker_tip"}};
  d.actuated = {"crank", "wrist", "tool", "slide"};
  return MechanismModel(d);
}

/// The planar_point four-bar on an actuated turntable (about x: it tilts the plane of the loop):
/// the turntable is the two tip frames' common ancestor and moves them rigidly together, so the
/// loop's rows do not depend on it (its column of A is zero, C's is a unit vector; the loop's
/// columns stop below it: MechanismData::loop_path_stop).
MechanismModel four_bar_on_turntable(LoopType type = LoopType::planar_point) {
  MechanismDescription d;
  d.gravity = Vec3(0.0, -9.81, 0.0);
  Joint turn{"turn", JointType::revolute, "base", at(0, 0, 0.1)};
  turn.axis = Vec3(1.0, 0.0, 0.0);
  d.joints = {turn, Joint{"crank", JointType::revolute, "turn"}, Joint{"coupler", JointType::revolute, "crank", at(0.2, 0, 0)},
              Joint{"rocker", JointType::revolute, "turn", at(0.45, 0, 0)}};
  d.bodies = {rod("turn", "turn", 2.0, 0.45), rod("crank", "crank", 0.8, 0.2), rod("coupler", "coupler", 1.5, 0.5),
              rod("rocker", "rocker", 1.1, 0.4)};
  d.frames = {Frame{"coupler_tip", "coupler", at(0.5, 0, 0)}, Frame{"rocker_tip", "rocker", at(0.4, 0, 0)}};
  d.loops = {LoopConstraint{"tip", type, "coupler_tip", "rocker_tip"}};
  d.actuated = {"turn", "crank"};
  return MechanismModel(d);
}

/// q near an assembly (the order of the coordinates is the joints', depth first)
Eigen::VectorXd four_bar_guess() { return (Eigen::VectorXd(3) << 1.0, -0.6, 1.75).finished(); }
Eigen::VectorXd five_bar_guess() { return (Eigen::VectorXd(4) << 2.0, -1.2, 1.1, 1.2).finished(); }

/// The solved q at actuated qa, warm-started from `guess`.
Eigen::VectorXd solved(const MechanismModel& model, MechanismData& data, const Eigen::VectorXd& qa,
                       const Eigen::VectorXd& guess) {
  Eigen::VectorXd q = guess;
  const Status s = solve_loop_positions(model, data, qa, q);
  EXPECT_EQ(s, Status::ok);
  return q;
}

/// Central differences (step 1e-6) of the loops' residual at q, one column per coordinate.
Eigen::MatrixXd residual_differences(const MechanismModel& model, MechanismData& data, const Eigen::VectorXd& q) {
  const double h = 1e-6;
  Eigen::MatrixXd out(model.num_constraints(), model.dof());
  for (int k = 0; k < model.dof(); ++k) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(model.dof());
    e(k) = h;
    EXPECT_EQ(loop_constraints(model, data, q + e), Status::ok);
    const Eigen::VectorXd plus = data.loop_residual;
    EXPECT_EQ(loop_constraints(model, data, q - e), Status::ok);
    out.col(k) = (plus - data.loop_residual) / (2 * h);
  }
  return out;
}

struct Case {
  const char* name;
  MechanismModel model;
  Eigen::VectorXd guess, qa;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  for (auto [name, type] : {std::pair{"point", LoopType::point}, {"planar_point", LoopType::planar_point},
                            {"axis", LoopType::axis}}) {
    out.push_back(Case{name, four_bar(type), four_bar_guess(), (Eigen::VectorXd(1) << 1.0).finished()});
  }
  out.push_back(Case{"five_bar", five_bar(), five_bar_guess(), (Eigen::VectorXd(2) << 2.0, 1.1).finished()});
  out.push_back(Case{"four_bar_on_turntable", four_bar_on_turntable(),
                     (Eigen::VectorXd(4) << 0.3, 1.0, -0.6, 1.75).finished(), (Eigen::VectorXd(2) << 0.3, 1.0).finished()});
  {
    MechanismModel model = four_bar_with_arm();
    Eigen::VectorXd guess = Eigen::VectorXd::Zero(model.dof()), qa(model.num_actuated());
    const std::map<std::string, double> near{{"crank", 1.0}, {"coupler", -0.6}, {"rocker", 1.75},
                                             {"wrist", 0.5}, {"tool", -0.8}, {"slide", 0.05}};
    for (int c = 0; c < model.dof(); ++c) guess(c) = near.at(model.coordinate_name(c));
    for (int i = 0; i < model.num_actuated(); ++i) qa(i) = guess(model.actuated_coordinates()[static_cast<std::size_t>(i)]);
    out.push_back(Case{"four_bar_with_arm", std::move(model), guess, qa});
  }
  return out;
}

}  // namespace

TEST(Loops, ClosureHoldsAfterTheSolve) {
  for (const auto& c : cases()) {
    MechanismData data(c.model);
    Eigen::VectorXd q = c.guess;
    for (int k = 0; k < 50; ++k) {  // a motion of the actuators, warm-started tick to tick
      const Eigen::VectorXd qa = c.qa + Eigen::VectorXd::Constant(c.qa.size(), 0.4 * std::sin(0.1 * k));
      ASSERT_EQ(solve_loop_positions(c.model, data, qa, q), Status::ok) << c.name << " tick " << k;
      ASSERT_EQ(loop_constraints(c.model, data, q), Status::ok);
      EXPECT_LT(data.loop_residual.cwiseAbs().maxCoeff(), 1e-12) << c.name;
      EXPECT_LE(data.loop_iterations, 6) << c.name;
      for (int i = 0; i < c.model.num_actuated(); ++i) {
        EXPECT_EQ(q(c.model.actuated_coordinates()[static_cast<std::size_t>(i)]), qa(i));
      }
    }
  }
}

TEST(Loops, JacobianMatchesFiniteDifferences) {
  // A from the loops' path columns (zero above a planar_point loop's common ancestor) against
  // central differences of the residual, near and away from the closure
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData data(model);
    const Eigen::VectorXd q0 = solved(model, data, c.qa, c.guess);
    for (const double away : {0.0, 0.05}) {
      const Eigen::VectorXd q = q0 + Eigen::VectorXd::LinSpaced(model.dof(), away, -away);
      ASSERT_EQ(loop_constraints(model, data, q), Status::ok) << c.name;
      const Eigen::MatrixXd A = data.loop_jacobian;
      const Eigen::MatrixXd fd = residual_differences(model, data, q);
      for (int k = 0; k < model.dof(); ++k) {
        EXPECT_LT((A.col(k) - fd.col(k)).cwiseAbs().maxCoeff(), 1e-8) << c.name << " coordinate " << k << " away " << away;
      }
    }
    if (std::string(c.name) == "four_bar_on_turntable") {
      EXPECT_EQ(data.loop_jacobian.col(0).cwiseAbs().maxCoeff(), 0.0);  // the turntable's
      EXPECT_EQ(data.loop_actuated_columns, std::vector<int>{1});       // the crank only
    }
  }
}

TEST(Loops, CommonAncestorColumnsMatchFiniteDifferences) {
  // point and axis loops walk both frames' paths to the root: the turntable is on both (one entry
  // of MechanismData::loop_path_joints, moving d by z x d and turning both frames alike); its column
  // and the others against central differences, away from the closure (where d != 0)
  for (const LoopType type : {LoopType::point, LoopType::axis}) {
    const MechanismModel model = four_bar_on_turntable(type);
    MechanismData data(model);
    const Eigen::VectorXd guess = (Eigen::VectorXd(4) << 0.3, 1.0, -0.6, 1.75).finished();
    const Eigen::VectorXd q0 = solved(model, data, (Eigen::VectorXd(2) << 0.3, 1.0).finished(), guess);
    int both = 0;
    for (const auto& e : data.loop_path_joints) both += e.sides == 3 ? 1 : 0;
    EXPECT_EQ(both, 1);  // the turntable
    const Eigen::VectorXd q = q0 + Eigen::VectorXd::LinSpaced(model.dof(), 0.07, -0.05);
    ASSERT_EQ(loop_constraints(model, data, q), Status::ok);
    const Eigen::MatrixXd A = data.loop_jacobian;
    EXPECT_GT(A.col(0).cwiseAbs().maxCoeff(), 1e-3);  // d != 0 away from the closure
    const Eigen::MatrixXd fd = residual_differences(model, data, q);
    for (int k = 0; k < model.dof(); ++k) {
      EXPECT_LT((A.col(k) - fd.col(k)).cwiseAbs().maxCoeff(), 1e-8) << static_cast<int>(type) << " coordinate " << k;
    }
  }
}

TEST(Loops, GearedJointsOnOneLoopAddTheirColumns) {
  // a knuckle between the coupler and its tip turns with the rocker (a gear, mimic ratio 0.5): the
  // rocker's coordinate drives a joint on each of the loop's paths, so its column is the sum of
  // both joints' (the first listed sets the column's rows, the second adds to them)
  for (const LoopType type : {LoopType::point, LoopType::axis, LoopType::planar_point}) {
    MechanismDescription d;
    d.gravity = Vec3(0.0, -9.81, 0.0);
    Joint knuckle{"knuckle", JointType::revolute, "coupler", at(0.4, 0, 0)};
    knuckle.mimic_joint = "rocker";
    knuckle.mimic_ratio = 0.5;
    d.joints = {Joint{"crank", JointType::revolute, "base"}, Joint{"coupler", JointType::revolute, "crank", at(0.2, 0, 0)},
                knuckle, Joint{"rocker", JointType::revolute, "base", at(0.45, 0, 0)}};
    d.bodies = {rod("crank", "crank", 0.8, 0.2), rod("coupler", "coupler", 1.5, 0.4), rod("knuckle", "knuckle", 0.3, 0.1),
                rod("rocker", "rocker", 1.1, 0.4)};
    d.frames = {Frame{"coupler_tip", "knuckle", at(0.1, 0, 0)}, Frame{"rocker_tip", "rocker", at(0.4, 0, 0)}};
    d.loops = {LoopConstraint{"tip", type, "coupler_tip", "rocker_tip"}};
    d.actuated = {"crank"};
    const MechanismModel model(d);
    MechanismData data(model);
    int repeated = 0;  // the joints listed after another on the same coordinate
    for (const auto& e : data.loop_path_joints) repeated += e.first ? 0 : 1;
    EXPECT_EQ(repeated, 1) << static_cast<int>(type);
    const Eigen::VectorXd q = (Eigen::VectorXd(3) << 0.9, -0.5, 1.6).finished();
    ASSERT_EQ(loop_constraints(model, data, q), Status::ok);
    const Eigen::MatrixXd A = data.loop_jacobian;
    const Eigen::MatrixXd fd = residual_differences(model, data, q);
    EXPECT_GT(A.cwiseAbs().maxCoeff(), 1e-2);
    for (int k = 0; k < model.dof(); ++k) {
      EXPECT_LT((A.col(k) - fd.col(k)).cwiseAbs().maxCoeff(), 1e-8) << static_cast<int>(type) << " coordinate " << k;
    }
  }
}

TEST(Loops, CouplingMatrixAndBiasMatchFiniteDifferences) {
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData data(model);
    const int na = model.num_actuated();
    const Eigen::VectorXd q0 = solved(model, data, c.qa, c.guess);
    // C: columns are d q / d qa_j (central differences of solved positions)
    Eigen::VectorXd va = Eigen::VectorXd::LinSpaced(na, 0.7, -1.3);
    ASSERT_EQ(loop_projection(model, data, q0, va), Status::ok) << c.name;
    const Eigen::MatrixXd C = data.loop_projection;
    const Eigen::VectorXd c_bias = data.loop_acceleration_bias;
    const double h = 1e-6;
    for (int j = 0; j < na; ++j) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(na);
      e(j) = h;
      const Eigen::VectorXd dq = (solved(model, data, c.qa + e, q0) - solved(model, data, c.qa - e, q0)) / (2 * h);
      EXPECT_LT((C.col(j) - dq).cwiseAbs().maxCoeff(), 1e-7) << c.name << " column " << j;
    }
    // c: along qa(t) = qa + va t + aa t^2/2, q''(0) = C aa + c (second differences)
    const Eigen::VectorXd aa = Eigen::VectorXd::LinSpaced(na, -0.4, 0.9);
    const double dt = 1e-4;
    const auto qa_at = [&](double t) { return Eigen::VectorXd(c.qa + va * t + 0.5 * aa * t * t); };
    const Eigen::VectorXd qdd = (solved(model, data, qa_at(dt), q0) - 2.0 * q0 + solved(model, data, qa_at(-dt), q0)) /
                                (dt * dt);
    EXPECT_LT((C * aa + c_bias - qdd).cwiseAbs().maxCoeff(), 1e-5) << c.name;
    // closed_motion returns the same
    Eigen::VectorXd q = q0;
    ASSERT_EQ(closed_motion(model, data, c.qa, va, aa, q), Status::ok);
    EXPECT_LT((data.closed_velocity - C * va).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((data.closed_acceleration - (C * aa + c_bias)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Loops, ProjectionEqualsTheDenseLeastSquaresSolution) {
  // C from the sparse LDL^T over the loops' structure, for the actuated columns that move a loop
  // only, equals the dense least-squares solution -pinv(A°) A# of the whole Jacobian (SVD), and the
  // columns of the actuated joints outside every loop are unit vectors
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData data(model);
    const int na = model.num_actuated(), np = model.num_passive();
    Eigen::VectorXd q = c.guess;
    const Eigen::VectorXd va = Eigen::VectorXd::LinSpaced(na, 0.7, -1.3), aa = Eigen::VectorXd::LinSpaced(na, -0.4, 0.9);
    for (int k = 0; k < 5; ++k) {
      const Eigen::VectorXd qa = c.qa + Eigen::VectorXd::Constant(na, 0.1 * k);
      ASSERT_EQ(closed_motion(model, data, qa, va, aa, q), Status::ok) << c.name;
      Eigen::MatrixXd Ap(model.num_constraints(), np), Aa(model.num_constraints(), na);
      for (int j = 0; j < np; ++j) Ap.col(j) = data.loop_jacobian.col(model.passive_coordinates()[static_cast<std::size_t>(j)]);
      for (int i = 0; i < na; ++i) Aa.col(i) = data.loop_jacobian.col(model.actuated_coordinates()[static_cast<std::size_t>(i)]);
      const Eigen::MatrixXd X = -Ap.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(Aa);
      for (int j = 0; j < np; ++j) {
        const int row = model.passive_coordinates()[static_cast<std::size_t>(j)];
        EXPECT_LT((data.loop_projection.row(row) - X.row(j)).cwiseAbs().maxCoeff(), 1e-12) << c.name;
      }
      for (int i = 0; i < na; ++i) {
        const bool in_loop = std::find(data.loop_actuated_columns.begin(), data.loop_actuated_columns.end(), i) !=
                             data.loop_actuated_columns.end();
        EXPECT_EQ(in_loop, Aa.col(i).cwiseAbs().maxCoeff() > 0.0) << c.name << " actuated " << i;
        if (in_loop) continue;
        Eigen::VectorXd unit = Eigen::VectorXd::Zero(model.dof());
        unit(model.actuated_coordinates()[static_cast<std::size_t>(i)]) = 1.0;
        EXPECT_TRUE((data.loop_projection.col(i).array() == unit.array()).all()) << c.name << " actuated " << i;
      }
    }
    if (std::string(c.name) == "four_bar_with_arm") EXPECT_EQ(data.loop_actuated_columns.size(), 1u);
  }
}

TEST(Loops, RefinementKeepsTheProjectionExactWhenIllConditioned) {
  // The normal equations of A° lose accuracy as 1 / rcond^2; below options.refine_rcond the
  // projection gets a step of iterative refinement. Walk the crank to the near-alignment, warm
  // started, and compare C and c with and without refinement against the closure itself
  // (A C = 0 and A c + gamma = 0).
  // a coupler of 0.250002 m nearly aligns with the rocker when the crank points away from the
  // rocker's pivot (0.2 + 0.45 = 0.65 m < 0.250002 + 0.4): A° is ill-conditioned there
  const MechanismModel model = four_bar(LoopType::point, 0.250002);
  MechanismData data(model);
  Eigen::VectorXd q = (Eigen::VectorXd(3) << 2.0, 2.5, 2.0).finished();
  Eigen::VectorXd qa(1), va = Eigen::VectorXd::Constant(1, 0.8), aa = Eigen::VectorXd::Constant(1, -0.3);
  Status s = Status::ok;
  for (int k = 0; k <= 400 && data.loop_rcond > 0.01; ++k) {  // crank 2.0 -> pi
    qa(0) = 2.0 + (M_PI - 2.0) * k / 400.0;
    s = closed_motion(model, data, qa, va, aa, q);
    ASSERT_FALSE(has(s, Status::solver_error)) << "crank " << qa(0);
  }
  const double rcond = data.loop_rcond;
  ASSERT_LT(rcond, 0.01);
  ASSERT_GT(rcond, 1e-6);
  const auto closure_errors = [&](const LoopSolveOptions& o) -> std::pair<double, double> {
    Eigen::VectorXd qq = q;
    closed_motion(model, data, qa, va, aa, qq);
    EXPECT_NEAR(data.loop_rcond, rcond, 1e-9);
    loop_projection(model, data, qq, va, o);
    const Eigen::MatrixXd C = data.loop_projection;
    const Eigen::VectorXd c = data.loop_acceleration_bias, gamma = data.loop_bias;
    EXPECT_EQ(loop_constraints(model, data, qq), Status::ok);
    return {(data.loop_jacobian * C).cwiseAbs().maxCoeff(),
                     (data.loop_jacobian * c + gamma).cwiseAbs().maxCoeff()};
  };
  LoopSolveOptions never, always, by_default;
  never.refine_rcond = 0.0;
  always.refine_rcond = 1.0;
  const auto [c_never, bias_never] = closure_errors(never);
  const auto [c_always, bias_always] = closure_errors(always);
  const auto [c_default, bias_default] = closure_errors(by_default);
  EXPECT_LT(c_always, 1e-16);  // measured 5e-20 (unrefined 3e-14)
  EXPECT_LT(bias_always, 1e-13);  // measured 2e-15 (unrefined 4e-12)
  EXPECT_LT(bias_always, 0.1 * bias_never);
  EXPECT_EQ(c_default, c_always);  // rcond < the default refine_rcond: refined
  EXPECT_EQ(bias_default, bias_always);
}

TEST(Loops, ChordStepsFallBackToNewtonAfterAJump) {
  // A warm-started tick reuses the last factorisation (chord steps); after a large jump of the
  // actuators it must fall back to full Newton and reach the same assembly as a cold solve.
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData warm(model), cold(model);
    const int na = model.num_actuated();
    const Eigen::VectorXd va = Eigen::VectorXd::Constant(na, 0.3), aa = Eigen::VectorXd::Zero(na);
    Eigen::VectorXd q = c.guess;
    ASSERT_EQ(closed_motion(model, warm, c.qa, va, aa, q), Status::ok) << c.name;
    const Eigen::VectorXd qa = c.qa + Eigen::VectorXd::Constant(na, 0.35);
    Eigen::VectorXd q_cold = q;
    ASSERT_EQ(closed_motion(model, warm, qa, va, aa, q), Status::ok) << c.name;
    cold.closed_position.setConstant(1e9);  // no warm start
    ASSERT_EQ(solve_loop_positions(model, cold, qa, q_cold), Status::ok) << c.name;
    EXPECT_LT((q - q_cold).cwiseAbs().maxCoeff(), 1e-10) << c.name;
    ASSERT_EQ(loop_constraints(model, warm, q), Status::ok);
    EXPECT_LT(warm.loop_residual.cwiseAbs().maxCoeff(), 1e-12) << c.name;
  }
}

TEST(Loops, VelocityMotionIsClosedMotionWithoutAccelerations) {
  // closed_velocity_motion: the same solve, C and v as closed_motion (to the last bit, from the
  // same warm start), and c / the accelerations left as they were
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData full(model), velocity(model);
    const int na = model.num_actuated();
    Eigen::VectorXd q_full = c.guess, q_velocity = c.guess, qa = c.qa, va(na), aa(na);
    for (int k = 0; k < 30; ++k) {
      qa.setConstant(0.3 * std::sin(0.05 * k));
      qa += c.qa;
      va.setConstant(0.5 * std::cos(0.05 * k));
      aa.setConstant(-0.2);
      if (k % 3 == 0) {  // both: the warm starts stay the same
        ASSERT_EQ(closed_motion(model, full, qa, va, aa, q_full), Status::ok) << c.name;
        ASSERT_EQ(closed_motion(model, velocity, qa, va, aa, q_velocity), Status::ok) << c.name;
        continue;
      }
      ASSERT_EQ(closed_motion(model, full, qa, va, aa, q_full), Status::ok) << c.name;
      const Eigen::VectorXd c_before = velocity.loop_acceleration_bias;
      ASSERT_EQ(closed_velocity_motion(model, velocity, qa, va, q_velocity), Status::ok) << c.name;
      EXPECT_TRUE((q_full.array() == q_velocity.array()).all()) << c.name << " tick " << k;
      EXPECT_TRUE((full.loop_projection.array() == velocity.loop_projection.array()).all()) << c.name;
      EXPECT_TRUE((full.closed_velocity.array() == velocity.closed_velocity.array()).all()) << c.name;
      EXPECT_TRUE((velocity.loop_acceleration_bias.array() == c_before.array()).all()) << c.name;
      // and back in step: the next full tick starts from the same place in both
      velocity.loop_acceleration_bias = full.loop_acceleration_bias;
    }
  }
}

TEST(Loops, AccelerationBiasFromAMomentumPassIsClosedMotions) {
  // closed_velocity_motion, then a momentum pass with the links' accelerations at a = 0
  // (velocity_momentum, as a controller's) and detail::loop_acceleration_bias_placed: the same c
  // as closed_motion's own bias pass, refined or not
  LoopSolveOptions refined;
  refined.refine_rcond = 1.0;
  for (const LoopSolveOptions& options : {LoopSolveOptions{}, refined}) {
    for (const auto& c : cases()) {
      const MechanismModel& model = c.model;
      MechanismData full(model), split(model);
      const int na = model.num_actuated();
      Eigen::VectorXd q_full = c.guess, q_split = c.guess, qa = c.qa, va(na), aa = Eigen::VectorXd::Zero(na);
      detail::LinkSubset none;
      none.member.assign(static_cast<std::size_t>(model.num_links()), 0);
      detail::Vec6 inside, rest;
      for (int k = 0; k < 10; ++k) {
        qa.setConstant(0.3 * std::sin(0.05 * k));
        qa += c.qa;
        va.setConstant(0.5 * std::cos(0.05 * k));
        ASSERT_EQ(closed_motion(model, full, qa, va, aa, q_full, options), Status::ok) << c.name;
        ASSERT_EQ(closed_velocity_motion(model, split, qa, va, q_split, options), Status::ok) << c.name;
        detail::joint_state<true, false>(model, split, q_split, split.closed_velocity, split.closed_velocity);
        detail::velocity_momentum(model, split, none, true, inside, rest, true);
        ASSERT_EQ(detail::loop_acceleration_bias_placed(model, split, options.refine_rcond), Status::ok) << c.name;
        const double scale = 1.0 + full.loop_acceleration_bias.cwiseAbs().maxCoeff();
        EXPECT_LT((split.loop_acceleration_bias - full.loop_acceleration_bias).cwiseAbs().maxCoeff(), 1e-13 * scale)
            << c.name << " tick " << k;
        EXPECT_GT(full.loop_acceleration_bias.cwiseAbs().maxCoeff(), 0.0) << c.name;  // not trivially zero
        // and the momentum of the pass is the mechanism's
        ASSERT_EQ(momentum(model, full, q_full, full.closed_velocity), Status::ok);
        const detail::Vec6 h = inside + rest;
        EXPECT_LT((h.head<3>() - full.shaking.linear_momentum).cwiseAbs().maxCoeff(), 1e-12) << c.name;
        EXPECT_LT((h.tail<3>() - full.shaking.angular_momentum).cwiseAbs().maxCoeff(), 1e-12) << c.name;
      }
    }
  }
}

TEST(Loops, ActuatorsOutsideTheLoopsLeaveTheWarmStartAlone) {
  // The four-bar carrying an actuated arm and slide, which move no loop frame: a tick that moves
  // them too solves the loop from the same warm start (history included) as one that does not,
  // so the loop's coordinates come out the same to the last bit, and the warm start keeps
  // closing the loop at its prediction. Also when they are moved between the solves in q and in
  // data.closed_position (what a reactionless controller does when it turns its balancing joints
  // at a pose whose loops are solved)
  const MechanismModel model = four_bar_with_arm();
  MechanismData still(model), moving(model);
  const int na = model.num_actuated();
  Eigen::VectorXd guess = Eigen::VectorXd::Zero(model.dof()), qa(na), va(na), aa = Eigen::VectorXd::Zero(na);
  const std::map<std::string, double> near{{"crank", 1.0}, {"coupler", -0.6}, {"rocker", 1.75},
                                           {"wrist", 0.5}, {"tool", -0.8}, {"slide", 0.05}};
  for (int c = 0; c < model.dof(); ++c) guess(c) = near.at(model.coordinate_name(c));
  Eigen::VectorXd q_still = guess, q_moving = guess;
  int crank = -1;
  for (int i = 0; i < na; ++i) {
    if (model.coordinate_name(model.actuated_coordinates()[static_cast<std::size_t>(i)]) == "crank") crank = i;
  }
  ASSERT_GE(crank, 0);
  int closed_at_prediction = 0;
  const int ticks = 200;
  for (int k = 0; k < ticks; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < na; ++i) {
      const int c = model.actuated_coordinates()[static_cast<std::size_t>(i)];
      qa(i) = guess(c);
      va(i) = 0.0;
    }
    qa(crank) = 1.0 + 0.4 * std::sin(2.0 * t);
    va(crank) = 0.8 * std::cos(2.0 * t);
    ASSERT_EQ(closed_motion(model, still, qa, va, aa, q_still), Status::ok) << k;
    for (int i = 0; i < na; ++i) {  // the arm and the slide wander
      if (i == crank) continue;
      qa(i) += 0.3 * std::sin(7.0 * t + i);
      va(i) = 2.1 * std::cos(7.0 * t + i);
    }
    ASSERT_EQ(closed_motion(model, moving, qa, va, aa, q_moving), Status::ok) << k;
    for (int i = 0; i < na; ++i) {
      if (i == crank) continue;
      const int c = model.actuated_coordinates()[static_cast<std::size_t>(i)];
      q_moving(c) += 0.01;
      moving.closed_position(c) = q_moving(c);
    }
    for (const int c : model.passive_coordinates()) EXPECT_EQ(q_moving(c), q_still(c)) << "tick " << k;
    EXPECT_EQ(moving.loop_iterations, still.loop_iterations) << "tick " << k;
    if (k >= 10 && moving.loop_iterations == 0) ++closed_at_prediction;
  }
  EXPECT_GT(closed_at_prediction, (ticks - 10) / 2);
}

TEST(Loops, TicksAllocateNothing) {
  LoopSolveOptions refined;  // the refinement path too
  refined.refine_rcond = 1.0;
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData data(model);
    const int na = model.num_actuated();
    Eigen::VectorXd q = c.guess, qa = c.qa, va(na), aa(na), tau(na);
    ASSERT_EQ(solve_loop_positions(model, data, qa, q), Status::ok);  // first assembly
    data.reserve_mass_matrix();  // the real-time set-up of the closed dynamics (data.hpp)
    test::AllocationScope scope;
    for (int k = 0; k < 20; ++k) {
      // a different pose each tick, warm-started from the last one (Newton iterates every tick)
      qa.setConstant(0.3 * std::sin(0.05 * k));
      qa += c.qa;
      va.setConstant(0.5 * std::cos(0.05 * k));
      aa.setConstant(-0.2);
      tau.setConstant(0.1);
      EXPECT_EQ(solve_loop_positions(model, data, qa, q), Status::ok) << c.name;
      EXPECT_EQ(loop_projection(model, data, q, va), Status::ok) << c.name;
      EXPECT_EQ(closed_motion(model, data, qa, va, aa, q), Status::ok) << c.name;
      EXPECT_EQ(closed_inverse_dynamics(model, data, qa, va, aa, q), Status::ok) << c.name;
      EXPECT_EQ(closed_mass_matrix(model, data, qa, q), Status::ok) << c.name;
      EXPECT_EQ(closed_forward_dynamics(model, data, qa, va, tau, q), Status::ok) << c.name;
      EXPECT_EQ(closed_motion(model, data, qa, va, aa, q, refined), Status::ok) << c.name;
      EXPECT_EQ(closed_velocity_motion(model, data, qa, va, q), Status::ok) << c.name;
      EXPECT_EQ(closed_shaking_wrench(model, data, qa, va, aa, q), Status::ok) << c.name;
    }
    EXPECT_EQ(scope.count(), 0u) << c.name;
  }
}

namespace {

/// |x - y| relative to max(1, |y|)
double relative(const Vec3& x, const Vec3& y) { return (x - y).norm() / std::max(1.0, y.norm()); }

/// closed_shaking_wrench against closed_motion + shaking_wrench, each on its own data from the
/// same warm start, over `ticks` ticks of the motion `at(k, qa, va, aa)`: the same q to the last
/// bit (the same solve), the same momenta and wrench to round-off; returns the largest
/// relative difference of the four.
template <class Motion>
double fused_against_separate(const MechanismModel& model, const Eigen::VectorXd& guess, int ticks, Motion&& at) {
  MechanismData fused(model), separate(model);
  const int na = model.num_actuated();
  Eigen::VectorXd q_fused = guess, q_separate = guess, qa(na), va(na), aa(na);
  double worst = 0.0;
  for (int k = 0; k < ticks; ++k) {
    at(k, qa, va, aa);
    EXPECT_EQ(closed_shaking_wrench(model, fused, qa, va, aa, q_fused), Status::ok) << "tick " << k;
    EXPECT_EQ(closed_motion(model, separate, qa, va, aa, q_separate), Status::ok) << "tick " << k;
    EXPECT_EQ(shaking_wrench(model, separate, separate.closed_position, separate.closed_velocity,
                             separate.closed_acceleration),
              Status::ok);
    EXPECT_TRUE((q_fused.array() == q_separate.array()).all()) << "tick " << k;
    EXPECT_TRUE((fused.closed_acceleration.array() == separate.closed_acceleration.array()).all()) << "tick " << k;
    const ShakingWrench &f = fused.shaking, &s = separate.shaking;
    // (an assertion that can fail: the wrench is not zero)
    EXPECT_GT(s.force.norm() + s.moment.norm(), 1e-3) << "tick " << k;
    worst = std::max({worst, relative(f.force, s.force), relative(f.moment, s.moment),
                      relative(f.linear_momentum, s.linear_momentum),
                      relative(f.angular_momentum, s.angular_momentum)});
  }
  return worst;
}

/// four_bar_with_arm with random bodies (test_support.hpp) and its wrist link massless (the
/// tool, below it, carries mass: the accelerations pass through a link the sums skip).
MechanismModel random_four_bar_with_arm(std::mt19937& rng) {
  MechanismDescription d = four_bar_with_arm().description();
  std::vector<Body> bodies;
  for (const Body& b : d.bodies) {
    if (b.link == "wrist") continue;
    const RigidBody r = test::random_body(rng);
    std::uniform_real_distribution<double> u(-0.1, 0.1);
    Body out = b;
    out.mass = r.mass;
    out.com = Vec3(u(rng), u(rng), u(rng));
    out.inertia = r.inertia_body;
    bodies.push_back(out);
  }
  d.bodies = bodies;
  return MechanismModel(d);
}

}  // namespace

TEST(Loops, ClosedShakingWrenchIsClosedMotionThenShakingWrench) {
  // every test mechanism (point, planar_point and axis loops, two actuators, a turntable, an arm
  // and a slide outside the loop), and the arm with random bodies and a massless link
  std::mt19937 rng(7);
  std::vector<Case> all = cases();
  {
    MechanismModel model = random_four_bar_with_arm(rng);
    EXPECT_FALSE(model.has_inertia(model.link_index("wrist")));
    EXPECT_EQ(static_cast<int>(model.inertial_links().size()), model.num_links() - 2);
    all.push_back(Case{"random_four_bar_with_arm", std::move(model), all.back().guess, all.back().qa});
  }
  for (const auto& c : all) {
    const double worst = fused_against_separate(c.model, c.guess, 40, [&](int k, Eigen::VectorXd& qa, Eigen::VectorXd& va,
                                                                          Eigen::VectorXd& aa) {
      const double t = 1e-3 * k;
      for (Eigen::Index i = 0; i < qa.size(); ++i) {
        const double w = 2.0 + 0.7 * static_cast<double>(i);
        qa(i) = c.qa(i) + 0.3 * std::sin(w * t);
        va(i) = 0.3 * w * std::cos(w * t) + 0.5;
        aa(i) = -0.3 * w * w * std::sin(w * t) - 1.0;
      }
    });
    EXPECT_LT(worst, 1e-12) << c.name;
  }
  // an open model (every coordinate actuated): shaking_wrench itself, the same to the last bit
  const MechanismModel open(test::random_chain(rng, "RRPR"));
  const double worst = fused_against_separate(open, Eigen::VectorXd::Zero(open.dof()), 5,
                                              [&](int k, Eigen::VectorXd& qa, Eigen::VectorXd& va, Eigen::VectorXd& aa) {
                                                qa.setConstant(0.1 * k);
                                                va.setConstant(1.0 - 0.1 * k);
                                                aa.setConstant(2.0);
                                              });
  EXPECT_EQ(worst, 0.0);
}

TEST(Loops, ClosedShakingWrenchOnPaminsa) {
  // PAMINSA as a general model (31 moving links, 9 loops, massless stages): along the bench's
  // motion at 1 kHz, and with jumps of 20 ms (Newton iterates)
  const PaminsaModel closed{PaminsaParameters{}};
  const MechanismModel model(bench::paminsa_description(closed));
  EXPECT_LT(static_cast<int>(model.inertial_links().size()), model.num_links() - 1);  // massless links
  const Eigen::VectorXd guess = bench::initial_guess(closed, model, test::platform_at(0.0), test::wrist_at(0.0));
  for (const double dt : {1e-3, 2e-2}) {
    const double worst = fused_against_separate(model, guess, 30, [&](int k, Eigen::VectorXd& qa, Eigen::VectorXd& va,
                                                                      Eigen::VectorXd& aa) {
      const bench::ActuatedState s = bench::actuated(closed, model, test::platform_at(k * dt), test::wrist_at(k * dt));
      qa = s.q;
      va = s.v;
      aa = s.a;
    });
    EXPECT_LT(worst, 1e-12) << "dt " << dt;
  }
}

TEST(Loops, ForwardDynamicsInvertsInverseDynamics) {
  for (const auto& c : cases()) {
    const MechanismModel& model = c.model;
    MechanismData data(model);
    const int na = model.num_actuated();
    Eigen::VectorXd q = c.guess;
    const Eigen::VectorXd va = Eigen::VectorXd::LinSpaced(na, 0.8, -0.5), aa = Eigen::VectorXd::LinSpaced(na, 1.5, 0.3);
    ASSERT_EQ(closed_inverse_dynamics(model, data, c.qa, va, aa, q), Status::ok);
    const Eigen::VectorXd tau = data.actuated_force;
    ASSERT_EQ(closed_forward_dynamics(model, data, c.qa, va, tau, q), Status::ok);
    EXPECT_LT((data.actuated_acceleration - aa).cwiseAbs().maxCoeff(), 1e-9) << c.name;
  }
}
