// Issue 24: the URDF reader cannot be made to crash, hang or build a non-physical model. A
// deterministic corpus (seeded mutations of a valid document: byte flips, cuts, insertions of
// markup and of bad numbers, deep nesting, joint cycles) goes through the reader; each document
// either gives std::invalid_argument with a one-line message or a model whose bodies are physical.
// `make test-sanitize` runs this corpus under AddressSanitizer and UndefinedBehaviorSanitizer (the
// parser fuzz target of the sanitizer build). Also: the data of a 10,000-link chain is O(n).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/io/urdf.hpp"
#include "urdf_error.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/rigid_body.hpp"

using namespace mechbal;

namespace {

const char* kSeed = R"(<?xml version="1.0"?>
<robot name="fuzz">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.2" rpy="0 0.1 0"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.15 0 0"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0 0.1 0"/><mass value="0.5"/>
      <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.005"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><limit lower="-1.5" upper="2" effort="30" velocity="3"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.4" rpy="0.3 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="j3" type="prismatic"><parent link="l1"/><child link="l3"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.3" effort="50" velocity="0.5"/><mimic joint="j1" multiplier="2"/></joint>
</robot>)";

const std::vector<std::string> kInsertions = {
    "<", ">", "/>", "</link>", "<link name=\"l1\"/>", "\"", "nan", "inf", "-1", "1e999", "abc",
    "<joint name=\"jx\" type=\"fixed\"><parent link=\"l2\"/><child link=\"l1\"/></joint>",
    "<joint name=\"jy\" type=\"revolute\"><parent link=\"l3\"/><child link=\"l3\"/></joint>",
    "<!--", "-->", "<![CDATA[", "]]>", "<?pi", "<!DOCTYPE r [", "&amp;", "&#0;", std::string(1, '\0'),
    "\xff\xfe", " xyz=\"1 2\"", " value=\"\"", "<a><b><c>", "</a></b>",
};

/// Either a one-line std::invalid_argument or a model with physical bodies; anything else (another
/// exception, a crash, a sanitizer report) fails the test.
void check(const std::string& xml, int& accepted, int& refused) {
  try {
    const MechanismModel model = model_from_urdf_string(xml);
    for (const Body& b : model.bodies()) {
      EXPECT_NO_THROW(validate_rigid_body(RigidBody{b.mass, b.inertia}, "fuzz")) << b.name;
      EXPECT_TRUE(b.com.allFinite()) << b.name;
    }
    MechanismData data(model);
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(model.dof(), 0.3);
    EXPECT_EQ(center_of_mass(model, data, q), Status::ok);
    EXPECT_TRUE(data.center_of_mass.allFinite());
    ++accepted;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_FALSE(what.empty());
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    ++refused;
  }
}

std::string mutate(std::mt19937& rng, std::string doc) {
  std::uniform_int_distribution<int> op(0, 4), count(1, 4);
  for (int k = count(rng); k > 0 && !doc.empty(); --k) {
    std::uniform_int_distribution<std::size_t> at(0, doc.size() - 1);
    const std::size_t i = at(rng);
    switch (op(rng)) {
      case 0: doc[i] = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng)); break;
      case 1: doc.erase(i, std::uniform_int_distribution<std::size_t>(1, 40)(rng)); break;
      case 2: doc.resize(i); break;
      case 3: doc.insert(i, kInsertions[std::uniform_int_distribution<std::size_t>(0, kInsertions.size() - 1)(rng)]); break;
      default: {  // duplicate a slice (repeated elements, repeated names)
        const std::size_t n = std::uniform_int_distribution<std::size_t>(1, 200)(rng);
        doc.insert(at(rng), doc.substr(i, n));
      }
    }
  }
  return doc;
}

using test::urdf_error_of;

}  // namespace

TEST(ParserFuzz, SeedIsValid) {
  const MechanismModel model = model_from_urdf_string(kSeed);
  EXPECT_EQ(model.dof(), 2);  // j3 follows j1
  EXPECT_EQ(model.num_bodies(), 3);
}

TEST(ParserFuzz, DeterministicMutationCorpus) {
  std::mt19937 rng(24);
  int accepted = 0, refused = 0;
  for (int i = 0; i < 3000; ++i) check(mutate(rng, kSeed), accepted, refused);
  // the corpus reaches both outcomes (a corpus that only produced errors would prove little)
  EXPECT_GT(accepted, 30);
  EXPECT_GT(refused, 300);
}

