#pragma once
// Robots loaded from URDF files for the general-model benchmarks (bench_urdf.cpp for mechbal,
// bench_urdf_pinocchio.cpp for Pinocchio): UR5 and Panda from example-robot-data (the PyPI test
// extra; its directory is found at configure time, bench/CMakeLists.txt).
#include <string>

#include "bench_registry.hpp"
#include "mechbal/model/model.hpp"

namespace mechbal::bench {

/// Path of a robot's URDF file: "ur5" or "panda".
std::string robot_urdf(const std::string& robot);

/// The robot's model read by mechbal's URDF reader, and 64 joint states of its dof.
struct UrdfRobot {
  explicit UrdfRobot(const std::string& robot);
  std::string path;
  MechanismModel model;
  JointStates x;
};

}  // namespace mechbal::bench
