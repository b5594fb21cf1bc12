// pybind11 glue for the passive "controller" (zero effort): conversion only, no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include <string>

#include "array_checks.hpp"
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

  m.def(
      "simulate_passive",
      [](ForwardDynamics& plant, const Array& q0_arg, const Array& qd0_arg, double dt,
         double duration, const Array& lower_arg, const Array& upper_arg) {
        const auto n = static_cast<py::ssize_t>(plant.dof());
        ClosedLoopOptions opt;
        opt.dt = dt;
        opt.duration = duration;
        const Eigen::VectorXd q0 = vector_arg(q0_arg, "q0", n, true);
        const Eigen::VectorXd qd0 = vector_arg(qd0_arg, "v0", n, true);
        opt.lower_limit = vector_arg(lower_arg, "lower_limit", n);
        opt.upper_limit = vector_arg(upper_arg, "upper_limit", n);
        ClosedLoopLog log;
        {
          py::gil_scoped_release release;
          log = simulate_passive(plant, q0, qd0, opt);
        }
        py::dict d;
        d["t"] = log.t;
        d["q"] = log.q;
        d["v"] = log.qd;
        d["tick_status"] = log.tick_status;
        d["steps_completed"] = log.steps_completed;
        d["stop_ticks"] = log.stop_ticks;
        return d;
      },
      py::arg("plant"), py::arg("q0"), py::arg("v0"), py::arg("dt"), py::arg("duration"),
      py::arg("lower_limit"), py::arg("upper_limit"),
      "Passive RK4 run of `plant` (any ForwardDynamics) from (q0, v0) with zero effort; "
      "lower_limit / upper_limit (dof values each; -inf / inf: no stop on that side) are "
      "inelastic stops. Returns a dict: t (N+1,), q, v (N+1, dof), tick_status, steps_completed, "
      "stop_ticks (steps that ended on a stop).");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(52, passive, bind_passive);

}  // namespace mechbal::pyb
