#pragma once
// The core's construction errors as Python ValueError: a std::invalid_argument (mechbal::ConfigError
// of the case reader, the URDF reader's errors, a model's or a controller's constructor) naming the
// field and the value becomes a ValueError with the same message, byte for byte (the parity tests
// compare it with the Python reader's).
#include <pybind11/pybind11.h>

#include <stdexcept>

namespace mechbal::pyb {

/// fn(), its std::invalid_argument rethrown as ValueError (message unchanged).
template <typename Fn>
auto value_errors(Fn fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const std::invalid_argument& e) {
    throw pybind11::value_error(e.what());
  }
}

}  // namespace mechbal::pyb
