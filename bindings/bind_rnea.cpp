#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include "array_checks.hpp"
#include "batch_inverse_dynamics.hpp"
#include "bindings.hpp"
#include "mechbal/rnea.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

std::string failure_text(Status s) {
  return std::string("rejected (") + status_name(s) + "): the state must be finite and, for a closed "
         "mechanism, the loops must close near the previous pose";
}

Eigen::VectorXd one_state(const MechanismDynamics& d, const Eigen::VectorXd& v, const char* name) {
  if (v.size() != d.dof()) {
    throw py::value_error(std::string(name) + " must have " + std::to_string(d.dof()) +
                          " values, got " + std::to_string(v.size()));
  }
  return v;
}

void bind_rnea(py::module_& m) {
  py::class_<MechanismDynamics, InverseDynamics, ForwardDynamics>(
      m, "MechanismDynamics",
      "Joint-space dynamics of a MechanismModel (recursive Newton-Euler inverse dynamics with the "
      "base support wrench, composite rigid body mass matrix): the InverseDynamics back end of the "
      "general model, for ComputedTorque and the simulators")
      .def(py::init([](const MechanismModel& model, const Eigen::VectorXd& q_guess) {
             try {
               return new MechanismDynamics(model, q_guess);
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }),
           py::arg("model"), py::arg("q_guess") = Eigen::VectorXd(),
           "Dynamics in the actuated coordinates (loops solved each call, warm-started from q_guess, "
           "the full coordinates near the assembly)")
      .def(
          "forward_dynamics",
          [](MechanismDynamics& d, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& tau) {
            one_state(d, q, "q");
            one_state(d, qd, "qd");
            one_state(d, tau, "tau");
            Eigen::VectorXd a(d.dof());
            const Status s = d.forward_dynamics(q, qd, tau, a);
            if (s != Status::ok) {
              throw py::value_error(std::string("forward dynamics failed: ") + status_name(s));
            }
            return a;
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"), "Accelerations a = M^-1 (tau - b) (actuated coordinates)")
      .def_property_readonly("solved_position",
                             [](const MechanismDynamics& d) { return Eigen::VectorXd(d.solved_position()); })
      .def_property_readonly("dof", &MechanismDynamics::dof)
      .def(
          "inverse_dynamics",
          [](MechanismDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch_inverse_dynamics(d, q, qd, qdd);
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, "
          "support_moment about the base origin, (N, 3)); q, qd, qdd each (N, dof). Instants with "
          "non-finite input give zeros and set their flag in `status`.")
      .def(
          "mass_matrix",
          [](MechanismDynamics& d, const Eigen::VectorXd& q) {
            one_state(d, q, "q");
            Eigen::MatrixXd M(d.dof(), d.dof());
            if (const Status s = d.mass_matrix(q, M); s != Status::ok) throw py::value_error(failure_text(s));
            return M;
          },
          py::arg("q"), "Mass matrix M(q) (dof, dof) by the composite rigid body algorithm")
      .def(
          "gravity",
          [](MechanismDynamics& d, const Eigen::VectorXd& q) {
            one_state(d, q, "q");
            Eigen::VectorXd g(d.dof());
            if (const Status s = d.gravity(q, g); s != Status::ok) throw py::value_error(failure_text(s));
            return g;
          },
          py::arg("q"), "Gravity torques G(q)")
      .def(
          "bias",
          [](MechanismDynamics& d, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
            one_state(d, q, "q");
            one_state(d, qd, "qd");
            Eigen::VectorXd b(d.dof());
            if (const Status s = d.bias(q, qd, b); s != Status::ok) throw py::value_error(failure_text(s));
            return b;
          },
          py::arg("q"), py::arg("qd"), "Bias torques C(q, qd) qd + G(q)")
      .def(
          "coriolis",
          [](MechanismDynamics& d, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
            one_state(d, q, "q");
            one_state(d, qd, "qd");
            Eigen::VectorXd c(d.dof());
            if (const Status s = d.coriolis(q, qd, c); s != Status::ok) throw py::value_error(failure_text(s));
            return c;
          },
          py::arg("q"), py::arg("qd"), "Coriolis and centrifugal torques C(q, qd) qd");

  py::class_<RneChainDynamics, MechanismDynamics>(
      m, "RneChainDynamics",
      "MechanismDynamics of a serial ChainModel (the chain as a general mechanism)")
      .def(py::init<const ChainModel&>(), py::arg("model"));
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(25, rnea, bind_rnea);

}  // namespace mechbal::pyb
