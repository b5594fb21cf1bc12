// Pinocchio C++ (header-only, the `pin` wheel's headers) on the robots of bench_urdf.cpp: rnea,
// crba and computeCentroidalMomentumTimeVariation on UR5 and Panda.
//
// Pinocchio's own URDF parser is not used here: it is built on the wheel's urdfdom (cmeel prefix,
// other headers and ABI than Debian's urdfdom that mechbal links), and the two cannot live in one
// executable. The Pinocchio model is built in C++ from mechbal's parsed description the way
// Pinocchio's parser builds it: a joint per revolute/prismatic URDF joint, JointModelRX/RY/RZ
// (PX/PY/PZ) when the axis is a unit axis and the unaligned joint otherwise, placement = the URDF
// origin composed with the fixed joints above it, fixed-joint links' inertias appended to the
// nearest moving ancestor, mimic joints as independent joints (the parser's default, mimic =
// false: Panda has 9 joints there, 8 coordinates in mechbal). Setup checks that torques, mass
// matrix and momentum rate equal mechbal's to 1e-9 at every bench state (aborts otherwise);
// tests/python/test_urdf.py checks mechbal against pin.buildModelFromUrdf on the same files.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <map>
#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include "bench_reactionless_panda.hpp"
#include "bench_support.hpp"
#include "bench_urdf.hpp"
#include "bench_urdf_pinocchio.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/model/data.hpp"

namespace mechbal::bench {
namespace {

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

struct Pin : UrdfRobot {
  explicit Pin(const std::string& robot) : UrdfRobot(robot), pin(to_pinocchio(model)), data(pin.model) {
    for (int k = 0; k < JointStates::count; ++k) {
      const auto sk = static_cast<std::size_t>(k);
      q.push_back(pin.G * x.q[sk] + pin.offset);
      v.push_back(pin.G * x.qd[sk]);
      a.push_back(pin.G * x.qdd[sk]);
    }
    // the same numbers as mechbal's, at every bench state
    MechanismData md(model);
    double worst = 0.0;
    for (int k = 0; k < JointStates::count; ++k) {
      const auto sk = static_cast<std::size_t>(k);
      inverse_dynamics(model, md, x.q[sk], x.qd[sk], x.qdd[sk]);
      pinocchio::rnea(pin.model, data, q[sk], v[sk], a[sk]);
      worst = std::max(worst, rel(md.joint_torque, pin.G.transpose() * data.tau));
      mass_matrix(model, md, x.q[sk]);
      pinocchio::crba(pin.model, data, q[sk]);
      data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose().triangularView<Eigen::StrictlyLower>();
      worst = std::max(worst, rel(md.mass_matrix, pin.G.transpose() * data.M * pin.G));
      shaking_wrench(model, md, x.q[sk], x.qd[sk], x.qdd[sk]);
      pinocchio::computeCentroidalMomentumTimeVariation(pin.model, data, q[sk], v[sk], a[sk]);
      const Vec3 c = data.com[0], dP = data.dhg.linear();
      const Vec3 dH_O = data.dhg.angular() + c.cross(dP);
      worst = std::max(worst, rel(md.shaking.force, dP));
      worst = std::max(worst, rel(md.shaking.moment, dH_O));
      gravity_torque(model, md, x.q[sk]);
      pinocchio::computeGeneralizedGravity(pin.model, data, q[sk]);
      worst = std::max(worst, rel(md.gravity_torque, pin.G.transpose() * data.g));
    }
    if (!(worst < 1e-9)) {
      std::fprintf(stderr, "mechbal-bench: Pinocchio disagrees with mechbal on %s (relative %g)\n",
                   robot.c_str(), worst);
      std::abort();
    }
  }
  PinModel pin;
  pinocchio::Data data;
  std::vector<Eigen::VectorXd> q, v, a;
  int k = 0;
  std::size_t next() { return static_cast<std::size_t>(k = (k + 1) & (JointStates::count - 1)); }
};

Tick id_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::rnea(s->pin.model, s->data, s->q[k], s->v[k], s->a[k]);
    benchmark::DoNotOptimize(s->data.tau.data());
    benchmark::ClobberMemory();
  };
}

