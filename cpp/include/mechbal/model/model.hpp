#pragma once
/// \file model.hpp
/// The general mechanism model (docs/architecture.md, "The model"): a kinematic tree of joints,
/// any number of named rigid bodies on each link, gear couplings between joints, named frames and
/// gravity. Immutable once built and validated; every algorithm is a free function over a model
/// and a MechanismData (data.hpp), as in Pinocchio's Model/Data split.
///
/// Frames and conventions (the same as URDF's):
///  - O is the fixed base frame (world), z up with gravity (0, 0, -9.81) unless `gravity` says
///    otherwise. The base link is called `root_name` (default "base") and never moves.
///  - Joint i moves link i (they share the joint's name). The frame F_i of link i is
///    F_i = F_parent * placement_i * J_i(q_i), where `placement` is the constant transform from the
///    parent link frame to the joint frame at q = 0 and J_i is a rotation about (revolute) or a
///    translation along (prismatic) the unit `axis`, expressed in the joint frame; fixed joints have
///    J = identity and no coordinate.
///  - A body's centre of mass `com` and its inertia about the centre of mass are expressed in the
///    frame of the link that carries it.
///  - Spherical joints are described as three revolute joints about z, y, x of the joint frame
///    with massless intermediate links (the TOML and URDF readers expand them).
///
/// Coordinates: every revolute/prismatic joint has a position. A joint with a gear coupling
/// (URDF `mimic`) follows q_j = ratio * q_master + offset and has no coordinate of its own; the
/// others are the independent coordinates q (size dof()), ordered as their links appear in the
/// model's depth-first link order. Velocities and accelerations follow (v_j = ratio * v_master),
/// and the generalised forces are projected accordingly (tau = G^T tau_joint).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

#include "mechbal/detail/large_buffer.hpp"
#include "mechbal/model/joint_type.hpp"
#include "mechbal/model/rigid_body.hpp"

