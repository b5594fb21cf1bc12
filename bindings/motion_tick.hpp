#pragma once
// What the bindings of the motion controllers share (the reactionless wrist and PAMINSA's tick in
// cpp/src/papers/paminsa/bind_paminsa.cpp, the general reactionless controller in
// bind_reactionless.cpp): their fast tick writes a command of positions, velocities and
// accelerations into a caller's (3, n) array, and their batch runs take a motion sampled on the
// half-step grid t_j = j dt/2 (2 steps + 1 rows). Conversions and checks only.
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "controller_step.hpp"
#include "mechbal/status.hpp"

namespace mechbal::pyb {

/// The fast tick of a motion controller: `out` is checked first (a writeable, C-contiguous,
/// aligned float64 array of shape (3, n); anything else is a TypeError or ValueError naming it,
/// and the controller does not tick), then `tick()` runs (returns a Status) and `rows(q, v, a)`
/// writes the command through three Eigen maps of n values (rows 0, 1, 2 of `out`). Returns the
/// status as an int. Nothing is copied or allocated.
template <typename Tick, typename Rows>
std::uint32_t motion_step_into(FastArg out, pybind11::ssize_t n, Tick&& tick, Rows&& rows) {
  double* o = detail::fast_matrix(out.h, "out", 3, n, true);
  const Status s = tick();
  using Row = Eigen::Map<Eigen::VectorXd>;
  rows(Row(o, n), Row(o + n, n), Row(o + 2 * n, n));
  return static_cast<std::uint32_t>(s);
}

/// The number of ticks of a run over a motion sampled on the half-step grid: `rows` = 2 steps + 1
/// with steps >= min_steps; else a ValueError naming the argument.
inline pybind11::ssize_t half_step_ticks(pybind11::ssize_t rows, const char* name, pybind11::ssize_t min_steps = 0) {
  if (rows < 2 * min_steps + 1 || rows % 2 == 0) {
    throw pybind11::value_error(std::string(name) + " must have 2 steps + 1 rows (the half-step grid t_j = j dt/2" +
                                (min_steps > 0 ? ", steps >= " + std::to_string(min_steps) : std::string()) +
                                "), got " + std::to_string(rows));
  }
  return (rows - 1) / 2;
}

}  // namespace mechbal::pyb
