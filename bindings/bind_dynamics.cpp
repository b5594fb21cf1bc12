// pybind11 glue for the InverseDynamics interface (dynamics.hpp): bound as the common base class
// of every joint-space dynamics back end (Arm2DofDynamics, KdlChainDynamics, RneChainDynamics), so
// that controllers taking an InverseDynamics (ComputedTorque) accept any of them. No logic.
#include "bindings.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/control/joint_controller.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_dynamics(py::module_& m) {
  py::class_<InverseDynamics>(m, "InverseDynamics",
                              "Joint-space inverse dynamics back end (base class of "
                              "Arm2DofDynamics, KdlChainDynamics, RneChainDynamics)")
      .def_property_readonly("dof", &InverseDynamics::dof);
  py::class_<ForwardDynamics>(m, "ForwardDynamics",
                              "Forward dynamics of a plant for closed-loop simulation (base class of "
                              "Arm2DofDynamics and MechanismDynamics)");
  py::class_<JointController>(m, "JointController",
                              "Joint-space tracking controller (base class of ComputedTorque and "
                              "DecoupledJointController)")
      .def_property_readonly("dof", &JointController::dof);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(15, dynamics, bind_dynamics);

}  // namespace mechbal::pyb
