#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include "array_checks.hpp"
#include "batch_inverse_dynamics.hpp"
#include "bindings.hpp"
#include "mechbal/rnea.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

Eigen::VectorXd one_state(const RneChainDynamics& d, const Array& v, const char* name) {
  return vector_arg(v, name, d.dof(), false, "one value per joint");
}

void bind_rnea(py::module_& m) {
  py::class_<RneChainDynamics, InverseDynamics>(
      m, "RneChainDynamics",
      "Joint-space dynamics of a ChainModel by mechbal's own recursive Newton-Euler (inverse "
      "dynamics, base support wrench) and composite rigid body algorithm (mass matrix)")
      .def(py::init<const ChainModel&>(), py::arg("model"))
      .def_property_readonly("dof", &RneChainDynamics::dof)
      .def(
          "inverse_dynamics",
          [](RneChainDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch_inverse_dynamics(d, q, qd, qdd);
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, "
          "support_moment about the base origin, (N, 3)); q, qd, qdd each (N, dof). Instants with "
          "non-finite input give zeros and set their flag in `status`.")
      .def(
          "mass_matrix",
          [](RneChainDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = one_state(d, q, "q");
            Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d.dof(), d.dof());
            raise_unless_ok(d.mass_matrix(q_, M), "RneChainDynamics.mass_matrix");
            return M;
          },
          py::arg("q"), "Mass matrix M(q) (dof, dof) by the composite rigid body algorithm")
      .def(
          "gravity",
          [](RneChainDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = one_state(d, q, "q");
            Eigen::VectorXd g = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.gravity(q_, g), "RneChainDynamics.gravity");
            return g;
          },
          py::arg("q"), "Gravity torques G(q)")
      .def(
          "bias",
          [](RneChainDynamics& d, const Array& q, const Array& qd) {
            const Eigen::VectorXd q_ = one_state(d, q, "q"), qd_ = one_state(d, qd, "qd");
            Eigen::VectorXd b = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.bias(q_, qd_, b), "RneChainDynamics.bias");
            return b;
          },
          py::arg("q"), py::arg("qd"), "Bias torques C(q, qd) qd + G(q)")
      .def(
          "coriolis",
          [](RneChainDynamics& d, const Array& q, const Array& qd) {
            const Eigen::VectorXd q_ = one_state(d, q, "q"), qd_ = one_state(d, qd, "qd");
            Eigen::VectorXd c = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.coriolis(q_, qd_, c), "RneChainDynamics.coriolis");
            return c;
          },
          py::arg("q"), py::arg("qd"), "Coriolis and centrifugal torques C(q, qd) qd");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(25, rnea, bind_rnea);

}  // namespace mechbal::pyb
