// pybind11 glue for the general reactionless controller (control/reactionless.hpp): conversions
// and checks only.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <memory>
#include <string>
#include <vector>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "controller_step.hpp"
#include "motion_tick.hpp"
#include "value_errors.hpp"
#include "mechbal/control/factory.hpp"
#include "mechbal/control/reactionless.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

/// The factory's cancel table and messages (ValueError), but for the empty list's, which this
/// binding has always worded without the colon.
std::uint32_t cancel_of(const std::vector<std::string>& cancel) {
  if (cancel.empty()) throw py::value_error("cancel must name at least one momentum component");
  return cancel_mask(cancel, "cancel");
}

ReactionlessIntegrator integrator_of(const std::string& name) {
  if (name == "euler") return ReactionlessIntegrator::euler;
  if (name == "rk4") return ReactionlessIntegrator::rk4;
  throw py::value_error("integrator must be 'euler' or 'rk4', got '" + name + "'");
}

ReactionlessConfig make_config(const std::vector<std::string>& balancing, const std::vector<std::string>& cancel,
                               const std::string& integrator, double rate_hz, double damping, double max_condition,
                               double max_rate, double max_acceleration, bool position_limits, bool velocity_limits, double home_gain,
                               double limit_gain, const py::object& home, double max_position, double max_speed,
                               double max_task_acceleration) {
  ReactionlessConfig c;
  c.balancing_joints = balancing;
  c.cancel = cancel_of(cancel);
  c.integrator = integrator_of(integrator);
  c.rate_hz = rate_hz;
  c.damping = damping;
  c.max_condition = max_condition;
  c.max_rate = max_rate;
  c.max_acceleration = max_acceleration;
  c.position_limits = position_limits;
  c.velocity_limits = velocity_limits;
  c.home_gain = home_gain;
  c.limit_gain = limit_gain;
  if (!home.is_none()) c.home = vector_arg(to_real_array(home), "home", -1, true);
  c.task_range.max_position = max_position;
  c.task_range.max_speed = max_speed;
  c.task_range.max_acceleration = max_task_acceleration;
  return c;
}

Eigen::VectorXd optional_vector(const py::object& o, const char* name, py::ssize_t n) {
  if (o.is_none()) return Eigen::VectorXd();
  return vector_arg(to_real_array(o), name, n);
}

std::vector<std::string> names_of(const ReactionlessController& c, const std::vector<int>& idx) {
  std::vector<std::string> out;
  const auto& act = c.model().actuated_coordinates();
  for (int i : idx) out.push_back(c.model().coordinate_name(act[static_cast<std::size_t>(i)]));
  return out;
}

#define MECHBAL_REACTIONLESS_ARGS                                                                   \
  py::arg("cancel") = std::vector<std::string>{"moment"},                                           \
      py::arg("integrator") = "euler", py::arg("rate_hz") = ReactionlessConfig{}.rate_hz,           \
      py::arg("damping") = ReactionlessConfig{}.damping,                                            \
      py::arg("max_condition") = ReactionlessConfig{}.max_condition,                                \
      py::arg("max_rate") = ReactionlessConfig{}.max_rate,                                          \
      py::arg("max_acceleration") = ReactionlessConfig{}.max_acceleration,                          \
      py::arg("position_limits") = true, py::arg("velocity_limits") = true, py::arg("home_gain") = 0.0, \
      py::arg("limit_gain") = 0.0,                                                                  \
      py::arg("home") = py::none(), py::arg("max_position") = JointInputRange{}.max_position,        \
      py::arg("max_speed") = JointInputRange{}.max_speed,                                           \
      py::arg("max_task_acceleration") = JointInputRange{}.max_acceleration

