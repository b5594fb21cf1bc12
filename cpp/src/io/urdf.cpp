// URDF input through urdfdom (see mechbal/urdf.hpp for the mapping).
#include "mechbal/io/urdf.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mechbal/model/rigid_body.hpp"

namespace mechbal {

namespace {

/// Collects urdfdom's error messages (it reports through console_bridge and returns null) so
/// that the exception can say what was wrong, instead of urdfdom printing it to stderr.
class CollectErrors : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
  std::vector<std::string> errors;
};

/// One line: whitespace runs collapsed, urdfdom's "Error:" prefix dropped.
std::string one_line(const std::string& text) {
  std::string out;
  bool space = false;
  for (char c : text) {
    if (c == '\n' || c == '\r' || c == '\t' || c == ' ') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += c;
  }
  for (const char* prefix : {"Error: ", "Error:"}) {
    if (out.rfind(prefix, 0) == 0) out.erase(0, std::strlen(prefix));
  }
  // urdfdom's missing-link message goes on with three sentences of advice: keep the fact
  const auto advice = out.find(". This is not valid according to the URDF spec");
  if (advice != std::string::npos) out.erase(advice);
  return out;
}

urdf::ModelInterfaceSharedPtr parse(const std::string& xml) {
  // console_bridge's handler is process-global: one parse at a time swaps it.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  CollectErrors collect;
  console_bridge::useOutputHandler(&collect);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {  // urdfdom throws on some malformed numbers
    collect.errors.push_back(e.what());
    model.reset();
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model) {
    std::string why;
    for (const auto& e : collect.errors) why += (why.empty() ? "" : " | ") + one_line(e);
    throw std::invalid_argument("URDF: " + (why.empty() ? std::string("not a valid URDF document") : why));
  }
  return model;
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const auto& r = pose.rotation;
  T.linear() = Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
  T.translation() = Vec3(pose.position.x, pose.position.y, pose.position.z);
  return T;
}

std::string type_name(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE: return "revolute";
    case urdf::Joint::CONTINUOUS: return "continuous";
    case urdf::Joint::PRISMATIC: return "prismatic";
    case urdf::Joint::FLOATING: return "floating";
    case urdf::Joint::PLANAR: return "planar";
    case urdf::Joint::FIXED: return "fixed";
    default: return "unknown";
  }
}

/// A zero (URDF's "unspecified") velocity or effort limit is no limit; negative ones are errors.
double rate_limit(double value, const std::string& joint, const char* what) {
  if (!std::isfinite(value) || value < 0.0) {
    std::ostringstream m;
    m << "URDF joint '" << joint << "': limit " << what << " must be >= 0 (got " << value << ")";
    throw std::invalid_argument(m.str());
  }
  return value == 0.0 ? std::numeric_limits<double>::infinity() : value;
}

Joint to_joint(const urdf::Joint& uj, const std::string& parent) {
  Joint j;
  j.name = uj.name;
  j.parent = parent;
  j.placement = to_isometry(uj.parent_to_joint_origin_transform);
  switch (uj.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS: j.type = JointType::revolute; break;
    case urdf::Joint::PRISMATIC: j.type = JointType::prismatic; break;
    case urdf::Joint::FIXED: j.type = JointType::fixed; break;
    default:
      throw std::invalid_argument("URDF joint '" + uj.name + "': type " + type_name(uj.type) +
                                  " is not supported (mechbal reads revolute, continuous, prismatic "
                                  "and fixed joints; the root link is the fixed base)");
  }
  if (j.type != JointType::fixed) j.axis = Vec3(uj.axis.x, uj.axis.y, uj.axis.z);
  if (j.type != JointType::fixed && uj.limits) {
    const auto& L = *uj.limits;
    if (uj.type != urdf::Joint::CONTINUOUS) {
      if (!std::isfinite(L.lower) || !std::isfinite(L.upper) || L.lower > L.upper) {
        std::ostringstream m;
        m << "URDF joint '" << uj.name << "': limit lower must be <= upper (got " << L.lower << ", "
          << L.upper << ")";
        throw std::invalid_argument(m.str());
      }
      j.lower = L.lower;
      j.upper = L.upper;
    }
    j.velocity_limit = rate_limit(L.velocity, uj.name, "velocity");
    j.effort_limit = rate_limit(L.effort, uj.name, "effort");
  }
  if (uj.mimic) {
    j.mimic_joint = uj.mimic->joint_name;
    j.mimic_ratio = uj.mimic->multiplier;
    j.mimic_offset = uj.mimic->offset;
  }
  return j;
}

