// mechbal's own real-time paths: shaking wrench of a body set, chain kinematics, recursive
// Newton-Euler inverse dynamics, the computed-torque tick (the real ComputedTorque controller over
// RneChainDynamics and over the closed-form Arm2DofDynamics) and the CRBA mass matrix.
#include <cstdio>
#include <cstdlib>
#include <random>

#include "bench_ct.hpp"
#include "bench_registry.hpp"
#include "mechbal/papers/arm2dof/arm2dof.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/control/rnea.hpp"
#include "mechbal/model/serial_chain.hpp"
#include "test_support.hpp"

namespace mechbal::bench {
namespace {

struct BodySet {
  std::vector<RigidBody> bodies;
  std::vector<BodyState> states;
  ShakingWrench out;
};

Tick shaking_wrench_case(int count) {
  auto s = std::make_shared<BodySet>();
  std::mt19937 rng(static_cast<unsigned>(count));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < count; ++i) {
    s->bodies.push_back(test::random_body(rng));
    BodyState st;
    st.com = Vec3(u(rng), u(rng), u(rng));
    st.com_velocity = Vec3(u(rng), u(rng), u(rng));
    st.com_acceleration = Vec3(u(rng), u(rng), u(rng));
    st.rotation = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    st.angular_velocity = Vec3(u(rng), u(rng), u(rng));
    st.angular_acceleration = Vec3(u(rng), u(rng), u(rng));
    s->states.push_back(st);
  }
  return [s] {
    shaking_wrench(s->bodies.data(), s->states.data(), s->states.size(), s->out);
    benchmark::DoNotOptimize(s->out);
  };
}

struct ChainKin {
  explicit ChainKin(int dof) : model(bench_chain(dof)), ws(model), x(bench_states(dof)) {}
  ChainModel model;
  ChainWorkspace ws;
  JointStates x;
  int k = 0;
};

Tick chain_kinematics_case(int dof) {
  auto s = std::make_shared<ChainKin>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    chain_kinematics(s->model, s->x.q[k], s->x.qd[k], s->x.qdd[k], s->ws);
    benchmark::DoNotOptimize(s->ws.states.data());
    benchmark::ClobberMemory();
  };
}

struct Rne {
  explicit Rne(int dof)
      : model(bench_chain(dof)), rne(model), x(bench_states(dof)), v(dof), tau(dof), M(dof, dof) {}
  ChainModel model;
  RneChainDynamics rne;
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
  const ChainModel model = bench_chain(dof);
  auto s = std::make_shared<Ct<RneChainDynamics>>(dof, model);
  RneChainDynamics reference(model);
  check_ct("ComputedTorque<RneChainDynamics>", *s, reference);
  return ct_tick(s);
}

// 2-DOF closed form (Arakelian et al. 2011, Sec. 4 parameters), checked against mechbal's RNE on
// the equivalent serial chain (arm2dof_chain_model): an independent model of the same arm.
Tick ct2_case() {
  const Arm2DofParameters arm{};
  auto s = std::make_shared<Ct<Arm2DofDynamics>>(2, arm);
  RneChainDynamics reference(arm2dof_chain_model(arm));
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
