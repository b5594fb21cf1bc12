// Decoupled joint control of a dynamically balanced arm (DecoupledJointController, Coutinho & Hess
// Coelho eqs 15, 26, 36) side by side with ComputedTorque over the arm's full coupled model
// (DiscArmDynamics: links + counter-rotating discs, coupling-matrix form): what the balancing buys
// per control tick (issue 6).
//
//  - decoupled_step3 / ct3_disc_arm: the balanced planar 3R with four discs of the discs-3r case
//    (the construction of tests/cpp/test_discs.cpp, eqs 8 and 14). Its mass matrix is constant and
//    diagonal, diag(k) (eq 16), so both controllers command the same torques: checked at setup.
//  - decoupled_step6 / ct6_disc_arm: six joints, ComputedTorque over a 6-joint DiscArmDynamics (the
//    bench's random 6-joint chain with one disc per link). mechbal has no balancing design for a
//    general 6-joint arm, so this one is NOT balanced and the two torques differ: it times what
//    each controller costs per tick at six joints (neither cost depends on the parameter values).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bench_registry.hpp"
#include "mechbal/computed_torque.hpp"
#include "mechbal/decoupled_control.hpp"
#include "mechbal/disc_arm.hpp"

namespace mechbal::bench {
namespace {

[[noreturn]] void fail(const char* what, double value) {
  std::fprintf(stderr, "mechbal-bench: %s (%g)\n", what, value);
  std::abort();
}

// Planar 3R of the discs-3r case (vertical y-z plane, joint axes x, link frames y along the link).
struct Planar3R {
  double l1 = 0.4, l2 = 0.3, m1 = 6.0, m2 = 3.0, m3 = 1.0;
  double J1 = 0.25, J2 = 0.06, J3 = 0.005, J4 = 0.002, J5 = 0.024, J6 = 0.001, J7 = 0.004;
};

JointSpec planar_link(const char* name, double offset, double m, double lg, double Jx) {
  JointSpec j;
  j.name = name;
  j.origin = Eigen::Isometry3d(Eigen::Translation3d(0.0, offset, 0.0));
  j.axis = Vec3::UnitX();
  j.link.mass = m;
  j.link.inertia_body = Vec3(Jx, 0.6 * Jx, 0.6 * Jx).asDiagonal();
  j.com = Vec3(0.0, lg, 0.0);
  return j;
}

DiscSpec disc(int carrier, int joint, double ratio, double J) {
  DiscSpec d;
  d.carrier = carrier;
  d.joint = joint;
  d.ratio = ratio;
  d.inertia = Vec3(J, J / 2, J / 2);
  return d;
}

// Static balancing (eq 8: link COMs) and dynamic balancing (eq 14: disc gear ratios).
DiscArmDynamics balanced_3r(const Planar3R& p) {
  const double lg1 = -p.l1 * (p.m2 + p.m3) / p.m1, lg2 = -p.l2 * p.m3 / p.m2;
  const double X = p.J2 + p.J3 + p.J4 + p.J6 + p.J7 + p.m3 * p.l2 * p.l2 +
                   p.m3 * p.m3 * p.l2 * p.l2 / p.m2;
  const double beta = -X / p.J5, gamma = -(p.J3 + p.J6) / p.J7;
  ChainModel chain({planar_link("j1", 0.0, p.m1, lg1, p.J1), planar_link("j2", p.l1, p.m2, lg2, p.J2),
                    planar_link("j3", p.l2, p.m3, 0.0, p.J3)});
  return DiscArmDynamics(chain, {disc(0, 1, 1.0, p.J4), disc(0, 1, beta, p.J5),
                                 disc(1, 2, 1.0, p.J6), disc(1, 2, gamma, p.J7)});
}

DiscArmDynamics disc_arm_6() {
  std::vector<DiscSpec> discs;
  for (int i = 0; i < 6; ++i) discs.push_back(disc(i, (i + 1) % 6, -2.0, 0.002 + 0.001 * i));
  return DiscArmDynamics(bench_chain(6), discs);
}

// The constant diagonal of the balanced mass matrix, k = diag(M'(q)), read from the model at one
// pose (the setup check then confirms, at every bench state, that both laws agree).
Eigen::VectorXd diagonal_of(DiscArmDynamics& dyn) {
  const int n = dyn.dof();
  Eigen::MatrixXd M(n, n);
  Eigen::VectorXd v(n), g(n);
  if (dyn.evaluate(Eigen::VectorXd::Constant(n, 0.3), Eigen::VectorXd::Zero(n), M, v, g) !=
      Status::ok)
    fail("DiscArmDynamics::evaluate failed at setup", 0.0);
  return M.diagonal();
}

struct CtDisc {
  CtDisc(DiscArmDynamics d)
      : dyn(std::move(d)),
        ctl(dyn, Eigen::VectorXd::Constant(dyn.dof(), ct_kp), Eigen::VectorXd::Constant(dyn.dof(), ct_kd)),
        x(bench_states(dyn.dof())), tau(dyn.dof()) {}
  DiscArmDynamics dyn;
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
  auto ct = std::make_shared<CtDisc>(balanced_3r(Planar3R{}));
  Decoupled dc(diagonal_of(ct->dyn), 3);
  for (int k = 0; k < JointStates::count; ++k) {
    const int m = (k + 1) % JointStates::count;
    const Status a = ct->ctl.step(ct->x.q[m], ct->x.qd[m], ct->x.q[k], ct->x.qd[k], ct->x.qdd[k], ct->tau);
    const Status b = dc.ctl.step(dc.x.q[m], dc.x.qd[m], dc.x.q[k], dc.x.qd[k], dc.x.qdd[k], dc.tau);
    const double rel = (ct->tau - dc.tau).norm() / std::max(1.0, ct->tau.norm());
    if (a != Status::ok || b != Status::ok || !(rel < 1e-9))
      fail("balanced 3R: DecoupledJointController != ComputedTorque over DiscArmDynamics", rel);
  }
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(ct3_disc_arm) {
  check_3r_agree();
  return tick_of(std::make_shared<CtDisc>(balanced_3r(Planar3R{})));
}
MECHBAL_BENCH_CASE(decoupled_step3) {
  check_3r_agree();
  mechbal::DiscArmDynamics dyn = balanced_3r(Planar3R{});
  return tick_of(std::make_shared<Decoupled>(diagonal_of(dyn), 3));
}
MECHBAL_BENCH_CASE(ct6_disc_arm) { return tick_of(std::make_shared<CtDisc>(disc_arm_6())); }
MECHBAL_BENCH_CASE(decoupled_step6) {
  mechbal::DiscArmDynamics dyn = disc_arm_6();
  Eigen::VectorXd k = diagonal_of(dyn);  // the diagonal of the unbalanced arm: a cost stand-in
  return tick_of(std::make_shared<Decoupled>(k, 6));
}
