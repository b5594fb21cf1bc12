// The URDF reader (urdf.hpp): structure of a small tree with every joint kind it reads, a gear
// coupling and a root inertial; its errors; and the algorithms on the model it builds allocate
// nothing. Physics against Pinocchio on the same files is in tests/python/test_urdf.py.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <stdexcept>
#include <string>

#include "alloc_counter.hpp"
#include "every_algorithm.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/regressor.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/io/urdf.hpp"
#include "urdf_error.hpp"

using namespace mechbal;

namespace {

// base -j1 (revolute, default axis)-> l1 -j2 (continuous)-> l2 -j4 (fixed)-> tool
//                                        -j3 (prismatic)-> l3 -j5 (revolute, mimic j1)-> l4
const char* kTree = R"(<?xml version="1.0"?>
<robot name="tree">
  <link name="base">
    <inertial><origin xyz="0.1 0 0.05" rpy="0 0 1.5707963267948966"/><mass value="4"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.25"/></inertial>
  </link>
  <link name="l1"><inertial><origin xyz="0 0 0.2"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.15 0 0"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0 0.1 0"/><mass value="0.5"/>
      <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.005"/></inertial></link>
  <link name="l4"><inertial><origin xyz="0 0 0.05"/><mass value="0.3"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0.02 0 0"/><mass value="0.2"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><limit lower="-1.5" upper="2" effort="30" velocity="3"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.4" rpy="0.3 0 0"/><axis xyz="0 1 0"/><limit effort="10" velocity="0"/></joint>
  <joint name="j3" type="prismatic"><parent link="l1"/><child link="l3"/>
    <origin xyz="0.1 0 0.2"/><axis xyz="0 0 1"/><limit lower="0" upper="0.3" effort="50" velocity="0.5"/></joint>
  <joint name="j4" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0.3 0 0"/></joint>
  <joint name="j5" type="revolute"><parent link="l3"/><child link="l4"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="5" velocity="2"/><mimic joint="j1" multiplier="-2" offset="0.1"/></joint>
</robot>)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

using test::urdf_error_of;

}  // namespace

TEST(Urdf, TreeStructure) {
  const MechanismModel model = model_from_urdf_string(kTree);
  EXPECT_EQ(model.root_name(), "base");
  // the fixed joint j4 is folded into j2's link when the model is built (bodies and frames move)
  EXPECT_EQ(model.num_links(), 5);
  ASSERT_EQ(model.dof(), 3);
  EXPECT_EQ(model.coordinate_names(), (std::vector<std::string>{"j1", "j2", "j3"}));
  // depth-first, children by name: j1, j2, (j4 folded), j3, j5
  EXPECT_EQ(model.link_name(1), "j1");
  EXPECT_EQ(model.link_name(2), "j2");
  EXPECT_EQ(model.link_name(3), "j3");
  EXPECT_EQ(model.link_name(4), "j5");
  EXPECT_EQ(model.parent(4), 3);
  EXPECT_EQ(model.joint_type(1), JointType::revolute);
  EXPECT_EQ(model.joint_type(2), JointType::revolute);  // continuous
  EXPECT_EQ(model.joint_type(3), JointType::prismatic);
  EXPECT_TRUE(model.axis(1).isApprox(Vec3::UnitX()));  // URDF's default axis
  EXPECT_TRUE(model.axis(2).isApprox(Vec3::UnitY()));
  EXPECT_TRUE(model.placement(2).linear().isApprox(Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix()));
  EXPECT_TRUE(model.placement(3).translation().isApprox(Vec3(0.1, 0.0, 0.2)));

  // limits: continuous has none; a zero velocity limit means "unspecified"
  EXPECT_DOUBLE_EQ(model.lower_limits()(0), -1.5);
  EXPECT_DOUBLE_EQ(model.upper_limits()(0), 2.0);
  EXPECT_TRUE(std::isinf(model.lower_limits()(1)) && std::isinf(model.upper_limits()(1)));
  EXPECT_TRUE(std::isinf(model.velocity_limits()(1)));
  EXPECT_DOUBLE_EQ(model.effort_limits()(1), 10.0);
  EXPECT_DOUBLE_EQ(model.velocity_limits()(2), 0.5);

  // mimic: j5 = -2 j1 + 0.1
  EXPECT_EQ(model.coordinate(4), 0);
  EXPECT_DOUBLE_EQ(model.coordinate_ratio(4), -2.0);
  EXPECT_DOUBLE_EQ(model.coordinate_offset(4), 0.1);

  // bodies: one per URDF link with an inertial, on the link its parent joint moves
  ASSERT_EQ(model.num_bodies(), 6);
  const Body& root = model.body(model.body_index("base"));
  EXPECT_EQ(root.link, "base");
  EXPECT_EQ(root.kind, "link");
  EXPECT_TRUE(root.com.isApprox(Vec3(0.1, 0.0, 0.05)));
  // the inertial's yaw of pi/2 swaps ixx and iyy in the link frame
  EXPECT_NEAR(root.inertia(0, 0), 0.2, 1e-15);
  EXPECT_NEAR(root.inertia(1, 1), 0.1, 1e-15);
  EXPECT_NEAR(root.inertia(2, 2), 0.25, 1e-15);
  EXPECT_EQ(model.body(model.body_index("tool")).link, "j2");  // folded with j4
  EXPECT_EQ(model.body(model.body_index("l4")).link, "j5");
  EXPECT_DOUBLE_EQ(model.total_mass(), 4.0 + 2.0 + 1.0 + 0.5 + 0.3 + 0.2);

  // frames: every URDF link by its own name
  ASSERT_EQ(model.num_frames(), 6);
  for (const char* name : {"base", "l1", "l2", "l3", "l4", "tool"}) EXPECT_GE(model.frame_index(name), 0) << name;
  EXPECT_EQ(model.frame(model.frame_index("tool")).link, "j2");
  EXPECT_TRUE(model.frame(model.frame_index("tool")).placement.translation().isApprox(Vec3(0.3, 0.0, 0.0)));
  EXPECT_EQ(model.frame(model.frame_index("l3")).link, "j3");
}

