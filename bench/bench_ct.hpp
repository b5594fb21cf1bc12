#pragma once
// The computed-torque case shared by every back end: the real ComputedTorque controller
// (computed_torque.hpp) over one InverseDynamics back end, ticked on the bench joint states.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <utility>

#include "bench_registry.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/dynamics.hpp"

namespace mechbal::bench {

// The real controller: ComputedTorque::step over any InverseDynamics back end, same inputs as
// the inline law (measured = state k+1, desired = state k). Checked once at setup against the
// inline law evaluated with `reference` (another back end) to 1e-9.
template <class Dynamics>
struct Ct {
  template <class... A>
  Ct(int dof, A&&... a)
      : dyn(std::forward<A>(a)...),
        ctl(dyn, Eigen::VectorXd::Constant(dof, ct_kp), Eigen::VectorXd::Constant(dof, ct_kd)),
        x(bench_states(dof)), tau(dof) {}
  Dynamics dyn;
  ComputedTorque ctl;
  JointStates x;
  Eigen::VectorXd tau;
  Status status = Status::ok;
  int k = 0;
};

template <class Dynamics>
inline void check_ct(const char* what, Ct<Dynamics>& s, InverseDynamics& reference) {
  const int n = s.ctl.dof();
  Eigen::VectorXd v(n), ref(n), tau(n);
  for (int k = 0; k < 4; ++k) {
    const int m = k + 1;
    v = s.x.qdd[k] + ct_kp * (s.x.q[k] - s.x.q[m]) + ct_kd * (s.x.qd[k] - s.x.qd[m]);
    reference.inverse_dynamics(s.x.q[m], s.x.qd[m], v, ref);
    const Status st = s.ctl.step(s.x.q[m], s.x.qd[m], s.x.q[k], s.x.qd[k], s.x.qdd[k], tau);
    const double rel = (tau - ref).norm() / std::max(1.0, ref.norm());
    if (st != Status::ok || !(rel < 1e-9)) {
      std::fprintf(stderr, "mechbal-bench: %s: ComputedTorque disagrees with the inline law "
                   "(status %u, relative %g)\n", what, static_cast<unsigned>(st), rel);
      std::abort();
    }
  }
}

template <class Dynamics>
inline Tick ct_tick(std::shared_ptr<Ct<Dynamics>> s) {
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    const int m = (k + 1) & (JointStates::count - 1);
    s->status = s->ctl.step(s->x.q[m], s->x.qd[m], s->x.q[k], s->x.qd[k], s->x.qdd[k], s->tau);
    benchmark::DoNotOptimize(s->tau.data());
    benchmark::DoNotOptimize(s->status);
    benchmark::ClobberMemory();
  };
}

}  // namespace mechbal::bench
