// pybind11 glue of the URDF reader (mechbal/urdf.hpp): a URDF file or document as a validated
// MechanismModel (or its description). Errors (std::invalid_argument naming the URDF element and
// the value) become ValueError. Python's mechbal.Mechanism.from_urdf wraps these.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "bindings.hpp"
#include "value_errors.hpp"
#include "mechbal/io/urdf.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_urdf(py::module_& m) {
  m.attr("MAX_URDF_BYTES") = kMaxUrdfBytes;
  m.attr("MAX_URDF_DEPTH") = kMaxUrdfDepth;
  m.def(
      "mechanism_from_urdf",
      [](const std::string& path) { return value_errors([&] { return model_from_urdf_file(path); }); },
      py::arg("path"),
      "The MechanismModel of a URDF file (urdfdom): links with inertials as bodies, revolute / "
      "continuous / prismatic / fixed joints, mimic as gear couplings, limits, a frame per link. "
      "ValueError names the URDF element and the value.");
  m.def(
      "mechanism_from_urdf_string",
      [](const std::string& xml) { return value_errors([&] { return model_from_urdf_string(xml); }); },
      py::arg("xml"), "The MechanismModel of a URDF document given as a string.");
  m.def(
      "read_urdf",
      [](const std::string& path, bool strict, bool allow_massless) {
        return value_errors([&] {
          UrdfReading r = read_urdf_file(path, UrdfOptions{strict, allow_massless});
          std::vector<std::string> warnings = r.warnings;
          return py::make_tuple(model_from_urdf_reading(std::move(r), "URDF file '" + path + "'"),
                                warnings);
        });
      },
      py::arg("path"), py::arg("strict") = false, py::arg("allow_massless") = false,
      "(MechanismModel, warnings) of a URDF file: strict refuses the defects that the lenient "
      "reading repairs with one warning each (mechbal/io/urdf.hpp, UrdfOptions); a URDF with no "
      "<inertial> on any moving link is refused unless allow_massless.");
  m.def(
      "urdf_description",
      [](const std::string& path) { return value_errors([&] { return urdf_description_from_file(path); }); },
      py::arg("path"), "The MechanismDescription of a URDF file (before validation by the model).");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(35, urdf, bind_urdf);

}  // namespace mechbal::pyb