py::dict run(ReactionlessController& c, const Array& q, const Array& v, const Array& a) {
  const auto nt = static_cast<py::ssize_t>(c.num_task());
  const std::string context = "the controller has " + std::to_string(nt) + " task joints";
  const auto rows = batch_rows(nt, {{q, "q_task"}}, context.c_str());
  const py::ssize_t steps = half_step_ticks(rows, "q_task"), N = steps + 1;
  require_rows(rows, nt, {{v, "v_task"}, {a, "a_task"}}, context.c_str());
  const auto na = static_cast<py::ssize_t>(c.num_actuated()), n = static_cast<py::ssize_t>(c.model().dof());
  OutArray Q = make_array({N, na}), V = make_array({N, na}), A = make_array({N, na});
  OutArray QF = make_array({N, n}), VF = make_array({N, n}), AF = make_array({N, n});
  OutArray H = make_array({N, 6}), F = make_array({N, 3}), M = make_array({N, 3}), cond = make_array({N});
  auto status = make_status_array(N);
  using CMap = Eigen::Map<const Eigen::VectorXd>;
  {
    py::gil_scoped_release release;
    for (py::ssize_t k = 0; k < N; ++k) {
      const py::ssize_t j = 2 * k;
      Status s;
      if (k < steps) {
        s = c.step(CMap(q.data(j, 0), nt), CMap(v.data(j, 0), nt), CMap(a.data(j, 0), nt), CMap(q.data(j + 1, 0), nt),
                   CMap(v.data(j + 1, 0), nt), CMap(q.data(j + 2, 0), nt), CMap(v.data(j + 2, 0), nt));
      } else {
        s = c.step_euler(CMap(q.data(j, 0), nt), CMap(v.data(j, 0), nt), CMap(a.data(j, 0), nt));
      }
      const ReactionlessCommand& cmd = c.command();
      Eigen::Map<Eigen::VectorXd>(Q.mutable_data(k, 0), na) = cmd.q;
      Eigen::Map<Eigen::VectorXd>(V.mutable_data(k, 0), na) = cmd.v;
      Eigen::Map<Eigen::VectorXd>(A.mutable_data(k, 0), na) = cmd.a;
      Eigen::Map<Eigen::VectorXd>(QF.mutable_data(k, 0), n) = cmd.q_full;
      Eigen::Map<Eigen::VectorXd>(VF.mutable_data(k, 0), n) = cmd.v_full;
      Eigen::Map<Eigen::VectorXd>(AF.mutable_data(k, 0), n) = cmd.a_full;
      Eigen::Map<Vec6>(H.mutable_data(k, 0)) = cmd.momentum;
      Eigen::Map<Vec3>(F.mutable_data(k, 0)) = cmd.shaking_force;
      Eigen::Map<Vec3>(M.mutable_data(k, 0)) = cmd.shaking_moment;
      cond.mutable_data()[k] = cmd.condition;
      status.mutable_data()[k] = static_cast<std::uint32_t>(s);
    }
  }
  py::dict d;
  d["q"] = Q;
  d["v"] = V;
  d["a"] = A;
  d["q_full"] = QF;
  d["v_full"] = VF;
  d["a_full"] = AF;
  d["momentum"] = H;
  d["shaking_force"] = F;
  d["shaking_moment"] = M;
  d["condition"] = cond;
  d["status"] = status;
  return d;
}

