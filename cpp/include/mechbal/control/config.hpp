#pragma once
/// \file control/config.hpp
/// ControlConfig: the `[control]` table of a case file as plain data (no parsing, no model).
/// io/case.hpp reads it from a file (load_case) and checks it against the model; control/factory.hpp
/// builds the configured controller from it (make_controller). Construction-time data only: nothing
/// here is used inside a control tick.
#include <string>
#include <vector>

namespace mechbal {

/// Which controller the `[control]` table asks for (`kind = "..."`); `none` when the file has no
/// `[control]` table.
enum class ControlKind { none, computed_torque, decoupled, reactionless, passive };

/// The `kind` string of a ControlKind ("none", "computed_torque", "decoupled", "reactionless",
/// "passive": no controller, zero effort, the mechanism moves under gravity and springs).
const char* control_kind_name(ControlKind kind) noexcept;

/// The `[control]` table. Per-joint vectors follow the model's actuated coordinates
/// (MechanismModel::actuated_coordinates(): every coordinate of an open mechanism).
struct ControlConfig {
  ControlKind kind = ControlKind::none;
  double rate_hz = 1000.0;  ///< the controller's tick rate [Hz]
  /// Diagonal gains of the outer loop, one value > 0 per actuated coordinate: required for
  /// computed_torque and decoupled; for reactionless the optional computed-torque stage (both or
  /// neither).
  std::vector<double> kp, kd;
  /// Command limits (one value > 0 per actuated coordinate); empty: default_torque_limit.
  std::vector<double> torque_limit;
  /// decoupled: the constant diagonal of the balanced mass matrix; empty: taken from the model
  /// (the diagonal of M# at q = 0, which must then be diagonal).
  std::vector<double> k;

  // ---- reactionless (issue 21's controller); only with kind = "reactionless" ----
  /// Joints whose motion cancels the momentum: actuated coordinates (required).
  std::vector<std::string> balancing_joints;
  /// Cancelled momentum components: "moment", "force", "both", "moment_x|y|z", "force_x|y|z".
  std::vector<std::string> cancel{"moment"};
  std::string integrator = "rk4";  ///< "rk4" or "euler"
  double damping = 1e-2;           ///< damped least squares near singularity, in (0, 1)
  double max_rate = 100.0;         ///< balancing joints' rate limit [rad/s or m/s], > 0
  double home_gain = 0.0;          ///< redundant balancing joints: pull towards the start pose [1/s]
  double limit_gain = 0.0;         ///< redundant balancing joints: push away from the joint limits
  /// Operational-space mode: the frame whose path [trajectory] gives (empty: joint-space mode).
  std::string task_frame;
  /// Operational-space mode: the frame's tracked twist components, "all" (default), "linear",
  /// "angular", "v_x" ... "w_z" (only with task_frame).
  std::vector<std::string> task_rows{"all"};
};

}  // namespace mechbal
