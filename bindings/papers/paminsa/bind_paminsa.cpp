// pybind11 glue for the PAMINSA model and the reactionless wrist (no logic: conversions only).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>

#include "array_checks.hpp"
#include "controller_step.hpp"
#include "motion_tick.hpp"
#include "bindings.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/papers/paminsa/reactionless_wrist.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

/// A wrist command into the rows of a fast tick's `out` (motion_tick.hpp).
template <typename Row>
void write_wrist(const WristCommand& c, Row q, Row v, Row a) {
  q = c.angles;
  v = c.rates;
  a = c.accelerations;
}

constexpr py::ssize_t kBodies = static_cast<py::ssize_t>(PaminsaBodyIndex::count);

struct BatchArrays {
  OutArray com, vel, acc, rot, w, wd, F, M, D, Dd, q, qd, qdd, cond;
  py::array_t<std::uint32_t> status;
  explicit BatchArrays(py::ssize_t N)
      : com(make_array({N, kBodies, 3})), vel(make_array({N, kBodies, 3})),
        acc(make_array({N, kBodies, 3})), rot(make_array({N, kBodies, 3, 3})),
        w(make_array({N, kBodies, 3})), wd(make_array({N, kBodies, 3})), F(make_array({N, 3})),
        M(make_array({N, 3})), D(make_array({N, 3})), Dd(make_array({N, 3})),
        q(make_array({N, 3})), qd(make_array({N, 3})), qdd(make_array({N, 3})),
        cond(make_array({N})), status(std::vector<py::ssize_t>{N}) {}
  PaminsaBatchOutput view() {
    PaminsaBatchOutput o;
    o.com = com.mutable_data();
    o.com_velocity = vel.mutable_data();
    o.com_acceleration = acc.mutable_data();
    o.rotation = rot.mutable_data();
    o.angular_velocity = w.mutable_data();
    o.angular_acceleration = wd.mutable_data();
    o.force = F.mutable_data();
    o.moment = M.mutable_data();
    o.D = D.mutable_data();
    o.D_dot = Dd.mutable_data();
    o.wrist_angles = q.mutable_data();
    o.wrist_rates = qd.mutable_data();
    o.wrist_accelerations = qdd.mutable_data();
    o.condition = cond.mutable_data();
    o.status = status.mutable_data();
    return o;
  }
  py::dict to_dict(Status all) {
    py::dict d;
    d["com"] = com;
    d["com_velocity"] = vel;
    d["com_acceleration"] = acc;
    d["rotation"] = rot;
    d["angular_velocity"] = w;
    d["angular_acceleration"] = wd;
    d["shaking_force"] = F;
    d["shaking_moment"] = M;
    d["D"] = D;
    d["D_dot"] = Dd;
    d["wrist_angles"] = q;
    d["wrist_rates"] = qd;
    d["wrist_accelerations"] = qdd;
    d["condition"] = cond;
    d["status_per_instant"] = status;
    d["status"] = all;
    return d;
  }
};

WristInertias inertias(const Array& J1, const Array& J2, const Array& J3) {
  return {fixed_matrix<3, 3>(J1, "J1", true), fixed_matrix<3, 3>(J2, "J2", true),
          fixed_matrix<3, 3>(J3, "J3", true)};
}