Body to_body(const urdf::Link& link, const std::string& carrier) {
  const urdf::Inertial& in = *link.inertial;
  const Eigen::Isometry3d T = to_isometry(in.origin);
  Mat3 I;
  I << in.ixx, in.ixy, in.ixz,  //
      in.ixy, in.iyy, in.iyz,   //
      in.ixz, in.iyz, in.izz;
  const std::string field = "URDF link '" + link.name + "' inertial";
  // checked in the inertial frame, as written (the rotation cannot make a bad tensor good)
  validate_rigid_body(RigidBody{in.mass, I}, field.c_str());
  if (!T.translation().allFinite()) {
    throw std::invalid_argument(field + " origin must be finite");
  }
  Body b;
  b.name = link.name;
  b.kind = "link";
  b.link = carrier;
  b.mass = in.mass;
  b.com = T.translation();
  b.inertia = T.linear() * I * T.linear().transpose();
  b.inertia = 0.5 * (b.inertia + b.inertia.transpose());  // exactly symmetric after rotation
  return b;
}

MechanismDescription describe(const urdf::ModelInterface& model) {
  const urdf::LinkConstSharedPtr root = model.getRoot();
  if (!root) throw std::invalid_argument("URDF: no root link");
  MechanismDescription d;
  d.root_name = root->name;

  // mimic targets first, with a URDF-level message (the model would name a description index)
  for (const auto& [name, uj] : model.joints_) {
    if (uj && uj->mimic && !model.getJoint(uj->mimic->joint_name)) {
      throw std::invalid_argument("URDF joint '" + name + "': mimic joint '" + uj->mimic->joint_name +
                                  "' does not exist");
    }
  }

  // depth-first from the root, children in urdfdom's order (Pinocchio's order)
  std::vector<std::pair<urdf::LinkConstSharedPtr, std::string>> stack{{root, d.root_name}};
  while (!stack.empty()) {
    auto [link, carrier] = stack.back();
    stack.pop_back();
    if (link->inertial) d.bodies.push_back(to_body(*link, carrier));
    d.frames.push_back(Frame{link->name, carrier, Eigen::Isometry3d::Identity()});
    // siblings in urdfdom's order (MechanismModel keeps the description's order among siblings);
    // pushed in reverse so that the first child is visited first
    for (const auto& uj : link->child_joints) d.joints.push_back(to_joint(*uj, carrier));
    for (auto it = link->child_joints.rbegin(); it != link->child_joints.rend(); ++it) {
      const urdf::Joint& uj = **it;
      const urdf::LinkConstSharedPtr child = model.getLink(uj.child_link_name);
      if (!child) {
        throw std::invalid_argument("URDF joint '" + uj.name + "': child link '" + uj.child_link_name +
                                    "' not found");
      }
      stack.emplace_back(child, uj.name);
    }
  }
  return d;
}

}  // namespace

MechanismDescription urdf_description_from_string(const std::string& xml) {
  const urdf::ModelInterfaceSharedPtr model = parse(xml);
  return describe(*model);
}

MechanismDescription urdf_description_from_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::invalid_argument("URDF file '" + path + "': cannot be read (" + std::strerror(errno) + ")");
  }
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return urdf_description_from_string(text.str());
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    if (what.rfind("URDF: ", 0) == 0) what.erase(0, 6);
    throw std::invalid_argument("URDF file '" + path + "': " + what);
  }
}

MechanismModel model_from_urdf_string(const std::string& xml) {
  return MechanismModel(urdf_description_from_string(xml));
}

MechanismModel model_from_urdf_file(const std::string& path) {
  MechanismDescription d = urdf_description_from_file(path);
  try {
    return MechanismModel(std::move(d));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("URDF file '" + path + "': " + e.what());
  }
}

}  // namespace mechbal