// crba fills the upper triangle; the lower one is copied so that the output equals mechbal's.
Tick mass_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::crba(s->pin.model, s->data, s->q[k]);
    s->data.M.triangularView<Eigen::StrictlyLower>() =
        s->data.M.transpose().triangularView<Eigen::StrictlyLower>();
    benchmark::DoNotOptimize(s->data.M.data());
    benchmark::ClobberMemory();
  };
}

Tick gravity_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::computeGeneralizedGravity(s->pin.model, s->data, s->q[k]);
    benchmark::DoNotOptimize(s->data.g.data());
    benchmark::ClobberMemory();
  };
}

Tick momentum_rate_case(const char* robot) {
  auto s = std::make_shared<Pin>(robot);
  return [s] {
    const auto k = s->next();
    pinocchio::computeCentroidalMomentumTimeVariation(s->pin.model, s->data, s->q[k], s->v[k], s->a[k]);
    benchmark::DoNotOptimize(s->data.dhg);
    benchmark::ClobberMemory();
  };
}

}  // namespace

// ---------------------------------------------------------------------------- reactionless Panda
// ReactionlessTaskController's tick (control/reactionless.cpp) written over Pinocchio, on the
// Panda case of bench_reactionless_panda.cpp (reactionless_panda_{euler,rk4}_pinocchio; the
// file comment there says what is compared).
namespace panda_reactionless {
namespace {

/// ReactionlessTaskController's tick (control/reactionless.cpp) over Pinocchio's kinematics: the
/// rates (J^+, N, S A N, their factorisations) and the acceleration feed-forward (J'v and
/// W(q, v, 0) = (dA/dt) v from one computeCentroidalMomentumTimeVariation at a = 0, then the
/// same two solves with the rates' factorisations), Euler or RK4 (three more rate evaluations).
struct PinocchioTaskController {
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  static constexpr double huge = std::numeric_limits<double>::max();

  /// mechbal's MinNorm with the path this case takes (every row independent: Cholesky of M M^T,
  /// damped when cond(M) > max_condition)
  struct MinNorm {
    bool zero = true;
    Small gram, inverse;
    SmallVector y, rhs;
    Eigen::SelfAdjointEigenSolver<Small> eig;
    Eigen::LLT<Small> llt;
  };

  PinocchioTaskController(const MechanismModel& m, const TaskSpaceConfig& c, const Eigen::VectorXd& q0)
      : pin(to_pinocchio(m)), data(pin.model), config(c) {
    n = m.dof();
    dt = 1.0 / c.rate_hz;
    rk4 = c.integrator == ReactionlessIntegrator::rk4;
    frame = pin.model.getFrameId(c.frame);
    for (int r = 0; r < 6; ++r) {
      if (c.task_rows & (1u << r)) task_rows.push_back(r);
      if (c.cancel & (1u << r)) rows.push_back(r);
    }
    const auto nt = static_cast<Eigen::Index>(task_rows.size()), nk = static_cast<Eigen::Index>(rows.size());
    if (nt > n || nk > n - nt) fail("reactionless Panda over Pinocchio: rows beyond the ranks (not this case)", 0);
    for (Eigen::VectorXd* v : {&q, &q_cmd, &v_cmd, &a_cmd, &a0, &k1, &k2, &k3, &k4, &q_stage, &v0, &z, &w})
      *v = Eigen::VectorXd::Zero(n);
    q_pin = Eigen::VectorXd::Zero(pin.model.nq);
    v_pin = Eigen::VectorXd::Zero(pin.model.nv);
    zero_pin = Eigen::VectorXd::Zero(pin.model.nv);
    J6 = pinocchio::Data::Matrix6x::Zero(6, pin.model.nv);
    JG = Eigen::MatrixXd::Zero(6, n);
    AO = Eigen::MatrixXd::Zero(6, n);
    A6 = Eigen::MatrixXd::Zero(6, pin.model.nv);
    J = Eigen::MatrixXd::Zero(nt, n);
    Jt = Eigen::MatrixXd::Zero(n, 6);
    JpJ = Eigen::MatrixXd::Zero(n, n);
    N = Eigen::MatrixXd::Zero(n, n);
    M = Eigen::MatrixXd::Zero(nk, n);
    rt = Eigen::VectorXd::Zero(nt);
    rm = Eigen::VectorXd::Zero(nk);
    for (MinNorm* f : {&task, &null}) {
      f->gram = Small::Identity(6, 6);
      f->inverse = Small::Identity(6, 6);
      f->eig.compute(f->gram, Eigen::EigenvaluesOnly);
      f->llt.compute(f->gram);
      f->y = f->rhs = SmallVector::Zero(6);
    }
    rate_limit = m.velocity_limits().cwiseMin(c.max_rate);
    q = q0;
    q_cmd = q0;
    target.setZero();  // at rest
  }

