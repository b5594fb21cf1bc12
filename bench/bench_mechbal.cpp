// mechbal's own real-time paths: the shaking wrench of a chain (general path), chain kinematics (the model's
// forward kinematics: every body's motion), recursive Newton-Euler inverse dynamics, the
// computed-torque tick (the real ComputedTorque controller over MechanismDynamics and over the
// closed-form Arm2DofDynamics) and the CRBA mass matrix.
#include <cstdio>
#include <cstdlib>
#include <random>

#include "bench_ct.hpp"
#include "bench_registry.hpp"
#include "mechbal/papers/arm2dof/arm2dof.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/model/data.hpp"
#include "test_support.hpp"

namespace mechbal::bench {
namespace {

// The general shaking wrench (algorithm/shaking_wrench.hpp: forward kinematics, then the momenta
// about O and their rates) of a chain of `count` links, one body each.
struct ChainWrench {
  explicit ChainWrench(int dof) : model(bench_chain(dof)), data(model), x(bench_states(dof)) {}
  MechanismModel model;
  MechanismData data;
  JointStates x;
  int k = 0;
};

Tick shaking_wrench_case(int count) {
  auto s = std::make_shared<ChainWrench>(count);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    shaking_wrench(s->model, s->data, s->x.q[k], s->x.qd[k], s->x.qdd[k]);
    benchmark::DoNotOptimize(&s->data.shaking);
    benchmark::ClobberMemory();
  };
}

struct ChainKin {
  explicit ChainKin(int dof) : model(bench_chain(dof)), ws(model), x(bench_states(dof)) {}
  MechanismModel model;
  MechanismData ws;
  JointStates x;
  int k = 0;
};

Tick chain_kinematics_case(int dof) {
  auto s = std::make_shared<ChainKin>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    forward_kinematics(s->model, s->ws, s->x.q[k], s->x.qd[k], s->x.qdd[k]);
    benchmark::DoNotOptimize(s->ws.body_states.data());
    benchmark::ClobberMemory();
  };
}

struct Rne {
  explicit Rne(int dof)
      : model(bench_chain(dof)), rne(model), x(bench_states(dof)), v(dof), tau(dof), M(dof, dof) {}
  MechanismModel model;
  MechanismDynamics rne;
  JointStates x;
  Eigen::VectorXd v, tau;
  Eigen::MatrixXd M;
  int k = 0;
};

Tick id_case(int dof) {
  auto s = std::make_shared<Rne>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    s->rne.inverse_dynamics(s->x.q[k], s->x.qd[k], s->x.qdd[k], s->tau);
    benchmark::DoNotOptimize(s->tau.data());
    benchmark::ClobberMemory();
  };
}

// The computed-torque law written inline (PD outer loop + inverse dynamics), as the KDL and
// Pinocchio ct cases compute it: reference = state k, measured = state k+1. Kept as
// ct6_mechbal_inline to show what the ComputedTorque class adds (checks, virtual call, clipping).
Tick ct_inline_case(int dof) {
  auto s = std::make_shared<Rne>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    const int m = (k + 1) & (JointStates::count - 1);
    s->v = s->x.qdd[k] + ct_kp * (s->x.q[k] - s->x.q[m]) + ct_kd * (s->x.qd[k] - s->x.qd[m]);
    s->rne.inverse_dynamics(s->x.q[m], s->x.qd[m], s->v, s->tau);
    benchmark::DoNotOptimize(s->tau.data());
    benchmark::ClobberMemory();
  };
}

Tick ct_case(int dof) {
  const MechanismModel model = bench_chain(dof);
  auto s = std::make_shared<Ct<MechanismDynamics>>(dof, model);
  MechanismDynamics reference(model);
  check_ct("ComputedTorque<MechanismDynamics>", *s, reference);
  return ct_tick(s);
}

// 2-DOF closed form (Arakelian et al. 2011, Sec. 4 parameters), checked against mechbal's RNE on
// the equivalent serial chain (arm2dof_description): an independent model of the same arm.
Tick ct2_case() {
  const Arm2DofParameters arm{};
  auto s = std::make_shared<Ct<Arm2DofDynamics>>(2, arm);
  MechanismDynamics reference{MechanismModel(arm2dof_description(arm))};
  check_ct("ComputedTorque<Arm2DofDynamics>", *s, reference);
  return ct_tick(s);
}

Tick mass_case(int dof) {
  auto s = std::make_shared<Rne>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    s->rne.mass_matrix(s->x.q[k], s->M);
    benchmark::DoNotOptimize(s->M.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(shaking_wrench_10) { return shaking_wrench_case(10); }
MECHBAL_BENCH_CASE(shaking_wrench_50) { return shaking_wrench_case(50); }
MECHBAL_BENCH_CASE(chain_kinematics_6) { return chain_kinematics_case(6); }
MECHBAL_BENCH_CASE(chain_kinematics_7) { return chain_kinematics_case(7); }
MECHBAL_BENCH_CASE(id6_mechbal) { return id_case(6); }
MECHBAL_BENCH_CASE(id7_mechbal) { return id_case(7); }
MECHBAL_BENCH_CASE(ct6_mechbal) { return ct_case(6); }
MECHBAL_BENCH_CASE(ct7_mechbal) { return ct_case(7); }
MECHBAL_BENCH_CASE(ct6_mechbal_inline) { return ct_inline_case(6); }
MECHBAL_BENCH_CASE(ct2_closed_form) { return ct2_case(); }
MECHBAL_BENCH_CASE(mass6_mechbal) { return mass_case(6); }
MECHBAL_BENCH_CASE(mass7_mechbal) { return mass_case(7); }
