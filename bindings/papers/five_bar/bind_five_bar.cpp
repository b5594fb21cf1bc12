// pybind11 glue for the per-tick five-bar evaluator (coupling-matrix method with a 4x4 A°,
// Coutinho & Hess Coelho). Conversion only: no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/papers/five_bar/five_bar.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

using V2 = Eigen::Vector2d;

V2 row2(const Array& a, py::ssize_t k) { return V2(a.at(k, 0), a.at(k, 1)); }

void bind_five_bar(py::module_& m) {
  py::class_<FiveBarParameters>(m, "FiveBarParameters",
                                "Planar 5R five-bar: lengths, masses, CoM positions along the "
                                "links, inertias about x (vertical y-z plane, gravity -z)")
      .def(py::init([](py::kwargs kw) {
        FiveBarParameters p;
        py::object o = py::cast(&p, py::return_value_policy::reference);
        for (auto item : kw) {
          const auto key = py::cast<std::string>(item.first);
          if (!py::hasattr(o, key.c_str()))
            throw py::value_error("FiveBarParameters: unknown field '" + key + "'");
          o.attr(key.c_str()) = item.second;
        }
        return p;
      }))
      .def_readwrite("a1", &FiveBarParameters::a1)
      .def_readwrite("a2", &FiveBarParameters::a2)
      .def_readwrite("b1", &FiveBarParameters::b1)
      .def_readwrite("b2", &FiveBarParameters::b2)
      .def_readwrite("d", &FiveBarParameters::d)
      .def_readwrite("mp1", &FiveBarParameters::mp1)
      .def_readwrite("mp2", &FiveBarParameters::mp2)
      .def_readwrite("md1", &FiveBarParameters::md1)
      .def_readwrite("md2", &FiveBarParameters::md2)
      .def_readwrite("mP", &FiveBarParameters::mP)
      .def_readwrite("cp1", &FiveBarParameters::cp1)
      .def_readwrite("cp2", &FiveBarParameters::cp2)
      .def_readwrite("cd1", &FiveBarParameters::cd1)
      .def_readwrite("cd2", &FiveBarParameters::cd2)
      .def_readwrite("Jp1", &FiveBarParameters::Jp1)
      .def_readwrite("Jp2", &FiveBarParameters::Jp2)
      .def_readwrite("Jd1", &FiveBarParameters::Jd1)
      .def_readwrite("Jd2", &FiveBarParameters::Jd2)
      .def_readwrite("gravity", &FiveBarParameters::gravity);

  // an InverseDynamics back end: the general ComputedTorque accepts it (bind_computed_torque.cpp)
  py::class_<FiveBarDynamics, InverseDynamics>(m, "FiveBarDynamics",
                              "Planar 5R by the coupling-matrix method (4x4 A°), evaluated per "
                              "tick: M'(q), v'(q, qd), g'(q); Status.singular at type-2 "
                              "singularities")
      .def(py::init<const FiveBarParameters&, double>(), py::arg("parameters"),
           py::arg("singular_tolerance") = 1e-6)
      .def_property_readonly("dof", &FiveBarDynamics::dof)
      .def_property_readonly("parameters", &FiveBarDynamics::parameters)
      .def_property_readonly("reciprocal_condition", &FiveBarDynamics::reciprocal_condition)
      .def(
          "evaluate",
          [](FiveBarDynamics& f, const Array& q, const Array& qd) {
            const auto N = batch_rows(2, {{q, "q"}, {qd, "v"}});
            OutArray M = make_array({N, 2, 2}), v = make_array({N, 2}), g = make_array({N, 2}),
                     rc = make_array({N});
            py::array_t<bool> ok(N);
            auto per_instant = make_status_array(N);
            Status status = Status::ok;
            for (py::ssize_t k = 0; k < N; ++k) {
              Eigen::Matrix2d Mk = Eigen::Matrix2d::Zero();
              V2 vk = V2::Zero(), gk = V2::Zero();
              const Status s = f.evaluate(row2(q, k), row2(qd, k), Mk, vk, gk);
              status |= s;
              per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
              ok.mutable_at(k) = s == Status::ok;
              rc.mutable_at(k) = f.reciprocal_condition();
              for (int i = 0; i < 2; ++i) {
                v.mutable_at(k, i) = vk(i);
                g.mutable_at(k, i) = gk(i);
                for (int j = 0; j < 2; ++j) M.mutable_at(k, i, j) = Mk(i, j);
              }
            }
            py::dict out;
            out["mass"] = M;
            out["velocity"] = v;
            out["gravity"] = g;
            out["ok"] = ok;
            out["reciprocal_condition"] = rc;
            out["status"] = status;
            out["status_per_instant"] = per_instant;
            return out;
          },
          py::arg("q"), py::arg("v"),
          "For N states (q, qd each (N, 2)): {'mass' (N, 2, 2), 'velocity', 'gravity' (N, 2), "
          "'ok' (N,), 'reciprocal_condition' (N,), 'status_per_instant' (N,), 'status' (OR)}; "
          "failed states give zeros")
      .def(
          "inverse_dynamics",
          [](FiveBarDynamics& f, const Array& q, const Array& qd, const Array& qdd) {
            const auto N = batch_rows(2, {{q, "q"}, {qd, "v"}, {qdd, "a"}});
            OutArray tau = make_array({N, 2});
            auto per_instant = make_status_array(N);
            Status status = Status::ok;
            for (py::ssize_t k = 0; k < N; ++k) {
              Eigen::VectorXd t = Eigen::VectorXd::Zero(2);
              const Status s = f.inverse_dynamics(row2(q, k), row2(qd, k), row2(qdd, k), t);
              if (s != Status::ok) t.setZero();
              status |= s;
              per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
              tau.mutable_at(k, 0) = t(0);
              tau.mutable_at(k, 1) = t(1);
            }
            py::dict out;
            out["tau"] = tau;
            out["status"] = status;
            out["status_per_instant"] = per_instant;
            return out;
          },
          py::arg("q"), py::arg("v"), py::arg("a"),
          "Joint torques (N, 2): {'tau', 'status_per_instant' (N,), 'status' (OR)}")
      .def(
          "motion",
          [](FiveBarDynamics& f, const Array& q, const Array& qd, const Array& qdd) {
            const auto N = batch_rows(2, {{q, "q"}, {qd, "v"}, {qdd, "a"}});
            OutArray ang = make_array({N, 4}), rate = make_array({N, 4}), acc = make_array({N, 4}),
                     P = make_array({N, 2}), vP = make_array({N, 2}), aP = make_array({N, 2});
            auto per_instant = make_status_array(N);
            Status status = Status::ok;
            for (py::ssize_t k = 0; k < N; ++k) {
              FiveBarMotion mo;  // zeros, left so by a failed instant
              const Status s = f.motion(row2(q, k), row2(qd, k), row2(qdd, k), mo);
              if (s != Status::ok) mo = FiveBarMotion{};
              status |= s;
              per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
              for (int i = 0; i < 4; ++i) {
                ang.mutable_at(k, i) = mo.angles(i);
                rate.mutable_at(k, i) = mo.rates(i);
                acc.mutable_at(k, i) = mo.accelerations(i);
              }
              for (int i = 0; i < 2; ++i) {
                P.mutable_at(k, i) = mo.end_effector(i);
                vP.mutable_at(k, i) = mo.end_effector_velocity(i);
                aP.mutable_at(k, i) = mo.end_effector_acceleration(i);
              }
            }
            py::dict out;
            out["angles"] = ang;
            out["rates"] = rate;
            out["accelerations"] = acc;
            out["end_effector"] = P;
            out["end_effector_velocity"] = vP;
            out["end_effector_acceleration"] = aP;
            out["status"] = status;
            out["status_per_instant"] = per_instant;
            return out;
          },
          py::arg("q"), py::arg("v"), py::arg("a"),
          "Joint angles/rates/accelerations (N, 4) in the order (theta1, theta12, theta2, "
          "theta22) and the end effector (y, z) position/velocity/acceleration (N, 2); "
          "status_per_instant (N,) and their OR, status; failed instants give zeros");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(55, five_bar, bind_five_bar);

}  // namespace mechbal::pyb
