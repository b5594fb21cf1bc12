// pybind11 glue for the 2-DOF arm (Arakelian, Le Baron & Mottu 2011), the computed-torque
// controller and the closed-loop simulator. Conversion only: no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "controller_step.hpp"
#include "mechbal/papers/arm2dof/arm2dof.hpp"
#include "mechbal/control/closed_loop.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/dynamics.hpp"

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

using CVec = Eigen::Map<const Eigen::VectorXd>;

// Applies a per-sample 2-in-3-out function over (N, 2) arrays.
template <class F>
py::dict batch3(const Array& a, const char* na, const Array& b, const char* nb, const Array& c,
                const char* nc, const char* out_name, F&& f) {
  const auto N = batch_rows(2, {{a, na}, {b, nb}, {c, nc}});
  OutArray out = make_array({N, 2});
  auto per_instant = make_status_array(N);
  Status status = Status::ok;
  for (py::ssize_t k = 0; k < N; ++k) {
    Eigen::Map<Eigen::VectorXd> o(out.mutable_data(k, 0), 2);
    const Status s = f(CVec(a.data(k, 0), 2), CVec(b.data(k, 0), 2), CVec(c.data(k, 0), 2), o);
    if (s != Status::ok) o.setZero();
    status |= s;
    per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
  }
  py::dict d;
  d[out_name] = out;
  d["status"] = status;
  d["status_per_instant"] = per_instant;
  return d;
}

