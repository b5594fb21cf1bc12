#pragma once
// Shape checks at the binding boundary: errors name the argument and the shape received.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <initializer_list>
#include <sstream>
#include <string>

namespace mechbal::pyb {

using Array = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

inline std::string shape_of(const Array& a) {
  std::ostringstream s;
  s << "(";
  for (pybind11::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

/// Requires `a` to have exactly `shape`; -1 matches any extent. Throws ValueError naming `name`.
inline void require_shape(const Array& a, const char* name, std::initializer_list<pybind11::ssize_t> shape) {
  bool ok = a.ndim() == static_cast<pybind11::ssize_t>(shape.size());
  if (ok) {
    pybind11::ssize_t i = 0;
    for (auto s : shape) {
      if (s >= 0 && a.shape(i) != s) ok = false;
      ++i;
    }
  }
  if (!ok) {
    std::ostringstream msg;
    msg << name << " must have shape (";
    bool first = true;
    for (auto s : shape) {
      msg << (first ? "" : ", ") << (s < 0 ? std::string("*") : std::to_string(s));
      first = false;
    }
    msg << (shape.size() == 1 ? ",)" : ")") << ", got " << shape_of(a);
    throw pybind11::value_error(msg.str());
  }
}

inline Array make_array(std::initializer_list<pybind11::ssize_t> shape) {
  return Array(std::vector<pybind11::ssize_t>(shape));
}

}  // namespace mechbal::pyb
