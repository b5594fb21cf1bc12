// Built with -fno-exceptions -fno-rtti (tests/cpp/CMakeLists.txt), as embedded code is: the
// real-time headers (model, data, algorithms, dynamics back end, controllers, trajectory) must
// compile without exceptions or RTTI, and step() must run. The model is built by the core library
// (construction may throw there, at load time); this translation unit throws and catches nothing.
#include <cmath>
#include <cstdio>
#include <memory>

#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/algorithm/springs.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/config.hpp"
#include "mechbal/control/factory.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/control/joint_limits.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"
#include "mechbal/control/trajectory.hpp"

#if defined(__cpp_exceptions) || defined(__EXCEPTIONS) || defined(__GXX_RTTI)
#error "this translation unit must be compiled with -fno-exceptions -fno-rtti"
#endif

using namespace mechbal;

static int failures = 0;
static void check(bool ok, const char* what) {
  if (!ok) {
    std::printf("FAILED: %s\n", what);
    ++failures;
  }
}

int main() {
  // a spatial 2R arm with a counterweight and a spring
  MechanismDescription d;
  Joint a;
  a.name = "a";
  a.axis = Vec3::UnitZ();
  Joint b;
  b.name = "b";
  b.parent = "a";
  b.axis = Vec3::UnitY();
  b.placement.translation() = Vec3(0.4, 0.0, 0.1);
  d.joints = {a, b};
  d.joints[0].parent = "base";
  Body la{"a", "link", "a", 2.0, Vec3(0.2, 0.0, 0.0), Vec3(0.01, 0.02, 0.02).asDiagonal()};
  Body lb{"b", "link", "b", 1.0, Vec3(0.3, 0.0, 0.0), Vec3(0.005, 0.01, 0.01).asDiagonal()};
  Body cw{"cw", "counterweight", "b", 0.5, Vec3(-0.2, 0.0, 0.0), Mat3::Zero()};
  d.bodies = {la, lb, cw};
  Spring s;
  s.name = "s";
  s.link_a = "base";
  s.anchor_a = Vec3(0.0, 0.0, 0.5);
  s.link_b = "b";
  s.anchor_b = Vec3(0.1, 0.0, 0.0);
  s.rate = 50.0;
  d.springs = {s};
  const MechanismModel model(d);

  MechanismData data(model);
  const Eigen::Vector2d q(0.3, -0.4), v(0.5, 0.2), acc(-1.0, 2.0);
  check(forward_kinematics(model, data, q) == Status::ok, "forward_kinematics");
  check(mass_matrix(model, data, q) == Status::ok, "mass_matrix");
  check(inverse_dynamics(model, data, q, v, acc) == Status::ok, "inverse_dynamics");
  const Eigen::VectorXd tau_id = data.joint_torque;
  check(shaking_wrench(model, data, q, v, acc) == Status::ok, "shaking_wrench");

  MechanismDynamics dynamics(model);
  ComputedTorque ct(dynamics, Eigen::Vector2d(100, 100), Eigen::Vector2d(20, 20));
  Eigen::VectorXd tau(2);
  check(ct.step(q, v, q, v, acc, tau) == Status::ok, "ComputedTorque::step");
  check((tau - tau_id).cwiseAbs().maxCoeff() < 1e-9, "ComputedTorque on track = inverse dynamics");
  const Eigen::Vector2d nan_q(std::nan(""), 0.0);
  check(has(ct.step(nan_q, v, q, v, acc, tau), Status::non_finite_input), "NaN input is a status");
  check((tau - tau_id).cwiseAbs().maxCoeff() < 1e-9, "NaN input holds the last command");

  DecoupledJointController dec(Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(10, 10), Eigen::Vector2d(5, 5));
  check(dec.step(q, v, q, v, acc, tau) == Status::ok && std::abs(tau[1] - 4.0) < 1e-12, "Decoupled::step");

  ControlConfig config;
  config.kind = ControlKind::computed_torque;
  config.kp = {100, 100};
  config.kd = {20, 20};
  std::unique_ptr<JointController> made = make_controller(model, config);
  check(made->step(q, v, q, v, acc, tau) == Status::ok, "make_controller(...)->step");
  check((tau - tau_id).cwiseAbs().maxCoeff() < 1e-9, "made controller = inverse dynamics");

  RestToRestTrajectory trajectory(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, -1), 0.5, TimeLaw::quintic);
  Eigen::Vector2d qt, vt, at;
  check(trajectory.evaluate(0.25, qt, vt, at) == Status::ok, "trajectory");

  std::printf("rt_no_exceptions: tau = [%.6f, %.6f], %d failure(s)\n", tau[0], tau[1], failures);
  return failures == 0 ? 0 : 1;
}
