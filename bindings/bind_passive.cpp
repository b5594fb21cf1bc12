// pybind11 glue for the passive "controller" (zero effort): conversion only, no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include "bindings.hpp"
#include "controller_step.hpp"
#include "mechbal/control/passive.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_passive(py::module_& m) {
  py::class_<PassiveController, JointController> pc(
      m, "PassiveController",
      "No controller: zero joint effort every tick, so the plant moves under gravity and its springs "
      "only (a passive simulation)");
  pc.def(py::init<int>(), py::arg("dof"), "dof: number of actuated coordinates (>= 1)")
      .def_property_readonly("dof", &PassiveController::dof);
  bind_joint_controller_ticks<PassiveController>(pc);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(52, passive, bind_passive);

}  // namespace mechbal::pyb
