// pybind11 glue of the C++ case-format reader (mechbal/io/case.hpp): the [mechanism] table of a
// case file or TOML text as a validated MechanismModel, read by C++ (toml++) rather than by
// mechbal.spec. The parity tests compare the two readers; errors (mechbal::ConfigError, naming the
// dotted field and the value) become ValueError.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "bindings.hpp"
#include "value_errors.hpp"
#include "mechbal/io/case.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_io(py::module_& m) {
  m.def(
      "load_mechanism_file", [](const std::string& path) { return value_errors([&] { return load_mechanism(path); }); },
      py::arg("path"),
      "The MechanismModel of the [mechanism] table of a case file or balanced.toml, read by the C++ "
      "reader (mechbal::load_mechanism). ValueError naming the dotted field and the value.");
  m.def(
      "mechanism_from_toml",
      [](const std::string& text, const std::string& source) {
        return value_errors([&] { return mechanism_from_string(text, source); });
      },
      py::arg("text"), py::arg("source") = "string",
      "As load_mechanism_file, from TOML text (the whole document).");
  py::class_<ControlConfig>(m, "ControlConfig", "The [control] table as the C++ reader checked it (read only)")
      .def_property_readonly("kind", [](const ControlConfig& c) { return std::string(control_kind_name(c.kind)); })
      .def_readonly("rate_hz", &ControlConfig::rate_hz)
      .def_readonly("kp", &ControlConfig::kp)
      .def_readonly("kd", &ControlConfig::kd)
      .def_readonly("torque_limit", &ControlConfig::torque_limit)
      .def_readonly("k", &ControlConfig::k)
      .def_readonly("balancing_joints", &ControlConfig::balancing_joints)
      .def_readonly("cancel", &ControlConfig::cancel)
      .def_readonly("integrator", &ControlConfig::integrator)
      .def_readonly("damping", &ControlConfig::damping)
      .def_readonly("max_rate", &ControlConfig::max_rate)
      .def_readonly("home_gain", &ControlConfig::home_gain)
      .def_readonly("limit_gain", &ControlConfig::limit_gain)
      .def_readonly("task_frame", &ControlConfig::task_frame);
  m.def(
      "load_case_file",
      [](const std::string& path) {
        return value_errors([&] {
          LoadedCase c = load_case(path);
          return py::make_tuple(std::move(c.model), c.control, c.name);
        });
      },
      py::arg("path"),
      "(model, control, name) of a case file read by the C++ reader (mechbal::load_case): the "
      "[mechanism] model, the [control] table checked against it (kind 'none' without one) and "
      "[case] name.");
  m.def(
      "case_from_toml",
      [](const std::string& text, const std::string& source) {
        return value_errors([&] {
          LoadedCase c = case_from_string(text, source);
          return py::make_tuple(std::move(c.model), c.control, c.name);
        });
      },
      py::arg("text"), py::arg("source") = "string", "As load_case_file, from TOML text (the whole document).");
  py::class_<TrajectoryConfig>(m, "TrajectoryConfig", "The [trajectory] table as the C++ reader checked it (read only)")
      .def_readonly("present", &TrajectoryConfig::present)
      .def_readonly("law", &TrajectoryConfig::law)
      .def_readonly("constant_speed", &TrajectoryConfig::constant_speed)
      .def_readonly("start", &TrajectoryConfig::start)
      .def_readonly("end", &TrajectoryConfig::end)
      .def_readonly("speed", &TrajectoryConfig::speed)
      .def_readonly("duration", &TrajectoryConfig::duration)
      .def_readonly("revolutions", &TrajectoryConfig::revolutions)
      .def_readonly("samples", &TrajectoryConfig::samples)
      .def_readonly("initial_guess", &TrajectoryConfig::initial_guess)
      .def_readonly("branch", &TrajectoryConfig::branch);
  m.def(
      "load_case_trajectory",
      [](const std::string& path) { return value_errors([&] { return load_case(path).trajectory; }); },
      py::arg("path"),
      "The [trajectory] of a mechanism case file as the C++ reader (mechbal::load_case) checked it: "
      "constant_speed with speed [rad/s] per actuated joint (rpm converted) and duration [s] "
      "(from revolutions when given), or a rest-to-rest law with start, end and duration.");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(36, io, bind_io);

}  // namespace mechbal::pyb
