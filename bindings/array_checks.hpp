#pragma once
// Checked conversion of array arguments at the binding boundary (issue 14: nothing garbage leaves
// a binding). Every array argument is a mechbal::pyb::Array: a numpy array, list, tuple or scalar
// of real numbers (integer or float) becomes a C-contiguous float64 array; complex numbers,
// strings, bytes, booleans, objects and ragged sequences are refused with a TypeError naming the
// argument, at its first use (require_shape, vector_arg, ...), instead of pybind11's forcecast,
// which dropped imaginary parts and parsed strings as numbers. Shape errors name the argument, the
// expected and the received shape.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "mechbal/status.hpp"

namespace mechbal::pyb {

/// Output arrays (and the storage of Array): float64, C order.
using OutArray = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

/// An array argument after the checked conversion. `refused` is empty when the argument was real
/// numbers; otherwise it says what was received and the array is empty.
class Array : public OutArray {
 public:
  using OutArray::OutArray;
  Array() = default;
  explicit Array(const OutArray& a) : OutArray(a) {}
  std::string refused;
};

namespace detail {

inline std::string describe_dtype(const pybind11::dtype& dt) {
  switch (dt.kind()) {
    case 'c': return "complex values";
    case 'b': return "booleans";
    case 'U':
    case 'S': return "strings";
    case 'O': return "Python objects";
    case 'M':
    case 'm': return "dates or time deltas";
    default: return "values of dtype " + pybind11::str(dt).cast<std::string>();
  }
}

}  // namespace detail

/// The data of `h` when it is already what the algorithms read: a numpy array (ndarray itself,
/// not a subclass) of native float64 values, C-contiguous and aligned, with `nd` dimensions
/// (dims[i] < 0 matches any extent); nullptr otherwise (nothing raised: the caller takes its
/// general path). The fast path of single calls (issue 26): a few loads from the array header.
inline double* float64_data(pybind11::handle h, int nd, const pybind11::ssize_t* dims) noexcept {
  namespace pd = pybind11::detail;
  const auto& api = pd::npy_api::get();
  if (Py_TYPE(h.ptr()) != api.PyArray_Type_) return nullptr;
  const pd::PyArray_Proxy* a = pd::array_proxy(h.ptr());
  constexpr int need = pd::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | pd::npy_api::NPY_ARRAY_ALIGNED_;
  if (a->nd != nd || (a->flags & need) != need) return nullptr;
  for (int i = 0; i < nd; ++i)
    if (dims[i] >= 0 && a->dimensions[i] != dims[i]) return nullptr;
  const pd::PyArrayDescr_Proxy* d = pd::array_descriptor_proxy(a->descr);
  if (d->type_num != pd::npy_api::NPY_DOUBLE_ || d->byteorder == '>') return nullptr;
  return reinterpret_cast<double*>(a->data);
}

/// float64_data of a 1-D array of n values.
inline const double* float64_vector(pybind11::handle h, pybind11::ssize_t n) noexcept {
  return float64_data(h, 1, &n);
}

/// A new, uninitialised float64 C-order numpy array (the numpy C API directly: no shape vectors).
inline pybind11::object new_float64_array(std::initializer_list<pybind11::ssize_t> shape) {
  namespace pd = pybind11::detail;
  const auto& api = pd::npy_api::get();
  Py_intptr_t dims[4];
  int nd = 0;
  for (auto s : shape) dims[nd++] = static_cast<Py_intptr_t>(s);
  static PyObject* const float64 = api.PyArray_DescrFromType_(pd::npy_api::NPY_DOUBLE_);  // kept
  Py_INCREF(float64);  // stolen by PyArray_NewFromDescr
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, float64, nd, dims, nullptr, nullptr, 0, nullptr);
  if (!a) throw pybind11::error_already_set();
  return pybind11::reinterpret_steal<pybind11::object>(a);
}

/// The data of an array made by new_float64_array.
inline double* float64_array_data(const pybind11::object& a) noexcept {
  return reinterpret_cast<double*>(pybind11::detail::array_proxy(a.ptr())->data);
}

/// The checked conversion (also usable on any handle).
inline Array to_real_array(pybind11::handle src) {
  namespace py = pybind11;
  // already float64, C-contiguous, aligned: used as it is (what OutArray::ensure would return)
  const auto& api = py::detail::npy_api::get();
  if (Py_TYPE(src.ptr()) == api.PyArray_Type_) {
    const auto* a = py::detail::array_proxy(src.ptr());
    constexpr int need = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
    const auto* d = py::detail::array_descriptor_proxy(a->descr);
    if ((a->flags & need) == need && d->type_num == py::detail::npy_api::NPY_DOUBLE_ && d->byteorder != '>')
      return Array(py::reinterpret_borrow<OutArray>(src));
  }
  py::array a;
  if (py::isinstance<py::array>(src)) {
    a = py::reinterpret_borrow<py::array>(src);
  } else {
    // leaked on purpose: a static py::object would be destroyed after the interpreter
    static py::object* asarray =
        new py::object(py::module_::import("numpy").attr("asarray"));
    try {
      a = py::reinterpret_steal<py::array>((*asarray)(src).release());
    } catch (py::error_already_set& e) {
      Array out;
      out.refused = "a sequence that is not an array of numbers (" + std::string(e.what()) + ")";
      return out;
    }
  }
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u' && kind != 'f') {
    Array out;
    out.refused = detail::describe_dtype(a.dtype());
    return out;
  }
  return Array(OutArray::ensure(a));
}

