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
#include <string>

#include "mechbal/model/model.hpp"

namespace mechbal {

/// The description of the URDF document `xml`.
MechanismDescription urdf_description_from_string(const std::string& xml);
/// The description of the URDF file at `path` (errors are prefixed with the path).
MechanismDescription urdf_description_from_file(const std::string& path);

/// The validated model of a URDF document / file (the description above, then MechanismModel).
MechanismModel model_from_urdf_string(const std::string& xml);
MechanismModel model_from_urdf_file(const std::string& path);

}  // namespace mechbal
