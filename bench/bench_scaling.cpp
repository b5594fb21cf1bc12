// Scaling rows (issue 26): centre of mass and inverse dynamics of 100-, 1000- and 10 000-link
// serial chains (bench_chain: random all-revolute chains, one body per link). Both algorithms are
// one pass (or two) over the links, so the cost per link should stay flat: merge_results.py
// reports ns per link and the ratio of the largest chain's cost per link to the smallest's
// (target <= 2). The 10 000-link chain's state vectors no longer fit in L1, which is what the row
// is for. Setup checks that every call returns Status::ok at every bench state (aborts
// otherwise): a long chain must not overflow.
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "bench_registry.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/model/data.hpp"

namespace mechbal::bench {
namespace {

struct Chain {
  explicit Chain(int links) : model(bench_chain(links)), data(model), x(bench_states(links, 17)) {}
  MechanismModel model;
  MechanismData data;
  JointStates x;
  int k = 0;
  std::size_t next() { return static_cast<std::size_t>(k = (k + 1) & (JointStates::count - 1)); }
};

void require_ok(Status s, const char* what, int links) {
  if (s != Status::ok) {
    std::fprintf(stderr, "mechbal-bench: %s of the %d-link chain: status %d\n", what, links, static_cast<int>(s));
    std::abort();
  }
}

Tick com_case(int links) {
  auto s = std::make_shared<Chain>(links);
  for (std::size_t k = 0; k < JointStates::count; ++k)
    require_ok(center_of_mass(s->model, s->data, s->x.q[k]), "center_of_mass", links);
  return [s] {
    const auto k = s->next();
    center_of_mass(s->model, s->data, s->x.q[k]);
    benchmark::DoNotOptimize(s->data.center_of_mass);
    benchmark::ClobberMemory();
  };
}

Tick id_case(int links) {
  auto s = std::make_shared<Chain>(links);
  for (std::size_t k = 0; k < JointStates::count; ++k)
    require_ok(inverse_dynamics(s->model, s->data, s->x.q[k], s->x.qd[k], s->x.qdd[k]), "inverse_dynamics", links);
  return [s] {
    const auto k = s->next();
    inverse_dynamics(s->model, s->data, s->x.q[k], s->x.qd[k], s->x.qdd[k]);
    benchmark::DoNotOptimize(s->data.joint_torque.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(scaling_com_100) { return com_case(100); }
MECHBAL_BENCH_CASE(scaling_com_1000) { return com_case(1000); }
MECHBAL_BENCH_CASE(scaling_com_10000) { return com_case(10000); }
MECHBAL_BENCH_CASE(scaling_id_100) { return id_case(100); }
MECHBAL_BENCH_CASE(scaling_id_1000) { return id_case(1000); }
MECHBAL_BENCH_CASE(scaling_id_10000) { return id_case(10000); }
