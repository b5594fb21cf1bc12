#pragma once
/// \file control/config.hpp
/// ControlConfig: the `[control]` table of a case file as plain data (no parsing, no model).
/// io/case.hpp reads it from a file (load_case) and checks it against the model; control/factory.hpp
/// builds the configured controller from it (make_controller). Construction-time data only: nothing
/// here is used inside a control tick.
#include <limits>
#include <string>
#include <vector>

namespace mechbal {

/// Which controller the `[control]` table asks for (`kind = "..."`); `none` when the file has no
/// `[control]` table.
enum class ControlKind { none, computed_torque, decoupled, reactionless, passive };

/// The `kind` string of a ControlKind ("none", "computed_torque", "decoupled", "reactionless",
/// "passive": no controller, zero effort, the mechanism moves under gravity and springs).
const char* control_kind_name(ControlKind kind) noexcept;

/// `[control] tolerance`: what counts as the controller's goal met (the verdict of a run: the
/// Python layer measures it; the controllers do not use it). Each > 0.
struct ControlTolerance {
  double residual = 1e-6;     ///< cancelled component's peak over its uncontrolled peak
  double floor = 1e-9;        ///< absolute floor of a cancelled component's residual [N or N m]
  double position = 1e-6;     ///< task frame's path error [m]
  double orientation = 1e-6;  ///< task frame's orientation error [rad]
  double joint = 1e-2;        ///< closed loop: the plant's departure from the command [rad or m]
};

/// The `[control]` table. Per-joint vectors follow the model's actuated coordinates
/// (MechanismModel::actuated_coordinates(): every coordinate of an open mechanism).
struct ControlConfig {
  ControlKind kind = ControlKind::none;
  double rate_hz = 1000.0;  ///< the controller's tick rate [Hz]
  /// Diagonal gains of the outer loop, one value > 0 per actuated coordinate: required for
  /// computed_torque and decoupled; for reactionless the optional computed-torque stage (both or
  /// neither).
  std::vector<double> kp, kd;
  /// Command limits (one value > 0 per actuated coordinate; +infinity: none); the model's
  /// declared effort limit when smaller; empty: only the model's (none when undeclared).
  std::vector<double> torque_limit;
  /// Input range of every stage's joint speeds (measured and desired) [rad/s or m/s], > 0;
  /// +infinity (the default): no limit.
  double max_speed = std::numeric_limits<double>::infinity();
  ControlTolerance tolerance;  ///< the goal's tolerances (`[control] tolerance = {...}`)
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
  /// balancing joints' rate limit [rad/s or m/s], > 0; the model's velocity limit when smaller;
  /// +infinity (the default): only the model's (none when undeclared)
  double max_rate = std::numeric_limits<double>::infinity();
  double home_gain = 0.0;          ///< redundant balancing joints: pull towards the start pose [1/s]
  double limit_gain = 0.0;         ///< redundant balancing joints: push away from the joint limits
  /// Operational-space mode: the frame whose path [trajectory] gives (empty: joint-space mode).
  std::string task_frame;
  /// Operational-space mode: the frame's tracked twist components, "all" (default), "linear",
  /// "angular", "v_x" ... "w_z" (only with task_frame).
  std::vector<std::string> task_rows{"all"};
};

}  // namespace mechbal
