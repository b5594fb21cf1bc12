// Decoupled joint control of a dynamically balanced arm (DecoupledJointController, Coutinho & Hess
// Coelho eqs 15, 26, 36) side by side with ComputedTorque over the arm's full model
// (MechanismDynamics: links + counter-rotating discs as gear-coupled links of the general model):
// what the balancing buys per control tick (issue 6).
//
//  - decoupled_step3 / ct3_disc_arm: the balanced planar 3R with four discs of the discs-3r case
//    (tests/cpp/disc_arms.hpp, eqs 8 and 14). Its mass matrix is constant and
//    diagonal, diag(k) (eq 16), so both controllers command the same torques: checked at setup.
//  - decoupled_step6 / ct6_disc_arm: six joints, ComputedTorque over a 6-joint disc arm (the
//    bench's random 6-joint chain with one disc per link). mechbal has no balancing design for a
//    general 6-joint arm, so this one is NOT balanced and the two torques differ: it times what
//    each controller costs per tick at six joints (neither cost depends on the parameter values).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bench_registry.hpp"
#include "bench_support.hpp"
#include "disc_arms.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"

namespace mechbal::bench {
namespace {

MechanismModel disc_arm_6() {
  std::vector<test::Disc> discs;
  for (int i = 0; i < 6; ++i) discs.push_back({i, (i + 1) % 6, -2.0, 0.002 + 0.001 * i});
  return test::disc_arm(bench_chain(6).description(), discs);
}

// The constant diagonal of the balanced mass matrix, k = diag(M(q)), read from the model at one
// pose (the setup check then confirms, at every bench state, that both laws agree).
Eigen::VectorXd diagonal_of(const MechanismModel& model) {
  MechanismData data(model);
  if (mass_matrix(model, data, Eigen::VectorXd::Constant(model.dof(), 0.3)) != Status::ok)
    fail("mass_matrix failed at setup", 0.0);
  return data.mass_matrix.diagonal();
}

struct CtDisc {
  explicit CtDisc(MechanismModel m)
      : dyn(std::move(m)),
        ctl(dyn, Eigen::VectorXd::Constant(dyn.dof(), ct_kp), Eigen::VectorXd::Constant(dyn.dof(), ct_kd)),
        x(bench_states(dyn.dof())), tau(dyn.dof()) {}
  MechanismDynamics dyn;
  ComputedTorque ctl;
  JointStates x;
  Eigen::VectorXd tau;
  Status status = Status::ok;
  int k = 0;
};

struct Decoupled {
  Decoupled(const Eigen::VectorXd& k, int dof)
      : ctl(k, Eigen::VectorXd::Constant(dof, ct_kp), Eigen::VectorXd::Constant(dof, ct_kd)),
        x(bench_states(dof)), tau(dof) {}
  DecoupledJointController ctl;
  JointStates x;
  Eigen::VectorXd tau;
  Status status = Status::ok;
  int k = 0;
};

// measured = state k+1, desired = state k (as the ct cases)
template <class S>
Tick tick_of(std::shared_ptr<S> s) {
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    const int m = (k + 1) & (JointStates::count - 1);
    s->status = s->ctl.step(s->x.q[m], s->x.qd[m], s->x.q[k], s->x.qd[k], s->x.qdd[k], s->tau);
    benchmark::DoNotOptimize(s->tau.data());
    benchmark::DoNotOptimize(s->status);
    benchmark::ClobberMemory();
  };
}

// Balanced 3R: both controllers' torques must agree at every bench state (eq 16: M' = diag(k),
// v' = g' = 0), else the bench aborts.
void check_3r_agree() {
  auto ct = std::make_shared<CtDisc>(test::balanced_planar_3r());
  Decoupled dc(diagonal_of(ct->dyn.model()), 3);
  for (int k = 0; k < JointStates::count; ++k) {
    const int m = (k + 1) % JointStates::count;
    const Status a = ct->ctl.step(ct->x.q[m], ct->x.qd[m], ct->x.q[k], ct->x.qd[k], ct->x.qdd[k], ct->tau);
    const Status b = dc.ctl.step(dc.x.q[m], dc.x.qd[m], dc.x.q[k], dc.x.qd[k], dc.x.qdd[k], dc.tau);
    const double rel = (ct->tau - dc.tau).norm() / std::max(1.0, ct->tau.norm());
    if (a != Status::ok || b != Status::ok || !(rel < 1e-9))
      fail("balanced 3R: DecoupledJointController != ComputedTorque over the general model", rel);
  }
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(ct3_disc_arm) {
  check_3r_agree();
  return tick_of(std::make_shared<CtDisc>(mechbal::test::balanced_planar_3r()));
}
MECHBAL_BENCH_CASE(decoupled_step3) {
  check_3r_agree();
  return tick_of(std::make_shared<Decoupled>(diagonal_of(mechbal::test::balanced_planar_3r()), 3));
}
MECHBAL_BENCH_CASE(ct6_disc_arm) { return tick_of(std::make_shared<CtDisc>(disc_arm_6())); }
MECHBAL_BENCH_CASE(decoupled_step6) {
  Eigen::VectorXd k = diagonal_of(disc_arm_6());  // the diagonal of the unbalanced arm: a cost stand-in
  return tick_of(std::make_shared<Decoupled>(k, 6));
}
