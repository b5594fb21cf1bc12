// pybind11 glue for the closed-loop simulator (control/closed_loop.hpp): any ForwardDynamics plant
// under any JointController, and the PD error of an exact computed-torque loop. Conversion only.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <utility>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/control/closed_loop.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/control/joint_controller.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

/// The simulator's options from the Python arguments (ValueError naming a bad sampling mode).
ClosedLoopOptions closed_loop_options(double dt, double duration, const std::string& sampling) {
  ClosedLoopOptions opt;
  opt.dt = dt;
  opt.duration = duration;
  if (sampling == "zero_order_hold") {
    opt.sampling = ControlSampling::zero_order_hold;
  } else if (sampling == "every_rk4_stage") {
    opt.sampling = ControlSampling::every_rk4_stage;
  } else {
    throw py::value_error("sampling must be 'zero_order_hold' or 'every_rk4_stage', got '" + sampling + "'");
  }
  return opt;
}

py::dict log_to_dict(const ClosedLoopLog& log) {
  py::dict d;
  d["t"] = log.t;
  d["q"] = log.q;
  d["v"] = log.qd;
  d["q_des"] = log.q_des;
  d["v_des"] = log.qd_des;
  d["tau"] = log.tau;
  d["status"] = log.status;
  d["tick_status"] = log.tick_status;
  d["saturated_ticks"] = log.saturated_ticks;
  d["steps_completed"] = log.steps_completed;
  return d;
}

/// simulate_closed_loop from the Python arguments (q0, v0 and the options checked first), the GIL
/// released while it runs; the log as a dict. `desired`: a RestToRestTrajectory or a SampledMotion.
template <typename Desired>
py::dict run_closed_loop(ForwardDynamics& plant, JointController& controller, const Desired& desired,
                         const Array& q0_arg, const Array& qd0_arg, double dt, double duration,
                         const std::string& sampling) {
  const Eigen::VectorXd q0 = vector_arg(q0_arg, "q0", -1), qd0 = vector_arg(qd0_arg, "v0", -1);
  const ClosedLoopOptions opt = closed_loop_options(dt, duration, sampling);
  ClosedLoopLog log;
  {
    py::gil_scoped_release release;
    log = simulate_closed_loop(plant, controller, desired, q0, qd0, opt);
  }
  return log_to_dict(log);
}

void bind_closed_loop(py::module_& m) {
  m.def(
      "simulate_closed_loop",
      [](ForwardDynamics& plant, JointController& controller, const RestToRestTrajectory& desired,
         const Array& q0_arg, const Array& qd0_arg, double dt, double duration,
         const std::string& sampling) {
        return run_closed_loop(plant, controller, desired, q0_arg, qd0_arg, dt, duration, sampling);
      },
      py::arg("plant"), py::arg("controller"), py::arg("desired"), py::arg("q0"), py::arg("v0"),
      py::arg("dt") = 1e-3, py::arg("duration") = 1.0, py::arg("sampling") = "zero_order_hold",
      "RK4 closed loop of `plant` (any ForwardDynamics: Arm2DofDynamics, MechanismDynamics of any "
      "mechanism) under `controller` (any JointController) tracking `desired`; returns a dict of arrays "
      "t (N+1,), q, v, q_des, v_des, tau (N+1, dof), status, saturated_ticks, steps_completed.");
  m.attr("simulate_computed_torque") = m.attr("simulate_closed_loop");
  m.def(
      "simulate_closed_loop_sampled",
      [](ForwardDynamics& plant, JointController& controller, const Array& q_des,
         const Array& qd_des, const Array& qdd_des, const Array& q0_arg, const Array& qd0_arg,
         double dt, double duration, const std::string& sampling) {
        const auto n = static_cast<py::ssize_t>(plant.dof());
        const auto J = batch_rows(n, {{q_des, "q_des"}}, "one row every dt/2, one value per joint");
        require_rows(J, n, {{qd_des, "v_des"}, {qdd_des, "a_des"}});
        using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
        SampledMotion desired;
        desired.q = Eigen::Map<const RowMajor>(q_des.data(), J, n);
        desired.qd = Eigen::Map<const RowMajor>(qd_des.data(), J, n);
        desired.qdd = Eigen::Map<const RowMajor>(qdd_des.data(), J, n);
        return run_closed_loop(plant, controller, desired, q0_arg, qd0_arg, dt, duration, sampling);
      },
      py::arg("plant"), py::arg("controller"), py::arg("q_des"), py::arg("v_des"),
      py::arg("a_des"), py::arg("q0"), py::arg("v0"), py::arg("dt") = 1e-3,
      py::arg("duration") = 1.0, py::arg("sampling") = "zero_order_hold",
      "simulate_closed_loop tracking a sampled desired motion: q_des, qd_des, qdd_des each "
      "(2 steps + 1, dof), sampled every dt/2 from t = 0 (steps = round(duration / dt)).");

  m.def(
      "pd_error_analytic",
      [](double e0, double ed0, double kp, double kd, const Array& t_arg) {
        const Eigen::VectorXd t = vector_arg(t_arg, "t", -1, true);
        for (const auto& [name, x] : {std::pair<const char*, double>{"e0", e0}, {"ed0", ed0}, {"kp", kp}, {"kd", kd}}) {
          if (!std::isfinite(x)) throw py::value_error(std::string("pd_error_analytic: ") + name + " must be finite, got " + std::to_string(x));
        }
        Eigen::VectorXd e(t.size());
        for (Eigen::Index i = 0; i < t.size(); ++i) e(i) = pd_error_analytic(e0, ed0, kp, kd, t(i));
        if (!e.allFinite()) {
          throw py::value_error("pd_error_analytic: the error overflows (gains or times too large for a finite result)");
        }
        return e;
      },
      py::arg("e0"), py::arg("ed0"), py::arg("kp"), py::arg("kd"), py::arg("t"),
      "Solution of e'' + kd e' + kp e = 0 (Arakelian et al. 2011, eq 6) at times t");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(39, closed_loop, bind_closed_loop);

}  // namespace mechbal::pyb
