// mechbal-bench: Google Benchmark runner for the registered cases (bench_registry.hpp), plus
// per-call percentiles and heap allocations per tick written to --tail_out (JSON).
//
// Usage: mechbal-bench [--tail_out=FILE] [--tail_samples=N] [Google Benchmark flags...]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
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
  for (int i = 0; i < 200; ++i) tick();  // warm-up (lazy initialisation is allowed before a loop)
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
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  std::string tail_out;
  int tail_samples = 20000;
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--tail_out=", 11) == 0) {
      tail_out = argv[i] + 11;
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
    out << "{\n  \"clock_overhead_ns\": " << overhead << ",\n  \"samples\": " << tail_samples
        << ",\n  \"cases\": {";
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const Tail t = measure_tail(ticks[i], tail_samples, overhead);
      out << (i ? "," : "") << "\n    \"" << cases[i].name << "\": {\"p50_ns\": " << t.p50
          << ", \"p99_ns\": " << t.p99 << ", \"p999_ns\": " << t.p999 << ", \"max_ns\": " << t.max
          << ", \"batch_median_ns\": " << t.batch_median << ", \"batch_calls\": " << t.batch
          << ", \"allocations_per_tick\": " << t.allocations_per_tick << "}";
      std::fprintf(stderr, "tail %-28s p50 %8.1f ns  batch %8.1f ns  p99 %8.1f ns  allocs/tick %.2f\n",
                   cases[i].name.c_str(), t.p50, t.batch_median, t.p99, t.allocations_per_tick);
    }
    out << "\n  }\n}\n";
  }

  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
