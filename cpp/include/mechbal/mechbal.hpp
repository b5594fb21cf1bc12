#pragma once
/// \file mechbal.hpp
/// Umbrella header of the mechbal C++ core.
#include "mechbal/decoupled_control.hpp"
#include "mechbal/disc_arm.hpp"
#include "mechbal/dynamics.hpp"
#include "mechbal/kdl_chain.hpp"
#include "mechbal/rigid_body.hpp"
#include "mechbal/serial_chain.hpp"
#include "mechbal/status.hpp"
#include "mechbal/trajectory.hpp"
#include "mechbal/urdf.hpp"
#include "mechbal/version.hpp"