template <typename T>
T finite_result(const T& value, const char* what) {
  bool finite;
  if constexpr (std::is_arithmetic_v<T>) finite = std::isfinite(value);
  else finite = value.allFinite();
  if (!finite)
    throw py::value_error(std::string("Arm2DofDynamics.") + what +
                          ": the result overflowed (input out of range)");
  return value;
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

void bind_arm2dof(py::module_& m) {
  py::class_<Arm2DofParameters>(m, "Arm2DofParameters",
                                "Bare 2R arm of Arakelian et al. 2011, Fig. 1 (defaults: Sec. 4)")
      .def(py::init([](double m1, double m2, double l1, double l_s1, double l_s2, double i_s1,
                       double i_s2, double g) {
             return Arm2DofParameters{m1, m2, l1, l_s1, l_s2, i_s1, i_s2, g};
           }),
           py::arg("m1") = 2.5, py::arg("m2") = 2.0, py::arg("l1") = 0.4, py::arg("l_s1") = 0.1,
           py::arg("l_s2") = 0.1, py::arg("i_s1") = 0.15, py::arg("i_s2") = 0.1,
           py::arg("g") = 9.81)
      .def_readwrite("m1", &Arm2DofParameters::m1)
      .def_readwrite("m2", &Arm2DofParameters::m2)
      .def_readwrite("l1", &Arm2DofParameters::l1)
      .def_readwrite("l_s1", &Arm2DofParameters::l_s1)
      .def_readwrite("l_s2", &Arm2DofParameters::l_s2)
      .def_readwrite("i_s1", &Arm2DofParameters::i_s1)
      .def_readwrite("i_s2", &Arm2DofParameters::i_s2)
      .def_readwrite("g", &Arm2DofParameters::g);

  py::class_<Arm2DofCounterweights>(m, "Arm2DofCounterweights",
                                    "Point-mass counterweights beyond A and B (eqs 25-31)")
      .def(py::init([](double m_cw1, double m_cw2, double r_cw1, double r_cw2) {
             return Arm2DofCounterweights{m_cw1, m_cw2, r_cw1, r_cw2};
           }),
           py::arg("m_cw1") = 0.0, py::arg("m_cw2") = 0.0, py::arg("r_cw1") = 0.0,
           py::arg("r_cw2") = 0.0)
      .def_readwrite("m_cw1", &Arm2DofCounterweights::m_cw1)
      .def_readwrite("m_cw2", &Arm2DofCounterweights::m_cw2)
      .def_readwrite("r_cw1", &Arm2DofCounterweights::r_cw1)
      .def_readwrite("r_cw2", &Arm2DofCounterweights::r_cw2);

  m.def("arm2dof_description", &arm2dof_description, py::arg("arm"),
        py::arg_v("counterweights", Arm2DofCounterweights{}, "Arm2DofCounterweights()"),
        "The 2-DOF arm (counterweights merged into the links) as a general MechanismDescription: "
        "x-z plane, joints 'shoulder' and 'elbow' with axes along -y, gravity (0, 0, -g)");

  py::class_<Arm2DofDynamics, InverseDynamics, ForwardDynamics>(m, "Arm2DofDynamics",
                              "Closed-form dynamics of the 2-DOF arm, eqs 14-31 (corrected)")
      .def(py::init<const Arm2DofParameters&, const Arm2DofCounterweights&>(), py::arg("arm"),
           py::arg_v("counterweights", Arm2DofCounterweights{}, "Arm2DofCounterweights()"))
      .def_property_readonly("dof", [](const Arm2DofDynamics& d) { return d.dof(); })
      .def_property_readonly("lumped",
                             [](const Arm2DofDynamics& d) {
                               const Arm2DofLumped& p = d.lumped();
                               py::dict o;
                               o["j1"] = p.j1;
                               o["s1"] = p.s1;
                               o["M2"] = p.M2;
                               o["s2"] = p.s2;
                               o["j2"] = p.j2;
                               o["l1"] = p.l1;
                               o["g"] = p.g;
                               return o;
                             })
      .def(
          "inverse_dynamics",
          [](Arm2DofDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch3(q, "q", qd, "v", qdd, "a", "tau",
                          [&](const auto& a, const auto& b, const auto& c, auto& o) {
                            return d.inverse_dynamics(a, b, c, o);
                          });
          },
          py::arg("q"), py::arg("v"), py::arg("a"), "Joint torques (N, 2): {'tau', 'status'}")
      .def(
          "forward_dynamics",
          [](Arm2DofDynamics& d, const Array& q, const Array& qd, const Array& tau) {
            return batch3(q, "q", qd, "v", tau, "tau", "a",
                          [&](const auto& a, const auto& b, const auto& c, auto& o) {
                            return d.forward_dynamics(a, b, c, o);
                          });
          },
          py::arg("q"), py::arg("v"), py::arg("tau"), "Accelerations (N, 2): {'a', 'status'}")
      // no status in these signatures: NaN input or an overflowing result is a ValueError
      .def("mass_matrix",
           [](const Arm2DofDynamics& d, const Array& q) {
             return finite_result(d.mass_matrix(fixed_vector<2>(q, "q", true)), "mass_matrix");
           },
           py::arg("q"), "A(q) (2, 2), eqs 14-19 (corrected)")
      .def("coriolis_matrix",
           [](const Arm2DofDynamics& d, const Array& q, const Array& qd) {
             return finite_result(d.coriolis_matrix(fixed_vector<2>(q, "q", true),
                                                    fixed_vector<2>(qd, "v", true)),
                                  "coriolis_matrix");
           },
           py::arg("q"), py::arg("v"), "C(q, v) (2, 2), Christoffel form")
      .def("gravity",
           [](const Arm2DofDynamics& d, const Array& q) {
             return finite_result(d.gravity(fixed_vector<2>(q, "q", true)), "gravity");
           },
           py::arg("q"), "Q(q) (2,), eqs 21-22")
      .def("kinetic_energy",
           [](const Arm2DofDynamics& d, const Array& q, const Array& qd) {
             return finite_result(d.kinetic_energy(fixed_vector<2>(q, "q", true),
                                                   fixed_vector<2>(qd, "v", true)),
                                  "kinetic_energy");
           },
           py::arg("q"), py::arg("v"))
      .def("potential_energy",
           [](const Arm2DofDynamics& d, const Array& q) {
             return finite_result(d.potential_energy(fixed_vector<2>(q, "q", true)),
                                  "potential_energy");
           },
           py::arg("q"));

  py::class_<ComputedTorque, JointController> ct(m, "ComputedTorque",
                             "Computed-torque control, Arakelian et al. 2011 eqs 2-6, over any "
                             "inverse-dynamics back end (keeps the model alive)");
  ct.def(py::init(&make_computed_torque<InverseDynamics>), py::arg("model"), py::arg("kp"),
           py::arg("kd"), py::arg("torque_limit") = py::none(), MECHBAL_JOINT_RANGE_ARGS,
           py::keep_alive<1, 2>(),
           "model: any InverseDynamics back end (Arm2DofDynamics, KdlChainDynamics, "
           "MechanismDynamics). torque_limit: one value per joint (default and +inf: "
           "no limit); max_position, max_speed, max_acceleration: the input range of a tick "
           "(default +inf: no limit; beyond it: the held command and Status.out_of_range)")
      .def_property_readonly("torque_limit", &ComputedTorque::torque_limit)
      .def_property_readonly("dof", &ComputedTorque::dof)
      .def_property_readonly("last_command", &ComputedTorque::last_command);
  bind_joint_controller_ticks<ComputedTorque>(ct);

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

MECHBAL_REGISTER_BINDINGS(40, arm2dof, bind_arm2dof);

}  // namespace mechbal::pyb
