// mechbal's general model on robots read from URDF (issue 9, performance): inverse dynamics,
// mass matrix and the momentum rate (shaking wrench: momenta about O and their rates) of UR5 and
// Panda, through MechanismModel / MechanismData. Pinocchio on the same files:
// bench_urdf_pinocchio.cpp.
#include "bench_urdf.hpp"

#include <cstdio>
#include <cstdlib>

#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/io/urdf.hpp"

namespace mechbal::bench {

std::string robot_urdf(const std::string& robot) {
  const std::string dir = MECHBAL_BENCH_ROBOTS_DIR;
  if (robot == "ur5") return dir + "/ur_description/urdf/ur5_robot.urdf";
  if (robot == "panda") return dir + "/panda_description/urdf/panda.urdf";
  if (robot == "talos") return dir + "/talos_data/robots/talos_reduced.urdf";
  if (robot == "romeo") return dir + "/romeo_description/urdf/romeo.urdf";
  std::fprintf(stderr, "mechbal-bench: unknown robot %s\n", robot.c_str());
  std::abort();
}

// Read as `mechbal` reads a URDF by default from Python (repairs allowed, each one a warning):
// Talos's gripper carries <mimic> tags on fixed joints, which the strict reader refuses.
UrdfRobot::UrdfRobot(const std::string& robot)
    : path(robot_urdf(robot)),
      model(model_from_urdf_reading(read_urdf_file(path, UrdfOptions{false, false}), path)),
      x(bench_states(model.dof(), 11)) {}

namespace {

struct Mech : UrdfRobot {
  explicit Mech(const std::string& robot) : UrdfRobot(robot), data(model) {}
  MechanismData data;
  int k = 0;
  int next() { return k = (k + 1) & (JointStates::count - 1); }
};

Tick id_case(const char* robot) {
  auto s = std::make_shared<Mech>(robot);
  return [s] {
    const int k = s->next();
    inverse_dynamics(s->model, s->data, s->x.q[k], s->x.qd[k], s->x.qdd[k]);
    benchmark::DoNotOptimize(s->data.joint_torque.data());
    benchmark::ClobberMemory();
  };
}

Tick mass_case(const char* robot) {
  auto s = std::make_shared<Mech>(robot);
  return [s] {
    const int k = s->next();
    mass_matrix(s->model, s->data, s->x.q[k]);
    benchmark::DoNotOptimize(s->data.mass_matrix.data());
    benchmark::ClobberMemory();
  };
}

Tick gravity_case(const char* robot) {
  auto s = std::make_shared<Mech>(robot);
  return [s] {
    const int k = s->next();
    gravity_torque(s->model, s->data, s->x.q[k]);
    benchmark::DoNotOptimize(s->data.gravity_torque.data());
    benchmark::ClobberMemory();
  };
}

Tick momentum_rate_case(const char* robot) {
  auto s = std::make_shared<Mech>(robot);
  return [s] {
    const int k = s->next();
    shaking_wrench(s->model, s->data, s->x.q[k], s->x.qd[k], s->x.qdd[k]);
    benchmark::DoNotOptimize(s->data.shaking);
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(id_ur5_mechbal) { return id_case("ur5"); }
MECHBAL_BENCH_CASE(mass_ur5_mechbal) { return mass_case("ur5"); }
MECHBAL_BENCH_CASE(momentum_rate_ur5_mechbal) { return momentum_rate_case("ur5"); }
MECHBAL_BENCH_CASE(id_panda_mechbal) { return id_case("panda"); }
MECHBAL_BENCH_CASE(mass_panda_mechbal) { return mass_case("panda"); }
MECHBAL_BENCH_CASE(momentum_rate_panda_mechbal) { return momentum_rate_case("panda"); }
MECHBAL_BENCH_CASE(gravity_ur5_mechbal) { return gravity_case("ur5"); }
MECHBAL_BENCH_CASE(gravity_panda_mechbal) { return gravity_case("panda"); }
// big trees (issue 26): Talos (talos_reduced: 32 revolute joints, no active mimic) and Romeo
// (55 revolute joints of which 22 finger joints follow another by <mimic>: 33 coordinates)
MECHBAL_BENCH_CASE(id_talos_mechbal) { return id_case("talos"); }
MECHBAL_BENCH_CASE(mass_talos_mechbal) { return mass_case("talos"); }
MECHBAL_BENCH_CASE(gravity_talos_mechbal) { return gravity_case("talos"); }
MECHBAL_BENCH_CASE(momentum_rate_talos_mechbal) { return momentum_rate_case("talos"); }
MECHBAL_BENCH_CASE(id_romeo_mechbal) { return id_case("romeo"); }
MECHBAL_BENCH_CASE(mass_romeo_mechbal) { return mass_case("romeo"); }
MECHBAL_BENCH_CASE(gravity_romeo_mechbal) { return gravity_case("romeo"); }
MECHBAL_BENCH_CASE(momentum_rate_romeo_mechbal) { return momentum_rate_case("romeo"); }
