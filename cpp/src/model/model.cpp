#include "mechbal/model/model.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "mechbal/model/data.hpp"

namespace mechbal {

namespace {

void check_name(const std::string& field, const std::string& name) {
  const std::string why = name_problem(name);
  if (!why.empty()) throw std::invalid_argument(field + " " + why);
}

std::string joint_field(std::size_t i, const Joint& j, const char* field) {
  std::ostringstream s;
  s << "joints[" << i << "]";
  if (!j.name.empty()) s << " (" << j.name << ")";
  s << "." << field;
  return s.str();
}

std::string indexed_field(const char* table, std::size_t i, const std::string& name,
                          const char* field) {
  std::ostringstream s;
  s << table << "[" << i << "]";
  if (!name.empty()) s << " (" << name << ")";
  s << "." << field;
  return s.str();
}

void check_placement(const Eigen::Isometry3d& T, const std::string& field) {
  if (!T.matrix().allFinite()) throw std::invalid_argument(field + " must be finite");
  const Mat3 R = T.linear();
  if ((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 || R.determinant() < 0.0) {
    throw std::invalid_argument(field + " rotation is not a proper orthonormal matrix");
  }
}

/// A rotation within rounding of a signed permutation is that permutation: rpy angles of +-pi/2
/// (URDF's usual way to turn a frame at a right angle) leave cos(pi/2) = 6e-17 where the zeros
/// belong, and 1 - 1e-16 for the ones. When every entry is within 4 ulp of 0, 1 or -1, each is set
/// to it (an orthonormal R then becomes an exact signed permutation: it has one entry near +-1 per
/// row and column). The model moves by at most 1e-15, toward the rotation meant, and its links
/// take the passes' shortcuts for frames at right angles (MechanismModel::local_rotation).
void snap_right_angles(Eigen::Isometry3d& T) {
  constexpr double kSnap = 4.0 * std::numeric_limits<double>::epsilon();
  const Mat3 R = T.linear();
  for (Eigen::Index i = 0; i < 9; ++i) {
    const double x = std::abs(R.data()[i]);
    if (!(x <= kSnap || std::abs(x - 1.0) <= kSnap)) return;
  }
  T.linear() = R.unaryExpr([](double x) { return std::abs(x) <= kSnap ? 0.0 : x > 0.0 ? 1.0 : -1.0; });
}

/// A rotation A with A e_z = axis (axis unit): the joint-aligned frame of a link.
Mat3 aligned_with_z(const Vec3& axis) {
  Vec3 seed = Vec3::UnitX();
  if (std::abs(axis.y()) < std::abs(axis.x()) && std::abs(axis.y()) <= std::abs(axis.z())) {
    seed = Vec3::UnitY();
  } else if (std::abs(axis.z()) < std::abs(axis.x())) {
    seed = Vec3::UnitZ();
  }
  // exactly aligned axes keep the identity (or a permutation), so rotations stay exact
  if (axis.isApprox(Vec3::UnitZ(), 0.0)) return Mat3::Identity();
  const Vec3 x = (seed - seed.dot(axis) * axis).normalized();
  Mat3 A;
  A.col(0) = x;
  A.col(1) = axis.cross(x);
  A.col(2) = axis;
  return A;
}

std::string nearest(const std::string& name, const std::vector<std::string>& known) {
  // the known name with the smallest edit distance, for "did you mean" hints
  std::string best;
  std::size_t best_d = std::string::npos;
  for (const auto& k : known) {
    std::vector<std::size_t> prev(k.size() + 1), cur(k.size() + 1);
    for (std::size_t j = 0; j <= k.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= name.size(); ++i) {
      cur[0] = i;
      for (std::size_t j = 1; j <= k.size(); ++j) {
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (name[i - 1] != k[j - 1])});
      }
      std::swap(prev, cur);
    }
    if (prev[k.size()] < best_d) {
      best_d = prev[k.size()];
      best = k;
    }
  }
  // a near miss, or one name inside the other ('crank' for 'crank_joint')
  bool contains = false;
  for (const auto& k : known) {
    if (!name.empty() && (k.find(name) != std::string::npos || name.find(k) != std::string::npos)) {
      if (!contains || k.size() < best.size()) best = k;
      contains = true;
    }
  }
  if (best.empty() || (!contains && best_d > std::max<std::size_t>(2, name.size() / 3))) return "";
  return " (did you mean '" + best + "'?)";
}

}  // namespace

std::string name_problem(const std::string& name) {
  if (name.empty()) return "must not be empty";
  std::size_t count = 0;
  for (std::size_t i = 0; i < name.size();) {
    const auto b = static_cast<unsigned char>(name[i]);
    std::size_t len = b < 0x80 ? 1 : (b >> 5) == 6 ? 2 : (b >> 4) == 14 ? 3 : (b >> 3) == 30 ? 4 : 0;
    if (len == 0 || i + len > name.size()) return "is not valid UTF-8";
    char32_t c = len == 1 ? b : len == 2 ? (b & 0x1Fu) : len == 3 ? (b & 0x0Fu) : (b & 0x07u);
    for (std::size_t k = 1; k < len; ++k) {
      const auto x = static_cast<unsigned char>(name[i + k]);
      if ((x & 0xC0) != 0x80) return "is not valid UTF-8";
      c = (c << 6) | (x & 0x3Fu);
    }
    const char32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
    if (c < least[len] || c > 0x10FFFF) return "is not valid UTF-8";
    if (c < 0x20 || (c >= 0x7F && c <= 0x9F) || (c >= 0xD800 && c <= 0xDFFF) || (c >= 0xFDD0 && c <= 0xFDEF) ||
        (c & 0xFFFEu) == 0xFFFEu) {
      char code[16];
      std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(c));
      return std::string("must not contain the character ") + code +
             " (names are printable: no control character, surrogate or noncharacter)";
    }
    ++count;
    i += len;
  }
  if (count > kMaxNameCharacters) return "must have at most " + std::to_string(kMaxNameCharacters) + " characters";
  return "";
}