void bind_task_controller(py::module_& m) {
  py::class_<ReactionlessTaskController>(
      m, "ReactionlessTaskController",
      "Operational-space reactionless control: a redundant open mechanism follows a desired twist of a "
      "frame, v = J^+ x' + N z, with z minimising the selected momentum components in the null space")
      .def(py::init([](const MechanismModel& model, const std::string& frame, const std::vector<std::string>& task_rows,
                       const std::vector<std::string>& cancel, const std::string& integrator, double rate_hz,
                       double damping, double max_condition, double max_rate, bool null_space,
                       const py::object& q0, const py::object& v0, bool velocity_limits) {
             TaskSpaceConfig c;
             c.null_space = null_space;
             c.velocity_limits = velocity_limits;
             c.frame = frame;
             c.task_rows = task_rows_mask(task_rows, "task_rows");  // the factory's table and messages
             c.cancel = cancel_of(cancel);
             c.integrator = integrator_of(integrator);
             c.rate_hz = rate_hz;
             c.damping = damping;
             c.max_condition = max_condition;
             c.max_rate = max_rate;
             const Eigen::VectorXd q = q0.is_none() ? Eigen::VectorXd(Eigen::VectorXd::Zero(model.dof()))
                                                    : vector_arg(to_real_array(q0), "q0", model.dof(), true);
             const Eigen::VectorXd v = optional_vector(v0, "v0", model.dof());
             return value_errors([&] {
               return new ReactionlessTaskController(std::make_shared<const MechanismModel>(model), c, q, v);
             });
           }),
           py::arg("model"), py::arg("task_frame"), py::arg("task_rows") = std::vector<std::string>{"all"},
           py::arg("cancel") = std::vector<std::string>{"moment"}, py::arg("integrator") = "euler",
           py::arg("rate_hz") = TaskSpaceConfig{}.rate_hz, py::arg("damping") = TaskSpaceConfig{}.damping,
           py::arg("max_condition") = TaskSpaceConfig{}.max_condition,
           py::arg("max_rate") = TaskSpaceConfig{}.max_rate, py::arg("null_space") = TaskSpaceConfig{}.null_space,
           py::arg("q0") = py::none(), py::arg("v0") = py::none(),
           py::arg("velocity_limits") = TaskSpaceConfig{}.velocity_limits)
      .def_property_readonly("dof", &ReactionlessTaskController::dof)
      .def_property_readonly("dt", &ReactionlessTaskController::dt)
      .def_property_readonly("target", &ReactionlessTaskController::target)
      .def(
          "step",
          [](ReactionlessTaskController& c, const Array& twist, const py::object& twist_rate,
             const py::object& twist_half, const py::object& twist_next) {
            const Vec6 now = fixed_vector<6>(twist, "twist");
            const Vec6 half = twist_half.is_none() ? now : fixed_vector<6>(to_real_array(twist_half), "twist_half");
            const Vec6 next = twist_next.is_none() ? now : fixed_vector<6>(to_real_array(twist_next), "twist_next");
            if (twist_rate.is_none()) return static_cast<std::uint32_t>(c.step(now, half, next));
            return static_cast<std::uint32_t>(
                c.step(now, fixed_vector<6>(to_real_array(twist_rate), "twist_rate"), half, next));
          },
          py::arg("twist"), py::arg("twist_rate") = py::none(), py::arg("twist_half") = py::none(),
          py::arg("twist_next") = py::none(),
          "One tick: the desired frame twist [v; w] (O axes) at t_n, its rate (default: estimated from the "
          "three samples) and, for RK4, the twist at t_n + dt/2 and t_n + dt (default: the twist at t_n). "
          "Returns the status (int, 0 = ok); the command is in q, v, a, momentum, frame_twist, "
          "shaking_force, shaking_moment. run() gives the same commands over a whole motion.")
      .def_property_readonly("q", [](const ReactionlessTaskController& c) { return Eigen::VectorXd(c.q()); },
                             "Commanded positions at t_n [rad or m] (dof,)")
      .def_property_readonly("v", [](const ReactionlessTaskController& c) { return Eigen::VectorXd(c.v()); },
                             "Commanded rates at t_n [rad/s or m/s] (dof,)")
      .def_property_readonly("a", [](const ReactionlessTaskController& c) { return Eigen::VectorXd(c.a()); },
                             "Acceleration feed-forward at t_n [rad/s^2 or m/s^2] (dof,)")
      .def_property_readonly("momentum", [](const ReactionlessTaskController& c) { return Vec6(c.momentum()); },
                             "Momentum [P; H_O] of the command (6,)")
      .def_property_readonly("frame_twist", [](const ReactionlessTaskController& c) { return Vec6(c.frame_twist()); },
                             "The frame's twist J v of the command [v; w] (6,)")
      .def_property_readonly("shaking_force", [](const ReactionlessTaskController& c) { return Vec3(c.shaking_force()); },
                             "Predicted shaking force of the command [N] (3,)")
      .def_property_readonly("shaking_moment", [](const ReactionlessTaskController& c) { return Vec3(c.shaking_moment()); },
                             "Predicted shaking moment about O of the command [N m] (3,)")
      .def_property_readonly("status", [](const ReactionlessTaskController& c) { return static_cast<std::uint32_t>(c.status()); },
                             "Status of the last tick (int, 0 = ok)")
      .def(
          "run",
          [](ReactionlessTaskController& c, const Array& twist, const py::object& twist_rate_obj) {
            require_shape(twist, "twist", {-1, 6});
            const auto rows = twist.shape(0);
            Array twist_rate;
            const bool with_rate = !twist_rate_obj.is_none();
            if (with_rate) {
              twist_rate = to_real_array(twist_rate_obj);
              require_shape(twist_rate, "twist_rate", {rows, 6});
            }
            const py::ssize_t steps = half_step_ticks(rows, "twist"), N = steps + 1, n = c.dof();
            OutArray Q = make_array({N, n}), V = make_array({N, n}), A = make_array({N, n}), H = make_array({N, 6}),
                     X = make_array({N, 6}), F = make_array({N, 3}), M = make_array({N, 3});
            auto status = make_status_array(N);
            {
              py::gil_scoped_release release;
              for (py::ssize_t k = 0; k < N; ++k) {
                const py::ssize_t j = std::min<py::ssize_t>(2 * k, rows - 1);
                const py::ssize_t jh = std::min<py::ssize_t>(j + 1, rows - 1), jn = std::min<py::ssize_t>(j + 2, rows - 1);
                const Eigen::Map<const Vec6> now(twist.data(j, 0)), half(twist.data(jh, 0)), next(twist.data(jn, 0));
                const Status s = with_rate ? c.step(now, Eigen::Map<const Vec6>(twist_rate.data(j, 0)), half, next)
                                           : c.step(now, half, next);
                Eigen::Map<Eigen::VectorXd>(Q.mutable_data(k, 0), n) = c.q();
                Eigen::Map<Eigen::VectorXd>(V.mutable_data(k, 0), n) = c.v();
                Eigen::Map<Eigen::VectorXd>(A.mutable_data(k, 0), n) = c.a();
                Eigen::Map<Vec6>(H.mutable_data(k, 0)) = c.momentum();
                Eigen::Map<Vec6>(X.mutable_data(k, 0)) = c.frame_twist();
                Eigen::Map<Vec3>(F.mutable_data(k, 0)) = c.shaking_force();
                Eigen::Map<Vec3>(M.mutable_data(k, 0)) = c.shaking_moment();
                status.mutable_data()[k] = static_cast<std::uint32_t>(s);
              }
            }
            py::dict d;
            d["q"] = Q;
            d["v"] = V;
            d["a"] = A;
            d["momentum"] = H;
            d["frame_twist"] = X;
            d["shaking_force"] = F;
            d["shaking_moment"] = M;
            d["status"] = status;
            return d;
          },
          py::arg("twist"), py::arg("twist_rate") = py::none(),
          "Ticks along the desired frame twist [v; w] (O axes) sampled every dt/2 ((2 steps + 1, 6)) and "
          "optionally its rate on the same grid (else estimated from the samples): q, v, a (steps + 1, dof), "
          "momentum, frame_twist (steps + 1, 6), predicted shaking_force, shaking_moment (steps + 1, 3), status.");
}

