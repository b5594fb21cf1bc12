// pybind11 glue for the decoupled joint controller of dynamically balanced arms (Coutinho & Hess
// Coelho; the arms themselves, discs included, are general mechanisms). Conversion only: no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "controller_step.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/decoupled_control.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {


void bind_decoupled_control(py::module_& m) {
  py::class_<DecoupledJointController, JointController> dc(
      m, "DecoupledJointController",
      "tau_i = k_i (a_des + Kp e + Kd e') for a dynamically balanced arm (Coutinho & Hess Coelho "
      "eqs 15, 26, 36)");
  dc.def(py::init([](const Array& k, const Array& kp, const Array& kd,
                       const py::object& torque_limit, double max_position, double max_speed,
                       double max_acceleration) {
             const Eigen::VectorXd limit =
                 torque_limit.is_none()
                     ? Eigen::VectorXd()
                     : vector_arg(to_real_array(torque_limit), "torque_limit", -1);
             return DecoupledJointController(
                 vector_arg(k, "k", -1), vector_arg(kp, "kp", -1), vector_arg(kd, "kd", -1), limit,
                 joint_input_range(max_position, max_speed, max_acceleration));
           }),
           py::arg("k"), py::arg("kp"), py::arg("kd"), py::arg("torque_limit") = py::none(),
           MECHBAL_JOINT_RANGE_ARGS,
           "k, kp, kd: one value per joint; torque_limit: one per joint (default and +inf: no "
           "limit); max_position, max_speed, max_acceleration: the input range of a tick (default "
           "+inf: no limit; beyond it: the held command and Status.out_of_range)");
  dc.def_property_readonly("torque_limit", [](const DecoupledJointController& c) {
        return Eigen::VectorXd(c.torque_limit());
      })
      .def_property_readonly("dof", &DecoupledJointController::dof)
      .def_property_readonly("k", [](const DecoupledJointController& c) {
        return Eigen::VectorXd(c.k());
      })
      .def_property_readonly("last_command", [](const DecoupledJointController& c) {
        return Eigen::VectorXd(c.last_command());
      });
  bind_joint_controller_ticks<DecoupledJointController>(dc);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(50, decoupled_control, bind_decoupled_control);

}  // namespace mechbal::pyb
