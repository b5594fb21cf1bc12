// Generated code for one mechanism (mechbal.codegen, `mechbal codegen`) beside mechbal's general
// model and Pinocchio on the same robots (bench_urdf.cpp, bench_urdf_pinocchio.cpp): inverse
// dynamics, mass matrix, gravity torque and the momentum rate (shaking wrench) of UR5 and Panda,
// and of Talos (talos_reduced), read from the same URDF files. The headers are generated at build
// time by mechbal_add_generated (cmake/MechbalGenerated.cmake).
//  - paminsa_generated_wrench: the generated closed tick of PAMINSA's general model (position solve
//    from the last tick's solution moved to second order (closed_tick), v = C v#, a = C a# + c,
//    shaking wrench), on the trajectory and
//    model of paminsa_general_wrench (bench_loops.cpp), checked at setup against the closed form:
//    ratio paminsa_generated_over_closed_form.
//  - four_bar_generated_tick: the generated closed inverse dynamics tick of four_bar_tick's
//    four-bar (bench/four_bar.toml; warm start moved from the last tick, position solve, v = C v#,
//    a = C a# + c, tau# = C^T tau) on four_bar_tick's crank motion, checked at setup against the
//    library's closed_inverse_dynamics on bench_four_bar(): ratio four_bar_generated_over_general.
#include <algorithm>
#include <memory>

#include "bench_registry.hpp"
#include "bench_support.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal_bench_four_bar.hpp"
#include "mechbal_bench_paminsa.hpp"
#include "mechbal_bench_panda.hpp"
#include "paminsa_general.hpp"
#include "paminsa_motion.hpp"
#include "mechbal_bench_talos.hpp"
#include "mechbal_bench_ur5.hpp"

