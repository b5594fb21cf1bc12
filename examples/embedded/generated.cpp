// mechbal_embedded_generated: the generated variant of the embedded handoff. The mechanism's C++ is
// generated at build time (mechbal_add_generated: one header, <cmath> only, no heap, no exceptions)
// and this program needs nothing else: no mechbal library, no Eigen, no case reader. It runs the
// closed mechanism's two ticks along a motion of its actuated joints, each warm-started from the
// last: closed_inverse_dynamics_tick (the actuated forces tau# = C^T tau that drive the motion) and
// closed_tick (the shaking wrench the motion puts on the base).
//
//   mechbal_embedded_generated MOTION [--trace FILE]
//
// MOTION (written by tools/generated_motion.py from a case): a first line with the warm start of
// every coordinate, then one line per tick with q#, v#, a# of the actuated joints. The trace has
// one line per tick: tau# (num_actuated values), the shaking force and moment (3 + 3). Prints the
// tick time percentiles. Exit 1 when a tick fails (its status and index named), 2 for bad input.
#include "embedded_mechanism.hpp"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace g = mechbal_generated::embedded_mechanism;

namespace {

bool read_values(std::FILE* f, double* out, int n) {
  for (int i = 0; i < n; ++i) {
    if (std::fscanf(f, "%lf", &out[i]) != 1) return false;
  }
  return true;
}

double now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  const char* motion_path = nullptr;
  const char* trace_path = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--trace") == 0 && i + 1 < argc) {
      trace_path = argv[++i];
    } else if (argv[i][0] != '-' && motion_path == nullptr) {
      motion_path = argv[i];
    } else {
      std::fprintf(stderr, "usage: mechbal_embedded_generated MOTION [--trace FILE]\n");
      return 2;
    }
  }
  if (motion_path == nullptr) {
    std::fprintf(stderr, "usage: mechbal_embedded_generated MOTION [--trace FILE]\n");
    return 2;
  }
  std::FILE* in = std::fopen(motion_path, "r");
  if (in == nullptr) {
    std::fprintf(stderr, "cannot read %s: %s\n", motion_path, std::strerror(errno));
    return 2;
  }
  // everything is read before the loop: the loop itself only calls the generated ticks
  g::ClosedState forces_state, wrench_state;
  if (!read_values(in, forces_state.q, g::dof)) {
    std::fprintf(stderr, "%s: the first line must hold the %d coordinates of the warm start\n", motion_path, g::dof);
    return 2;
  }
  std::copy(forces_state.q, forces_state.q + g::dof, wrench_state.q);
  constexpr int na = g::num_actuated;
  std::vector<double> motion;
  double row[3 * na];
  while (read_values(in, row, 3 * na)) motion.insert(motion.end(), row, row + 3 * na);
  std::fclose(in);
  const std::size_t ticks = motion.size() / (3 * na);
  if (ticks == 0) {
    std::fprintf(stderr, "%s: no tick (each line: q#, v#, a# of the %d actuated joints)\n", motion_path, na);
    return 2;
  }
  std::vector<double> trace(ticks * (na + 6));
  std::vector<double> elapsed(ticks);
  for (std::size_t k = 0; k < ticks; ++k) {
    const double* qa = &motion[k * 3 * na];
    double* out = &trace[k * (na + 6)];
    const double start = now_ns();
    const int a = g::closed_inverse_dynamics_tick(forces_state, qa, qa + na, qa + 2 * na, out);
    const int b = g::closed_tick(wrench_state, qa, qa + na, qa + 2 * na, out + na, out + na + 3);
    elapsed[k] = now_ns() - start;
    if (a != g::ok || b != g::ok) {
      std::fprintf(stderr, "tick %zu failed: closed_inverse_dynamics_tick status %d, closed_tick status %d\n", k, a, b);
      return 1;
    }
  }
  std::printf("%zu ticks of the generated closed inverse dynamics and shaking wrench: p50 %.0f ns, "
              "p99.9 %.0f ns, max %.0f ns\n",
              ticks, percentile(elapsed, 0.5), percentile(elapsed, 0.999), percentile(elapsed, 1.0));
  if (trace_path != nullptr) {
    std::FILE* out = std::fopen(trace_path, "w");
    if (out == nullptr) {
      std::fprintf(stderr, "cannot write %s: %s\n", trace_path, std::strerror(errno));
      return 2;
    }
    for (std::size_t k = 0; k < ticks; ++k) {
      for (int i = 0; i < na + 6; ++i) std::fprintf(out, "%s%.17g", i ? " " : "", trace[k * (na + 6) + i]);
      std::fprintf(out, "\n");
    }
    std::fclose(out);
  }
  return 0;
}