void bind_reactionless(py::module_& m) {
  bind_task_controller(m);
  py::class_<ReactionlessCommand>(m, "ReactionlessCommand",
                                  "One reactionless tick's command: actuated q, v, a (task as given, "
                                  "balancing computed), every coordinate q_full, v_full, a_full, the "
                                  "balancing joints' next positions, momentum [P; H_O], the predicted "
                                  "shaking_force [N] and shaking_moment [N m], condition, status")
      .def_readonly("q", &ReactionlessCommand::q)
      .def_readonly("v", &ReactionlessCommand::v)
      .def_readonly("a", &ReactionlessCommand::a)
      .def_readonly("q_full", &ReactionlessCommand::q_full)
      .def_readonly("v_full", &ReactionlessCommand::v_full)
      .def_readonly("a_full", &ReactionlessCommand::a_full)
      .def_readonly("next_balancing", &ReactionlessCommand::next_balancing)
      .def_readonly("momentum", &ReactionlessCommand::momentum)
      .def_readonly("shaking_force", &ReactionlessCommand::shaking_force)
      .def_readonly("shaking_moment", &ReactionlessCommand::shaking_moment)
      .def_readonly("condition", &ReactionlessCommand::condition)
      .def_property_readonly("status", [](const ReactionlessCommand& c) { return static_cast<std::uint32_t>(c.status); });

  py::class_<ReactionlessController>(
      m, "ReactionlessController",
      "Reactionless control of any MechanismModel (C++ mechbal::ReactionlessController): balancing joints "
      "keep the selected momentum components at their target")
      .def(py::init([](const MechanismModel& model, const std::vector<std::string>& balancing, const py::object& q0,
                       const std::vector<std::string>& cancel, const std::string& integrator, double rate_hz,
                       double damping, double max_condition, double max_rate, double max_acceleration,
                       bool position_limits, bool velocity_limits, double home_gain, double limit_gain, const py::object& home,
                       double max_position, double max_speed, double max_task_acceleration,
                       const py::object& v0, const py::object& q_guess) {
             const ReactionlessConfig c =
                 make_config(balancing, cancel, integrator, rate_hz, damping, max_condition, max_rate, max_acceleration,
                             position_limits, velocity_limits, home_gain, limit_gain, home, max_position, max_speed,
                             max_task_acceleration);
             const Eigen::VectorXd q0_ =
                 q0.is_none() ? Eigen::VectorXd(Eigen::VectorXd::Zero(model.num_actuated()))
                              : vector_arg(to_real_array(q0), "q0", model.num_actuated(), true);
             const Eigen::VectorXd v0_ = optional_vector(v0, "v0", model.num_actuated());
             const Eigen::VectorXd guess = optional_vector(q_guess, "q_guess", model.dof());
             return value_errors([&] {
               return new ReactionlessController(std::make_shared<const MechanismModel>(model), c, q0_, v0_, guess);
             });
           }),
           py::arg("model"), py::arg("balancing_joints"), py::arg("q0") = py::none(), MECHBAL_REACTIONLESS_ARGS,
           py::arg("v0") = py::none(), py::arg("q_guess") = py::none(),
           "q0: the actuated coordinates at the start (default zeros); v0: their rates (default rest)")
      .def_property_readonly("num_actuated", &ReactionlessController::num_actuated)
      .def_property_readonly("num_task", &ReactionlessController::num_task)
      .def_property_readonly("num_balancing", &ReactionlessController::num_balancing)
      .def_property_readonly("dt", &ReactionlessController::dt)
      .def_property_readonly("task_joints", [](const ReactionlessController& c) { return names_of(c, c.task_joints()); })
      .def_property_readonly("balancing_joints",
                             [](const ReactionlessController& c) { return names_of(c, c.balancing_joints()); })
      .def_property_readonly("task_indices", &ReactionlessController::task_joints)
      .def_property_readonly("balancing_indices", &ReactionlessController::balancing_joints)
      .def_property_readonly("cancelled_rows", &ReactionlessController::cancelled_rows)
      .def_property_readonly("target", &ReactionlessController::target)
      .def_property_readonly("balancing_state", &ReactionlessController::balancing_state)
      .def_property_readonly("command", &ReactionlessController::command, py::return_value_policy::copy)
      .def(
          "reset",
          [](ReactionlessController& c, const Array& q0, const py::object& v0) {
            const Eigen::VectorXd q = vector_arg(q0, "q0", c.num_actuated());
            const Eigen::VectorXd v =
                v0.is_none() ? Eigen::VectorXd(Eigen::VectorXd::Zero(c.num_actuated())) : optional_vector(v0, "v0", c.num_actuated());
            return static_cast<std::uint32_t>(c.reset(q, v));
          },
          py::arg("q0"), py::arg("v0") = py::none())
      .def(
          "set_target",
          [](ReactionlessController& c, const Array& h, const Array& hd) {
            return static_cast<std::uint32_t>(c.set_target(fixed_vector<6>(h, "momentum"), fixed_vector<6>(hd, "momentum_rate")));
          },
          py::arg("momentum"), py::arg("momentum_rate"))
      .def(
          "step",
          [](ReactionlessController& c, const Array& q, const Array& v, const Array& a, const py::object& qh,
             const py::object& vh, const py::object& qn, const py::object& vn) {
            const auto nt = static_cast<py::ssize_t>(c.num_task());
            const std::string ctx = "the controller has " + std::to_string(nt) + " task joints";
            const Eigen::VectorXd q_ = vector_arg(q, "q_task", nt, false, ctx.c_str());
            const Eigen::VectorXd v_ = vector_arg(v, "v_task", nt, false, ctx.c_str());
            const Eigen::VectorXd a_ = vector_arg(a, "a_task", nt, false, ctx.c_str());
            if (qh.is_none() || vh.is_none() || qn.is_none() || vn.is_none())
              return static_cast<std::uint32_t>(c.step_euler(q_, v_, a_));
            const Eigen::VectorXd qh_ = vector_arg(to_real_array(qh), "q_half", nt, false, ctx.c_str());
            const Eigen::VectorXd vh_ = vector_arg(to_real_array(vh), "v_half", nt, false, ctx.c_str());
            const Eigen::VectorXd qn_ = vector_arg(to_real_array(qn), "q_next", nt, false, ctx.c_str());
            const Eigen::VectorXd vn_ = vector_arg(to_real_array(vn), "v_next", nt, false, ctx.c_str());
            return static_cast<std::uint32_t>(c.step(q_, v_, a_, qh_, vh_, qn_, vn_));
          },
          py::arg("q_task"), py::arg("v_task"), py::arg("a_task"), py::arg("q_half") = py::none(),
          py::arg("v_half") = py::none(), py::arg("q_next") = py::none(), py::arg("v_next") = py::none(),
          "One tick; without the half/next samples an Euler tick. Returns the status; the command is in `command`.")
      .def(
          "step_into",
          [](ReactionlessController& c, FastArg now, FastArg half, FastArg next, FastArg out) {
            const auto nt = static_cast<py::ssize_t>(c.num_task()), na = static_cast<py::ssize_t>(c.num_actuated());
            using CMap = Eigen::Map<const Eigen::VectorXd>;
            const double* p = detail::fast_matrix(now.h, "now", 3, nt);
            const double* h = detail::fast_matrix(half.h, "half", 2, nt);
            const double* x = detail::fast_matrix(next.h, "next", 2, nt);
            return motion_step_into(
                out, na,
                [&] {
                  return c.step(CMap(p, nt), CMap(p + nt, nt), CMap(p + 2 * nt, nt), CMap(h, nt), CMap(h + nt, nt),
                                CMap(x, nt), CMap(x + nt, nt));
                },
                [&](auto q, auto v, auto a) {
                  q = c.command().q;
                  v = c.command().v;
                  a = c.command().a;
                });
          },
          py::arg("now"), py::arg("half"), py::arg("next"), py::arg("out"),
          "The fast tick: now (3, n_task) rows q, v, a of the task joints at t_n; half and next (2, n_task) "
          "rows q, v at t_n + dt/2 and t_n + dt; writes the actuated command into out (3, n_actuated) rows "
          "q, v, a; returns the status. C-contiguous float64 arrays only.")
      .def("run", &run, py::arg("q_task"), py::arg("v_task"), py::arg("a_task"),
           "Ticks along the task motion sampled on the half-step grid t_j = j dt/2 ((2 steps + 1, n_task) "
           "each): the command at the steps + 1 ticks t_n = n dt (the last tick Euler).");

  py::class_<ReactionlessJointController, JointController> jc(
      m, "ReactionlessJointController",
      "The reactionless controller followed by computed torque over the model: a JointController over the "
      "actuated coordinates (the balancing joints' desired entries are ignored)");
  jc.def(py::init([](const MechanismModel& model, const std::vector<std::string>& balancing, const Array& q0,
                     const Array& kp, const Array& kd, const std::vector<std::string>& cancel,
                     const std::string& integrator, double rate_hz, double damping, double max_condition,
                     double max_rate, double max_acceleration, bool position_limits, bool velocity_limits, double home_gain,
                     double limit_gain, const py::object& home, double max_position, double max_speed,
                     double max_task_acceleration, const py::object& torque_limit, const py::object& q_guess) {
           const ReactionlessConfig c =
               make_config(balancing, cancel, integrator, rate_hz, damping, max_condition, max_rate, max_acceleration,
                           position_limits, velocity_limits, home_gain, limit_gain, home, max_position, max_speed, max_task_acceleration);
           const Eigen::VectorXd q0_ = vector_arg(q0, "q0", model.num_actuated(), true);
           const Eigen::VectorXd limit = optional_vector(torque_limit, "torque_limit", -1);
           const Eigen::VectorXd guess = optional_vector(q_guess, "q_guess", model.dof());
           const Eigen::VectorXd kp_ = vector_arg(kp, "kp", -1), kd_ = vector_arg(kd, "kd", -1);
           return value_errors([&] {
             return new ReactionlessJointController(std::make_shared<const MechanismModel>(model), c, q0_, kp_, kd_,
                                                    limit, c.task_range, guess);  // one input range, both stages
           });
         }),
         py::arg("model"), py::arg("balancing_joints"), py::arg("q0"), py::arg("kp"), py::arg("kd"),
         MECHBAL_REACTIONLESS_ARGS, py::arg("torque_limit") = py::none(), py::arg("q_guess") = py::none())
      .def_property_readonly("dof", &ReactionlessJointController::dof)
      .def_property_readonly("last_command", &ReactionlessJointController::last_command)
      .def_property_readonly(
          "reactionless", [](ReactionlessJointController& c) -> ReactionlessController& { return c.reactionless(); },
          py::return_value_policy::reference_internal);
  bind_joint_controller_ticks<ReactionlessJointController>(jc);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(60, reactionless, bind_reactionless);

}  // namespace mechbal::pyb