TEST(Urdf, FrameOfALinkIsThatLinksPose) {
  const MechanismModel model = model_from_urdf_string(kTree);
  MechanismData data(model);
  const Eigen::Vector3d q(0.0, 0.0, 0.0);
  ASSERT_EQ(forward_kinematics(model, data, q), Status::ok);
  // at q = 0 the tool sits at base(0,0,0.1) + l1(0,0,0.4) + Rx(0.3) (0.3,0,0)
  const auto& T = data.frame_placements[static_cast<std::size_t>(model.frame_index("tool"))];
  EXPECT_TRUE(T.translation().isApprox(Vec3(0.3, 0.0, 0.5), 1e-14));
}

TEST(Urdf, AlgorithmsAllocateNothing) {
  const MechanismModel model = model_from_urdf_string(kTree);
  MechanismData data(model);
  const Eigen::Vector3d q(0.3, -0.7, 0.1), v(1.0, -0.5, 0.2), a(-0.4, 2.0, 0.3);
  const int tool = model.frame_index("tool");
  EXPECT_EQ(test::allocations_of_every_algorithm(model, data, q, v, a, tool), 0u);
  EXPECT_TRUE(data.joint_torque.allFinite());
}

TEST(Urdf, ErrorsNameTheElement) {
  std::string e = urdf_error_of(replaced(kTree, "type=\"prismatic\"", "type=\"floating\""));
  EXPECT_NE(e.find("URDF joint 'j3'"), std::string::npos) << e;
  EXPECT_NE(e.find("floating"), std::string::npos) << e;

  e = urdf_error_of(replaced(kTree, "<parent link=\"l3\"/>", "<parent link=\"l33\"/>"));
  EXPECT_NE(e.find("l33"), std::string::npos) << e;
  EXPECT_NE(e.find("j5"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;

  e = urdf_error_of(replaced(kTree, "<mass value=\"0.5\"/>", "<mass value=\"-0.5\"/>"));
  EXPECT_NE(e.find("URDF link 'l3' inertial.mass"), std::string::npos) << e;
  EXPECT_NE(e.find("-0.5"), std::string::npos) << e;

  e = urdf_error_of(replaced(kTree, "ixx=\"0.005\"", "ixx=\"0.5\""));  // triangle inequality
  EXPECT_NE(e.find("URDF link 'l3' inertial.inertia"), std::string::npos) << e;

  e = urdf_error_of(replaced(kTree, "<mimic joint=\"j1\"", "<mimic joint=\"jj1\""));
  EXPECT_NE(e.find("URDF joint 'j5': mimic joint 'jj1' does not exist"), std::string::npos) << e;

  e = urdf_error_of("<robot name=\"x\"><link name=\"a\"></robot>");
  EXPECT_EQ(e.rfind("URDF: ", 0), 0u) << e;

  try {
    model_from_urdf_file("/nonexistent/robot.urdf");
    FAIL() << "no error";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("URDF file '/nonexistent/robot.urdf': cannot be read"), std::string::npos)
        << ex.what();
  }
}

// icub's feet: a zero tensor with 1e-20 products of inertia passes the absolute tolerance (1e-12
// kg m^2) but breaks the triangle inequality by 100 % of its own size, which MuJoCo refuses: the
// strict reading refuses it, naming the link; the lenient one repairs it with one warning and
// keeps the repaired moments off the triangle's boundary (1e-12 of the trace to spare).
TEST(Urdf, RoundingThatBreaksTheTriangleIsJudgedToTheInertiasOwnScale) {
  const std::string tiny = replaced(kTree, "ixx=\"0.005\" ixy=\"0\" ixz=\"0\" iyy=\"0.005\" iyz=\"0\" izz=\"0.005\"",
                                    "ixx=\"0\" ixy=\"0\" ixz=\"1.35525e-20\" iyy=\"0\" iyz=\"0\" izz=\"0\"");
  ASSERT_NE(tiny, std::string(kTree));
  const std::string e = urdf_error_of(tiny);
  EXPECT_NE(e.find("URDF link 'l3' inertial.inertia is not physical to its own scale"), std::string::npos) << e;
  UrdfOptions lenient;
  lenient.strict = false;
  const UrdfReading r = read_urdf_string(tiny, lenient);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("URDF link 'l3' <inertial>"), std::string::npos) << r.warnings[0];
  bool found = false;
  for (const Body& b : r.description.bodies) {
    if (b.name != "l3") continue;
    found = true;
    Eigen::SelfAdjointEigenSolver<Mat3> eig(b.inertia, Eigen::EigenvaluesOnly);
    const Vec3 p = eig.eigenvalues();
    EXPECT_GT(p.sum(), 0.0);
    EXPECT_GE(p(0) + p(1) - p(2), 0.5e-12 * p.sum());
  }
  EXPECT_TRUE(found);
}