namespace mechbal {

/// Names (of joints, links, bodies, frames, loops, springs): 1 .. kMaxNameCharacters characters
/// of valid UTF-8, none of them a control character (U+0000..U+001F, U+007F..U+009F), a
/// surrogate or a noncharacter (U+FDD0..U+FDEF, U+xFFFE, U+xFFFF): printable text that every file
/// format mechbal writes (TOML, URDF, MJCF, JSON, CSV) can hold. docs/case_format.md, "Names".
inline constexpr std::size_t kMaxNameCharacters = 256;

/// Why `name` is not a valid name ("" when it is): "must not be empty", "is not valid UTF-8",
/// "must not contain the character U+0001 (...)", "must have at most 256 characters".
std::string name_problem(const std::string& name);

/// One joint of the description. `parent` names the parent link (a joint's name, or the root).
struct Joint {
  std::string name;
  JointType type = JointType::revolute;
  std::string parent;  ///< parent link: the name of the joint that moves it, or the root's name
  Eigen::Isometry3d placement = Eigen::Isometry3d::Identity();  ///< parent link -> joint frame
  Vec3 axis = Vec3::UnitZ();  ///< in the joint frame (normalised by the model)
  double lower = -std::numeric_limits<double>::infinity();  ///< position limits [rad or m]
  double upper = std::numeric_limits<double>::infinity();
  double velocity_limit = std::numeric_limits<double>::infinity();  ///< [rad/s or m/s]
  double effort_limit = std::numeric_limits<double>::infinity();    ///< [N m or N]
  /// Gear coupling: when `mimic_joint` is non-empty, q = mimic_ratio * q(mimic_joint) + mimic_offset.
  std::string mimic_joint;
  double mimic_ratio = 1.0;
  double mimic_offset = 0.0;
};

/// A named rigid body rigidly attached to a link (its own inertia, a counterweight, a motor, a
/// disc housing, a payload). `kind` is a free label used by reports and balancing methods.
struct Body {
  std::string name;
  std::string kind = "link";
  std::string link;           ///< name of the carrying link (a joint's name, or the root's name)
  double mass = 0.0;          ///< [kg]
  Vec3 com = Vec3::Zero();    ///< centre of mass in the link frame [m]
  Mat3 inertia = Mat3::Zero();  ///< about the centre of mass, link-frame axes [kg m^2]
};

/// A named frame rigidly attached to a link (tool, sensor, loop-closure point).
struct Frame {
  std::string name;
  std::string link;
  Eigen::Isometry3d placement = Eigen::Isometry3d::Identity();  ///< in the link frame
};

/// A linear spring between anchor A on link `link_a` and anchor B on link `link_b` (Martini et al.
/// 2015, Tables 1-2; mechbal.balance.springs): `count` identical springs in parallel, each of rate
/// `rate` [N/m] carrying `preload` [N] (its initial tension) when the anchor distance is
/// `free_length` [m], acting through a block and tackle of ratio k = `pulley_ratio` (the anchor
/// distance d changes k times as much as each spring's length). By virtual work the tension at the
/// anchors and its potential energy are
///
///     T(d) = count preload / k + K_eq (d - free_length),   K_eq = count rate / k^2,
///     V(d) = count preload / k (d - free_length) + K_eq (d - free_length)^2 / 2.
///
/// A zero-free-length spring has free_length = 0 and preload = 0: T = K_eq d. The law is linear
/// on both sides of the free length (no slack): a tension spring shorter than its free length is
/// the caller's to avoid (the balancing method reports it). Anchors are in the frame of their link
/// (as a body's centre of mass: the frame right after the joint's motion; a link welded by fixed
/// joints is folded into its moving ancestor with the anchor moved along). The springs are
/// massless: give their mass as bodies when it matters.
struct Spring {
  std::string name;
  std::string link_a;  ///< link carrying anchor A: a joint's name, or the root's name
  Vec3 anchor_a = Vec3::Zero();  ///< in link_a's frame [m]
  std::string link_b;
  Vec3 anchor_b = Vec3::Zero();  ///< in link_b's frame [m]
  double rate = 0.0;          ///< of each spring [N/m]
  double free_length = 0.0;   ///< anchor distance at which each spring carries only its preload [m]
  double preload = 0.0;       ///< initial tension of each spring [N]
  int count = 1;              ///< identical springs in parallel
  double pulley_ratio = 1.0;  ///< k: anchor distance change / spring length change
};

/// Loop-closure constraint types between two frames A and B (loops.hpp for the equations):
///  - point: the origins coincide (3 equations, a spherical closure);
///  - planar_point: the origins coincide in the plane normal to A's z axis (2 equations);
///  - axis: the origins coincide and the z axes are parallel (5 equations, a revolute closure);
///  - weld: the frames coincide (6 equations).
enum class LoopType { point, planar_point, axis, weld };

/// Number of scalar closure equations of a loop type.
constexpr int loop_equations(LoopType t) noexcept {
  return t == LoopType::point ? 3 : t == LoopType::planar_point ? 2 : t == LoopType::axis ? 5 : 6;
}

/// A loop closure between two named frames (usually on two branches of the tree).
struct LoopConstraint {
  std::string name;
  LoopType type = LoopType::point;
  std::string frame_a;
  std::string frame_b;
};

/// Everything a MechanismModel is built from (what the URDF and TOML readers produce).
struct MechanismDescription {
  std::string root_name = "base";
  std::vector<Joint> joints;
  std::vector<Body> bodies;
  std::vector<Frame> frames;
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);
  /// Loop closures; with loops, `actuated` must name the actuated joints (the independent
  /// coordinates q#); the other coordinates are passive and follow from the closure equations.
  std::vector<LoopConstraint> loops;
  /// Names of the actuated joints (coordinates). Empty without loops: every coordinate.
  std::vector<std::string> actuated;
  /// Springs between links (algorithm/springs.hpp); their forces enter the inverse dynamics.
  std::vector<Spring> springs;
};

/// The validated, immutable model. Link 0 is the base; links 1..num_links()-1 are the joints'
/// links in depth-first order (a parent before its children). Construction throws
/// std::invalid_argument naming the offending field (`joints[2] (elbow).axis: ...`); nothing is
/// half-built. Not real-time.
class MechanismModel {
 public:
  explicit MechanismModel(MechanismDescription description);

  /// Number of independent coordinates (joints with a coordinate and no gear coupling).
  int dof() const noexcept { return dof_; }
  /// Links including the base (link 0).
  int num_links() const noexcept { return static_cast<int>(parent_.size()); }
  int num_bodies() const noexcept { return static_cast<int>(bodies_.size()); }
  int num_frames() const noexcept { return static_cast<int>(frames_.size()); }
  const Vec3& gravity() const noexcept { return gravity_; }
  const std::string& root_name() const noexcept { return root_name_; }
  /// The description, with joints reordered depth-first (joint k moves link k + 1) and axes unit.
  const MechanismDescription& description() const noexcept { return description_; }