inline std::string shape_of(const pybind11::array& a) {
  std::ostringstream s;
  s << "(";
  for (pybind11::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

/// TypeError naming `name` when the argument was not real numbers.
inline void require_real(const Array& a, const char* name) {
  if (!a.refused.empty())
    throw pybind11::type_error(std::string(name) +
                               " must be an array of real numbers (int or float), got " +
                               a.refused);
}

/// Requires real numbers and exactly `shape`; -1 matches any extent. ValueError naming `name`,
/// the expected and the received shape (and `context`, e.g. "one value per joint", when given).
inline void require_shape(const Array& a, const char* name,
                          std::initializer_list<pybind11::ssize_t> shape,
                          const char* context = nullptr) {
  require_real(a, name);
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
    msg << (shape.size() == 1 ? ",)" : ")");
    if (context) msg << " (" << context << ")";
    msg << ", got " << shape_of(a);
    throw pybind11::value_error(msg.str());
  }
}

/// An array argument and the name its errors give.
struct NamedArray {
  const Array& array;
  const char* name;
};

/// Each argument real numbers of shape (rows, cols) (rows < 0: any), checked in order: the
/// ValueError of the first that is not names it (require_shape, with `context`).
inline void require_rows(pybind11::ssize_t rows, pybind11::ssize_t cols, std::initializer_list<NamedArray> args,
                         const char* context = nullptr) {
  for (const NamedArray& a : args) require_shape(a.array, a.name, {rows, cols}, context);
}

/// The arguments of a batch over N instants, each (N, cols): the first sets N (any number of
/// rows), the others must have as many. Returns N; checks and messages as require_shape's.
inline pybind11::ssize_t batch_rows(pybind11::ssize_t cols, std::initializer_list<NamedArray> args,
                                    const char* context = nullptr) {
  const NamedArray& first = *args.begin();
  require_shape(first.array, first.name, {-1, cols}, context);
  const pybind11::ssize_t N = first.array.shape(0);
  for (auto it = args.begin() + 1; it != args.end(); ++it) require_shape(it->array, it->name, {N, cols}, context);
  return N;
}

/// ValueError naming `name` when any value is NaN or infinite (functions with no status).
inline void require_finite(const Array& a, const char* name) {
  const double* p = a.data();
  for (pybind11::ssize_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(p[i]))
      throw pybind11::value_error(std::string(name) + " must be finite, got " +
                                  std::to_string(p[i]));
}

/// A vector argument of n values (n < 0: any length), optionally required finite.
inline Eigen::VectorXd vector_arg(const Array& a, const char* name, pybind11::ssize_t n,
                                  bool finite = false, const char* context = nullptr) {
  require_shape(a, name, {n}, context);
  if (finite) require_finite(a, name);
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
}

template <int N>
inline Eigen::Matrix<double, N, 1> fixed_vector(const Array& a, const char* name,
                                                bool finite = false) {
  require_shape(a, name, {N});
  if (finite) require_finite(a, name);
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(a.data());
}

/// A (rows, cols) matrix argument (row-major numpy to Eigen), optionally required finite.
template <int R, int C>
inline Eigen::Matrix<double, R, C> fixed_matrix(const Array& a, const char* name,
                                                bool finite = false) {
  require_shape(a, name, {R, C});
  if (finite) require_finite(a, name);
  return Eigen::Map<const Eigen::Matrix<double, R, C, (C == 1 ? Eigen::ColMajor : Eigen::RowMajor)>>(
      a.data());
}

/// ValueError for a per-sample function with no status in its Python signature: names the
/// function and the reason (the Status).
inline void raise_unless_ok(Status s, const char* what) {
  if (s == Status::ok) return;
  std::string why;
  if (has(s, Status::non_finite_input)) why = "an input is NaN or infinite";
  else if (has(s, Status::out_of_range)) why = "the result overflowed (input out of range)";
  else if (has(s, Status::singular)) why = "singular configuration";
  else if (has(s, Status::solver_error)) why = "the solver failed";
  else if (has(s, Status::bad_size)) why = "wrong sizes";
  else why = status_name(s);
  throw pybind11::value_error(std::string(what) + ": " + why + " (status " + status_name(s) + ")");
}

inline OutArray make_array(std::initializer_list<pybind11::ssize_t> shape) {
  return OutArray(std::vector<pybind11::ssize_t>(shape));
}

/// Per-instant status array (N,) of a batch function (uint32 bit flags of mechbal.Status).
inline pybind11::array_t<std::uint32_t> make_status_array(pybind11::ssize_t N) {
  pybind11::array_t<std::uint32_t> s(std::vector<pybind11::ssize_t>{N});
  if (N > 0) std::fill(s.mutable_data(), s.mutable_data() + N, 0u);
  return s;
}

}  // namespace mechbal::pyb

namespace pybind11::detail {

/// Every mechbal::pyb::Array argument goes through the checked conversion; loading never fails,
/// refusals are reported (naming the argument) where the binding first uses the argument.
template <>
struct type_caster<mechbal::pyb::Array> {
  PYBIND11_TYPE_CASTER(mechbal::pyb::Array, const_name("numpy.typing.ArrayLike"));
  bool load(handle src, bool) {
    value = mechbal::pyb::to_real_array(src);
    return true;
  }
  static handle cast(const mechbal::pyb::Array& a, return_value_policy, handle) {
    return a.inc_ref();
  }
};

}  // namespace pybind11::detail