TEST(ParserFuzz, DeepNestingIsAnErrorNotACrash) {
  for (const int depth : {65, 1000, 100000}) {
    std::string xml = "<robot name=\"r\">";
    for (int i = 0; i < depth; ++i) xml += "<a>";
    for (int i = 0; i < depth; ++i) xml += "</a>";
    xml += "</robot>";
    const std::string e = urdf_error_of(xml);
    EXPECT_NE(e.find("nest more than 64 deep"), std::string::npos) << e.substr(0, 200);
  }
  std::string ok = "<robot name=\"r\"><link name=\"base\"/>";
  for (int i = 0; i < 60; ++i) ok += "<a>";
  for (int i = 0; i < 60; ++i) ok += "</a>";
  EXPECT_EQ(urdf_error_of(ok + "</robot>"), "no error");
}

TEST(ParserFuzz, JointCyclesAreRefusedNamingTheJoints) {
  const std::string links = "<link name=\"base\"/><link name=\"a\"/><link name=\"b\"/>";
  std::string e = urdf_error_of("<robot name=\"r\">" + links +
                           "<joint name=\"j0\" type=\"fixed\"><parent link=\"base\"/><child link=\"a\"/></joint>"
                           "<joint name=\"j1\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>"
                           "<joint name=\"j2\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>");
  EXPECT_NE(e.find("'j0'"), std::string::npos) << e;
  EXPECT_NE(e.find("'j2'"), std::string::npos) << e;
  e = urdf_error_of("<robot name=\"r\">" + links +
               "<joint name=\"j1\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>"
               "<joint name=\"j2\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>");
  EXPECT_NE(e.find("cycle"), std::string::npos) << e;
  EXPECT_NE(e.find("'j1'"), std::string::npos) << e;
  EXPECT_NE(e.find("'j2'"), std::string::npos) << e;
}

TEST(ParserFuzz, NumbersAreStrict) {
  for (const char* bad : {"nan", "inf", "-inf", "abc", "1e999", "", "1.0.0", "0x", "2kg"}) {
    std::string xml = kSeed;
    xml.replace(xml.find("<mass value=\"1\"/>"), 17, std::string("<mass value=\"") + bad + "\"/>");
    const std::string e = urdf_error_of(xml);
    EXPECT_NE(e.find("URDF link 'l2' <mass value="), std::string::npos) << bad << ": " << e;
  }
}

TEST(ParserFuzz, DataOfA10000LinkChainIsLinear) {
  MechanismDescription d;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    Joint j;
    j.name = "j" + std::to_string(i);
    j.parent = i == 0 ? "base" : "j" + std::to_string(i - 1);
    j.placement.translation() = Vec3(0.05, 0.0, 0.0);
    j.axis = i % 2 ? Vec3::UnitY() : Vec3::UnitZ();
    d.joints.push_back(j);
    Body b;
    b.name = "b" + std::to_string(i);
    b.link = j.name;
    b.mass = 0.1;
    b.com = Vec3(0.025, 0.0, 0.0);
    b.inertia = Mat3::Identity() * 1e-4;
    d.bodies.push_back(b);
  }
  const MechanismModel model(d);
  MechanismData data(model);
  // no buffer quadratic in n until an algorithm with a quadratic result runs
  EXPECT_EQ(data.mass_matrix.size(), 0);
  EXPECT_EQ(data.torque_regressor.size(), 0);
  EXPECT_EQ(data.gravity_regressor.size(), 0);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(n, 1e-3), v = q, a = q;
  EXPECT_EQ(center_of_mass(model, data, q), Status::ok);
  EXPECT_EQ(forward_kinematics(model, data, q, v, a), Status::ok);
  EXPECT_EQ(inverse_dynamics(model, data, q, v, a), Status::ok);
  EXPECT_EQ(momentum_matrix(model, data, q), Status::ok);
  EXPECT_TRUE(data.center_of_mass.allFinite() && data.joint_torque.allFinite());
  EXPECT_NEAR(data.mass, 0.1 * n, 1e-9);
  EXPECT_EQ(data.mass_matrix.size(), 0);
}
