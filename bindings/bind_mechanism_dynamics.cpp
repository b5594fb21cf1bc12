#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include <memory>
#include <stdexcept>

#include "array_checks.hpp"
#include "batch_inverse_dynamics.hpp"
#include "bindings.hpp"
#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

Eigen::VectorXd one_state(const MechanismDynamics& d, const Array& v, const char* name) {
  return vector_arg(v, name, d.dof(), false, "one value per joint");
}

void bind_mechanism_dynamics(py::module_& m) {
  py::class_<MechanismDynamics, InverseDynamics, ForwardDynamics>(
      m, "MechanismDynamics",
      "Joint-space dynamics of a MechanismModel (recursive Newton-Euler inverse dynamics with the "
      "base support wrench, composite rigid body mass matrix): the InverseDynamics back end of the "
      "general model, for ComputedTorque and the simulators")
      .def(py::init([](const MechanismModel& model, const Array& q_guess) {
             const Eigen::VectorXd guess = vector_arg(q_guess, "q_guess", -1);
             try {
               return new MechanismDynamics(model, guess);
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }),
           py::arg("model"), py::arg("q_guess") = Eigen::VectorXd(),
           "Dynamics in the actuated coordinates (loops solved each call, warm-started from q_guess, "
           "the full coordinates near the assembly)")
      .def(
          "forward_dynamics",
          [](MechanismDynamics& d, const Array& q, const Array& qd, const Array& tau) {
            const Eigen::VectorXd q_ = one_state(d, q, "q"), qd_ = one_state(d, qd, "v"),
                                  tau_ = one_state(d, tau, "tau");
            Eigen::VectorXd a = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.forward_dynamics(q_, qd_, tau_, a), "MechanismDynamics.forward_dynamics");
            return a;
          },
          py::arg("q"), py::arg("v"), py::arg("tau"), "Accelerations a = M^-1 (tau - b) (actuated coordinates)")
      .def_property_readonly("solved_position",
                             [](const MechanismDynamics& d) { return Eigen::VectorXd(d.solved_position()); })
      .def_property_readonly("dof", &MechanismDynamics::dof)
      .def(
          "inverse_dynamics",
          [](MechanismDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch_inverse_dynamics(d, q, qd, qdd);
          },
          py::arg("q"), py::arg("v"), py::arg("a"),
          "Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, "
          "support_moment about the base origin, (N, 3)); q, v, a each (N, dof). Instants with "
          "non-finite input give zeros and set their flag in `status`.")
      .def(
          "mass_matrix",
          [](MechanismDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = one_state(d, q, "q");
            Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d.dof(), d.dof());
            raise_unless_ok(d.mass_matrix(q_, M), "MechanismDynamics.mass_matrix");
            return M;
          },
          py::arg("q"), "Mass matrix M(q) (dof, dof) by the composite rigid body algorithm")
      .def(
          "gravity",
          [](MechanismDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = one_state(d, q, "q");
            Eigen::VectorXd g = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.gravity(q_, g), "MechanismDynamics.gravity");
            return g;
          },
          py::arg("q"), "Gravity torques G(q) (gravity alone; with springs see static_torque)")
      .def(
          "static_torque",
          [](MechanismDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = one_state(d, q, "q");
            Eigen::VectorXd g = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.static_torque(q_, g), "MechanismDynamics.static_torque");
            return g;
          },
          py::arg("q"), "Static torques G(q) + K(q): gravity and springs")
      .def(
          "bias",
          [](MechanismDynamics& d, const Array& q, const Array& qd) {
            const Eigen::VectorXd q_ = one_state(d, q, "q"), qd_ = one_state(d, qd, "v");
            Eigen::VectorXd b = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.bias(q_, qd_, b), "MechanismDynamics.bias");
            return b;
          },
          py::arg("q"), py::arg("v"), "Bias torques C(q, v) v + G(q) + K(q) (springs included)")
      .def(
          "coriolis",
          [](MechanismDynamics& d, const Array& q, const Array& qd) {
            const Eigen::VectorXd q_ = one_state(d, q, "q"), qd_ = one_state(d, qd, "v");
            Eigen::VectorXd c = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.coriolis(q_, qd_, c), "MechanismDynamics.coriolis");
            return c;
          },
          py::arg("q"), py::arg("v"), "Coriolis and centrifugal torques C(q, v) v");

  py::class_<KdlChainDynamics, InverseDynamics>(
      m, "KdlChainDynamics",
      "Joint-space dynamics of a serial MechanismModel through Orocos KDL (the independent engine)")
      .def(py::init([](const MechanismModel& model) {
             try {
               return std::make_unique<KdlChainDynamics>(model);
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }),
           py::arg("model"),
           "From the general MechanismModel when it is a serial chain (bodies lumped per link); "
           "ValueError naming the link or joint otherwise")
      .def_property_readonly("dof", &KdlChainDynamics::dof)
      .def(
          "inverse_dynamics",
          [](KdlChainDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch_inverse_dynamics(d, q, qd, qdd);
          },
          py::arg("q"), py::arg("v"), py::arg("a"),
          "Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, "
          "support_moment about the base origin, (N, 3)) by KDL's ChainIdSolver_RNE.")
      .def(
          "mass_matrix",
          [](KdlChainDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = vector_arg(q, "q", d.dof(), false, "one value per joint");
            Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d.dof(), d.dof());
            raise_unless_ok(d.mass_matrix(q_, M), "KdlChainDynamics.mass_matrix");
            return M;
          },
          py::arg("q"), "Mass matrix M(q) (dof, dof); ValueError for non-finite or overflowing q")
      .def(
          "coriolis",
          [](KdlChainDynamics& d, const Array& q, const Array& qd) {
            const Eigen::VectorXd q_ = vector_arg(q, "q", d.dof(), false, "one value per joint");
            const Eigen::VectorXd qd_ = vector_arg(qd, "v", d.dof(), false, "one value per joint");
            Eigen::VectorXd c = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.coriolis(q_, qd_, c), "KdlChainDynamics.coriolis");
            return c;
          },
          py::arg("q"), py::arg("v"), "Coriolis and centrifugal torques C(q, v) v")
      .def(
          "gravity",
          [](KdlChainDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = vector_arg(q, "q", d.dof(), false, "one value per joint");
            Eigen::VectorXd g = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.gravity(q_, g), "KdlChainDynamics.gravity");
            return g;
          },
          py::arg("q"), "Gravity torques G(q)");
}

}  // namespace

// after bind_mechanism (30): the signatures name MechanismModel, so it must be bound first
MECHBAL_REGISTER_BINDINGS(32, mechanism_dynamics, bind_mechanism_dynamics);

}  // namespace mechbal::pyb
