// mechbal-bench: Google Benchmark runner for the registered cases (bench_registry.hpp), plus
// per-call percentiles and heap allocations per tick written to --tail_out (JSON).
//
// Usage: mechbal-bench [--tail_out=FILE] [--tail_samples=N] [--only=SUB1,SUB2] [Google Benchmark flags...]
// (--only: build and run only the cases whose name contains one of the substrings)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "alloc_counter.hpp"
#include "bench_registry.hpp"
#include "test_support.hpp"

namespace mechbal::bench {

MechanismModel bench_chain(int dof) {
  std::mt19937 rng(1000u + static_cast<unsigned>(dof));
  return MechanismModel(test::random_chain(rng, std::string(static_cast<std::size_t>(dof), 'R').c_str()));
}

JointStates bench_states(int dof, unsigned seed) {
  std::mt19937 rng(seed);
  JointStates s;
  for (int k = 0; k < JointStates::count; ++k) {
    s.q.push_back(test::random_vector(rng, dof, 2.0));
    s.qd.push_back(test::random_vector(rng, dof, 1.5));
    s.qdd.push_back(test::random_vector(rng, dof, 3.0));
  }
  return s;
}

}  // namespace mechbal::bench

namespace {

using Clock = std::chrono::steady_clock;

struct Tail {
  double p50 = 0, p99 = 0, p999 = 0, max = 0, clock_overhead = 0;
  double batch_median = 0;  // median over batches of `batch` calls of (batch time / batch)
  int batch = 1;
  double allocations_per_tick = 0;
  int samples = 0;
};

double percentile(std::vector<double>& v, double p) {
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// Cost of the timer itself, subtracted from every per-call sample.
double clock_overhead_ns() {
  std::vector<double> d(20000);
  for (auto& x : d) {
    const auto a = Clock::now();
    const auto b = Clock::now();
    x = std::chrono::duration<double, std::nano>(b - a).count();
  }
  return percentile(d, 0.5);
}

Tail measure_tail(const mechbal::bench::Tick& tick, int samples, double overhead) {
  Tail t;
  const auto warm = Clock::now();
  for (int i = 0; i < 200; ++i) tick();  // warm-up (lazy initialisation is allowed before a loop)
  // big cases (10 000-link chains: ~0.5 ms a call) get fewer samples: about 1 s of calls at most
  const double per_call = std::chrono::duration<double, std::nano>(Clock::now() - warm).count() / 200.0;
  samples = static_cast<int>(std::clamp(1e9 / std::max(per_call, 1.0), 500.0, static_cast<double>(samples)));
  {
    const int ticks = 1000;
    mechbal::test::AllocationScope scope;
    for (int i = 0; i < ticks; ++i) tick();
    t.allocations_per_tick = static_cast<double>(scope.count()) / ticks;
  }
  std::vector<double> d(static_cast<std::size_t>(samples));
  for (auto& x : d) {
    const auto a = Clock::now();
    tick();
    const auto b = Clock::now();
    x = std::max(0.0, std::chrono::duration<double, std::nano>(b - a).count() - overhead);
  }
  t.max = *std::max_element(d.begin(), d.end());
  t.p999 = percentile(d, 0.999);
  t.p99 = percentile(d, 0.99);
  t.p50 = percentile(d, 0.5);
  t.clock_overhead = overhead;
  // cross-check of the single-call median: batches of k calls (~5 us each), timer cost amortised
  t.batch = static_cast<int>(std::clamp(5000.0 / std::max(t.p50, 10.0), 1.0, 500.0));
  std::vector<double> b(static_cast<std::size_t>(std::max(50, samples / 40)));
  for (auto& x : b) {
    const auto a = Clock::now();
    for (int i = 0; i < t.batch; ++i) tick();
    const auto e = Clock::now();
    x = (std::chrono::duration<double, std::nano>(e - a).count() - overhead) / t.batch;
  }
  t.batch_median = percentile(b, 0.5);
  t.samples = samples;
  return t;
}

/// One engine against another in the same run, interleaved: rounds of (a batch of `other`, a
/// batch of `mechbal`), each batch ~5 us of calls, so that both see the same machine load.
struct Pair {
  double other_ns = 0, mechbal_ns = 0, ratio = 0, ratio_p25 = 0, ratio_p75 = 0;
  int rounds = 0;
};

double batch_ns(const mechbal::bench::Tick& tick, int calls, double overhead) {
  const auto a = Clock::now();
  for (int i = 0; i < calls; ++i) tick();
  const auto e = Clock::now();
  return (std::chrono::duration<double, std::nano>(e - a).count() - overhead) / calls;
}

Pair measure_pair(const mechbal::bench::Tick& other, const Tail& other_tail, const mechbal::bench::Tick& mechbal,
                  const Tail& mechbal_tail, double overhead) {
  Pair p;
  // ~0.4 s per pair at most, 2000 rounds at most
  const double round_ns = other_tail.batch * other_tail.batch_median + mechbal_tail.batch * mechbal_tail.batch_median;
  p.rounds = static_cast<int>(std::clamp(4e8 / std::max(round_ns, 1.0), 50.0, 2000.0));
  std::vector<double> a(static_cast<std::size_t>(p.rounds)), b(a.size()), r(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    // alternate which engine goes first, so that neither always runs on a cache the other warmed
    if (i % 2 == 0) {
      a[i] = batch_ns(other, other_tail.batch, overhead);
      b[i] = batch_ns(mechbal, mechbal_tail.batch, overhead);
    } else {
      b[i] = batch_ns(mechbal, mechbal_tail.batch, overhead);
      a[i] = batch_ns(other, other_tail.batch, overhead);
    }
    r[i] = b[i] > 0.0 ? a[i] / b[i] : 0.0;
  }
  p.other_ns = percentile(a, 0.5);
  p.mechbal_ns = percentile(b, 0.5);
  p.ratio = p.mechbal_ns > 0.0 ? p.other_ns / p.mechbal_ns : 0.0;
  p.ratio_p25 = percentile(r, 0.25);
  p.ratio_p75 = percentile(r, 0.75);
  return p;
}

/// The mechbal case another engine's case is compared with: X_pinocchio* -> X_mechbal or X,
/// X_kdl_raw -> X_mechbal (the names of bench_registry.hpp's cases); a general-model case -> the
/// paper's closed form of the same tick (its ratio is then general / closed form); -1 when there
/// is none.
int counterpart(const std::vector<mechbal::bench::CaseEntry>& cases, const std::string& name) {
  auto find = [&](const std::string& n) {
    for (std::size_t i = 0; i < cases.size(); ++i)
      if (cases[i].name == n) return static_cast<int>(i);
    return -1;
  };
  // the general path over the closed form (fast path) of the same quantities
  static const std::pair<const char*, const char*> closed_forms[] = {
      {"paminsa_general_wrench", "paminsa_wrench"},
      {"reactionless_paminsa_euler", "paminsa_tick_euler"},
      {"reactionless_paminsa_rk4", "paminsa_tick_rk4"}};
  for (const auto& [general, closed] : closed_forms) {
    if (name == general) return find(closed);
  }
  for (const char* tag : {"_pinocchio", "_kdl_raw"}) {
    const auto at = name.rfind(tag);
    if (at == std::string::npos || at + std::strlen(tag) != name.size()) continue;
    const std::string stem = name.substr(0, at);
    if (int i = find(stem + "_mechbal"); i >= 0) return i;
    if (int i = find(stem); i >= 0) return i;
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  std::string tail_out;
  std::string only;  // comma-separated substrings: build and run only the cases whose name has one
  int tail_samples = 20000;
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--tail_out=", 11) == 0) {
      tail_out = argv[i] + 11;
    } else if (std::strncmp(argv[i], "--only=", 7) == 0) {
      only = argv[i] + 7;
    } else if (std::strncmp(argv[i], "--tail_samples=", 15) == 0) {
      tail_samples = std::max(100, std::atoi(argv[i] + 15));
    } else {
      rest.push_back(argv[i]);
    }
  }
  int bargc = static_cast<int>(rest.size());
  benchmark::Initialize(&bargc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(bargc, rest.data())) return 1;

#ifndef MECHBAL_BENCH_HAVE_PINOCCHIO
  std::fprintf(stderr,
               "mechbal-bench: Pinocchio C++ headers not found at configure time: the *_pinocchio "
               "cases are skipped (install the `pin` wheel in .venv, or pass "
               "-DMECHBAL_PINOCCHIO_PREFIX=<prefix with include/pinocchio>)\n");
#endif

  auto& cases = mechbal::bench::cases();
  if (!only.empty()) {
    std::vector<std::string> keys;
    for (std::size_t at = 0; at <= only.size();) {
      const std::size_t end = std::min(only.find(',', at), only.size());
      if (end > at) keys.push_back(only.substr(at, end - at));
      at = end + 1;
    }
    cases.erase(std::remove_if(cases.begin(), cases.end(), [&](const auto& c) {
                  return std::none_of(keys.begin(), keys.end(),
                                      [&](const std::string& k) { return c.name.find(k) != std::string::npos; });
                }),
                cases.end());
  }
  std::sort(cases.begin(), cases.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<mechbal::bench::Tick> ticks;
  ticks.reserve(cases.size());
  for (const auto& c : cases) ticks.push_back(c.make());

  for (std::size_t i = 0; i < cases.size(); ++i) {
    const mechbal::bench::Tick* tick = &ticks[i];
    benchmark::RegisterBenchmark(cases[i].name.c_str(), [tick](benchmark::State& state) {
      const std::size_t before = mechbal::test::allocation_count();
      for (auto _ : state) (*tick)();
      state.counters["allocs_per_tick"] = benchmark::Counter(
          static_cast<double>(mechbal::test::allocation_count() - before) /
          static_cast<double>(std::max<benchmark::IterationCount>(1, state.iterations())));
    });
  }

  if (!tail_out.empty()) {
    const double overhead = clock_overhead_ns();
    std::ofstream out(tail_out);
    double load[3] = {0, 0, 0};
    if (getloadavg(load, 3) < 1) load[0] = -1;  // the machine's load when the timings start
    out << "{\n  \"clock_overhead_ns\": " << overhead << ",\n  \"load_average_at_start\": " << load[0]
        << ",\n  \"samples\": " << tail_samples
        << ",\n  \"cases\": {";
    std::vector<Tail> tails;
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const Tail t = measure_tail(ticks[i], tail_samples, overhead);
      tails.push_back(t);
      out << (i ? "," : "") << "\n    \"" << cases[i].name << "\": {\"samples\": " << t.samples << ", \"p50_ns\": " << t.p50
          << ", \"p99_ns\": " << t.p99 << ", \"p999_ns\": " << t.p999 << ", \"max_ns\": " << t.max
          << ", \"batch_median_ns\": " << t.batch_median << ", \"batch_calls\": " << t.batch
          << ", \"allocations_per_tick\": " << t.allocations_per_tick << "}";
      std::fprintf(stderr, "tail %-28s p50 %8.1f ns  batch %8.1f ns  p99 %8.1f ns  allocs/tick %.2f\n",
                   cases[i].name.c_str(), t.p50, t.batch_median, t.p99, t.allocations_per_tick);
    }
    out << "\n  },\n  \"interleaved\": {";
    bool first = true;
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const int j = counterpart(cases, cases[i].name);
      if (j < 0) continue;
      const auto sj = static_cast<std::size_t>(j);
      const Pair p = measure_pair(ticks[i], tails[i], ticks[sj], tails[sj], overhead);
      out << (first ? "" : ",") << "\n    \"" << cases[i].name << "\": {\"mechbal_case\": \"" << cases[sj].name
          << "\", \"other_ns\": " << p.other_ns << ", \"mechbal_ns\": " << p.mechbal_ns << ", \"ratio\": " << p.ratio
          << ", \"ratio_p25\": " << p.ratio_p25 << ", \"ratio_p75\": " << p.ratio_p75 << ", \"rounds\": " << p.rounds << "}";
      first = false;
      std::fprintf(stderr, "pair %-36s / %-28s %6.2f (IQR of rounds %.2f-%.2f)\n", cases[i].name.c_str(),
                   cases[sj].name.c_str(), p.ratio, p.ratio_p25, p.ratio_p75);
    }
    if (getloadavg(load, 3) < 1) load[0] = -1;
    out << "\n  },\n  \"load_average_at_end\": " << load[0] << "\n}\n";
  }

  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
