// URDF input through urdfdom (see mechbal/urdf.hpp for the mapping).
#include "mechbal/io/urdf.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

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


// ---- pre-scan ----------------------------------------------------------------------------------
// urdfdom (TinyXML underneath) recurses once per nesting level and reads numbers leniently
// ("nan", "abc" -> 0), and the tree it builds is walked from the root: a document nested 100,000
// deep crashes it, a joint cycle makes the walk endless. One streaming pass (no recursion, O(size))
// checks the size, the nesting depth, every number mechbal reads, and the joints' tree structure
// before urdfdom sees the document.

std::string line_of(const std::string& xml, std::size_t pos) {
  std::size_t line = 1;
  for (std::size_t i = 0; i < pos && i < xml.size(); ++i) line += xml[i] == '\n';
  return "line " + std::to_string(line);
}

/// Strict number: the whole token, finite (a leading '+' allowed).
bool strict_number(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size()) return false;
  if (ec == std::errc::result_out_of_range) {  // an underflow (1e-320) reads as ~0, an overflow refused
    const std::string copy(token);
    return std::isfinite(std::strtod(copy.c_str(), nullptr));
  }
  return ec == std::errc() && std::isfinite(value);
}

/// The numeric attributes of the elements mechbal reads (inside a <link> or a <joint>).
bool numeric_attribute(std::string_view element, std::string_view attribute) {
  static const std::map<std::string_view, std::set<std::string_view>> table{
      {"mass", {"value"}},
      {"inertia", {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}},
      {"origin", {"xyz", "rpy"}},
      {"axis", {"xyz"}},
      {"limit", {"lower", "upper", "effort", "velocity"}},
      {"mimic", {"multiplier", "offset"}},
      {"dynamics", {"damping", "friction"}},
      {"safety_controller", {"soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"}},
      {"calibration", {"rising", "falling"}},
  };
  const auto it = table.find(element);
  return it != table.end() && it->second.count(attribute) > 0;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

struct ScannedJoint {
  std::string name, parent, child;
};

void check_tree(const std::vector<ScannedJoint>& joints) {
  std::map<std::string, const ScannedJoint*> parent_joint;  // child link -> its joint
  for (const auto& j : joints) {
    if (j.parent.empty() || j.child.empty()) continue;  // urdfdom reports a missing parent/child
    if (j.parent == j.child) {
      throw std::invalid_argument("URDF joint '" + j.name + "': parent and child are the same link '" +
                                  j.child + "' (a joint cycle)");
    }
    const auto [it, inserted] = parent_joint.emplace(j.child, &j);
    if (!inserted) {
      throw std::invalid_argument("URDF link '" + j.child + "' is the child of two joints ('" + it->second->name +
                                  "' and '" + j.name + "'): a URDF is a tree, each link has one parent joint");
    }
  }
  // each link has at most one parent: follow parents; a walk that comes back is a cycle
  std::map<std::string, int> state;  // 1 = on the current walk, 2 = reaches the root
  for (const auto& start : parent_joint) {
    std::vector<std::string> walk;
    std::string link = start.first;
    while (true) {
      auto& s = state[link];
      if (s == 2) break;
      if (s == 1) {  // cycle: from `link` back to `link`
        std::string names;
        auto first = std::find(walk.begin(), walk.end(), link);
        for (auto it = first; it != walk.end(); ++it) {
          names += (names.empty() ? "'" : " <- '") + parent_joint.at(*it)->name + "'";
        }
        throw std::invalid_argument("URDF: joints " + names + " form a cycle (through link '" + link +
                                    "'): a URDF is a tree");
      }
      s = 1;
      walk.push_back(link);
      const auto p = parent_joint.find(link);
      if (p == parent_joint.end()) break;  // a root
      link = p->second->parent;
    }
    for (const auto& l : walk) state[l] = 2;
  }
}

void prescan(const std::string& xml) {
  if (xml.size() > kMaxUrdfBytes) {
    throw std::invalid_argument("URDF: the document is " + std::to_string(xml.size()) +
                                " bytes, more than a URDF may be (" + std::to_string(kMaxUrdfBytes) + ")");
  }
  const std::size_t n = xml.size();
  std::vector<std::string> open;  // element names from the root down
  std::string context;            // "link 'x'" / "joint 'y'" of the current depth-2 element
  std::vector<ScannedJoint> joints;
  bool in_joint = false;
  std::size_t i = 0;
  auto skip_to = [&](const char* end) {
    const std::size_t at = xml.find(end, i);
    if (at == std::string::npos) return false;
    i = at + std::strlen(end);
    return true;
  };
  while (i < n) {
    if (xml[i] != '<') {
      ++i;
      continue;
    }
    const std::size_t tag = i;
    if (xml.compare(i, 4, "<!--") == 0) {
      if (!skip_to("-->")) return;  // malformed: urdfdom says where
      continue;
    }
    if (xml.compare(i, 9, "<![CDATA[") == 0) {
      if (!skip_to("]]>")) return;
      continue;
    }
    if (xml.compare(i, 2, "<?") == 0) {
      if (!skip_to("?>")) return;
      continue;
    }
    if (xml.compare(i, 2, "<!") == 0) {  // DOCTYPE, possibly with an internal subset [...]
      const std::size_t gt = xml.find('>', i), br = xml.find('[', i);
      if (br != std::string::npos && br < gt) {
        if (!skip_to("]>")) return;
      } else if (!skip_to(">")) {
        return;
      }
      continue;
    }
    if (xml.compare(i, 2, "</") == 0) {
      if (!skip_to(">")) return;
      if (!open.empty()) open.pop_back();
      if (open.size() < 2) {
        context.clear();
        in_joint = false;
      }
      continue;
    }
    // a start tag: name, attributes, '>' or '/>'
    ++i;
    const std::size_t name_start = i;
    while (i < n && !is_space(xml[i]) && xml[i] != '>' && xml[i] != '/') ++i;
    const std::string name = xml.substr(name_start, i - name_start);
    if (name.empty()) return;
    const std::size_t depth = open.size() + 1;
    if (depth > kMaxUrdfDepth) {
      throw std::invalid_argument("URDF: elements nest more than " + std::to_string(kMaxUrdfDepth) +
                                  " deep (<" + name.substr(0, 40) + "> at " + line_of(xml, tag) +
                                  "); a URDF needs a few levels");
    }
    const bool top = depth == 2 && (name == "link" || name == "joint");
    if (depth == 2) {
      context.clear();
      in_joint = name == "joint";
      if (in_joint) joints.push_back({});
    }
    bool self_closing = false;
    while (true) {
      while (i < n && is_space(xml[i])) ++i;
      if (i >= n) return;
      if (xml[i] == '>') {
        ++i;
        break;
      }
      if (xml[i] == '/') {
        if (i + 1 < n && xml[i + 1] == '>') {
          self_closing = true;
          i += 2;
          break;
        }
        return;
      }
      const std::size_t attr_start = i;
      while (i < n && !is_space(xml[i]) && xml[i] != '=' && xml[i] != '>' && xml[i] != '/') ++i;
      const std::string attr = xml.substr(attr_start, i - attr_start);
      while (i < n && is_space(xml[i])) ++i;
      if (i >= n || xml[i] != '=') return;
      ++i;
      while (i < n && is_space(xml[i])) ++i;
      if (i >= n || (xml[i] != '"' && xml[i] != '\'')) return;
      const char quote = xml[i++];
      const std::size_t value_start = i;
      const std::size_t value_end = xml.find(quote, i);
      if (value_end == std::string::npos) return;
      i = value_end + 1;
      const std::string_view value(xml.data() + value_start, value_end - value_start);
      if (top && attr == "name") {
        context = name + " '" + std::string(value) + "'";
        if (in_joint) joints.back().name = std::string(value);
      }
      if (in_joint && depth == 3 && attr == "link" && (name == "parent" || name == "child")) {
        (name == "parent" ? joints.back().parent : joints.back().child) = std::string(value);
      }
      if (depth >= 3 && !context.empty() && numeric_attribute(name, attr)) {
        std::size_t k = 0;
        bool any = false;
        while (k < value.size()) {
          while (k < value.size() && is_space(value[k])) ++k;
          const std::size_t t = k;
          while (k < value.size() && !is_space(value[k])) ++k;
          if (k == t) break;
          any = true;
          const std::string_view token = value.substr(t, k - t);
          if (!strict_number(token)) {
            throw std::invalid_argument("URDF " + context + " <" + name + " " + attr + "=\"" +
                                        std::string(value.substr(0, 60)) + "\">: '" +
                                        std::string(token.substr(0, 40)) + "' is not a finite number (" +
                                        line_of(xml, tag) + ")");
          }
        }
        if (!any) {
          throw std::invalid_argument("URDF " + context + " <" + name + " " + attr +
                                      "=\"\">: a number is required (" + line_of(xml, tag) + ")");
        }
      }
    }
    if (!self_closing) open.push_back(name);
    if (self_closing && depth == 2) {
      context.clear();
      in_joint = false;
    }
  }
  check_tree(joints);
}

urdf::ModelInterfaceSharedPtr parse(const std::string& xml) {
  prescan(xml);
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

/// validate_rigid_body's tolerances are absolute below 1 kg m^2 (1e-12), so a tiny inertia whose
/// rounding breaks the triangle inequality by 100 % of itself passes them (icub's 1e-20 products of
/// inertia, which MuJoCo refuses). A URDF inertia is also checked against its own size: principal
/// moments >= -1e-12 |I| and A + B >= C - 1e-12 |I|, |I| its largest moment in magnitude.
void check_inertia_to_its_own_scale(const Mat3& I, const std::string& field) {
  Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (I + I.transpose()), Eigen::EigenvaluesOnly);
  const Vec3 p = eig.eigenvalues();  // ascending
  const double tol = 1e-12 * p.cwiseAbs().maxCoeff();
  if (p(0) < -tol || p(2) > p(0) + p(1) + tol) {
    std::ostringstream msg;
    msg << field << ".inertia is not physical to its own scale (principal moments " << p(0) << ", " << p(1)
        << ", " << p(2) << ": negative, or A + B < C beyond rounding)";
    throw std::invalid_argument(msg.str());
  }
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
  check_inertia_to_its_own_scale(I, field);
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

// ---- lenient reading (issue 23): the repairs of UrdfOptions, each with its warning ----------

/// The nearest physical inertia (see UrdfOptions): S = tr(I)/2 1 - I clipped to S >= 1e-12 tr(S)
/// (not to 0: the triangle inequality then holds with 1e-12 of the trace to spare, not on its
/// boundary, where rounding would put it on either side of another engine's check).
Mat3 nearest_physical_inertia(const Mat3& I_in) {
  const Mat3 I = 0.5 * (I_in + I_in.transpose());
  const Mat3 S = 0.5 * I.trace() * Mat3::Identity() - I;
  Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
  const Vec3 clipped = eig.eigenvalues().cwiseMax(0.0);
  const Vec3 lam = clipped.cwiseMax(1e-12 * clipped.sum());
  const Mat3 Sp = eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
  Mat3 out = Sp.trace() * Mat3::Identity() - Sp;
  return 0.5 * (out + out.transpose());
}

std::string matrix_text(const Mat3& I) {
  std::ostringstream m;
  m << "[" << I.format(Eigen::IOFormat(4, 0, ", ", "; ")) << "]";
  return m.str();
}

double total_mass(const urdf::ModelInterface& model) {
  double total = 0.0;
  for (const auto& [name, link] : model.links_) {
    if (link && link->inertial && std::isfinite(link->inertial->mass) && link->inertial->mass > 0.0) {
      total += link->inertial->mass;
    }
  }
  return total;
}

/// The body of `link` under the options: validated; a negligible body with a non-physical inertia
/// regularised (lenient) or, on the root, dropped (returns false). Warnings appended.
bool lenient_body(const urdf::Link& link, const std::string& carrier, bool is_root, double total,
                  const UrdfOptions& options, std::vector<std::string>& warnings, Body& out) {
  try {
    out = to_body(link, carrier);
    return true;
  } catch (const std::invalid_argument& e) {
    const urdf::Inertial& in = *link.inertial;
    const bool negligible = std::isfinite(in.mass) && in.mass >= 0.0 &&
                            in.mass <= kNegligibleMassFraction * total;
    if (options.strict) throw;
    std::ostringstream w;
    if (is_root && negligible) {
      w << "URDF link '" << link.name << "' <inertial>: dropped (a negligible placeholder of "
        << in.mass << " kg on the fixed root, whose inertia is not physical: " << e.what() << ")";
      warnings.push_back(w.str());
      return false;
    }
    urdf::Link fixed = link;
    auto inertial = std::make_shared<urdf::Inertial>(in);
    Mat3 I;
    I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    if (!I.allFinite()) throw;
    const Mat3 P = nearest_physical_inertia(I);
    inertial->ixx = P(0, 0), inertial->iyy = P(1, 1), inertial->izz = P(2, 2);
    inertial->ixy = P(0, 1), inertial->ixz = P(0, 2), inertial->iyz = P(1, 2);
    fixed.inertial = inertial;
    out = to_body(fixed, carrier);  // throws if still not physical (not expected)
    w << "URDF link '" << link.name << "' <inertial>: inertia " << matrix_text(I) << " is not physical";
    if (negligible) {
      w << " on a negligible body (" << in.mass << " kg <= " << kNegligibleMassFraction
        << " of the total " << total << " kg)";
    } else {
      w << " (a body of " << in.mass << " kg, not negligible: the dynamics differ from the file's; "
        << "correct the file)";
    }
    w << ": replaced by the nearest physical one " << matrix_text(P);
    warnings.push_back(w.str());
    return true;
  }
}

/// Fixed joints with a <mimic>: ignored with a warning (lenient) or refused (strict).
void check_fixed_mimic(const urdf::ModelInterface& model, const UrdfOptions& options,
                       std::vector<std::string>& warnings) {
  for (const auto& [name, uj] : model.joints_) {
    if (!uj || !uj->mimic || uj->type != urdf::Joint::FIXED) continue;
    const std::string what = "URDF joint '" + name + "': <mimic joint=\"" + uj->mimic->joint_name +
                             "\"> on a fixed joint";
    if (options.strict) {
      throw std::invalid_argument(what + " (a fixed joint has no coordinate to couple; the lenient "
                                         "reading ignores it)");
    }
    warnings.push_back(what + ": ignored (a fixed joint has no coordinate to couple)");
  }
}

/// No <inertial> on any link that moves: refused unless allow_massless.
void check_massless(const urdf::ModelInterface& model, const MechanismDescription& d,
                    const UrdfOptions& options, std::vector<std::string>& warnings) {
  bool moves = false;
  for (const auto& j : d.joints) moves = moves || j.type != JointType::fixed;
  if (!moves) return;
  for (const auto& b : d.bodies) {
    if (b.link != d.root_name) return;  // a body on a moving link
  }
  (void)model;
  const std::string what = "no <inertial> on any moving link: every mass, gravity and inertia "
                           "torque would be zero";
  if (!options.allow_massless) {
    throw std::invalid_argument("URDF: " + what + " (give --allow-massless, or allow_massless=True "
                                "in Python, to load it for kinematics only)");
  }
  warnings.push_back("URDF: " + what + ": loaded for kinematics only (allow_massless)");
}

MechanismDescription describe(const urdf::ModelInterface& model, const UrdfOptions& options,
                              std::vector<std::string>& warnings);

MechanismDescription describe(const urdf::ModelInterface& model) {
  std::vector<std::string> warnings;
  return describe(model, UrdfOptions{true, true}, warnings);
}

MechanismDescription describe(const urdf::ModelInterface& model, const UrdfOptions& options,
                              std::vector<std::string>& warnings) {
  const urdf::LinkConstSharedPtr root = model.getRoot();
  if (!root) throw std::invalid_argument("URDF: no root link");
  MechanismDescription d;
  d.root_name = root->name;
  check_fixed_mimic(model, options, warnings);
  const double total = total_mass(model);

  // mimic targets first, with a URDF-level message (the model would name a description index)
  std::vector<std::string> orphan_mimics;  // lenient: a mimic of a missing joint is dropped
  for (const auto& [name, uj] : model.joints_) {
    if (uj && uj->mimic && !model.getJoint(uj->mimic->joint_name)) {
      const std::string what = "URDF joint '" + name + "': mimic joint '" + uj->mimic->joint_name +
                               "' does not exist";
      if (options.strict) throw std::invalid_argument(what);
      warnings.push_back(what + ": <mimic> ignored (an independent joint, as Pinocchio reads it)");
      orphan_mimics.push_back(name);
    }
  }

  // depth-first from the root, children in urdfdom's order (Pinocchio's order)
  std::vector<std::pair<urdf::LinkConstSharedPtr, std::string>> stack{{root, d.root_name}};
  std::set<std::string> visited;  // the pre-scan refuses cycles; this keeps the walk finite anyway
  while (!stack.empty()) {
    auto [link, carrier] = stack.back();
    stack.pop_back();
    if (!visited.insert(link->name).second) {
      throw std::invalid_argument("URDF link '" + link->name + "' is reached twice from the root (joint '" +
                                  carrier + "'): a URDF is a tree");
    }
    if (link->inertial) {
      Body b;
      if (lenient_body(*link, carrier, link == root, total, options, warnings, b)) d.bodies.push_back(b);
    }
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
  for (auto& j : d.joints) {  // mimics ignored above (lenient): not couplings
    if (j.type == JointType::fixed) j.mimic_joint.clear();
    for (const auto& o : orphan_mimics) {
      if (j.name == o) j.mimic_joint.clear();
    }
  }
  check_massless(model, d, options, warnings);
  return d;
}

/// "joints[3]" -> "URDF joint 'elbow'", "bodies[2]" -> "URDF link 'x' <inertial>", "frames[1]"
/// -> "URDF link 'y'": the model's messages in the URDF's words.
std::string urdf_words(const std::string& message, const MechanismDescription& d) {
  static const std::regex index(R"((joints|bodies|frames)\[(\d+)\])");
  std::string out;
  auto begin = std::sregex_iterator(message.begin(), message.end(), index);
  std::size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    out += message.substr(last, static_cast<std::size_t>(m.position(0)) - last);
    const std::string kind = m[1];
    const std::size_t i = std::stoul(m[2]);
    std::string name;
    if (kind == "joints" && i < d.joints.size()) name = "URDF joint '" + d.joints[i].name + "'";
    if (kind == "bodies" && i < d.bodies.size()) name = "URDF link '" + d.bodies[i].name + "' <inertial>";
    if (kind == "frames" && i < d.frames.size()) name = "URDF link '" + d.frames[i].name + "'";
    out += name.empty() ? m.str(0) : name;
    last = static_cast<std::size_t>(m.position(0) + m.length(0));
  }
  return out + message.substr(last);
}

/// The text of a URDF file: a regular file of bounded size only (/dev/zero would be read forever,
/// a FIFO would block).
std::string read_checked_file(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    throw std::invalid_argument("URDF file '" + path + "': " +
                                (std::filesystem::is_directory(status) ? "is a folder" : "is not a regular file") +
                                ", not a URDF file");
  }
  if (!ec && std::filesystem::is_regular_file(status)) {
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxUrdfBytes) {
      throw std::invalid_argument("URDF file '" + path + "': is " + std::to_string(size) +
                                  " bytes, more than a URDF may be (" + std::to_string(kMaxUrdfBytes) + ")");
    }
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::invalid_argument("URDF file '" + path + "': cannot be read (" + std::strerror(errno) + ")");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

UrdfReading read_urdf_string(const std::string& xml, const UrdfOptions& options) {
  try {
    const urdf::ModelInterfaceSharedPtr model = parse(xml);
    UrdfReading r;
    r.description = describe(*model, options, r.warnings);
    return r;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(one_line(e.what()));  // names and values may hold line breaks
  }
}

UrdfReading read_urdf_file(const std::string& path, const UrdfOptions& options) {
  const std::string text = read_checked_file(path);
  try {
    return read_urdf_string(text, options);
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    if (what.rfind("URDF: ", 0) == 0) what.erase(0, 6);
    throw std::invalid_argument("URDF file '" + path + "': " + what);
  }
}

MechanismModel model_from_urdf_reading(UrdfReading reading, const std::string& source) {
  const MechanismDescription copy = reading.description;
  try {
    return MechanismModel(std::move(reading.description));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + urdf_words(e.what(), copy));
  }
}

MechanismDescription urdf_description_from_string(const std::string& xml) {
  try {
    const urdf::ModelInterfaceSharedPtr model = parse(xml);
    return describe(*model);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(one_line(e.what()));  // names and values may hold line breaks
  }
}

MechanismDescription urdf_description_from_file(const std::string& path) {
  const std::string text = read_checked_file(path);
  try {
    return urdf_description_from_string(text);
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