MechanismModel::MechanismModel(MechanismDescription d) {
  check_name("root_name", d.root_name);
  if (!d.gravity.allFinite()) throw std::invalid_argument("gravity must be finite");
  root_name_ = d.root_name;
  gravity_ = d.gravity;

  // ---- joints: names, parents, types, axes, limits ----
  std::map<std::string, std::size_t> by_name;
  std::vector<std::string> link_names{d.root_name};
  for (std::size_t i = 0; i < d.joints.size(); ++i) {
    Joint& j = d.joints[i];
    check_name("joints[" + std::to_string(i) + "].name", j.name);
    if (j.name == d.root_name) {
      throw std::invalid_argument(joint_field(i, j, "name") + " must differ from the root link's name '" +
                                  d.root_name + "'");
    }
    if (!by_name.emplace(j.name, i).second) {
      throw std::invalid_argument(joint_field(i, j, "name") + " is used by two joints");
    }
    link_names.push_back(j.name);
  }
  for (std::size_t i = 0; i < d.joints.size(); ++i) {
    Joint& j = d.joints[i];
    if (j.parent != d.root_name && !by_name.count(j.parent)) {
      throw std::invalid_argument(joint_field(i, j, "parent") + ": no link named '" + j.parent + "'" +
                                  nearest(j.parent, link_names));
    }
    if (j.parent == j.name) throw std::invalid_argument(joint_field(i, j, "parent") + " is the joint itself");
    check_placement(j.placement, joint_field(i, j, "placement"));
    snap_right_angles(j.placement);
    if (j.type != JointType::fixed) {
      const double scale = j.axis.cwiseAbs().maxCoeff();
      if (!j.axis.allFinite() || !(scale > 0.0)) {
        std::ostringstream m;
        m << joint_field(i, j, "axis") << " must be a finite non-zero vector, got ["
          << j.axis.transpose() << "]";
        throw std::invalid_argument(m.str());
      }
      const Vec3 a = j.axis / scale;  // scaled first: no overflow of the norm
      j.axis = a / a.norm();
    } else {
      j.axis = Vec3::UnitZ();
    }
    if (std::isnan(j.lower) || std::isnan(j.upper) || j.lower > j.upper) {
      std::ostringstream m;
      m << joint_field(i, j, "limits") << ": lower must be <= upper (got " << j.lower << ", "
        << j.upper << ")";
      throw std::invalid_argument(m.str());
    }
    if (!(j.velocity_limit > 0.0) || !(j.effort_limit > 0.0)) {
      std::ostringstream m;
      m << joint_field(i, j, "limits") << ": velocity and effort limits must be > 0 (got "
        << j.velocity_limit << ", " << j.effort_limit << ")";
      throw std::invalid_argument(m.str());
    }
    if (!j.mimic_joint.empty()) {
      if (j.type == JointType::fixed) {
        throw std::invalid_argument(joint_field(i, j, "mimic") + ": a fixed joint cannot follow a gear coupling");
      }
      if (j.mimic_joint == j.name) throw std::invalid_argument(joint_field(i, j, "mimic") + " names the joint itself");
      auto it = by_name.find(j.mimic_joint);
      if (it == by_name.end()) {
        std::vector<std::string> names(link_names.begin() + 1, link_names.end());
        throw std::invalid_argument(joint_field(i, j, "mimic") + ": no joint named '" + j.mimic_joint +
                                    "'" + nearest(j.mimic_joint, names));
      }
      if (d.joints[it->second].type == JointType::fixed) {
        throw std::invalid_argument(joint_field(i, j, "mimic") + ": joint '" + j.mimic_joint +
                                    "' is fixed and has no coordinate to follow");
      }
      if (!std::isfinite(j.mimic_ratio) || !std::isfinite(j.mimic_offset)) {
        throw std::invalid_argument(joint_field(i, j, "mimic") + ": ratio and offset must be finite");
      }
    }
  }

  // ---- depth-first order from the root; unreached joints form a cycle ----
  std::map<std::string, std::vector<std::size_t>> children;
  for (std::size_t i = 0; i < d.joints.size(); ++i) children[d.joints[i].parent].push_back(i);
  std::vector<std::size_t> order;  // description indices in DFS order
  std::vector<std::pair<std::string, std::size_t>> stack;  // (link name, next child)
  stack.emplace_back(d.root_name, 0);
  while (!stack.empty()) {
    auto& top = stack.back();
    auto it = children.find(top.first);
    if (it == children.end() || top.second >= it->second.size()) {
      stack.pop_back();
      continue;
    }
    const std::size_t child = it->second[top.second++];
    order.push_back(child);
    stack.emplace_back(d.joints[child].name, 0);
  }
  if (order.size() != d.joints.size()) {
    std::vector<bool> seen(d.joints.size(), false);
    for (auto k : order) seen[k] = true;
    for (std::size_t i = 0; i < d.joints.size(); ++i) {
      if (!seen[i]) {
        throw std::invalid_argument(joint_field(i, d.joints[i], "parent") + ": '" + d.joints[i].parent +
                                    "' does not lead to the root '" + d.root_name + "' (a cycle)");
      }
    }
  }

  // ---- fold fixed joints into their moving ancestor (as Pinocchio's URDF reader does): their
  // children hang from the ancestor with the composed placement, and the bodies and frames they
  // carry are moved onto it (below). Fewer links: every pass and column walk is shorter, and a
  // chain with welded tool links is still a serial chain.
  std::map<std::string, std::pair<std::string, Eigen::Isometry3d>> folded;  // name -> (carrier, pose)
  {
    std::vector<std::size_t> moving;
    for (auto k : order) {
      Joint& j = d.joints[k];
      auto f = folded.find(j.parent);
      if (f != folded.end()) {
        j.parent = f->second.first;
        j.placement = f->second.second * j.placement;
      }
      if (j.type == JointType::fixed) {
        folded[j.name] = {j.parent, j.placement};
      } else {
        moving.push_back(k);
      }
    }
    order = moving;
  }
  auto fold = [&](std::string& link, Eigen::Isometry3d* pose) {
    auto f = folded.find(link);
    if (f == folded.end()) return false;
    link = f->second.first;
    if (pose) *pose = f->second.second * *pose;
    return true;
  };
  for (Body& body : d.bodies) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    if (fold(body.link, &T) && body.com.allFinite() && body.inertia.allFinite()) {
      body.com = T * body.com;
      body.inertia = T.linear() * body.inertia * T.linear().transpose();
    }
  }
  for (Frame& fr : d.frames) fold(fr.link, &fr.placement);
  for (Spring& sp : d.springs) {
    Eigen::Isometry3d Ta = Eigen::Isometry3d::Identity(), Tb = Eigen::Isometry3d::Identity();
    if (fold(sp.link_a, &Ta) && sp.anchor_a.allFinite()) sp.anchor_a = Ta * sp.anchor_a;
    if (fold(sp.link_b, &Tb) && sp.anchor_b.allFinite()) sp.anchor_b = Tb * sp.anchor_b;
  }

  // ---- links in DFS order ----
  const std::size_t nl = order.size() + 1;
  link_names_.assign(1, d.root_name);
  parent_.assign(1, -1);
  type_.assign(1, JointType::fixed);
  placement_.assign(1, Eigen::Isometry3d::Identity());
  axis_.assign(1, Vec3::UnitZ());
  std::map<std::string, int> link_of;
  link_of[d.root_name] = 0;
  std::vector<Joint> ordered;
  ordered.reserve(d.joints.size());
  for (auto k : order) {
    const Joint& j = d.joints[k];
    link_of[j.name] = static_cast<int>(link_names_.size());
    link_names_.push_back(j.name);
    parent_.push_back(link_of.at(j.parent));
    type_.push_back(j.type);
    placement_.push_back(j.placement);
    axis_.push_back(j.axis);
    ordered.push_back(j);
  }

  // ---- coordinates: independent joints in link order; gear couplings resolved to a master ----
  coordinate_.assign(nl, -1);
  ratio_.assign(nl, 1.0);
  offset_.assign(nl, 0.0);
  std::vector<double> lo, up, vl, el;
  for (std::size_t l = 1; l < nl; ++l) {
    const Joint& j = ordered[l - 1];
    if (j.type == JointType::fixed || !j.mimic_joint.empty()) continue;
    coordinate_[l] = dof_++;
    coordinate_names_.push_back(j.name);
    lo.push_back(j.lower);
    up.push_back(j.upper);
    vl.push_back(j.velocity_limit);
    el.push_back(j.effort_limit);
  }
  for (std::size_t l = 1; l < nl; ++l) {
    const Joint& j = ordered[l - 1];
    if (j.mimic_joint.empty()) continue;
    double ratio = j.mimic_ratio, offset = j.mimic_offset;
    std::string master = j.mimic_joint;
    for (std::size_t hops = 0;; ++hops) {
      if (hops > nl) {
        throw std::invalid_argument("joints (" + j.name + ").mimic: gear couplings form a cycle");
      }
      const Joint& m = ordered[static_cast<std::size_t>(link_of.at(master)) - 1];
      if (m.mimic_joint.empty()) break;
      offset = ratio * m.mimic_offset + offset;  // q = r (r_m q_mm + o_m) + o
      ratio *= m.mimic_ratio;
      master = m.mimic_joint;
    }
    coordinate_[l] = coordinate_[static_cast<std::size_t>(link_of.at(master))];
    ratio_[l] = ratio;
    offset_[l] = offset;
  }
  auto to_vec = [](const std::vector<double>& v) {
    return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())).eval();
  };
  lower_ = to_vec(lo);
  upper_ = to_vec(up);
  velocity_limit_ = to_vec(vl);
  effort_limit_ = to_vec(el);

  // ---- bodies ----
  std::map<std::string, std::size_t> body_names;
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const Body& body = d.bodies[b];
    check_name("bodies[" + std::to_string(b) + "].name", body.name);
    if (!body_names.emplace(body.name, b).second) {
      throw std::invalid_argument(indexed_field("bodies", b, body.name, "name") + " is used by two bodies");
    }
    auto it = link_of.find(body.link);
    if (it == link_of.end()) {
      throw std::invalid_argument(indexed_field("bodies", b, body.name, "link") + ": no link named '" +
                                  body.link + "'" + nearest(body.link, link_names_));
    }
    if (!body.com.allFinite()) throw std::invalid_argument(indexed_field("bodies", b, body.name, "com") + " must be finite");
    RigidBody rb{body.mass, body.inertia};
    validate_rigid_body(rb, indexed_field("bodies", b, body.name, "mass").c_str());
    bodies_.push_back(body);
    body_link_.push_back(it->second);
    total_mass_ += body.mass;
  }

  // ---- frames ----
  std::map<std::string, std::size_t> frame_names;
  for (std::size_t f = 0; f < d.frames.size(); ++f) {
    const Frame& fr = d.frames[f];
    check_name("frames[" + std::to_string(f) + "].name", fr.name);
    if (!frame_names.emplace(fr.name, f).second) {
      throw std::invalid_argument(indexed_field("frames", f, fr.name, "name") + " is used by two frames");
    }
    auto it = link_of.find(fr.link);
    if (it == link_of.end()) {
      throw std::invalid_argument(indexed_field("frames", f, fr.name, "link") + ": no link named '" +
                                  fr.link + "'" + nearest(fr.link, link_names_));
    }
    check_placement(fr.placement, indexed_field("frames", f, fr.name, "placement"));
    frames_.push_back(fr);
    frame_link_.push_back(it->second);
  }

  // ---- constants: joint-aligned frames and lumped inertia per link ----
  constants_.resize(nl);
  for (std::size_t l = 0; l < nl; ++l) {
    LinkConstants& c = constants_[l];
    c.aligned = type_[l] == JointType::fixed ? Mat3::Identity() : aligned_with_z(axis_[l]);
    const Mat3 A_parent = l == 0 ? Mat3::Identity() : constants_[static_cast<std::size_t>(parent_[l])].aligned;
    c.rotation = A_parent.transpose() * placement_[l].linear() * c.aligned;
    c.translation = A_parent.transpose() * placement_[l].translation();
    c.mass = 0.0;
    c.first_moment.setZero();
    c.inertia_origin.setZero();
  }
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    LinkConstants& c = constants_[static_cast<std::size_t>(body_link_[b])];
    const Vec3 com = c.aligned.transpose() * bodies_[b].com;
    const Mat3 I = c.aligned.transpose() * bodies_[b].inertia * c.aligned;
    const double m = bodies_[b].mass;
    c.mass += m;
    c.first_moment += m * com;
    c.inertia_origin += I + m * (com.squaredNorm() * Mat3::Identity() - com * com.transpose());
  }
  local_rotation_.assign(nl, LocalRotation::general);
  for (std::size_t l = 1; l < nl; ++l) {
    const Mat3& C = constants_[l].rotation;
    if (!C.unaryExpr([](double x) { return x == 0.0 || x == 1.0 || x == -1.0 ? 0.0 : 1.0; }).isZero(0.0)) continue;
    if (type_[l] != JointType::revolute && C == Mat3::Identity()) {
      local_rotation_[l] = LocalRotation::identity;
      continue;
    }
    Eigen::Index axis = 0;  // the row of C e_z's one nonzero entry
    C.col(2).cwiseAbs().maxCoeff(&axis);
    local_rotation_[l] = axis == 0 ? LocalRotation::along_x : axis == 1 ? LocalRotation::along_y : LocalRotation::along_z;
  }
  has_aligned_links_ = std::any_of(local_rotation_.begin() + 1, local_rotation_.end(),
                                   [](LocalRotation r) { return r != LocalRotation::general; });
  has_inertia_.assign(nl, 0);
  inertial_links_.clear();
  for (std::size_t l = 1; l < nl; ++l) {
    const LinkConstants& c = constants_[l];
    if (c.mass != 0.0 || !c.first_moment.isZero(0.0) || !c.inertia_origin.isZero(0.0)) {
      has_inertia_[l] = 1;
      inertial_links_.push_back(static_cast<int>(l));
    }
  }

  // ---- springs ----
  std::map<std::string, std::size_t> spring_names;
  for (std::size_t i = 0; i < d.springs.size(); ++i) {
    const Spring& sp = d.springs[i];
    auto field = [&](const char* f) { return indexed_field("springs", i, sp.name, f); };
    auto value = [](double x) {
      std::ostringstream s;
      s << x;
      return s.str();
    };
    check_name("springs[" + std::to_string(i) + "].name", sp.name);
    if (!spring_names.emplace(sp.name, i).second) throw std::invalid_argument(field("name") + " is used by two springs");
    int links[2];
    for (int side = 0; side < 2; ++side) {
      const std::string& link = side == 0 ? sp.link_a : sp.link_b;
      const Vec3& anchor = side == 0 ? sp.anchor_a : sp.anchor_b;
      auto it = link_of.find(link);
      if (it == link_of.end()) {
        throw std::invalid_argument(field(side == 0 ? "link_a" : "link_b") + ": no link named '" + link + "'" +
                                    nearest(link, link_names_));
      }
      if (!anchor.allFinite()) throw std::invalid_argument(field(side == 0 ? "anchor_a" : "anchor_b") + " must be finite");
      links[side] = it->second;
    }
    if (links[0] == links[1]) {
      throw std::invalid_argument(field("link_b") + ": both anchors are on the same link ('" +
                                  link_names_[static_cast<std::size_t>(links[0])] +
                                  "', fixed joints folded), so the spring never changes length");
    }
    if (!(std::isfinite(sp.rate) && sp.rate >= 0.0)) throw std::invalid_argument(field("rate") + ": must be >= 0 [N/m], got " + value(sp.rate));
    if (!(std::isfinite(sp.free_length) && sp.free_length >= 0.0)) {
      throw std::invalid_argument(field("free_length") + ": must be >= 0 [m], got " + value(sp.free_length));
    }
    if (!(std::isfinite(sp.preload) && sp.preload >= 0.0)) {
      throw std::invalid_argument(field("preload") + ": must be >= 0 [N], got " + value(sp.preload));
    }
    if (sp.count < 1) throw std::invalid_argument(field("count") + ": must be >= 1, got " + std::to_string(sp.count));
    if (!(std::isfinite(sp.pulley_ratio) && sp.pulley_ratio > 0.0)) {
      throw std::invalid_argument(field("pulley_ratio") + ": must be > 0, got " + value(sp.pulley_ratio));
    }
    SpringConstants c;
    c.link_a = links[0];
    c.link_b = links[1];
    c.anchor_a = constants_[static_cast<std::size_t>(links[0])].aligned.transpose() * sp.anchor_a;
    c.anchor_b = constants_[static_cast<std::size_t>(links[1])].aligned.transpose() * sp.anchor_b;
    c.equivalent_rate = sp.count * sp.rate / (sp.pulley_ratio * sp.pulley_ratio);
    c.preload_tension = sp.count * sp.preload / sp.pulley_ratio;
    c.free_length = sp.free_length;
    springs_.push_back(sp);
    spring_constants_.push_back(c);
  }

  // ---- loops and actuation ----
  std::vector<std::string> frame_name_list;
  for (const auto& fr : frames_) frame_name_list.push_back(fr.name);
  std::map<std::string, std::size_t> loop_names;
  for (std::size_t i = 0; i < d.loops.size(); ++i) {
    const LoopConstraint& lc = d.loops[i];
    check_name("loops[" + std::to_string(i) + "].name", lc.name);
    if (!loop_names.emplace(lc.name, i).second) {
      throw std::invalid_argument(indexed_field("loops", i, lc.name, "name") + " is used by two loops");
    }
    const int fa = frame_index(lc.frame_a), fb = frame_index(lc.frame_b);
    if (fa < 0) {
      throw std::invalid_argument(indexed_field("loops", i, lc.name, "frame_a") + ": no frame named '" +
                                  lc.frame_a + "'" + nearest(lc.frame_a, frame_name_list));
    }
    if (fb < 0) {
      throw std::invalid_argument(indexed_field("loops", i, lc.name, "frame_b") + ": no frame named '" +
                                  lc.frame_b + "'" + nearest(lc.frame_b, frame_name_list));
    }
    if (frame_link_[static_cast<std::size_t>(fa)] == frame_link_[static_cast<std::size_t>(fb)]) {
      throw std::invalid_argument(indexed_field("loops", i, lc.name, "frame_b") +
                                  ": both frames are on the same link, so the loop closes nothing");
    }
    loops_.push_back(lc);
    loop_frames_.emplace_back(fa, fb);
    loop_rows_.push_back(num_constraints_);
    num_constraints_ += loop_equations(lc.type);
  }
  std::vector<bool> is_actuated(static_cast<std::size_t>(dof_), d.actuated.empty() && d.loops.empty());
  for (std::size_t i = 0; i < d.actuated.size(); ++i) {
    const auto& name = d.actuated[i];
    auto it = std::find(coordinate_names_.begin(), coordinate_names_.end(), name);
    if (it == coordinate_names_.end()) {
      throw std::invalid_argument("actuated[" + std::to_string(i) + "]: '" + name +
                                  "' is not a joint with a coordinate (a fixed or gear-coupled joint "
                                  "cannot be actuated)" + nearest(name, coordinate_names_));
    }
    const auto k = static_cast<std::size_t>(it - coordinate_names_.begin());
    if (is_actuated[k]) throw std::invalid_argument("actuated[" + std::to_string(i) + "]: '" + name + "' is named twice");
    is_actuated[k] = true;
  }
  if (!d.loops.empty() && d.actuated.empty()) {
    throw std::invalid_argument("actuated: a mechanism with loops must name its actuated joints");
  }
  for (int c = 0; c < dof_; ++c) (is_actuated[static_cast<std::size_t>(c)] ? actuated_ : passive_).push_back(c);

  serial_chain_ = nl > 1 && loops_.empty();
  for (std::size_t l = 1; l < nl; ++l) {
    if (parent_[l] != static_cast<int>(l) - 1 || type_[l] == JointType::fixed || ratio_[l] != 1.0 ||
        offset_[l] != 0.0 || coordinate_[l] != static_cast<int>(l) - 1) {
      serial_chain_ = false;
    }
  }

  d.joints = ordered;
  description_ = std::move(d);
}

