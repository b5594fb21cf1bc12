#pragma once
/// \file joint_type.hpp
/// Joint types shared by the serial-chain description and the general mechanism model.

namespace mechbal {

/// revolute: rotation about the joint axis; prismatic: translation along it; fixed: a rigid
/// connection (no coordinate). Spherical joints are described as three revolute joints (model.hpp).
enum class JointType { revolute, prismatic, fixed };

}  // namespace mechbal