  Status factorise(MinNorm& f, const Eigen::MatrixXd& Mat) const {
    const Eigen::Index rows_n = Mat.rows();
    f.gram.resize(rows_n, rows_n);
    f.gram.noalias() = Mat * Mat.transpose();
    f.zero = true;
    if (!f.gram.allFinite()) return Status::out_of_range;
    f.eig.compute(f.gram, Eigen::EigenvaluesOnly);
    const double lmax = f.eig.eigenvalues()(rows_n - 1), lmin = f.eig.eigenvalues()(0);
    if (!(lmax > 0.0)) return Status::singular;
    Status st = Status::ok;
    const double cond = lmin > 0.0 ? std::sqrt(lmax / lmin) : huge;
    if (cond > config.max_condition) {
      f.gram.diagonal().array() += config.damping * config.damping * lmax;
      st = Status::singular;
    }
    f.llt.compute(f.gram);
    f.zero = false;
    return st;
  }

  static void solve(MinNorm& f, const Eigen::MatrixXd& Mat, const Eigen::Ref<const Eigen::VectorXd>& r,
                    Eigen::VectorXd& x) {
    if (f.zero) {
      x.setZero();
      return;
    }
    const Eigen::Index rows_n = Mat.rows();
    f.rhs.resize(rows_n);
    for (Eigen::Index i = 0; i < rows_n; ++i) f.rhs(i) = r(i);
    f.y = f.llt.solve(f.rhs);
    x.noalias() = Mat.transpose() * f.y;
  }

  static void gram_inverse(MinNorm& f) {
    const Eigen::Index rows_n = f.gram.rows();
    f.inverse.resize(rows_n, rows_n);
    if (f.zero) {
      f.inverse.setZero();
    } else {
      f.inverse.setIdentity();
      f.llt.solveInPlace(f.inverse);
    }
  }

  Status rates(const Eigen::VectorXd& qc, const Vec6& twist, Eigen::VectorXd& v) {
    q_pin.noalias() = pin.G * qc;
    q_pin += pin.offset;
    pinocchio::computeFrameJacobian(pin.model, data, q_pin, frame, pinocchio::LOCAL_WORLD_ALIGNED, J6);
    JG.noalias() = J6 * pin.G;
    pinocchio::computeCentroidalMap(pin.model, data, q_pin);
    A6 = data.Ag;  // about the centre of mass; about O: H_O = H_G + c x P
    const Vec3 c = data.com[0];
    for (Eigen::Index j = 0; j < A6.cols(); ++j) A6.col(j).tail<3>() += c.cross(Vec3(A6.col(j).head<3>()));
    AO.noalias() = A6 * pin.G;
    for (std::size_t i = 0; i < task_rows.size(); ++i) {
      J.row(static_cast<Eigen::Index>(i)) = JG.row(task_rows[i]);
      rt(static_cast<Eigen::Index>(i)) = twist(task_rows[i]);
    }
    Status st = factorise(task, J);
    solve(task, J, rt, v0);
    const Eigen::Index nt = J.rows();
    gram_inverse(task);
    Jt.leftCols(nt).noalias() = J.transpose() * task.inverse;
    JpJ.noalias() = Jt.leftCols(nt) * J;
    N = -JpJ;
    N.diagonal().array() += 1.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      M.row(r).noalias() = AO.row(rows[i]) * N;
      rm(r) = target(rows[i]) - AO.row(rows[i]).dot(v0);
    }
    st |= factorise(null, M);
    solve(null, M, rm, z);
    v = v0;
    v.noalias() += N * z;
    double peak = 0.0;
    for (int j = 0; j < n; ++j) peak = std::max(peak, std::abs(v(j)) / rate_limit(j));
    if (peak > 1.0) {
      v *= 1.0 / peak;
      st |= Status::saturated;
    }
    return st;
  }