int MechanismModel::link_index(const std::string& name) const noexcept {
  for (std::size_t i = 0; i < link_names_.size(); ++i) {
    if (link_names_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

int MechanismModel::body_index(const std::string& name) const noexcept {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int MechanismModel::spring_index(const std::string& name) const noexcept {
  for (std::size_t i = 0; i < springs_.size(); ++i) {
    if (springs_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int MechanismModel::frame_index(const std::string& name) const noexcept {
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    if (frames_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

bool MechanismData::size_dense(Eigen::MatrixXd& buffer, Eigen::Index rows, Eigen::Index cols) noexcept {
  if (buffer.rows() == rows && buffer.cols() == cols) return true;
  try {
    buffer.setZero(rows, cols);
    return true;
  } catch (...) {  // std::bad_alloc: the caller reports it as a Status
    buffer.resize(0, 0);
    return false;
  }
}

void MechanismData::reserve_mass_matrix() { mass_matrix.setZero(dof, dof); }

bool MechanismData::size_actuated_buffers(const MechanismModel& model) noexcept {
  const Eigen::Index na = model.num_actuated();
  if (loop_projection.rows() == dof && loop_projection.cols() == na && reduced_mass_matrix.rows() == na &&
      loop_reduced_work.cols() == na) {
    return true;
  }
  try {
    loop_projection.setZero(dof, na);
    for (Eigen::Index i = 0; i < na; ++i) loop_projection(model.actuated_coordinates()[static_cast<std::size_t>(i)], i) = 1.0;
    reduced_mass_matrix.setZero(na, na);
    loop_reduced_work.setZero(dof, na);
    reduced_ldlt.compute(Eigen::MatrixXd::Identity(na, na));
    return true;
  } catch (...) {  // std::bad_alloc
    loop_projection.resize(0, 0);
    reduced_mass_matrix.resize(0, 0);
    loop_reduced_work.resize(0, 0);
    return false;
  }
}

namespace {

/// Fills data.loop_elimination and data.loop_factor_start / loop_factor_rows (the symbolic
/// structure of the loop solve's sparse LDL^T, algorithm/loops.hpp) and the frames' placements in
/// their links from the model's structure (which coordinates each loop's frames depend on).
/// Construction only; allocates.
void loop_factor_structure(const MechanismModel& model, MechanismData& data) {
  data.frame_rotation_in_link.clear();
  data.frame_position_in_link.clear();
  for (int f = 0; f < model.num_frames(); ++f) {
    const Mat3 aligned_t = model.link_constants(model.frame_link(f)).aligned.transpose();
    data.frame_rotation_in_link.push_back(aligned_t * model.frame(f).placement.linear());
    data.frame_position_in_link.push_back(aligned_t * model.frame(f).placement.translation());
  }
  // where each loop's walks from its frames' links towards the root stop (loop_path_stop): at the
  // root, or for a planar_point loop at the two frames' deepest common ancestor, whose joint and
  // those above it move both frames rigidly together and leave its rows (x_A . (p_B - p_A))
  // unchanged: their columns are zero (computed, they cancel to round-off)
  data.loop_path_stop.assign(static_cast<std::size_t>(model.num_loops()), 0);
  for (int i = 0; i < model.num_loops(); ++i) {
    if (model.loop(i).type != LoopType::planar_point) continue;
    std::vector<char> above_a(static_cast<std::size_t>(model.num_links()), 0);
    for (int k = model.frame_link(model.loop_frame_a(i)); k >= 1; k = model.parent(k)) above_a[static_cast<std::size_t>(k)] = 1;
    int k = model.frame_link(model.loop_frame_b(i));
    while (k >= 1 && !above_a[static_cast<std::size_t>(k)]) k = model.parent(k);
    data.loop_path_stop[static_cast<std::size_t>(i)] = std::max(k, 0);
  }
  const auto path = [&](int i, int frame) {  // the links whose joints can move loop i's rows
    std::vector<int> links;
    for (int k = model.frame_link(frame); k >= 1 && k != data.loop_path_stop[static_cast<std::size_t>(i)]; k = model.parent(k)) {
      links.push_back(k);
    }
    return links;
  };
  data.loop_path_joints.clear();
  data.loop_path_joint_start.assign(1, 0);
  for (int i = 0; i < model.num_loops(); ++i) {
    const auto first_index = data.loop_path_joints.size();
    for (int side = 0; side < 2; ++side) {
      for (int k : path(i, side == 0 ? model.loop_frame_a(i) : model.loop_frame_b(i))) {
        const int c = model.coordinate(k);
        if (c < 0) continue;
        const auto bit = static_cast<unsigned char>(side == 0 ? 1 : 2);
        bool listed = false;
        for (auto e = first_index; e < data.loop_path_joints.size(); ++e) {
          if (data.loop_path_joints[e].link == k) {
            data.loop_path_joints[e].sides = static_cast<unsigned char>(data.loop_path_joints[e].sides | bit);
            listed = true;
          }
        }
        if (!listed) {
          bool first = true;  // (a coordinate may drive several links: gears)
          for (auto e = first_index; e < data.loop_path_joints.size(); ++e) first = first && data.loop_path_joints[e].coordinate != c;
          data.loop_path_joints.push_back(
              {k, c, bit, first, model.joint_type(k) == JointType::revolute, model.coordinate_ratio(k)});
        }
      }
    }
    data.loop_path_joint_start.push_back(static_cast<int>(data.loop_path_joints.size()));
  }
  const auto& passive = model.passive_coordinates();
  const auto np = passive.size();
  std::vector<int> slot(static_cast<std::size_t>(model.dof()), -1);  // coordinate -> passive index
  for (std::size_t j = 0; j < np; ++j) slot[static_cast<std::size_t>(passive[j])] = static_cast<int>(j);
  // N = A°^T A° couples two passive coordinates when a loop's frames depend on both: each loop's
  // rows involve the coordinates on the paths from its two frames' links to the root
  std::vector<std::vector<char>> adjacent(np, std::vector<char>(np, 0));
  std::vector<int> members;
  for (int i = 0; i < model.num_loops(); ++i) {
    members.clear();
    for (int frame : {model.loop_frame_a(i), model.loop_frame_b(i)}) {
      for (int k : path(i, frame)) {
        const int c = model.coordinate(k);
        if (c >= 0 && slot[static_cast<std::size_t>(c)] >= 0) members.push_back(slot[static_cast<std::size_t>(c)]);
      }
    }
    for (int u : members) {
      for (int v : members) {
        if (u != v) adjacent[static_cast<std::size_t>(u)][static_cast<std::size_t>(v)] = 1;
      }
    }
  }
  // the actuated coordinates that move a loop frame: C's other columns are unit vectors (their
  // passive rows zero), so the projection solves for these columns only
  data.loop_actuated_columns.clear();
  const auto& actuated = model.actuated_coordinates();
  for (std::size_t i = 0; i < actuated.size(); ++i) {
    bool in_loop = false;
    for (int l = 0; l < model.num_loops() && !in_loop; ++l) {
      for (int frame : {model.loop_frame_a(l), model.loop_frame_b(l)}) {
        for (int k : path(l, frame)) in_loop = in_loop || model.coordinate(k) == actuated[i];
      }
    }
    if (in_loop) data.loop_actuated_columns.push_back(static_cast<int>(i));
  }
  const auto nla = static_cast<Eigen::Index>(data.loop_actuated_columns.size());
  const Eigen::Index m = model.num_constraints();
  data.loop_block_residual = MechanismData::RowMajorMatrix::Zero(m, nla);
  data.loop_block_step = MechanismData::RowMajorMatrix::Zero(static_cast<Eigen::Index>(np), nla);
  data.loop_solution = MechanismData::RowMajorMatrix::Zero(static_cast<Eigen::Index>(np), nla);
  // minimum-degree elimination (ties: the lowest index), recording each column's rows of L: the
  // neighbours not yet eliminated, fill included
  std::vector<char> eliminated(np, 0);
  std::vector<int> order, position(np, 0);
  std::vector<std::vector<int>> below(np);
  for (std::size_t step = 0; step < np; ++step) {
    std::size_t best = np;
    int best_degree = 0;
    for (std::size_t u = 0; u < np; ++u) {
      if (eliminated[u]) continue;
      int degree = 0;
      for (std::size_t v = 0; v < np; ++v) degree += !eliminated[v] && adjacent[u][v];
      if (best == np || degree < best_degree) {
        best = u;
        best_degree = degree;
      }
    }
    eliminated[best] = 1;
    position[best] = static_cast<int>(step);
    order.push_back(static_cast<int>(best));
    for (std::size_t v = 0; v < np; ++v) {
      if (eliminated[v] || !adjacent[best][v]) continue;
      below[step].push_back(static_cast<int>(v));
      for (std::size_t w = 0; w < np; ++w) {
        if (w != v && !eliminated[w] && adjacent[best][w]) adjacent[v][w] = 1;
      }
    }
  }
  // then by height in the elimination tree (a column's parent: the first row below its pivot),
  // ties in the minimum-degree order: any order that eliminates each column after all its
  // descendants in that tree has the same fill and the same L, permuted. Independent branches
  // (PAMINSA's three legs) then alternate column by column, so that the chains of dependent
  // pivots of the factorisation and of the triangular solves (each pivot a division or a long
  // sum) interleave instead of running one after the other
  {
    std::vector<int> height(np, 0);
    for (std::size_t k = 0; k < np; ++k) {
      int parent = -1;
      for (const int v : below[k]) {
        const int at = position[static_cast<std::size_t>(v)];
        if (parent < 0 || at < parent) parent = at;
      }
      if (parent >= 0) {
        height[static_cast<std::size_t>(parent)] =
            std::max(height[static_cast<std::size_t>(parent)], height[k] + 1);
      }
    }
    std::vector<int> steps(np);
    for (std::size_t k = 0; k < np; ++k) steps[k] = static_cast<int>(k);
    std::stable_sort(steps.begin(), steps.end(), [&](int a, int b) {
      return height[static_cast<std::size_t>(a)] < height[static_cast<std::size_t>(b)];
    });
    std::vector<int> scheduled(np);
    std::vector<std::vector<int>> scheduled_below(np);
    for (std::size_t k = 0; k < np; ++k) {
      const auto from = static_cast<std::size_t>(steps[k]);
      scheduled[k] = order[from];
      scheduled_below[k] = std::move(below[from]);
      position[static_cast<std::size_t>(order[from])] = static_cast<int>(k);
    }
    order = std::move(scheduled);
    below = std::move(scheduled_below);
  }
  data.loop_elimination.clear();
  data.loop_factor_start.assign(1, 0);
  data.loop_factor_rows.clear();
  for (std::size_t k = 0; k < np; ++k) {
    data.loop_elimination.push_back(passive[static_cast<std::size_t>(order[k])]);
    std::vector<int>& rows = below[k];
    for (int& v : rows) v = position[static_cast<std::size_t>(v)];
    std::sort(rows.begin(), rows.end());
    data.loop_factor_rows.insert(data.loop_factor_rows.end(), rows.begin(), rows.end());
    data.loop_factor_start.push_back(static_cast<int>(data.loop_factor_rows.size()));
  }
  // L's entries row by row
  data.loop_factor_row_start.assign(np + 1, 0);
  data.loop_factor_row_entries.assign(data.loop_factor_rows.size(), 0);
  data.loop_factor_row_columns.assign(data.loop_factor_rows.size(), 0);
  for (const int r : data.loop_factor_rows) ++data.loop_factor_row_start[static_cast<std::size_t>(r) + 1];
  for (std::size_t i = 0; i < np; ++i) data.loop_factor_row_start[i + 1] += data.loop_factor_row_start[i];
  {
    std::vector<int> fill(data.loop_factor_row_start.begin(), data.loop_factor_row_start.end() - 1);
    for (std::size_t k = 0; k < np; ++k) {  // (columns in order: each row's entries by increasing column)
      for (int p = data.loop_factor_start[k]; p < data.loop_factor_start[k + 1]; ++p) {
        const int at = fill[static_cast<std::size_t>(data.loop_factor_rows[static_cast<std::size_t>(p)])]++;
        data.loop_factor_row_entries[static_cast<std::size_t>(at)] = p;
        data.loop_factor_row_columns[static_cast<std::size_t>(at)] = static_cast<int>(k);
      }
    }
  }
  // each loop's passive columns (elimination positions, increasing): N = A°^T A° is the sum over
  // the loops of their rows' small dense products
  data.loop_member_start.assign(1, 0);
  data.loop_members.clear();
  data.loop_row_start.clear();
  for (int i = 0; i < model.num_loops(); ++i) data.loop_row_start.push_back(model.loop_row(i));
  data.loop_row_start.push_back(model.num_constraints());
  for (int i = 0; i < model.num_loops(); ++i) {
    std::vector<int> own;
    for (int frame : {model.loop_frame_a(i), model.loop_frame_b(i)}) {
      for (int k : path(i, frame)) {
        const int c = model.coordinate(k);
        if (c >= 0 && slot[static_cast<std::size_t>(c)] >= 0)
          own.push_back(position[static_cast<std::size_t>(slot[static_cast<std::size_t>(c)])]);
      }
    }
    std::sort(own.begin(), own.end());
    own.erase(std::unique(own.begin(), own.end()), own.end());
    data.loop_members.insert(data.loop_members.end(), own.begin(), own.end());
    data.loop_member_start.push_back(static_cast<int>(data.loop_members.size()));
  }
  // each loop's slice of A (loop_blocks): its rows over its passive columns (A°'s structural
  // nonzeros: a passive column is nonzero in the rows of the loops whose joints it moves) and over
  // the actuated columns that move it (A#'s)
  data.loop_blocks.clear();
  data.loop_actuated_members.clear();
  int passive_size = 0, actuated_size = 0;
  for (int i = 0; i < model.num_loops(); ++i) {
    const auto li = static_cast<std::size_t>(i);
    MechanismData::LoopBlockInfo info;
    info.row = data.loop_row_start[li];
    info.rows = data.loop_row_start[li + 1] - info.row;
    info.member = data.loop_member_start[li];
    info.count = data.loop_member_start[li + 1] - info.member;
    info.block = passive_size;
    passive_size += info.rows * info.count;
    info.actuated = static_cast<int>(data.loop_actuated_members.size());
    for (std::size_t t = 0; t < data.loop_actuated_columns.size(); ++t) {
      const int coordinate = actuated[static_cast<std::size_t>(data.loop_actuated_columns[t])];
      bool moves = false;
      for (int frame : {model.loop_frame_a(i), model.loop_frame_b(i)}) {
        for (int k : path(i, frame)) moves = moves || model.coordinate(k) == coordinate;
      }
      if (moves) data.loop_actuated_members.push_back(static_cast<int>(t));
    }
    info.actuated_count = static_cast<int>(data.loop_actuated_members.size()) - info.actuated;
    info.actuated_block = actuated_size;
    actuated_size += info.rows * info.actuated_count;
    data.loop_blocks.push_back(info);
  }
  data.loop_passive_blocks = Eigen::VectorXd::Zero(passive_size);
  data.loop_actuated_blocks = Eigen::VectorXd::Zero(actuated_size);
  // the numeric LDL^T as straight lists: N's (and L's) entries in loop_factor_values (the np
  // pivots, then L's entries in loop_factor_rows' order); where each loop's products of its
  // columns add into N, and where each column's elimination updates the columns after it
  const auto entry = [&](int column, int row) {  // (row, column) of N's lower triangle
    if (row == column) return column;
    const auto first = data.loop_factor_rows.begin() + data.loop_factor_start[static_cast<std::size_t>(column)];
    const auto last = data.loop_factor_rows.begin() + data.loop_factor_start[static_cast<std::size_t>(column) + 1];
    const auto at = std::lower_bound(first, last, row);
    if (at == last || *at != row) throw std::logic_error("loop factor structure: missing fill entry");
    return static_cast<int>(np) + static_cast<int>(at - data.loop_factor_rows.begin());
  };
  const auto nvalues = static_cast<Eigen::Index>(np + data.loop_factor_rows.size());
  data.loop_factor_values = Eigen::VectorXd::Zero(nvalues);
  data.loop_factor_values.head(static_cast<Eigen::Index>(np)).setOnes();  // N = I until the first factorisation
  data.loop_pivot_inverse = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(np));
  // (an entry's first product is stored, ~target, the others added: N needs no clearing but of
  // the entries no product reaches, fill, loop_factor_clear)
  data.loop_normal_targets.clear();
  std::vector<char> reached(static_cast<std::size_t>(nvalues), 0);
  for (int i = 0; i < model.num_loops(); ++i) {
    const int begin = data.loop_member_start[static_cast<std::size_t>(i)];
    const int end = data.loop_member_start[static_cast<std::size_t>(i) + 1];
    const int rows = data.loop_blocks[static_cast<std::size_t>(i)].rows;
    for (int a = begin; a < end; ++a) {
      for (int b = a; b < end; ++b) {
        const int t = entry(data.loop_members[static_cast<std::size_t>(a)], data.loop_members[static_cast<std::size_t>(b)]);
        data.loop_normal_targets.push_back(reached[static_cast<std::size_t>(t)] ? t : ~t);
        data.loop_normal_targets.push_back((a - begin) * rows);
        data.loop_normal_targets.push_back((b - begin) * rows);
        reached[static_cast<std::size_t>(t)] = 1;
      }
    }
  }
  data.loop_factor_clear.clear();
  for (Eigen::Index t = 0; t < nvalues; ++t) {
    if (!reached[static_cast<std::size_t>(t)]) data.loop_factor_clear.push_back(static_cast<int>(t));
  }
  // the factorisation's products l_jk u_ik (pairs of L's entries in column k: j's scaled, i's
  // not), grouped by the entry (pivot or entry of L) they are subtracted from
  {
    std::vector<std::vector<int>> sums(static_cast<std::size_t>(nvalues));
    for (std::size_t k = 0; k < np; ++k) {
      const int begin = data.loop_factor_start[k], end = data.loop_factor_start[k + 1];
      for (int p = begin; p < end; ++p) {
        for (int r = p; r < end; ++r) {
          auto& list = sums[static_cast<std::size_t>(entry(data.loop_factor_rows[static_cast<std::size_t>(p)],
                                                          data.loop_factor_rows[static_cast<std::size_t>(r)]))];
          list.push_back(p);
          list.push_back(r);
        }
      }
    }
    data.loop_factor_updates.clear();
    data.loop_factor_update_start.assign(1, 0);
    for (const auto& list : sums) {
      data.loop_factor_updates.insert(data.loop_factor_updates.end(), list.begin(), list.end());
      data.loop_factor_update_start.push_back(static_cast<int>(data.loop_factor_updates.size() / 2));
    }
  }
  data.loop_factor_unscaled = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(data.loop_factor_rows.size()));
}

}  // namespace

MechanismData::MechanismData(const MechanismModel& model)
    : dof(model.dof()),
      num_links(model.num_links()),
      num_bodies(model.num_bodies()),
      num_frames(model.num_frames()),
      num_springs(model.num_springs()) {
  const auto nl = static_cast<std::size_t>(num_links);
  const auto nb = static_cast<std::size_t>(num_bodies);
  joint_position.assign(nl, 0.0);
  joint_velocity.assign(nl, 0.0);
  joint_acceleration.assign(nl, 0.0);
  link_rotation.assign(nl, Mat3::Identity());
  link_position.assign(nl, Vec3::Zero());
  link_angular_velocity.assign(nl, Vec3::Zero());
  link_velocity.assign(nl, Vec3::Zero());
  link_angular_acceleration.assign(nl, Vec3::Zero());
  link_acceleration.assign(nl, Vec3::Zero());
  body_states.assign(nb, BodyState{});
  body_inertias.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    body_inertias[b].mass = model.bodies()[b].mass;
    body_inertias[b].inertia_body = model.bodies()[b].inertia;
  }
  frame_placements.assign(static_cast<std::size_t>(num_frames), Eigen::Isometry3d::Identity());
  mass = model.total_mass();
  joint_torque = Eigen::VectorXd::Zero(dof);
  gravity_torque = Eigen::VectorXd::Zero(dof);
  bias_torque = Eigen::VectorXd::Zero(dof);
  spring_torque = Eigen::VectorXd::Zero(dof);
  static_torque = Eigen::VectorXd::Zero(dof);
  spring_length = Eigen::VectorXd::Zero(num_springs);
  spring_tension = Eigen::VectorXd::Zero(num_springs);
  momentum_matrix = Eigen::MatrixXd::Zero(6, dof);
  frame_jacobian = Eigen::MatrixXd::Zero(6, dof);
  momentum_regressor = Eigen::MatrixXd::Zero(6, 10 * num_bodies);
  link_regressor = Eigen::MatrixXd::Zero(dof, 10);
  link_momentum_regressor = Eigen::MatrixXd::Zero(6, 10);
  work.resize(nl);
  for (std::size_t l = 0; l < nl; ++l) {
    LinkWork& w = work[l];
    const auto& c = model.link_constants(static_cast<int>(l));
    w.rotation = c.rotation;
    w.translation = c.translation;
    w.w = w.alpha = w.acc = w.vel = w.force = w.moment = Vec3::Zero();
    w.world_rotation = Mat3::Identity();
    w.world_position = Vec3::Zero();
    w.composite_mass = 0.0;
    w.composite_first_moment = Vec3::Zero();
    w.composite_inertia = Mat3::Zero();
    w.placed_at = std::numeric_limits<double>::quiet_NaN();  // the first placement computes every link
    w.world_stale = true;
    w.world_moved = false;  // the base (link 0) never moves
    w.composite_current = false;
    w.momentum_current = false;
  }
  momentum_column_stale.assign(static_cast<std::size_t>(dof), 0);
  const int m = model.num_constraints(), na = model.num_actuated(), np = model.num_passive();
  loop_residual = Eigen::VectorXd::Zero(m);
  loop_jacobian = Eigen::MatrixXd::Zero(m, dof);
  loop_bias = Eigen::VectorXd::Zero(m);
  // dof x na buffers: for an open model na = dof, quadratic: sized by the first closed-loop call
  if (model.is_closed() && !size_actuated_buffers(model)) throw std::bad_alloc();
  loop_acceleration_bias = Eigen::VectorXd::Zero(dof);
  closed_position = Eigen::VectorXd::Zero(dof);
  closed_velocity = Eigen::VectorXd::Zero(dof);
  closed_acceleration = Eigen::VectorXd::Zero(dof);
  actuated_force = Eigen::VectorXd::Zero(na);
  actuated_gravity = Eigen::VectorXd::Zero(na);
  actuated_static_torque = Eigen::VectorXd::Zero(na);
  actuated_acceleration = Eigen::VectorXd::Zero(na);
  loop_block_residual = RowMajorMatrix::Zero(m, na);
  loop_block_step = RowMajorMatrix::Zero(np, na);
  loop_constraint_work = Eigen::VectorXd::Zero(m);
  loop_refine_solution = Eigen::VectorXd::Zero(np);
  loop_step = Eigen::VectorXd::Zero(np);
  loop_trial = Eigen::VectorXd::Zero(dof);
  loop_solution = RowMajorMatrix::Zero(np, na);
  loop_vector_work = Eigen::VectorXd::Zero(dof);
  loop_prediction_error = Eigen::VectorXd::Zero(dof);
  loop_prediction_error_old = Eigen::VectorXd::Zero(dof);
  loop_prediction_offset = Eigen::VectorXd::Zero(np);
  loop_prediction_origin = Eigen::VectorXd::Constant(dof, std::numeric_limits<double>::quiet_NaN());
  if (model.is_closed()) loop_acceleration_field.assign(2 * nl, Vec3::Zero());
  loop_factor_structure(model, *this);
}

}  // namespace mechbal
