// Generated code for one mechanism (mechbal.codegen, `mechbal codegen`) beside mechbal's general
// model and Pinocchio on the same robots (bench_urdf.cpp, bench_urdf_pinocchio.cpp): inverse
// dynamics, mass matrix, gravity torque and the momentum rate (shaking wrench) of UR5 and Panda,
// and of Talos (talos_reduced), read from the same URDF files. The headers are generated at build
// time by mechbal_add_generated (cmake/MechbalGenerated.cmake).
#include <memory>

#include "bench_registry.hpp"
#include "mechbal_bench_panda.hpp"
#include "mechbal_bench_talos.hpp"
#include "mechbal_bench_ur5.hpp"

namespace mechbal::bench {
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

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_GENERATED_CASES(ur5, mechbal_bench_ur5)
MECHBAL_GENERATED_CASES(panda, mechbal_bench_panda)
MECHBAL_GENERATED_CASES(talos, mechbal_bench_talos)