  // ---- per link (index 0 = base) ----
  const std::string& link_name(int link) const { return link_names_.at(static_cast<std::size_t>(link)); }
  /// Link index by name, -1 when absent.
  int link_index(const std::string& name) const noexcept;
  int parent(int link) const noexcept { return parent_[static_cast<std::size_t>(link)]; }
  JointType joint_type(int link) const noexcept { return type_[static_cast<std::size_t>(link)]; }
  /// Independent coordinate driving link's joint (-1 for fixed joints and the base).
  int coordinate(int link) const noexcept { return coordinate_[static_cast<std::size_t>(link)]; }
  /// Joint position = ratio * q(coordinate) + offset (1 and 0 without a gear coupling).
  double coordinate_ratio(int link) const noexcept { return ratio_[static_cast<std::size_t>(link)]; }
  double coordinate_offset(int link) const noexcept { return offset_[static_cast<std::size_t>(link)]; }
  const Eigen::Isometry3d& placement(int link) const noexcept { return placement_[static_cast<std::size_t>(link)]; }
  const Vec3& axis(int link) const noexcept { return axis_[static_cast<std::size_t>(link)]; }

  // ---- independent coordinates ----
  /// Name of the joint whose coordinate is q(i).
  const std::string& coordinate_name(int i) const { return coordinate_names_.at(static_cast<std::size_t>(i)); }
  const std::vector<std::string>& coordinate_names() const noexcept { return coordinate_names_; }
  const Eigen::VectorXd& lower_limits() const noexcept { return lower_; }
  const Eigen::VectorXd& upper_limits() const noexcept { return upper_; }
  const Eigen::VectorXd& velocity_limits() const noexcept { return velocity_limit_; }
  const Eigen::VectorXd& effort_limits() const noexcept { return effort_limit_; }

  // ---- bodies and frames ----
  const Body& body(int b) const { return bodies_.at(static_cast<std::size_t>(b)); }
  const std::vector<Body>& bodies() const noexcept { return bodies_; }
  /// Link index carrying body b.
  int body_link(int b) const noexcept { return body_link_[static_cast<std::size_t>(b)]; }
  int body_index(const std::string& name) const noexcept;
  const Frame& frame(int f) const { return frames_.at(static_cast<std::size_t>(f)); }
  int frame_link(int f) const noexcept { return frame_link_[static_cast<std::size_t>(f)]; }
  int frame_index(const std::string& name) const noexcept;
  /// Total mass of all bodies (the base's included) [kg].
  double total_mass() const noexcept { return total_mass_; }
  /// True when the tree is a single chain of joints with coordinates (no branch, fixed joint or
  /// gear) and has no loops.
  bool is_serial_chain() const noexcept { return serial_chain_; }

  // ---- springs ----
  int num_springs() const noexcept { return static_cast<int>(springs_.size()); }
  const Spring& spring(int s) const { return springs_.at(static_cast<std::size_t>(s)); }
  const std::vector<Spring>& springs() const noexcept { return springs_; }
  int spring_index(const std::string& name) const noexcept;
  /// Per-spring constants the algorithms use: link indices, anchors in the joint-aligned frames
  /// L_i (see LinkConstants), K_eq = count rate / k^2 and the preload tension count preload / k.
  struct SpringConstants {
    int link_a, link_b;
    Vec3 anchor_a, anchor_b;  ///< in L_{link_a}, L_{link_b}
    double equivalent_rate;   ///< [N/m] at the anchors
    double preload_tension;   ///< [N] at the anchors, at d = free_length
    double free_length;       ///< [m]
  };
  const SpringConstants& spring_constants(int s) const noexcept { return spring_constants_[static_cast<std::size_t>(s)]; }

  // ---- loops and actuation ----
  int num_loops() const noexcept { return static_cast<int>(loops_.size()); }
  bool is_closed() const noexcept { return !loops_.empty(); }
  const LoopConstraint& loop(int i) const { return loops_.at(static_cast<std::size_t>(i)); }
  int loop_frame_a(int i) const noexcept { return loop_frames_[static_cast<std::size_t>(i)].first; }
  int loop_frame_b(int i) const noexcept { return loop_frames_[static_cast<std::size_t>(i)].second; }
  /// First row of loop i in the stacked closure equations.
  int loop_row(int i) const noexcept { return loop_rows_[static_cast<std::size_t>(i)]; }
  /// Total number of scalar closure equations.
  int num_constraints() const noexcept { return num_constraints_; }
  /// Indices into q of the actuated (independent) and passive coordinates.
  const std::vector<int>& actuated_coordinates() const noexcept { return actuated_; }
  const std::vector<int>& passive_coordinates() const noexcept { return passive_; }
  int num_actuated() const noexcept { return static_cast<int>(actuated_.size()); }
  int num_passive() const noexcept { return static_cast<int>(passive_.size()); }

