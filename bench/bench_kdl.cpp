// Orocos KDL on the same chains: mechbal's KdlChainDynamics wrapper (RNE with six virtual base
// joints for the support wrench; its ct cases run mechbal's ComputedTorque controller over it) and
// raw KDL (ChainIdSolver_RNE, ChainDynParam on the plain chain; its ct cases compute the same
// computed-torque law inline).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>

#include "bench_ct.hpp"
#include "bench_registry.hpp"
#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/control/rnea.hpp"

namespace mechbal::bench {
namespace {

KDL::Frame to_kdl(const Eigen::Isometry3d& T) {
  const Mat3 R = T.linear();
  const Vec3 p = T.translation();
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                  R(2, 1), R(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

// The plain KDL chain of a ChainModel (same construction as kdl_chain.cpp without the virtual
// base joints): segment i's tip is the next joint's origin, inertia re-expressed there.
KDL::Chain plain_chain(const ChainModel& model) {
  KDL::Chain chain;
  const std::size_t n = model.joints().size();
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::Fixed),
                                to_kdl(model.base() * model.joints()[0].origin)));
  for (std::size_t i = 0; i < n; ++i) {
    const JointSpec& j = model.joints()[i];
    const Eigen::Isometry3d next =
        i + 1 < n ? model.joints()[i + 1].origin : Eigen::Isometry3d::Identity();
    const Mat3& I = j.link.inertia_body;
    const KDL::RigidBodyInertia in_F(
        j.link.mass, KDL::Vector(j.com.x(), j.com.y(), j.com.z()),
        KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
    const KDL::Joint joint(j.name, KDL::Vector::Zero(), KDL::Vector(j.axis.x(), j.axis.y(), j.axis.z()),
                           j.type == JointType::revolute ? KDL::Joint::RotAxis
                                                         : KDL::Joint::TransAxis);
    chain.addSegment(KDL::Segment(j.name, joint, to_kdl(next), to_kdl(next.inverse()) * in_F));
  }
  return chain;
}

KDL::JntArray to_jnt(const Eigen::VectorXd& v) {
  KDL::JntArray a(static_cast<unsigned>(v.size()));
  a.data = v;
  return a;
}

void check_close(const char* what, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double rel = (a - b).norm() / std::max(1.0, b.norm());
  if (!(rel < 1e-9)) {
    std::fprintf(stderr, "mechbal-bench: %s disagrees with mechbal (relative %g)\n", what, rel);
    std::abort();
  }
}

struct Raw {
  explicit Raw(int dof)
      : model(bench_chain(dof)),
        chain(plain_chain(model)),
        grav(model.gravity().x(), model.gravity().y(), model.gravity().z()),
        rne(chain, grav),
        dyn(chain, grav),
        f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero()),
        v(static_cast<unsigned>(dof)),
        tau(static_cast<unsigned>(dof)),
        M(static_cast<unsigned>(dof)) {
    const JointStates x = bench_states(dof);
    for (int k = 0; k < JointStates::count; ++k) {
      q.push_back(to_jnt(x.q[k]));
      qd.push_back(to_jnt(x.qd[k]));
      qdd.push_back(to_jnt(x.qdd[k]));
    }
    // the chain must be the same chain: compare with mechbal once
    RneChainDynamics ref(model);
    Eigen::VectorXd t(dof);
    ref.inverse_dynamics(x.q[0], x.qd[0], x.qdd[0], t);
    rne.CartToJnt(q[0], qd[0], qdd[0], f_ext, tau);
    check_close("raw KDL ChainIdSolver_RNE", tau.data, t);
  }
  ChainModel model;
  KDL::Chain chain;
  KDL::Vector grav;
  KDL::ChainIdSolver_RNE rne;
  KDL::ChainDynParam dyn;
  KDL::Wrenches f_ext;
  std::vector<KDL::JntArray> q, qd, qdd;
  KDL::JntArray v, tau;
  KDL::JntSpaceInertiaMatrix M;
  int k = 0;
};

Tick raw_id_case(int dof) {
  auto s = std::make_shared<Raw>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    s->rne.CartToJnt(s->q[k], s->qd[k], s->qdd[k], s->f_ext, s->tau);
    benchmark::DoNotOptimize(s->tau.data.data());
    benchmark::ClobberMemory();
  };
}

Tick raw_ct_case(int dof) {
  auto s = std::make_shared<Raw>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    const int m = (k + 1) & (JointStates::count - 1);
    s->v.data = s->qdd[k].data + ct_kp * (s->q[k].data - s->q[m].data) +
                ct_kd * (s->qd[k].data - s->qd[m].data);
    s->rne.CartToJnt(s->q[m], s->qd[m], s->v, s->f_ext, s->tau);
    benchmark::DoNotOptimize(s->tau.data.data());
    benchmark::ClobberMemory();
  };
}

Tick raw_mass_case(int dof) {
  auto s = std::make_shared<Raw>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    s->dyn.JntToMass(s->q[k], s->M);
    benchmark::DoNotOptimize(s->M.data.data());
    benchmark::ClobberMemory();
  };
}

struct Wrapper {
  explicit Wrapper(int dof)
      : model(bench_chain(dof)), kdl(model), x(bench_states(dof)), v(dof), tau(dof) {}
  ChainModel model;
  KdlChainDynamics kdl;
  JointStates x;
  Eigen::VectorXd v, tau;
  int k = 0;
};

Tick wrapper_id_case(int dof) {
  auto s = std::make_shared<Wrapper>(dof);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    s->kdl.inverse_dynamics(s->x.q[k], s->x.qd[k], s->x.qdd[k], s->tau);
    benchmark::DoNotOptimize(s->tau.data());
    benchmark::ClobberMemory();
  };
}

// mechbal's ComputedTorque controller over the KdlChainDynamics back end (checked against the
// inline law through mechbal's RNE).
Tick wrapper_ct_case(int dof) {
  const ChainModel model = bench_chain(dof);
  auto s = std::make_shared<Ct<KdlChainDynamics>>(dof, model);
  RneChainDynamics reference(model);
  check_ct("ComputedTorque<KdlChainDynamics>", *s, reference);
  return ct_tick(s);
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(id6_kdl_raw) { return raw_id_case(6); }
MECHBAL_BENCH_CASE(id7_kdl_raw) { return raw_id_case(7); }
MECHBAL_BENCH_CASE(ct6_kdl_raw) { return raw_ct_case(6); }
MECHBAL_BENCH_CASE(ct7_kdl_raw) { return raw_ct_case(7); }
MECHBAL_BENCH_CASE(mass6_kdl_raw) { return raw_mass_case(6); }
MECHBAL_BENCH_CASE(mass7_kdl_raw) { return raw_mass_case(7); }
MECHBAL_BENCH_CASE(id6_kdl_wrapper) { return wrapper_id_case(6); }
MECHBAL_BENCH_CASE(id7_kdl_wrapper) { return wrapper_id_case(7); }
MECHBAL_BENCH_CASE(ct6_kdl_wrapper) { return wrapper_ct_case(6); }
MECHBAL_BENCH_CASE(ct7_kdl_wrapper) { return wrapper_ct_case(7); }
