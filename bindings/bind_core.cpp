#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_core(pybind11::module_& m) {
  py::enum_<Status>(m, "Status", py::arithmetic(), "Bit flags returned by real-time algorithms")
      .value("ok", Status::ok)
      .value("non_finite_input", Status::non_finite_input)
      .value("singular", Status::singular)
      .value("saturated", Status::saturated)
      .value("bad_size", Status::bad_size)
      .value("solver_error", Status::solver_error)
      .value("out_of_range", Status::out_of_range);
  // A status compares equal to the integer of its bit flags (and hashes like it), so that the
  // Status a tick returns, the int of step_into and the uint32 entries of a batch's status array
  // are interchangeable: `status == Status.ok`, `run.status[k] == Status.saturated`.
  py::object status_cls = m.attr("Status");
  auto index_of = [](const py::handle& o) -> py::object {
    PyObject* r = PyNumber_Index(o.ptr());
    if (!r) {
      PyErr_Clear();
      return py::none();
    }
    return py::reinterpret_steal<py::object>(r);
  };
  status_cls.attr("__eq__") = py::cpp_function(
      [index_of](const py::object& a, const py::object& b) -> py::object {
        py::object ib = index_of(b);
        if (ib.is_none()) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
        return py::bool_(index_of(a).equal(ib));
      },
      py::is_method(status_cls), py::arg("other"));
  status_cls.attr("__ne__") = py::cpp_function(
      [index_of](const py::object& a, const py::object& b) -> py::object {
        py::object ib = index_of(b);
        if (ib.is_none()) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
        return py::bool_(!index_of(a).equal(ib));
      },
      py::is_method(status_cls), py::arg("other"));
  status_cls.attr("__hash__") = py::cpp_function(
      [index_of](const py::object& a) { return py::hash(index_of(a)); }, py::is_method(status_cls));

  m.def("status_name", [](std::uint32_t s) { return std::string(status_name(static_cast<Status>(s))); },
        py::arg("status"), "Name of a Status value ('multiple' for a combination of flags)");

  m.def(
      "validate_rigid_body",
      [](double mass, const Array& inertia, const std::string& field) {
        RigidBody b;
        b.mass = mass;
        b.inertia_body = fixed_matrix<3, 3>(inertia, "inertia_body");
        validate_rigid_body(b, field.c_str());
      },
      py::arg("mass"), py::arg("inertia_body"), py::arg("field") = "body",
      "Raise ValueError naming `field` if the mass is negative/non-finite or the inertia is not a "
      "symmetric positive semi-definite tensor satisfying the triangle inequality.");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(0, core, bind_core);

}  // namespace mechbal::pyb
