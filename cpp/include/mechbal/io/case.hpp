#pragma once
/// \file io/case.hpp
/// The C++ reader of mechbal's own case format (TOML): the `[mechanism]` table of a case file or
/// of a `balanced.toml` written by `mechbal balance`, and its `[control]` table. One format, two
/// readers: it builds the same MechanismModel as the Python reader (python/mechbal/spec.py):
///  - joints in every form the format allows: `origin = {xyz, rpy}` with `axis`, `mdh` (modified
///    DH) or `dh` (standard DH: the part after the joint is carried into the children, bodies,
///    frames and spring anchors of the link), fixed, spherical (three revolute joints about z, y, x
///    named <name>_z, <name>_y, <name>_x), gear couplings (`mimic`), limits;
///  - a joint's `link = {mass, com, inertia}` and `[[mechanism.bodies]]` (with `rpy`);
///  - `[[mechanism.frames]]`, `[[mechanism.loops]]`, `actuated`, `[[mechanism.springs]]`, `gravity`
///    and `base` (the placement of the root joints' base frame in O).
/// Strict like the Python reader: unknown keys, wrong types, non-finite or absurd (> 1e12) numbers,
/// missing fields, bad cross references all throw ConfigError, whose message names the dotted
/// field and the value (`mechanism.joints[1].link.mass: must be >= 0 (got -1.0)`). Other tables of
/// the file ([case], [trajectory], [balance], ...) are left to their own readers.
/// Load time only: nothing here is called from a control tick.
#include <stdexcept>
#include <string>

#include "mechbal/control/config.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/control/trajectory.hpp"

namespace mechbal {

/// A configuration value is missing, unknown, of the wrong type or out of range. what() is
/// "<field>: <message>"; field() is the dotted path (`mechanism.joints[1].link.mass`).
class ConfigError : public std::invalid_argument {
 public:
  ConfigError(std::string field, const std::string& message);
  const std::string& field() const noexcept { return field_; }

 private:
  std::string field_;
};

/// The MechanismDescription of a `[mechanism]` table given as TOML text (the whole document;
/// `source` names it in parse errors).
MechanismDescription mechanism_description_from_string(const std::string& toml_text,
                                                      const std::string& source = "string");

/// The model of the `[mechanism]` table of a case file or `balanced.toml`.
MechanismModel load_mechanism(const std::string& path);
/// As load_mechanism, from TOML text.
MechanismModel mechanism_from_string(const std::string& toml_text, const std::string& source = "string");

/// The `[trajectory]` table of a mechanism case (kinds `mechanism` and `serial_chain`): a
/// rest-to-rest motion of the actuated coordinates (model order), `initial_guess` the full
/// coordinates near the assembly at start (closed mechanisms; empty when absent).
struct TrajectoryConfig {
  bool present = false;
  /// law = "quintic" | "cubic": rest-to-rest from start to end in duration (law holds which);
  /// law = "constant_speed": constant_speed is true, q = start + speed t over duration.
  TimeLaw law = TimeLaw::quintic;
  bool constant_speed = false;
  std::vector<double> start, end;
  /// constant_speed: one speed per actuated joint [rad/s or m/s] (`rpm` converted; one number
  /// given applies to every joint)
  std::vector<double> speed;
  /// [s]; constant_speed with `revolutions`: revolutions 2 pi / max |speed|
  double duration = 0.0;
  double revolutions = 0.0;  ///< constant_speed: turns of the fastest joint, when given (else 0)
  int samples = 501;
  /// every joint coordinate near the assembly at start, or the actuated joints only (the passive
  /// ones are then solved on `branch`)
  std::vector<double> initial_guess;
  std::string branch;  ///< "open" | "crossed" (four-bar-like loops), or empty
};

/// A case as the embedded side needs it: the model, the `[control]` table checked against it
/// (kind none when absent), the `[trajectory]` of a mechanism case and the case's name
/// (`[case] name`, empty when absent).
struct LoadedCase {
  MechanismModel model;
  ControlConfig control;
  TrajectoryConfig trajectory;
  std::string name;
};

/// load_mechanism + the `[control]` table (sizes, joint and frame names checked against the model)
/// + the `[trajectory]` of a `mechanism` / `serial_chain` case (sizes checked; other kinds' own
/// trajectory tables are left alone).
LoadedCase load_case(const std::string& path);
LoadedCase case_from_string(const std::string& toml_text, const std::string& source = "string");

/// The `[control]` table of a TOML file of its own (the controls engineer's settings kept apart
/// from the design that `mechbal balance` writes), checked against `model`.
ControlConfig load_control(const std::string& path, const MechanismModel& model);

}  // namespace mechbal
