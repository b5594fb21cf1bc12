// pybind11 glue for the 2-DOF arm's closed-form dynamics (Arakelian, Le Baron & Mottu 2011). The
// computed-torque controller and the closed-loop simulator it is run with are general
// (bindings/bind_computed_torque.cpp, bindings/bind_closed_loop.cpp). Conversion only: no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/papers/arm2dof/arm2dof.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

using CVec = Eigen::Map<const Eigen::VectorXd>;

// Applies a per-sample 2-in-3-out function over (N, 2) arrays.
template <class F>
py::dict batch3(const Array& a, const char* na, const Array& b, const char* nb, const Array& c,
                const char* nc, const char* out_name, F&& f) {
  const auto N = batch_rows(2, {{a, na}, {b, nb}, {c, nc}});
  OutArray out = make_array({N, 2});
  auto per_instant = make_status_array(N);
  Status status = Status::ok;
  for (py::ssize_t k = 0; k < N; ++k) {
    Eigen::Map<Eigen::VectorXd> o(out.mutable_data(k, 0), 2);
    const Status s = f(CVec(a.data(k, 0), 2), CVec(b.data(k, 0), 2), CVec(c.data(k, 0), 2), o);
    if (s != Status::ok) o.setZero();
    status |= s;
    per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
  }
  py::dict d;
  d[out_name] = out;
  d["status"] = status;
  d["status_per_instant"] = per_instant;
  return d;
}

template <typename T>
T finite_result(const T& value, const char* what) {
  bool finite;
  if constexpr (std::is_arithmetic_v<T>) finite = std::isfinite(value);
  else finite = value.allFinite();
  if (!finite)
    throw py::value_error(std::string("Arm2DofDynamics.") + what +
                          ": the result overflowed (input out of range)");
  return value;
}

