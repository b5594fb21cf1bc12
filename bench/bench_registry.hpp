#pragma once
// mechbal-bench case registry. A benchmark case is ONE function that builds whatever it needs
// (models, solvers, preallocated buffers: not timed) and returns the tick to time:
//
//   MECHBAL_BENCH_CASE(ct6_mylib) {
//     auto s = std::make_shared<MyState>(...);          // setup, not timed
//     return [s] { s->solver.step(...); benchmark::DoNotOptimize(s->out); };
//   }
//
// mechbal-bench then times the tick with Google Benchmark (median over repetitions), times every
// call of a separate run to get per-call percentiles (p50/p99/p99.9), and counts heap
// allocations per tick (global operator new is replaced in this executable).
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mechbal/model/serial_chain.hpp"

namespace mechbal::bench {

using Tick = std::function<void()>;
using CaseFactory = Tick (*)();

struct CaseEntry {
  std::string name;
  CaseFactory make;
};

inline std::vector<CaseEntry>& cases() {
  static std::vector<CaseEntry> registry;
  return registry;
}

struct RegisterCase {
  RegisterCase(const char* name, CaseFactory make) { cases().push_back({name, make}); }
};

/// The chains every library is compared on: all-revolute serial chains with arbitrary joint axes
/// and origins (deterministic seeds), dof = 6 or 7 (any dof >= 1 works).
ChainModel bench_chain(int dof);

/// A fixed set of joint states (cycled through by the ticks so that no single input is cached).
struct JointStates {
  static constexpr int count = 64;
  std::vector<Eigen::VectorXd> q, qd, qdd;
};
JointStates bench_states(int dof, unsigned seed = 7);

/// Computed-torque gains. mechbal's ct cases run the ComputedTorque controller (bench_ct.hpp); the
/// KDL-raw and Pinocchio ct cases compute the same law inline with their own inverse dynamics:
/// v = qdd_ref + Kp (q_ref - q) + Kd (qd_ref - qd); tau = ID(q, qd, v).
constexpr double ct_kp = 100.0, ct_kd = 20.0;

}  // namespace mechbal::bench

#define MECHBAL_BENCH_CASE(case_name)                                                  \
  static ::mechbal::bench::Tick mechbal_bench_make_##case_name();                     \
  static const ::mechbal::bench::RegisterCase mechbal_bench_reg_##case_name(          \
      #case_name, &mechbal_bench_make_##case_name);                                   \
  static ::mechbal::bench::Tick mechbal_bench_make_##case_name()