namespace mechbal::bench {
MechanismModel bench_four_bar();  // bench_loops.cpp
namespace {

template <int Dof>
struct GeneratedState {
  JointStates x = bench_states(Dof, 11);
  double out[Dof * Dof > 6 ? Dof * Dof : 6];
  double force[3];
  double moment[3];
  int k = 0;
  int next() { return k = (k + 1) & (JointStates::count - 1); }
};

#define MECHBAL_GENERATED_CASES(robot, ns)                                                       \
  MECHBAL_BENCH_CASE(id_##robot##_generated) {                                                   \
    auto s = std::make_shared<GeneratedState<mechbal_generated::ns::dof>>();                      \
    return [s] {                                                                                 \
      const int k = s->next();                                                                   \
      mechbal_generated::ns::inverse_dynamics(s->x.q[k].data(), s->x.qd[k].data(),               \
                                              s->x.qdd[k].data(), s->out);                       \
      benchmark::DoNotOptimize(s->out);                                                          \
      benchmark::ClobberMemory();                                                                \
    };                                                                                           \
  }                                                                                              \
  MECHBAL_BENCH_CASE(mass_##robot##_generated) {                                                 \
    auto s = std::make_shared<GeneratedState<mechbal_generated::ns::dof>>();                      \
    return [s] {                                                                                 \
      const int k = s->next();                                                                   \
      mechbal_generated::ns::mass_matrix(s->x.q[k].data(), s->out);                              \
      benchmark::DoNotOptimize(s->out);                                                          \
      benchmark::ClobberMemory();                                                                \
    };                                                                                           \
  }                                                                                              \
  MECHBAL_BENCH_CASE(gravity_##robot##_generated) {                                              \
    auto s = std::make_shared<GeneratedState<mechbal_generated::ns::dof>>();                      \
    return [s] {                                                                                 \
      const int k = s->next();                                                                   \
      mechbal_generated::ns::gravity_torque(s->x.q[k].data(), s->out);                           \
      benchmark::DoNotOptimize(s->out);                                                          \
      benchmark::ClobberMemory();                                                                \
    };                                                                                           \
  }                                                                                              \
  MECHBAL_BENCH_CASE(momentum_rate_##robot##_generated) {                                        \
    auto s = std::make_shared<GeneratedState<mechbal_generated::ns::dof>>();                      \
    return [s] {                                                                                 \
      const int k = s->next();                                                                   \
      mechbal_generated::ns::shaking_wrench(s->x.q[k].data(), s->x.qd[k].data(),                 \
                                            s->x.qdd[k].data(), s->force, s->moment);            \
      benchmark::DoNotOptimize(s->force);                                                        \
      benchmark::DoNotOptimize(s->moment);                                                       \
      benchmark::ClobberMemory();                                                                \
    };                                                                                           \
  }

namespace gp = mechbal_generated::mechbal_bench_paminsa;

struct PaminsaGeneratedCase {
  PaminsaModel closed{PaminsaParameters{}};
  MechanismModel model{paminsa_description(closed)};
  std::vector<ActuatedState> in;
  double q[gp::dof];
  double q0[gp::dof];
  double force[3], moment[3];
  gp::ClosedState state;
  PingPong<1024> order;
  int status = 0;
};

Tick paminsa_generated_case() {
  auto s = std::make_shared<PaminsaGeneratedCase>();
  constexpr double dt = 1e-3;
  if (s->model.dof() != gp::dof || s->model.num_actuated() != gp::num_actuated)
    fail("generated PAMINSA: not the model of paminsa_general.hpp (dof)", gp::dof);
  for (int i = 0; i < gp::num_actuated; ++i)
    if (s->model.actuated_coordinates()[static_cast<std::size_t>(i)] != gp::actuated_index[i])
      fail("generated PAMINSA: actuated coordinates differ", i);
  for (int n = 0; n < 1024; ++n)
    s->in.push_back(actuated(s->closed, s->model, test::platform_at(n * dt), test::wrist_at(n * dt)));
  const Eigen::VectorXd guess = initial_guess(s->closed, s->model, test::platform_at(0.0), test::wrist_at(0.0));
  std::copy(guess.data(), guess.data() + gp::dof, s->q0);
  std::copy(s->q0, s->q0 + gp::dof, s->q);
  PaminsaWorkspace ws;
  for (int n = 0; n < 64; ++n) {  // the generated tick moves as the closed form (1e-9 relative)
    const ActuatedState& a = s->in[static_cast<std::size_t>(n)];
    if (gp::closed_shaking_wrench(a.q.data(), a.v.data(), a.a.data(), s->q, s->force, s->moment) != gp::ok)
      fail("generated PAMINSA: the closed tick failed on the bench trajectory", n);
    ShakingWrench w;
    if (paminsa_kinematics(s->closed, test::platform_at(n * dt), test::wrist_at(n * dt), ws) != Status::ok ||
        paminsa_shaking_wrench(s->closed, ws, w) != Status::ok)
      fail("PAMINSA closed form failed on the bench trajectory", n);
    const double rel = std::max((Eigen::Map<const Vec3>(s->force) - w.force).norm() / std::max(1.0, w.force.norm()),
                                (Eigen::Map<const Vec3>(s->moment) - w.moment).norm() / std::max(1.0, w.moment.norm()));
    if (!(rel < 1e-9)) fail("generated PAMINSA != closed form (relative)", rel);
  }
  std::copy(s->q0, s->q0 + gp::dof, s->q);
  std::copy(s->q0, s->q0 + gp::dof, s->state.q);
  return [s] {
    const ActuatedState& a = s->in[s->order.next()];
    s->status = gp::closed_tick(s->state, a.q.data(), a.v.data(), a.a.data(), s->force, s->moment);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(s->force);
    benchmark::DoNotOptimize(s->moment);
    benchmark::ClobberMemory();
  };
}

namespace gf = mechbal_generated::mechbal_bench_four_bar;

struct FourBarGeneratedCase {
  MechanismModel model{bench_four_bar()};
  MechanismData data{model};
  std::vector<ActuatedState> in;
  gf::ClosedState state;
  double tau[gf::num_actuated];
  PingPong<1024> order;
  int status = 0;
};

Tick four_bar_generated_case() {
  auto s = std::make_shared<FourBarGeneratedCase>();
  if (s->model.dof() != gf::dof || s->model.num_actuated() != gf::num_actuated)
    fail("generated four-bar: not the model of bench_four_bar (dof)", gf::dof);
  for (int n = 0; n < 1024; ++n) {  // four_bar_tick's motion: the crank swings 1.0 +- 0.4 rad at 2 rad/s
    const double t = n * 1e-3;
    s->in.push_back({Eigen::VectorXd::Constant(1, 1.0 + 0.4 * std::sin(2.0 * t)),
                     Eigen::VectorXd::Constant(1, 0.8 * std::cos(2.0 * t)),
                     Eigen::VectorXd::Constant(1, -1.6 * std::sin(2.0 * t))});
  }
  const double guess[gf::dof] = {1.0, -0.6, 1.75};
  Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(guess, gf::dof);
  std::copy(guess, guess + gf::dof, s->state.q);
  for (int n = 0; n < 256; ++n) {  // the generated tick drives the crank as the library does (1e-9)
    const ActuatedState& a = s->in[static_cast<std::size_t>(n)];
    if (gf::closed_inverse_dynamics_tick(s->state, a.q.data(), a.v.data(), a.a.data(), s->tau) != gf::ok)
      fail("generated four-bar: the closed tick failed on the bench trajectory", n);
    if (closed_inverse_dynamics(s->model, s->data, a.q, a.v, a.a, q) != Status::ok)
      fail("four-bar: closed_inverse_dynamics failed", n);
    const double rel = std::abs(s->tau[0] - s->data.actuated_force[0]) / std::max(1.0, std::abs(s->data.actuated_force[0]));
    if (!(rel < 1e-9)) fail("generated four-bar != the library's closed inverse dynamics (relative)", rel);
  }
  s->state = gf::ClosedState{};
  std::copy(guess, guess + gf::dof, s->state.q);
  return [s] {
    const ActuatedState& a = s->in[s->order.next()];
    s->status = gf::closed_inverse_dynamics_tick(s->state, a.q.data(), a.v.data(), a.a.data(), s->tau);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(s->tau);
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(four_bar_generated_tick) { return four_bar_generated_case(); }
MECHBAL_BENCH_CASE(paminsa_generated_wrench) { return paminsa_generated_case(); }
MECHBAL_GENERATED_CASES(ur5, mechbal_bench_ur5)
MECHBAL_GENERATED_CASES(panda, mechbal_bench_panda)
MECHBAL_GENERATED_CASES(talos, mechbal_bench_talos)
