#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <sstream>
#include <vector>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

std::vector<RigidBody> make_bodies(const Array& mass, const Array& inertia) {
  require_shape(mass, "mass", {-1});
  const auto B = mass.shape(0);
  require_shape(inertia, "inertia_body", {B, 3, 3});
  std::vector<RigidBody> bodies(static_cast<std::size_t>(B));
  auto m = mass.unchecked<1>();
  auto I = inertia.unchecked<3>();
  for (pybind11::ssize_t j = 0; j < B; ++j) {
    bodies[j].mass = m(j);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) bodies[j].inertia_body(r, c) = I(j, r, c);
    const std::string field = "bodies[" + std::to_string(j) + "]";
    validate_rigid_body(bodies[j], field.c_str());
  }
  return bodies;
}

}  // namespace

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

  m.def(
      "shaking_wrench",
      [](const Array& mass, const Array& inertia_body, const Array& com, const Array& com_velocity,
         const Array& com_acceleration, const Array& rotation, const Array& angular_velocity,
         const Array& angular_acceleration) {
        require_shape(com, "com", {-1, -1, 3});
        const auto N = com.shape(0), B = com.shape(1);
        std::vector<RigidBody> bodies = make_bodies(mass, inertia_body);
        if (static_cast<pybind11::ssize_t>(bodies.size()) != B) {
          std::ostringstream msg;
          msg << "com has " << B << " bodies but mass has " << bodies.size();
          throw pybind11::value_error(msg.str());
        }
        require_shape(com_velocity, "com_velocity", {N, B, 3});
        require_shape(com_acceleration, "com_acceleration", {N, B, 3});
        require_shape(rotation, "rotation", {N, B, 3, 3});
        require_shape(angular_velocity, "angular_velocity", {N, B, 3});
        require_shape(angular_acceleration, "angular_acceleration", {N, B, 3});
        OutArray F = make_array({N, 3}), M = make_array({N, 3}), P = make_array({N, 3}),
                 H = make_array({N, 3});
        auto per_instant = make_status_array(N);
        BodyTrajectoryView view{static_cast<std::size_t>(N), static_cast<std::size_t>(B),
                                com.data(), com_velocity.data(), com_acceleration.data(),
                                rotation.data(), angular_velocity.data(),
                                angular_acceleration.data()};
        Status s;
        {
          py::gil_scoped_release release;
          s = shaking_wrench_batch(bodies.data(), view, F.mutable_data(), M.mutable_data(),
                                   P.mutable_data(), H.mutable_data(), per_instant.mutable_data());
        }
        py::dict out;
        out["force"] = F;
        out["moment"] = M;
        out["linear_momentum"] = P;
        out["angular_momentum"] = H;
        out["status"] = s;
        out["status_per_instant"] = per_instant;
        return out;
      },
      py::arg("mass"), py::arg("inertia_body"), py::arg("com"), py::arg("com_velocity"),
      py::arg("com_acceleration"), py::arg("rotation"), py::arg("angular_velocity"),
      py::arg("angular_acceleration"),
      R"doc(Shaking force and moment about O of B bodies over N instants (Briot & Arakelian 2009,
eqs 1-4), in one C++ call.

mass (B,), inertia_body (B,3,3) about each centre of mass in the body frame; com, com_velocity,
com_acceleration, angular_velocity, angular_acceleration (N,B,3) and rotation (N,B,3,3) body->base,
all in the base frame. Returns a dict of (N,3) arrays: force (dP/dt), moment (dH_O/dt),
linear_momentum, angular_momentum; status_per_instant (N,) and their OR, status. Instants with
non-finite input (non_finite_input) or an overflowing wrench (out_of_range) give zeros.)doc");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(0, core, bind_core);

}  // namespace mechbal::pyb
