#pragma once
// What the benchmark cases share besides their registry (bench_registry.hpp): the abort of a
// setup check that failed, and the order the ticks walk through a precomputed stretch of motion.
// Setup and indexing only: nothing here is timed but PingPong::next, a few integer operations.
#include <cstddef>
#include <cstdio>
#include <cstdlib>

namespace mechbal::bench {

/// A setup check failed (a case would time a wrong computation): says what, with the value, on
/// stderr and aborts mechbal-bench.
[[noreturn]] inline void fail(const char* what, double value) {
  std::fprintf(stderr, "mechbal-bench: %s (%g)\n", what, value);
  std::abort();
}

/// 0, 1, ..., Count - 1, Count - 2, ..., 1, 0, 1, ...: consecutive instants stay neighbours (the
/// warm starts of the loop solves never jump).
template <int Count>
struct PingPong {
  int k = 0, step = 1;
  std::size_t next() noexcept {
    const int out = k;
    if (k + step < 0 || k + step >= Count) step = -step;
    k += step;
    return static_cast<std::size_t>(out);
  }
};

}  // namespace mechbal::bench
