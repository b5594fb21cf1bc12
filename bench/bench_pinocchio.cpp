// Pinocchio (C++, header-only build against the `pin` wheel's headers) on the same chains:
// rnea for inverse dynamics and the computed-torque tick, crba for the mass matrix.
// Compiled only when the headers were found at configure time (bench/CMakeLists.txt).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include "bench_registry.hpp"
#include "mechbal/control/rnea.hpp"

namespace mechbal::bench {
namespace {

/// The ChainModel as a Pinocchio model: unaligned revolute/prismatic joints, placement = joint
/// origin (base folded into the first), one body per joint with Inertia(mass, com, I_com).
pinocchio::Model to_pinocchio(const ChainModel& chain) {
  pinocchio::Model model;
  pinocchio::JointIndex parent = 0;
  for (int i = 0; i < chain.dof(); ++i) {
    const JointSpec& j = chain.joints()[static_cast<std::size_t>(i)];
    const Eigen::Isometry3d origin = i == 0 ? chain.base() * j.origin : j.origin;
    const pinocchio::SE3 placement(origin.linear(), origin.translation());
    pinocchio::JointIndex id;
    if (j.type == JointType::revolute) {
      id = model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(j.axis), placement, j.name);
    } else {
      id = model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(j.axis), placement, j.name);
    }
    model.appendBodyToJoint(id, pinocchio::Inertia(j.link.mass, j.com, j.link.inertia_body),
                            pinocchio::SE3::Identity());
    parent = id;
  }
  model.gravity.linear(chain.gravity());
  return model;
}

/// The same chain given to Pinocchio in joint-aligned frames (the trick RneChainDynamics uses
/// internally): link i is expressed in L_i = F_i A_i with A_i e_z = axis_i, so every joint is a
/// JointModelRZ / JointModelPZ. Pinocchio's best case for this chain.
Mat3 aligned_with_z(const Vec3& axis) {
  const Vec3 seed = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 x = (seed - seed.dot(axis) * axis).normalized();
  Mat3 A;
  A << x, axis.cross(x), axis;
  return A;
}

pinocchio::Model to_pinocchio_aligned(const ChainModel& chain) {
  pinocchio::Model model;
  pinocchio::JointIndex parent = 0;
  Mat3 A_parent = Mat3::Identity();
  for (int i = 0; i < chain.dof(); ++i) {
    const JointSpec& j = chain.joints()[static_cast<std::size_t>(i)];
    const Eigen::Isometry3d origin = i == 0 ? chain.base() * j.origin : j.origin;
    const Mat3 A = aligned_with_z(j.axis);
    const pinocchio::SE3 placement(A_parent.transpose() * origin.linear() * A,
                                   A_parent.transpose() * origin.translation());
    pinocchio::JointIndex id;
    if (j.type == JointType::revolute) {
      id = model.addJoint(parent, pinocchio::JointModelRZ(), placement, j.name);
    } else {
      id = model.addJoint(parent, pinocchio::JointModelPZ(), placement, j.name);
    }
    model.appendBodyToJoint(id,
                            pinocchio::Inertia(j.link.mass, A.transpose() * j.com,
                                               A.transpose() * j.link.inertia_body * A),
                            pinocchio::SE3::Identity());
    parent = id;
    A_parent = A;
  }
  model.gravity.linear(chain.gravity());
  return model;
}

struct Pin {
  explicit Pin(int dof, bool aligned = false)
      : chain(bench_chain(dof)),
        model(aligned ? to_pinocchio_aligned(chain) : to_pinocchio(chain)),
        data(model),
        x(bench_states(dof)),
        v(dof) {
    RneChainDynamics ref(chain);
    Eigen::VectorXd t(dof);
    ref.inverse_dynamics(x.q[0], x.qd[0], x.qdd[0], t);
    pinocchio::rnea(model, data, x.q[0], x.qd[0], x.qdd[0]);
    const double rel = (data.tau - t).norm() / std::max(1.0, t.norm());
    if (!(rel < 1e-9)) {
      std::fprintf(stderr, "mechbal-bench: Pinocchio rnea disagrees with mechbal (relative %g)\n",
                   rel);
      std::abort();
    }
  }
  ChainModel chain;
  pinocchio::Model model;
  pinocchio::Data data;
  JointStates x;
  Eigen::VectorXd v;
  int k = 0;
};

Tick id_case(int dof, bool aligned = false) {
  auto s = std::make_shared<Pin>(dof, aligned);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    pinocchio::rnea(s->model, s->data, s->x.q[k], s->x.qd[k], s->x.qdd[k]);
    benchmark::DoNotOptimize(s->data.tau.data());
    benchmark::ClobberMemory();
  };
}

Tick ct_case(int dof, bool aligned = false) {
  auto s = std::make_shared<Pin>(dof, aligned);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    const int m = (k + 1) & (JointStates::count - 1);
    s->v = s->x.qdd[k] + ct_kp * (s->x.q[k] - s->x.q[m]) + ct_kd * (s->x.qd[k] - s->x.qd[m]);
    pinocchio::rnea(s->model, s->data, s->x.q[m], s->x.qd[m], s->v);
    benchmark::DoNotOptimize(s->data.tau.data());
    benchmark::ClobberMemory();
  };
}

// crba fills the upper triangle; the lower one is copied so that the output equals mechbal's.
Tick mass_case(int dof, bool aligned = false) {
  auto s = std::make_shared<Pin>(dof, aligned);
  return [s] {
    const int k = s->k = (s->k + 1) & (JointStates::count - 1);
    pinocchio::crba(s->model, s->data, s->x.q[k]);
    s->data.M.triangularView<Eigen::StrictlyLower>() =
        s->data.M.transpose().triangularView<Eigen::StrictlyLower>();
    benchmark::DoNotOptimize(s->data.M.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(id6_pinocchio) { return id_case(6); }
MECHBAL_BENCH_CASE(id7_pinocchio) { return id_case(7); }
MECHBAL_BENCH_CASE(ct6_pinocchio) { return ct_case(6); }
MECHBAL_BENCH_CASE(ct7_pinocchio) { return ct_case(7); }
MECHBAL_BENCH_CASE(mass6_pinocchio) { return mass_case(6); }
MECHBAL_BENCH_CASE(mass7_pinocchio) { return mass_case(7); }
MECHBAL_BENCH_CASE(id6_pinocchio_aligned) { return id_case(6, true); }
MECHBAL_BENCH_CASE(ct6_pinocchio_aligned) { return ct_case(6, true); }
MECHBAL_BENCH_CASE(mass6_pinocchio_aligned) { return mass_case(6, true); }