  /// the feed-forward at q (right after rates(q, ...)): J'v and W(q, v, 0) from one forward pass
  /// with the rates at a = 0 (computeCentroidalMomentumTimeVariation runs forwardKinematics(q, v,
  /// 0), which getFrameClassicalAcceleration reads), then a = J^+ (x'' - J'v) + N w
  void acceleration(const Eigen::VectorXd& v, const Vec6& twist_rate, bool saturated) {
    v_pin.noalias() = pin.G * v;
    pinocchio::computeCentroidalMomentumTimeVariation(pin.model, data, q_pin, v_pin, zero_pin);
    const pinocchio::Motion acc =
        pinocchio::getFrameClassicalAcceleration(pin.model, data, frame, pinocchio::LOCAL_WORLD_ALIGNED);
    Vec6 bias;
    bias << acc.linear(), acc.angular();
    Vec6 W;  // dh_G/dt moved to O: dH_O/dt = dH_G/dt + c x dP/dt
    W.head<3>() = data.dhg.linear();
    W.tail<3>() = data.dhg.angular() + data.com[0].cross(data.dhg.linear());
    const Eigen::Index nt = J.rows();
    for (Eigen::Index i = 0; i < nt; ++i) {
      const int row = task_rows[static_cast<std::size_t>(i)];
      rt(i) = twist_rate(row) - bias(row);
    }
    a0.noalias() = Jt.leftCols(nt) * rt;
    a_cmd = a0;
    if (saturated) {
      a_cmd.setZero();
    } else {
      for (std::size_t i = 0; i < rows.size(); ++i)
        rm(static_cast<Eigen::Index>(i)) = -W(rows[i]) - AO.row(rows[i]).dot(a0);
      solve(null, M, rm, z);
      a_cmd.noalias() += N * z;
    }
    Vec6 predicted;
    predicted.noalias() = AO * a_cmd;
    predicted += W;
    force = predicted.head<3>();
    moment = predicted.tail<3>();
  }

  Status step(const Vec6& twist, const Vec6& twist_half, const Vec6& twist_next) {
    const Vec6 twist_rate = (-3.0 * twist + 4.0 * twist_half - twist_next) / dt;  // as mechbal's step
    Status st = rates(q, twist, k1);
    h.noalias() = AO * k1;
    twist_cmd.noalias() = JG * k1;
    acceleration(k1, twist_rate, has(st, Status::saturated));
    if (rk4) {
      w = q + (0.5 * dt) * k1;
      st |= rates(w, twist_half, k2);
      w = q + (0.5 * dt) * k2;
      st |= rates(w, twist_half, k3);
      w = q + dt * k3;
      st |= rates(w, twist_next, k4);
      q_stage = q + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    } else {
      q_stage = q + dt * k1;
    }
    q_cmd = q;
    v_cmd = k1;
    q = q_stage;
    return st;
  }