void bind_arm2dof(py::module_& m) {
  py::class_<Arm2DofParameters>(m, "Arm2DofParameters",
                                "Bare 2R arm of Arakelian et al. 2011, Fig. 1 (defaults: Sec. 4)")
      .def(py::init([](double m1, double m2, double l1, double l_s1, double l_s2, double i_s1,
                       double i_s2, double g) {
             return Arm2DofParameters{m1, m2, l1, l_s1, l_s2, i_s1, i_s2, g};
           }),
           py::arg("m1") = 2.5, py::arg("m2") = 2.0, py::arg("l1") = 0.4, py::arg("l_s1") = 0.1,
           py::arg("l_s2") = 0.1, py::arg("i_s1") = 0.15, py::arg("i_s2") = 0.1,
           py::arg("g") = 9.81)
      .def_readwrite("m1", &Arm2DofParameters::m1)
      .def_readwrite("m2", &Arm2DofParameters::m2)
      .def_readwrite("l1", &Arm2DofParameters::l1)
      .def_readwrite("l_s1", &Arm2DofParameters::l_s1)
      .def_readwrite("l_s2", &Arm2DofParameters::l_s2)
      .def_readwrite("i_s1", &Arm2DofParameters::i_s1)
      .def_readwrite("i_s2", &Arm2DofParameters::i_s2)
      .def_readwrite("g", &Arm2DofParameters::g);

  py::class_<Arm2DofCounterweights>(m, "Arm2DofCounterweights",
                                    "Point-mass counterweights beyond A and B (eqs 25-31)")
      .def(py::init([](double m_cw1, double m_cw2, double r_cw1, double r_cw2) {
             return Arm2DofCounterweights{m_cw1, m_cw2, r_cw1, r_cw2};
           }),
           py::arg("m_cw1") = 0.0, py::arg("m_cw2") = 0.0, py::arg("r_cw1") = 0.0,
           py::arg("r_cw2") = 0.0)
      .def_readwrite("m_cw1", &Arm2DofCounterweights::m_cw1)
      .def_readwrite("m_cw2", &Arm2DofCounterweights::m_cw2)
      .def_readwrite("r_cw1", &Arm2DofCounterweights::r_cw1)
      .def_readwrite("r_cw2", &Arm2DofCounterweights::r_cw2);

  m.def("arm2dof_description", &arm2dof_description, py::arg("arm"),
        py::arg_v("counterweights", Arm2DofCounterweights{}, "Arm2DofCounterweights()"),
        "The 2-DOF arm (counterweights merged into the links) as a general MechanismDescription: "
        "x-z plane, joints 'shoulder' and 'elbow' with axes along -y, gravity (0, 0, -g)");

  py::class_<Arm2DofDynamics, InverseDynamics, ForwardDynamics>(m, "Arm2DofDynamics",
                              "Closed-form dynamics of the 2-DOF arm, eqs 14-31 (corrected)")
      .def(py::init<const Arm2DofParameters&, const Arm2DofCounterweights&>(), py::arg("arm"),
           py::arg_v("counterweights", Arm2DofCounterweights{}, "Arm2DofCounterweights()"))
      .def_property_readonly("dof", [](const Arm2DofDynamics& d) { return d.dof(); })
      .def_property_readonly("lumped",
                             [](const Arm2DofDynamics& d) {
                               const Arm2DofLumped& p = d.lumped();
                               py::dict o;
                               o["j1"] = p.j1;
                               o["s1"] = p.s1;
                               o["M2"] = p.M2;
                               o["s2"] = p.s2;
                               o["j2"] = p.j2;
                               o["l1"] = p.l1;
                               o["g"] = p.g;
                               return o;
                             })
      .def(
          "inverse_dynamics",
          [](Arm2DofDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch3(q, "q", qd, "v", qdd, "a", "tau",
                          [&](const auto& a, const auto& b, const auto& c, auto& o) {
                            return d.inverse_dynamics(a, b, c, o);
                          });
          },
          py::arg("q"), py::arg("v"), py::arg("a"), "Joint torques (N, 2): {'tau', 'status'}")
      .def(
          "forward_dynamics",
          [](Arm2DofDynamics& d, const Array& q, const Array& qd, const Array& tau) {
            return batch3(q, "q", qd, "v", tau, "tau", "a",
                          [&](const auto& a, const auto& b, const auto& c, auto& o) {
                            return d.forward_dynamics(a, b, c, o);
                          });
          },
          py::arg("q"), py::arg("v"), py::arg("tau"), "Accelerations (N, 2): {'a', 'status'}")
      // no status in these signatures: NaN input or an overflowing result is a ValueError
      .def("mass_matrix",
           [](const Arm2DofDynamics& d, const Array& q) {
             return finite_result(d.mass_matrix(fixed_vector<2>(q, "q", true)), "mass_matrix");
           },
           py::arg("q"), "A(q) (2, 2), eqs 14-19 (corrected)")
      .def("coriolis_matrix",
           [](const Arm2DofDynamics& d, const Array& q, const Array& qd) {
             return finite_result(d.coriolis_matrix(fixed_vector<2>(q, "q", true),
                                                    fixed_vector<2>(qd, "v", true)),
                                  "coriolis_matrix");
           },
           py::arg("q"), py::arg("v"), "C(q, v) (2, 2), Christoffel form")
      .def("gravity",
           [](const Arm2DofDynamics& d, const Array& q) {
             return finite_result(d.gravity(fixed_vector<2>(q, "q", true)), "gravity");
           },
           py::arg("q"), "Q(q) (2,), eqs 21-22")
      .def("kinetic_energy",
           [](const Arm2DofDynamics& d, const Array& q, const Array& qd) {
             return finite_result(d.kinetic_energy(fixed_vector<2>(q, "q", true),
                                                   fixed_vector<2>(qd, "v", true)),
                                  "kinetic_energy");
           },
           py::arg("q"), py::arg("v"))
      .def("potential_energy",
           [](const Arm2DofDynamics& d, const Array& q) {
             return finite_result(d.potential_energy(fixed_vector<2>(q, "q", true)),
                                  "potential_energy");
           },
           py::arg("q"));
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(40, arm2dof, bind_arm2dof);

}  // namespace mechbal::pyb
