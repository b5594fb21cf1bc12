#pragma once
/// \file urdf.hpp
/// URDF input (through urdfdom): a robot description file as a MechanismDescription, so that an
/// embedded controller loads the same file as the Python layer. Not real-time.
///
/// Mapping (model.hpp's conventions are URDF's, so placements carry over unchanged):
///  - The URDF root link is the base: `root_name` is its name.
///  - Every revolute, continuous, prismatic or fixed URDF joint becomes a Joint of the same name,
///    with `placement` = the joint's <origin>, `axis` = its <axis> (URDF's default (1, 0, 0)),
///    limits lower / upper / velocity / effort from <limit>. A continuous joint is a revolute
///    joint without position limits (one coordinate, not Pinocchio's (cos, sin) pair). A zero
///    velocity or effort limit (URDF's "unspecified") is read as no limit.
///  - <mimic joint multiplier offset> becomes a gear coupling (q = multiplier q_joint + offset).
///  - A link's <inertial> becomes a Body named after the URDF link (kind "link") on the link its
///    parent joint moves (on the base for the root link): com = the inertial origin's xyz, inertia
///    rotated by the inertial origin's rpy into the link frame.
///  - Every URDF link also becomes a Frame named after it (identity placement on its link), so a
///    link's pose and Jacobian can be asked for by its URDF name. In the model a link is named after
///    the joint that moves it; Body::link and Frame::link hold that joint's name (the root's name
///    for the root link).
///  - Joints are listed depth-first from the root, children in urdfdom's order (by joint name), as
///    Pinocchio's URDF reader does: q has the same order as Pinocchio's (continuous joints aside).
/// Errors: std::invalid_argument naming the URDF element and the value, e.g.
/// `URDF joint 'shoulder': type floating is not supported (...)`, `URDF link 'forearm': inertial
/// .mass must be a finite number >= 0, got -1`, `URDF: parent link 'bse' of joint 'j1' not found`;
/// nothing is half-built.
/// Before urdfdom reads the document, one streaming pass refuses (one-line messages): a document
/// larger than kMaxUrdfBytes, elements nested deeper than kMaxUrdfDepth, a number mechbal reads
/// (mass, inertia, origin, axis, limit, mimic, dynamics, safety_controller, calibration) that is
/// not a finite number ("nan", "inf", "abc", "1e999"; the message names the link or joint, the
/// element and the line), and joints that do not form a tree (a joint whose parent is its child,
/// a link with two parent joints, a cycle: the message names the joints).
#include <cstddef>
#include <string>
#include <vector>

#include "mechbal/model/model.hpp"

namespace mechbal {

/// Largest URDF document read [bytes] (a 10,000-link chain is about 6 MB).
inline constexpr std::size_t kMaxUrdfBytes = 64u << 20;
/// Deepest element nesting read (a URDF needs 4: robot / link / inertial / origin).
inline constexpr std::size_t kMaxUrdfDepth = 64;
/// How the reader treats harmless defects that Pinocchio loads (issue 23).
///  - strict: refuse them (the functions without options read strictly).
///  - lenient (strict = false): repair each with one warning naming the URDF element and the repair:
///    * a <mimic> on a fixed joint is ignored (a fixed joint has no coordinate to couple);
///    * a <mimic> of a joint that does not exist is ignored (Pinocchio reads an independent joint);
///    * a body whose inertia is not physical (not positive semi-definite, or breaking the triangle
///      inequality; Pinocchio loads it) gets the nearest physical one: the second moment of mass
///      S = tr(I)/2 1 - I has its eigenvalues raised to at least 1e-12 tr(S) (S >= 0 is exactly
///      "physical"; the margin keeps the triangle inequality off its boundary), and
///      I = tr(S) 1 - S. "Not physical" is judged to the inertia's own scale too: a tiny inertia
///      whose rounding breaks the triangle inequality (relative 1e-12) is repaired (or refused by
///      strict), not passed on to engines that refuse it. The warning says whether the body is
///      negligible (mass <= kNegligibleMassFraction of the URDF's total mass) or not (then the dynamics differ from
///      the file's, and the warning asks for the file to be corrected);
///    * a negligible, non-physical <inertial> on the root link (a placeholder on the fixed base,
///      which never moves) is dropped.
///  - allow_massless: load a URDF with no <inertial> on any moving link (kinematics only: every
///    dynamic quantity is zero), with a warning; otherwise it is refused in both modes, naming the
///    option.
struct UrdfOptions {
  bool strict = true;
  bool allow_massless = false;
};

/// A body is negligible when its mass is at most this fraction of the URDF's total mass.
inline constexpr double kNegligibleMassFraction = 1e-4;

/// A description read under UrdfOptions, with one warning per repair.
struct UrdfReading {
  MechanismDescription description;
  std::vector<std::string> warnings;
};

/// The description of the URDF document `xml` / file `path` under `options`.
UrdfReading read_urdf_string(const std::string& xml, const UrdfOptions& options);
UrdfReading read_urdf_file(const std::string& path, const UrdfOptions& options);
/// The validated model of a description read by read_urdf_*: errors of the model name URDF
/// elements (URDF joint 'x', URDF link 'y' <inertial>), not description indices. `source` prefixes
/// them (e.g. "URDF file 'arm.urdf'").
MechanismModel model_from_urdf_reading(UrdfReading reading, const std::string& source);

/// The description of the URDF document `xml`.
MechanismDescription urdf_description_from_string(const std::string& xml);
/// The description of the URDF file at `path` (errors are prefixed with the path).
MechanismDescription urdf_description_from_file(const std::string& path);

/// The validated model of a URDF document / file (the description above, then MechanismModel).
MechanismModel model_from_urdf_string(const std::string& xml);
MechanismModel model_from_urdf_file(const std::string& path);

}  // namespace mechbal