  PinModel pin;
  pinocchio::Data data;
  TaskSpaceConfig config;
  int n = 0;
  double dt = 1e-3;
  bool rk4 = false;
  pinocchio::FrameIndex frame = 0;
  std::vector<int> task_rows, rows;
  Eigen::VectorXd q, q_cmd, v_cmd, a_cmd, a0, k1, k2, k3, k4, q_stage, v0, z, w, rate_limit, q_pin, v_pin, zero_pin;
  pinocchio::Data::Matrix6x J6;
  Eigen::MatrixXd JG, AO, A6, J, Jt, JpJ, N, M;
  Eigen::VectorXd rt, rm;
  MinNorm task, null;
  Vec6 target, h = Vec6::Zero(), twist_cmd = Vec6::Zero();
  Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
};

struct PinCase {
  std::unique_ptr<PinocchioTaskController> ctrl;
  TwistSamples x;
  int k = 0;
  Status status = Status::ok;
};

Tick panda_reactionless_case(ReactionlessIntegrator integrator) {
  auto s = std::make_shared<PinCase>();
  UrdfRobot panda("panda");
  s->ctrl = std::make_unique<PinocchioTaskController>(panda.model, config(integrator), home(panda.model.dof()));
  auto ref = mechbal_controller(integrator);
  for (int n = 0; n < 300; ++n) {
    const auto k = static_cast<std::size_t>(n);
    ref->step(s->x.now[k], s->x.half[k], s->x.next[k]);
    s->ctrl->step(s->x.now[k], s->x.half[k], s->x.next[k]);
    const double err = std::max({(ref->v() - s->ctrl->v_cmd).cwiseAbs().maxCoeff(),
                                 (ref->next() - s->ctrl->q).cwiseAbs().maxCoeff(),
                                 (ref->momentum() - s->ctrl->h).cwiseAbs().maxCoeff(),
                                 (ref->a() - s->ctrl->a_cmd).cwiseAbs().maxCoeff() / std::max(1.0, ref->a().cwiseAbs().maxCoeff()),
                                 (ref->shaking_force() - s->ctrl->force).cwiseAbs().maxCoeff(),
                                 (ref->shaking_moment() - s->ctrl->moment).cwiseAbs().maxCoeff()});
    if (!(err < 1e-9)) fail("reactionless Panda over Pinocchio != mechbal's controller", err);
  }
  s->k = 300;
  return [s] {
    const auto k = static_cast<std::size_t>(s->k);
    s->k = s->k + 1 == kTicks ? 0 : s->k + 1;
    s->status = s->ctrl->step(s->x.now[k], s->x.half[k], s->x.next[k]);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(s->ctrl->v_cmd.data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace panda_reactionless
}  // namespace mechbal::bench

using namespace mechbal::bench;
MECHBAL_BENCH_CASE(id_ur5_pinocchio) { return id_case("ur5"); }
MECHBAL_BENCH_CASE(mass_ur5_pinocchio) { return mass_case("ur5"); }
MECHBAL_BENCH_CASE(momentum_rate_ur5_pinocchio) { return momentum_rate_case("ur5"); }
MECHBAL_BENCH_CASE(id_panda_pinocchio) { return id_case("panda"); }
MECHBAL_BENCH_CASE(mass_panda_pinocchio) { return mass_case("panda"); }
MECHBAL_BENCH_CASE(momentum_rate_panda_pinocchio) { return momentum_rate_case("panda"); }
MECHBAL_BENCH_CASE(gravity_ur5_pinocchio) { return gravity_case("ur5"); }
MECHBAL_BENCH_CASE(gravity_panda_pinocchio) { return gravity_case("panda"); }
MECHBAL_BENCH_CASE(id_talos_pinocchio) { return id_case("talos"); }
MECHBAL_BENCH_CASE(mass_talos_pinocchio) { return mass_case("talos"); }
MECHBAL_BENCH_CASE(gravity_talos_pinocchio) { return gravity_case("talos"); }
MECHBAL_BENCH_CASE(momentum_rate_talos_pinocchio) { return momentum_rate_case("talos"); }
MECHBAL_BENCH_CASE(id_romeo_pinocchio) { return id_case("romeo"); }
MECHBAL_BENCH_CASE(mass_romeo_pinocchio) { return mass_case("romeo"); }
MECHBAL_BENCH_CASE(gravity_romeo_pinocchio) { return gravity_case("romeo"); }
MECHBAL_BENCH_CASE(momentum_rate_romeo_pinocchio) { return momentum_rate_case("romeo"); }
MECHBAL_BENCH_CASE(reactionless_panda_euler_pinocchio) {
  return panda_reactionless::panda_reactionless_case(mechbal::ReactionlessIntegrator::euler);
}
MECHBAL_BENCH_CASE(reactionless_panda_rk4_pinocchio) {
  return panda_reactionless::panda_reactionless_case(mechbal::ReactionlessIntegrator::rk4);
}