  /// Precomputed per-link constants the algorithms use (joint-aligned frames, lumped inertia).
  /// Implementation detail made public for the algorithm files; see model.cpp.
  // Field order: the per-tick passes read rotation .. inertia_origin; `aligned` (world quantities
  // of links, rarely per tick) last, so that a pass over a long chain loads fewer cache lines.
  struct LinkConstants {
    Mat3 rotation;         ///< L_i at q = 0 relative to L_parent
    Vec3 translation;      ///< origin of L_i in L_parent
    double mass;           ///< lumped mass of the link's bodies
    Vec3 first_moment;     ///< m c of the lumped bodies, in L_i
    Mat3 inertia_origin;   ///< lumped inertia about L_i's origin, in L_i
    Mat3 aligned;          ///< A_i: F_i -> L_i rotation with A_i e_z = axis (identity when fixed)
  };
  const LinkConstants& link_constants(int link) const noexcept { return constants_[static_cast<std::size_t>(link)]; }
  /// The moving links (1 .. num_links - 1, in order) that carry mass or inertia: a link without
  /// either (a massless intermediate link: a prismatic stage, a gimbal's first axis) adds nothing
  /// to a momentum or a wrench sum, which then visit these only.
  const std::vector<int>& inertial_links() const noexcept { return inertial_links_; }
  /// Whether link `link` carries mass or inertia (inertial_links' membership).
  bool has_inertia(int link) const noexcept { return has_inertia_[static_cast<std::size_t>(link)] != 0; }
  /// How link `link`'s rotation R relative to its parent acts (the passes' products with it):
  /// identity when R is the identity (a prismatic or fixed joint whose constant rotation is exactly
  /// the identity); along_x, along_y, along_z when its constant rotation is a signed permutation
  /// (exact zeros and ones: frames at right angles, links along parallel axes, a pantograph's;
  /// a joint placement within 4 ulp of one, as rpy angles of +-pi/2 give, is taken as exact)
  /// that takes the joint's axis to the parent's x, y or z axis, so that R's third column has one
  /// nonzero entry, in that row, and its first two columns none there; general otherwise.
  enum class LocalRotation : unsigned char { general, along_x, along_y, along_z, identity };
  LocalRotation local_rotation(int link) const noexcept { return local_rotation_[static_cast<std::size_t>(link)]; }
  /// Whether any link's rotation is other than general (the passes then branch per link to the
  /// shortcuts; a model without one runs the dense products straight through).
  bool has_aligned_links() const noexcept { return has_aligned_links_; }

 private:
  MechanismDescription description_;
  std::string root_name_;
  Vec3 gravity_;
  int dof_ = 0;
  std::vector<std::string> link_names_;
  std::vector<int> parent_;
  std::vector<JointType> type_;
  std::vector<int> coordinate_;
  std::vector<double> ratio_, offset_;
  std::vector<Eigen::Isometry3d> placement_;
  std::vector<Vec3> axis_;
  std::vector<std::string> coordinate_names_;
  Eigen::VectorXd lower_, upper_, velocity_limit_, effort_limit_;
  std::vector<Body> bodies_;
  std::vector<int> body_link_;
  std::vector<int> inertial_links_;
  std::vector<unsigned char> has_inertia_;
  std::vector<LocalRotation> local_rotation_;
  bool has_aligned_links_ = false;
  std::vector<Frame> frames_;
  std::vector<int> frame_link_;
  std::vector<LinkConstants, detail::LargeBufferAllocator<LinkConstants>> constants_;
  std::vector<Spring> springs_;
  std::vector<SpringConstants> spring_constants_;
  std::vector<LoopConstraint> loops_;
  std::vector<std::pair<int, int>> loop_frames_;
  std::vector<int> loop_rows_;
  int num_constraints_ = 0;
  std::vector<int> actuated_, passive_;
  double total_mass_ = 0.0;
  bool serial_chain_ = false;
};

}  // namespace mechbal
