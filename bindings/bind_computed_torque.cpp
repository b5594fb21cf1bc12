// pybind11 glue for the computed-torque controller (control/computed_torque.hpp), over any
// InverseDynamics back end. Conversion only: no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "controller_step.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/dynamics.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_computed_torque(py::module_& m) {
  py::class_<ComputedTorque, JointController> ct(m, "ComputedTorque",
                             "Computed-torque control, Arakelian et al. 2011 eqs 2-6, over any "
                             "inverse-dynamics back end (keeps the model alive)");
  ct.def(py::init(&make_computed_torque<InverseDynamics>), py::arg("model"), py::arg("kp"),
           py::arg("kd"), py::arg("torque_limit") = py::none(), MECHBAL_JOINT_RANGE_ARGS,
           py::keep_alive<1, 2>(),
           "model: any InverseDynamics back end (MechanismDynamics, KdlChainDynamics, a "
           "paper's closed form such as Arm2DofDynamics or FiveBarDynamics). torque_limit: one value per joint (default and +inf: "
           "no limit); max_position, max_speed, max_acceleration: the input range of a tick "
           "(default +inf: no limit; beyond it: the held command and Status.out_of_range)")
      .def_property_readonly("torque_limit", &ComputedTorque::torque_limit)
      .def_property_readonly("dof", &ComputedTorque::dof)
      .def_property_readonly("last_command", &ComputedTorque::last_command);
  bind_joint_controller_ticks<ComputedTorque>(ct);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(38, computed_torque, bind_computed_torque);

}  // namespace mechbal::pyb