void bind_paminsa(py::module_& m) {
  py::class_<PaminsaCounterweights>(m, "PaminsaCounterweights",
                                    "Counterweight masses [kg] of PAMINSA (Briot & Arakelian 2009, "
                                    "eqs 11, 14-16): at_A (CP1), at_F (CP2), at_L (CP3), vertical")
      .def(py::init<>())
      .def_readwrite("at_A", &PaminsaCounterweights::at_A)
      .def_readwrite("at_F", &PaminsaCounterweights::at_F)
      .def_readwrite("at_L", &PaminsaCounterweights::at_L)
      .def_readwrite("vertical", &PaminsaCounterweights::vertical);

  py::class_<PaminsaParameters> pp(m, "PaminsaParameters",
                                   "Every PAMINSA parameter (defaults: the paper's Sec. II.A and "
                                   "the reconstruction choices A1-A11), SI units");
  pp.def(py::init<>());
#define MB_RW(field) pp.def_readwrite(#field, &PaminsaParameters::field)
  MB_RW(k); MB_RW(a); MB_RW(b); MB_RW(c); MB_RW(d); MB_RW(e); MB_RW(f);
  MB_RW(length_BG); MB_RW(length_AE); MB_RW(length_DF); MB_RW(length_CE); MB_RW(length_AF);
  MB_RW(length_CJ); MB_RW(length_MS5); MB_RW(length_MO); MB_RW(platform_mass); MB_RW(link_mass);
  MB_RW(link_inertia); MB_RW(wrist_inertia); MB_RW(nominal_platform); MB_RW(nominal_rho);
  MB_RW(z_A); MB_RW(elbow); MB_RW(vertical_mass_at_centroid); MB_RW(vertical_mass_xy);
  MB_RW(vertical_mass_z0); MB_RW(cp3_ratio); MB_RW(counterweights);
#undef MB_RW

  py::enum_<WristIntegrator>(m, "WristIntegrator")
      .value("euler", WristIntegrator::euler)
      .value("rk4", WristIntegrator::rk4);

  py::class_<ReactionlessWristConfig>(m, "ReactionlessWristConfig",
                                      "Reactionless wrist tick: rate, integrator, limits (every "
                                      "limit finite) and damping; validated on construction")
      .def(py::init([](double rate_hz, WristIntegrator integrator, double max_rate,
                       double max_condition, double damping, double max_acceleration,
                       double max_momentum, double max_moment) {
             ReactionlessWristConfig c;
             c.rate_hz = rate_hz;
             c.integrator = integrator;
             c.max_rate = max_rate;
             c.max_condition = max_condition;
             c.damping = damping;
             c.max_acceleration = max_acceleration;
             c.max_momentum = max_momentum;
             c.max_moment = max_moment;
             validate_wrist_config(c);
             return c;
           }),
           py::arg("rate_hz") = ReactionlessWristConfig{}.rate_hz,
           py::arg("integrator") = WristIntegrator::euler,
           py::arg("max_rate") = ReactionlessWristConfig{}.max_rate,
           py::arg("max_condition") = ReactionlessWristConfig{}.max_condition,
           py::arg("damping") = ReactionlessWristConfig{}.damping,
           py::arg("max_acceleration") = ReactionlessWristConfig{}.max_acceleration,
           py::arg("max_momentum") = ReactionlessWristConfig{}.max_momentum,
           py::arg("max_moment") = ReactionlessWristConfig{}.max_moment)
      .def_readonly("rate_hz", &ReactionlessWristConfig::rate_hz)
      .def_readonly("integrator", &ReactionlessWristConfig::integrator)
      .def_readonly("max_rate", &ReactionlessWristConfig::max_rate)
      .def_readonly("max_condition", &ReactionlessWristConfig::max_condition)
      .def_readonly("damping", &ReactionlessWristConfig::damping)
      .def_readonly("max_acceleration", &ReactionlessWristConfig::max_acceleration)
      .def_readonly("max_momentum", &ReactionlessWristConfig::max_momentum)
      .def_readonly("max_moment", &ReactionlessWristConfig::max_moment);

  // no status in these signatures: NaN input or an overflowing result is a ValueError
  m.def("wrist_momentum_matrix",
        [](const Array& J1, const Array& J2, const Array& J3, const Array& q) {
          const Mat3 N = wrist_momentum_matrix(inertias(J1, J2, J3), fixed_vector<3>(q, "angles", true));
          if (!N.allFinite()) throw py::value_error("wrist_momentum_matrix: the result overflowed");
          return N;
        },
        py::arg("J1"), py::arg("J2"), py::arg("J3"), py::arg("angles"),
        "N(q) of Briot & Arakelian 2009 eq 23 (corrected): wrist angular momentum = N qdot");
  m.def("wrist_momentum_bias",
        [](const Array& J1, const Array& J2, const Array& J3, const Array& q, const Array& qd) {
          const Vec3 b = wrist_momentum_bias(inertias(J1, J2, J3), fixed_vector<3>(q, "angles", true),
                                             fixed_vector<3>(qd, "rates", true));
          if (!b.allFinite()) throw py::value_error("wrist_momentum_bias: the result overflowed");
          return b;
        },
        py::arg("J1"), py::arg("J2"), py::arg("J3"), py::arg("angles"), py::arg("rates"),
        "d/dt(N qdot) - N qddot");

  py::class_<WristCommand>(m, "WristCommand",
                           "A reactionless-wrist tick's command: angles [rad], rates [rad/s], "
                           "accelerations [rad/s^2] (feed-forward), next_angles [rad], the "
                           "condition number of N(q) and the status")
      .def_readonly("angles", &WristCommand::angles)
      .def_readonly("rates", &WristCommand::rates)
      .def_readonly("accelerations", &WristCommand::accelerations)
      .def_readonly("next_angles", &WristCommand::next_angles)
      .def_readonly("condition_number", &WristCommand::condition_number)
      .def_readonly("status", &WristCommand::status);

  py::class_<ReactionlessWrist>(m, "ReactionlessWrist",
                                "Reactionless z-x-z wrist controller (Briot & Arakelian 2009, "
                                "eqs 23-26, corrected)")
      .def(py::init([](const Array& J1, const Array& J2, const Array& J3,
                       const ReactionlessWristConfig& c, const Array& q0, const Array& H) {
             return ReactionlessWrist(inertias(J1, J2, J3), c, fixed_vector<3>(q0, "initial_angles"),
                                      fixed_vector<3>(H, "target_momentum"));
           }),
           py::arg("J1"), py::arg("J2"), py::arg("J3"), py::arg("config"),
           py::arg("initial_angles"), py::arg("target_momentum"))
      // the tick takes NaN (and returns Status.non_finite_input with the held command)
      .def("step",
           [](ReactionlessWrist& w, const Array& D, const Array& Dd, const Array& Dh,
              const Array& Dn) {
             return w.step(fixed_vector<3>(D, "D"), fixed_vector<3>(Dd, "D_dot"),
                           fixed_vector<3>(Dh, "D_half"), fixed_vector<3>(Dn, "D_next"));
           },
           py::arg("D"), py::arg("D_dot"), py::arg("D_half"), py::arg("D_next"),
           "One tick (configured integrator). Returns the Status; the command is in .command")
      .def("step_euler",
           [](ReactionlessWrist& w, const Array& D, const Array& Dd) {
             return w.step_euler(fixed_vector<3>(D, "D"), fixed_vector<3>(Dd, "D_dot"));
           },
           py::arg("D"), py::arg("D_dot"))
      .def("reset",
           [](ReactionlessWrist& w, const Array& q, const Array& H) {
             return w.reset(fixed_vector<3>(q, "angles"), fixed_vector<3>(H, "target_momentum"));
           },
           py::arg("angles"), py::arg("target_momentum"))
      .def(
          "step_into",
          [](ReactionlessWrist& w, FastArg D, FastArg Dd, FastArg Dh, FastArg Dn, FastArg out) {
            using CV = Eigen::Map<const Vec3>;
            const double* d = detail::fast_array(D.h, "D", 3);
            const double* dd = detail::fast_array(Dd.h, "D_dot", 3);
            const double* dh = detail::fast_array(Dh.h, "D_half", 3);
            const double* dn = detail::fast_array(Dn.h, "D_next", 3);
            return motion_step_into(out, 3, [&] { return w.step(CV(d), CV(dd), CV(dh), CV(dn)); },
                                    [&](auto q, auto v, auto a) { write_wrist(w.command(), q, v, a); });
          },
          py::arg("D"), py::arg("D_dot"), py::arg("D_half"), py::arg("D_next"), py::arg("out"),
          "The fast tick: D [kg m^2/s], D_dot [N m], D_half, D_next as float64 arrays of 3; writes "
          "the command into `out` (3, 3): rows angles [rad], rates [rad/s], accelerations "
          "[rad/s^2]; returns the status as an int. Nothing is copied or allocated.")
      .def(
          "run",
          [](ReactionlessWrist& w, const Array& D, const Array& Dd, const Array& Dh,
             const Array& Dn) {
            const auto N = batch_rows(3, {{D, "D"}, {Dd, "D_dot"}, {Dh, "D_half"}, {Dn, "D_next"}});
            OutArray q = make_array({N, 3}), qd = make_array({N, 3}), qdd = make_array({N, 3}),
                     cond = make_array({N});
            auto status = make_status_array(N);
            using CV = Eigen::Map<const Vec3>;
            {
              py::gil_scoped_release release;
              for (py::ssize_t k = 0; k < N; ++k) {
                const Status st = w.step(CV(D.data(k, 0)), CV(Dd.data(k, 0)), CV(Dh.data(k, 0)),
                                         CV(Dn.data(k, 0)));
                const WristCommand& c = w.command();
                Eigen::Map<Vec3>(q.mutable_data(k, 0)) = c.angles;
                Eigen::Map<Vec3>(qd.mutable_data(k, 0)) = c.rates;
                Eigen::Map<Vec3>(qdd.mutable_data(k, 0)) = c.accelerations;
                cond.mutable_data()[k] = c.condition_number;
                status.mutable_data()[k] = static_cast<std::uint32_t>(st);
              }
            }
            py::dict d;
            d["wrist_angles"] = q;
            d["wrist_rates"] = qd;
            d["wrist_accelerations"] = qdd;
            d["condition"] = cond;
            d["status"] = status;
            return d;
          },
          py::arg("D"), py::arg("D_dot"), py::arg("D_half"), py::arg("D_next"),
          "N consecutive ticks in one call: D, D_dot, D_half, D_next each (N, 3) -> "
          "{'wrist_angles', 'wrist_rates', 'wrist_accelerations' (N, 3), 'condition' (N,), "
          "'status' (N,) per tick}")
      .def_property_readonly("command", &ReactionlessWrist::command)
      .def_property_readonly("angles", &ReactionlessWrist::angles)
      .def_property_readonly("dt", &ReactionlessWrist::dt);

  py::class_<PaminsaModel>(m, "PaminsaModel",
                           "Immutable PAMINSA model (Briot & Arakelian 2009), validated")
      .def(py::init<const PaminsaParameters&>(), py::arg("parameters"))
      .def_property_readonly("parameters", &PaminsaModel::parameters)
      .def_property_readonly("body_names",
                             [](const PaminsaModel&) {
                               std::vector<std::string> n;
                               for (std::size_t i = 0; i < PaminsaBodyIndex::count; ++i)
                                 n.emplace_back(PaminsaModel::body_name(i));
                               return n;
                             })
      .def_property_readonly("masses",
                             [](const PaminsaModel& mo) {
                               Eigen::VectorXd v(kBodies);
                               for (py::ssize_t i = 0; i < kBodies; ++i) v(i) = mo.bodies()[i].mass;
                               return v;
                             })
      .def_property_readonly("inertia_body",
                             [](const PaminsaModel& mo) {
                               Array a = make_array({kBodies, 3, 3});
                               for (py::ssize_t i = 0; i < kBodies; ++i)
                                 Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
                                     a.mutable_data(i, 0, 0)) = mo.bodies()[i].inertia_body;
                               return a;
                             })
      .def_property_readonly("slider_lines", [](const PaminsaModel& mo) {
        Eigen::Matrix<double, 3, 2, Eigen::RowMajor> x;
        for (int i = 0; i < 3; ++i) x.row(i) = mo.slider_line()[i].transpose();
        return x;
      })
      .def_property_readonly("guide_pivots", [](const PaminsaModel& mo) {
        Eigen::Matrix<double, 3, 2, Eigen::RowMajor> x;
        for (int i = 0; i < 3; ++i) x.row(i) = mo.guide_pivot()[i].transpose();
        return x;
      })
      .def_property_readonly("vertical_mass_xy", &PaminsaModel::vertical_mass_xy)
      .def("inverse_kinematics",
           [](const PaminsaModel& mo, const Array& P) {
             PaminsaActuators a;
             const Status s = mo.inverse_kinematics(fixed_vector<3>(P, "P"), a);
             if (s != Status::ok) a = PaminsaActuators{};  // zeros with the status
             py::dict d;
             d["alpha1"] = a.alpha1;
             d["alpha3"] = a.alpha3;
             d["z_B"] = a.z_B;
             d["alpha2"] = a.alpha2;
             d["stroke"] = Eigen::Vector3d(a.stroke);
             d["status"] = s;
             return d;
           },
           py::arg("P"))
      .def("forward_kinematics",
           [](const PaminsaModel& mo, double a1, double a3, double zB) {
             Eigen::Vector3d P = Eigen::Vector3d::Zero();
             const Status s = mo.forward_kinematics(a1, a3, zB, P);
             return py::make_tuple(P, s);
           },
           py::arg("alpha1"), py::arg("alpha3"), py::arg("z_B"))
      .def("leg_points",
           [](const PaminsaModel& mo, const Array& P) {
             PaminsaWorkspace ws;
             PlatformMotion pm;
             pm.position = fixed_vector<3>(P, "P");
             const Status s = paminsa_mechanism_kinematics(mo, pm, ws);
             OutArray a = make_array({3, 6, 3});
             for (int i = 0; i < 3; ++i)
               for (int n = 0; n < 6; ++n)  // zeros when the pose failed (never uninitialised memory)
                 Eigen::Map<Eigen::Vector3d>(a.mutable_data(i, n, 0)) =
                     s == Status::ok ? ws.leg_points[i][n] : Vec3::Zero();
             return py::make_tuple(a, s);
           },
           py::arg("P"),
           "(points, status): base-frame points A, B, C, D, E, F of each leg (3, 6, 3) at pose P; "
           "zeros and the status when P is not finite, unreachable or overflows");

  py::class_<PaminsaController>(
      m, "PaminsaController",
      "One tick of the fully balanced PAMINSA (Briot & Arakelian 2009): kinematics at t_n, D "
      "(eq 19), the reactionless-wrist step, every body's motion and the shaking wrench")
      .def(py::init([](const PaminsaModel& mo, const ReactionlessWristConfig& c, const Array& q0,
                       double max_speed, double max_acceleration) {
             PlatformLimits lim;
             lim.max_speed = max_speed;
             lim.max_acceleration = max_acceleration;
             return new PaminsaController(mo, c, fixed_vector<3>(q0, "initial_wrist_angles"), lim);
           }),
           py::arg("model"), py::arg("config"), py::arg("initial_wrist_angles"),
           py::arg("max_speed") = PlatformLimits{}.max_speed,
           py::arg("max_acceleration") = PlatformLimits{}.max_acceleration,
           "max_speed [m/s], max_acceleration [m/s^2]: the platform motion a tick accepts (per "
           "component)")
      .def(
          "reset",
          [](PaminsaController& c, const Array& P, const Array& wrist_angles) {
            PlatformMotion rest;
            rest.position = fixed_vector<3>(P, "P");
            return c.reset(rest, fixed_vector<3>(wrist_angles, "wrist_angles"));
          },
          py::arg("P"), py::arg("wrist_angles"),
          "Restart at rest at platform position P [m] with the wrist at `wrist_angles` [rad]; "
          "returns the Status (nothing changes unless ok)")
      .def(
          "step",
          [](PaminsaController& c, const Array& P, const Array& Pd, const Array& Pdd,
             const Array& P_half, const Array& Pd_half, const Array& Pdd_half,
             const Array& P_next, const Array& Pd_next, const Array& Pdd_next) {
            auto motion = [](const Array& a, const Array& b, const Array& cc, const char* na,
                             const char* nb, const char* nc) {
              PlatformMotion m;
              m.position = fixed_vector<3>(a, na);
              m.velocity = fixed_vector<3>(b, nb);
              m.acceleration = fixed_vector<3>(cc, nc);
              return m;
            };
            return c.tick(motion(P, Pd, Pdd, "P", "Pd", "Pdd"),
                          motion(P_half, Pd_half, Pdd_half, "P_half", "Pd_half", "Pdd_half"),
                          motion(P_next, Pd_next, Pdd_next, "P_next", "Pd_next", "Pdd_next"));
          },
          py::arg("P"), py::arg("Pd"), py::arg("Pdd"), py::arg("P_half"), py::arg("Pd_half"),
          py::arg("Pdd_half"), py::arg("P_next"), py::arg("Pd_next"), py::arg("Pdd_next"),
          "One tick: platform position [m], velocity [m/s], acceleration [m/s^2] at t_n, "
          "t_n + dt/2, t_n + dt (Euler ignores the last two). Returns the Status; the result is "
          "in shaking_force, shaking_moment, D, D_dot and wrist_command")
      .def(
          "step_into",
          [](PaminsaController& c, FastArg now, FastArg half, FastArg next, FastArg out) {
            auto motion = [](const double* p) {
              PlatformMotion m;
              m.position = Eigen::Map<const Vec3>(p);
              m.velocity = Eigen::Map<const Vec3>(p + 3);
              m.acceleration = Eigen::Map<const Vec3>(p + 6);
              return m;
            };
            const double* n = detail::fast_matrix(now.h, "now", 3, 3);
            const double* h = detail::fast_matrix(half.h, "half", 3, 3);
            const double* x = detail::fast_matrix(next.h, "next", 3, 3);
            return motion_step_into(out, 3, [&] { return c.tick(motion(n), motion(h), motion(x)); },
                                    [&](auto q, auto v, auto a) { write_wrist(c.wrist().command(), q, v, a); });
          },
          py::arg("now"), py::arg("half"), py::arg("next"), py::arg("out"),
          "The fast tick: the platform motion at t_n, t_n + dt/2, t_n + dt, each a (3, 3) float64 "
          "array with rows position [m], velocity [m/s], acceleration [m/s^2]; writes the wrist "
          "command into `out` (3, 3): rows angles [rad], rates [rad/s], accelerations [rad/s^2]; "
          "returns the status as an int (the wrench stays in shaking_force, shaking_moment)")
      .def_property_readonly("shaking_force",
                             [](const PaminsaController& c) { return Vec3(c.wrench().force); })
      .def_property_readonly("shaking_moment",
                             [](const PaminsaController& c) { return Vec3(c.wrench().moment); })
      .def_property_readonly("D", [](const PaminsaController& c) { return Vec3(c.D()); })
      .def_property_readonly("D_dot", [](const PaminsaController& c) { return Vec3(c.D_dot()); })
      .def_property_readonly("wrist_command",
                             [](const PaminsaController& c) { return c.wrist().command(); })
      .def_property_readonly("wrist_angles",
                             [](const PaminsaController& c) { return Vec3(c.wrist().angles()); });

  m.def("paminsa_kinematics",
        [](const PaminsaModel& mo, const Array& P, const Array& Pd, const Array& Pdd,
           const Array& q, const Array& qd, const Array& qdd) {
          const auto N = batch_rows(3, {{P, "P"}, {Pd, "Pd"}, {Pdd, "Pdd"}, {q, "q"}, {qd, "v"}, {qdd, "a"}});
          BatchArrays out(N);
          const Status s = paminsa_kinematics_batch(mo, static_cast<std::size_t>(N), P.data(),
                                                    Pd.data(), Pdd.data(), q.data(), qd.data(),
                                                    qdd.data(), out.view());
          return out.to_dict(s);
        },
        py::arg("model"), py::arg("P"), py::arg("Pd"), py::arg("Pdd"), py::arg("q"),
        py::arg("v"), py::arg("a"),
        "Every body's motion (N, 38, ...), the shaking wrench about O and D, dD/dt (eq 19) for "
        "platform motion and prescribed wrist motion, each (N, 3).");

  m.def("paminsa_reactionless_run",
        [](const PaminsaModel& mo, const ReactionlessWristConfig& c, const Array& q0_arg,
           const Array& P, const Array& Pd, const Array& Pdd) {
          const Vec3 q0 = fixed_vector<3>(q0_arg, "initial_wrist_angles");
          const auto J = batch_rows(3, {{P, "P_half"}});
          const auto steps = half_step_ticks(J, "P_half", 1);
          require_rows(J, 3, {{Pd, "Pd_half"}, {Pdd, "Pdd_half"}});
          BatchArrays out(steps + 1);
          const Status s = paminsa_reactionless_run(mo, c, q0, static_cast<std::size_t>(steps),
                                                    P.data(), Pd.data(), Pdd.data(), out.view());
          return out.to_dict(s);
        },
        py::arg("model"), py::arg("config"), py::arg("initial_wrist_angles"), py::arg("P_half"),
        py::arg("Pd_half"), py::arg("Pdd_half"),
        "Fully balanced run with the reactionless wrist ticking at config.rate_hz. Platform motion "
        "sampled every dt/2 ((2 steps + 1, 3) each); outputs at the steps + 1 ticks.");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(40, paminsa, bind_paminsa);

}  // namespace mechbal::pyb
