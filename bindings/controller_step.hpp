#pragma once
// One Python tick of a joint controller (ComputedTorque, DecoupledJointController): (tau, status).
// Arguments go through the checked conversion (array_checks.hpp); a wrong size is a ValueError
// naming the argument, the expected and the received shape. Non-finite or out-of-range input
// returns the held command and its status, as the C++ step does.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>

#include "array_checks.hpp"
#include "mechbal/status.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/joint_limits.hpp"

namespace mechbal::pyb {

/// An argument of the fast tick: the Python object as is (checked by detail::fast_array), typed
/// as a float64 numpy array in the signature (and so in the stubs).
struct FastArg {
  pybind11::handle h;
};

/// An argument of step(): the Python object as is, any real array-like (typed so in the
/// signature); the binding reads a float64 array in place and converts anything else.
struct ArrayLikeArg {
  pybind11::handle h;
};

}  // namespace mechbal::pyb

namespace pybind11::detail {
template <>
struct type_caster<mechbal::pyb::FastArg> {
  PYBIND11_TYPE_CASTER(mechbal::pyb::FastArg, const_name("numpy.typing.NDArray[numpy.float64]"));
  bool load(handle src, bool) {
    value.h = src;
    return true;
  }
  static handle cast(const mechbal::pyb::FastArg& a, return_value_policy, handle) {
    return a.h.inc_ref();
  }
};
template <>
struct type_caster<mechbal::pyb::ArrayLikeArg> {
  PYBIND11_TYPE_CASTER(mechbal::pyb::ArrayLikeArg, const_name("numpy.typing.ArrayLike"));
  bool load(handle src, bool) {
    value.h = src;
    return true;
  }
  static handle cast(const mechbal::pyb::ArrayLikeArg& a, return_value_policy, handle) {
    return a.h.inc_ref();
  }
};
}  // namespace pybind11::detail

namespace mechbal::pyb {

template <typename Controller>
pybind11::tuple controller_step(Controller& c, const Array& q, const Array& qd, const Array& q_des,
                                const Array& qd_des, const Array& qdd_des) {
  const auto n = static_cast<pybind11::ssize_t>(c.dof());
  const std::string context = "the controller has " + std::to_string(n) + " joints";
  const Eigen::VectorXd q_ = vector_arg(q, "q", n, false, context.c_str());
  const Eigen::VectorXd qd_ = vector_arg(qd, "v", n, false, context.c_str());
  const Eigen::VectorXd q_des_ = vector_arg(q_des, "q_des", n, false, context.c_str());
  const Eigen::VectorXd qd_des_ = vector_arg(qd_des, "v_des", n, false, context.c_str());
  const Eigen::VectorXd qdd_des_ = vector_arg(qdd_des, "a_des", n, false, context.c_str());
  Eigen::VectorXd tau = c.last_command();
  const Status s = c.step(q_, qd_, q_des_, qd_des_, qdd_des_, tau);
  return pybind11::make_tuple(tau, s);
}

/// One tick from Python (issue 26: step() at most 1.5 us): (tau (n,) numpy array, status). When
/// every argument is already a 1-D C-contiguous float64 numpy array of n values it is read in
/// place and the torque written straight into the new result array; anything else goes through
/// the checked conversion of controller_step (same errors). `Int`: the status as an int, else as
/// mechbal.Status.
template <typename Controller, bool Int = true>
pybind11::tuple controller_tick(Controller& c, ArrayLikeArg q, ArrayLikeArg qd, ArrayLikeArg q_des,
                                ArrayLikeArg qd_des, ArrayLikeArg qdd_des) {
  const auto n = static_cast<pybind11::ssize_t>(c.dof());
  const double* pq = float64_vector(q.h, n);
  const double* pqd = float64_vector(qd.h, n);
  const double* pq_des = float64_vector(q_des.h, n);
  const double* pqd_des = float64_vector(qd_des.h, n);
  const double* pqdd_des = float64_vector(qdd_des.h, n);
  if (!pq || !pqd || !pq_des || !pqd_des || !pqdd_des) {
    pybind11::tuple r = controller_step(c, to_real_array(q.h), to_real_array(qd.h), to_real_array(q_des.h),
                                        to_real_array(qd_des.h), to_real_array(qdd_des.h));
    if (Int) r = pybind11::make_tuple(r[0], static_cast<std::uint32_t>(r[1].cast<Status>()));
    return r;
  }
  using CMap = Eigen::Map<const Eigen::VectorXd>;
  pybind11::object tau = new_float64_array({n});
  Eigen::Map<Eigen::VectorXd> t(float64_array_data(tau), n);
  t = c.last_command();
  const Status s = c.step(CMap(pq, n), CMap(pqd, n), CMap(pq_des, n), CMap(pqd_des, n), CMap(pqdd_des, n), t);
  if (Int) return pybind11::make_tuple(std::move(tau), static_cast<std::uint32_t>(s));
  return pybind11::make_tuple(std::move(tau), s);
}

/// The fast tick (issue 15: at most 1.5 us from Python). The arguments arrive as plain handles
/// (no pybind11 conversion, no overload resolution) and are checked here on the array header:
/// a numpy array, 1-D, of n native float64 values, C-contiguous and aligned (`out` also
/// writeable); the data are then read and written in place through Eigen::Map, nothing copied or
/// allocated. Anything else is a TypeError or ValueError naming the argument. Returns the status
/// as an int.
namespace detail {

[[noreturn]] inline void fast_refuse(pybind11::handle h, const char* name, pybind11::ssize_t n,
                                     bool writeable) {
  std::string got = pybind11::str(pybind11::type::handle_of(h)).cast<std::string>();
  if (pybind11::isinstance<pybind11::array>(h)) {
    const auto a = pybind11::reinterpret_borrow<pybind11::array>(h);
    got = "an array of dtype " + pybind11::str(a.dtype()).cast<std::string>() + " and shape " +
          shape_of(a);
    if (a.ndim() != 1 || a.shape(0) != n)
      throw pybind11::value_error(std::string("step_into: ") + name + " must have shape (" +
                                  std::to_string(n) + ",) (the controller has " +
                                  std::to_string(n) + " joints), got " + shape_of(a));
    if (writeable && !a.writeable())
      throw pybind11::value_error(std::string("step_into: ") + name + " must be writeable");
  }
  throw pybind11::type_error(std::string("step_into: ") + name +
                             " must be a C-contiguous numpy array of float64 "
                             "(numpy.ascontiguousarray(x, dtype=float)), got " + got +
                             "; step() accepts any real array-like");
}

inline double* fast_array(pybind11::handle h, const char* name, pybind11::ssize_t n,
                          bool writeable = false) {
  namespace pd = pybind11::detail;
  const auto& api = pd::npy_api::get();
  if (!api.PyArray_Check_(h.ptr())) fast_refuse(h, name, n, writeable);
  const pd::PyArray_Proxy* a = pd::array_proxy(h.ptr());
  const pd::PyArrayDescr_Proxy* d = pd::array_descriptor_proxy(a->descr);
  constexpr int need = pd::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | pd::npy_api::NPY_ARRAY_ALIGNED_;
  const int flags = a->flags;
  if (a->nd != 1 || a->dimensions[0] != n || d->type_num != pd::npy_api::NPY_DOUBLE_ ||
      d->byteorder == '>' || (flags & need) != need ||
      (writeable && !(flags & pd::npy_api::NPY_ARRAY_WRITEABLE_)))
    fast_refuse(h, name, n, writeable);
  return reinterpret_cast<double*>(a->data);
}

/// A (rows, cols) native float64 C-contiguous aligned array (the fast path's matrices).
inline double* fast_matrix(pybind11::handle h, const char* name, pybind11::ssize_t rows,
                           pybind11::ssize_t cols, bool writeable = false) {
  namespace pd = pybind11::detail;
  const auto& api = pd::npy_api::get();
  constexpr int need = pd::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | pd::npy_api::NPY_ARRAY_ALIGNED_;
  if (api.PyArray_Check_(h.ptr())) {
    const pd::PyArray_Proxy* a = pd::array_proxy(h.ptr());
    const pd::PyArrayDescr_Proxy* d = pd::array_descriptor_proxy(a->descr);
    const int flags = a->flags;
    if (a->nd == 2 && a->dimensions[0] == rows && a->dimensions[1] == cols &&
        d->type_num == pd::npy_api::NPY_DOUBLE_ && d->byteorder != '>' && (flags & need) == need &&
        (!writeable || (flags & pd::npy_api::NPY_ARRAY_WRITEABLE_)))
      return reinterpret_cast<double*>(a->data);
    const auto arr = pybind11::reinterpret_borrow<pybind11::array>(h);
    if (arr.ndim() != 2 || arr.shape(0) != rows || arr.shape(1) != cols)
      throw pybind11::value_error(std::string("step_into: ") + name + " must have shape (" +
                                  std::to_string(rows) + ", " + std::to_string(cols) + "), got " +
                                  shape_of(arr));
    if (writeable && !arr.writeable())
      throw pybind11::value_error(std::string("step_into: ") + name + " must be writeable");
  }
  throw pybind11::type_error(std::string("step_into: ") + name +
                             " must be a C-contiguous numpy array of float64 "
                             "(numpy.ascontiguousarray(x, dtype=float)), got " +
                             pybind11::str(pybind11::type::handle_of(h)).cast<std::string>());
}

}  // namespace detail

template <typename Controller>
std::uint32_t controller_step_into(Controller& c, FastArg q, FastArg qd, FastArg q_des,
                                   FastArg qd_des, FastArg qdd_des, FastArg out) {
  const auto n = static_cast<pybind11::ssize_t>(c.dof());
  using CMap = Eigen::Map<const Eigen::VectorXd>;
  const double* q_ = detail::fast_array(q.h, "q", n);
  const double* qd_ = detail::fast_array(qd.h, "v", n);
  const double* q_des_ = detail::fast_array(q_des.h, "q_des", n);
  const double* qd_des_ = detail::fast_array(qd_des.h, "v_des", n);
  const double* qdd_des_ = detail::fast_array(qdd_des.h, "a_des", n);
  Eigen::Map<Eigen::VectorXd> tau(detail::fast_array(out.h, "out", n, true), n);
  return static_cast<std::uint32_t>(c.step(CMap(q_, n), CMap(qd_, n), CMap(q_des_, n),
                                           CMap(qd_des_, n), CMap(qdd_des_, n), tau));
}

/// Batch: N consecutive ticks over (N, n) arrays in one call -> {'joint_torque' (N, n),
/// 'status' (N,) per tick}. The controller's state (held command) carries from tick to tick.
template <typename Controller>
pybind11::dict controller_run(Controller& c, const Array& q, const Array& qd, const Array& q_des,
                              const Array& qd_des, const Array& qdd_des) {
  const auto n = static_cast<pybind11::ssize_t>(c.dof());
  const std::string context = "the controller has " + std::to_string(n) + " joints";
  const auto N = batch_rows(n, {{q, "q"}, {qd, "v"}, {q_des, "q_des"}, {qd_des, "v_des"}, {qdd_des, "a_des"}}, context.c_str());
  OutArray tau = make_array({N, n});
  auto status = make_status_array(N);
  using CMap = Eigen::Map<const Eigen::VectorXd>;
  {
    pybind11::gil_scoped_release release;
    for (pybind11::ssize_t k = 0; k < N; ++k) {
      Eigen::Map<Eigen::VectorXd> t(tau.mutable_data(k, 0), n);
      status.mutable_data()[k] = static_cast<std::uint32_t>(
          c.step(CMap(q.data(k, 0), n), CMap(qd.data(k, 0), n), CMap(q_des.data(k, 0), n),
                 CMap(qd_des.data(k, 0), n), CMap(qdd_des.data(k, 0), n), t));
    }
  }
  pybind11::dict d;
  d["joint_torque"] = tau;
  d["status"] = status;
  return d;
}

/// The keyword names of earlier releases (qd, qd_des, qdd_des), accepted for one release: a
/// second overload of step / step_into / run that renames them (a DeprecationWarning each) and
/// calls the method again. Positional calls never reach it (the first overload takes them).
inline pybind11::object call_with_renamed_kwargs(const pybind11::object& self, const char* method,
                                                 const pybind11::args& args,
                                                 const pybind11::kwargs& kwargs) {
  static const char* const renames[][2] = {{"qd", "v"}, {"qd_des", "v_des"}, {"qdd_des", "a_des"}};
  pybind11::dict kw;
  bool renamed = false;
  for (const auto& item : kwargs) {
    std::string key = pybind11::str(item.first);
    for (const auto& r : renames) {
      if (key == r[0]) {
        const std::string message = std::string(method) + ": '" + r[0] + "' is deprecated, use '" +
                                    r[1] + "' (the old name goes in the next release)";
        if (PyErr_WarnEx(PyExc_DeprecationWarning, message.c_str(), 1) < 0)
          throw pybind11::error_already_set();
        if (kwargs.contains(r[1]))
          throw pybind11::type_error(std::string(method) + ": got both '" + r[0] +
                                     "' (deprecated) and '" + r[1] + "'");
        key = r[1];
        renamed = true;
        break;
      }
    }
    kw[pybind11::str(key)] = item.second;
  }
  if (!renamed)
    throw pybind11::type_error(std::string(method) +
                               "(): incompatible arguments; the signature is (q, v, q_des, v_des, "
                               "a_des" + (std::string(method) == "step_into" ? ", out)" : ")"));
  return self.attr(method)(*args, **kw);
}

/// step, step_into, run and reset of a joint controller class (the same methods on every one).
template <typename Controller, typename PyClass>
void bind_joint_controller_ticks(PyClass& cls) {
  namespace py = pybind11;
  static constexpr const char* deprecated_doc =
      "Deprecated keyword names (qd, qd_des, qdd_des: use v, v_des, a_des), for one release";
  cls.def("step", &controller_tick<Controller, false>, py::arg("q"), py::arg("v"), py::arg("q_des"),
          py::arg("v_des"), py::arg("a_des"),
          "One tick: (tau, status), tau [N m or N] (n,). Any real array-like input; non-finite or "
          "out-of-range input returns the held command and a non-ok status.")
      .def("_tick", &controller_tick<Controller, true>, py::arg("q"), py::arg("v"), py::arg("q_des"),
           py::arg("v_des"), py::arg("a_des"),
           "step() with the status as an int (what the Python classes' step wraps in a JointCommand)")
      .def("step_into", &controller_step_into<Controller>, py::arg("q"), py::arg("v"),
           py::arg("q_des"), py::arg("v_des"), py::arg("a_des"), py::arg("out"),
           "The fast tick: writes tau [N m or N] into `out` (a preallocated float64 array of n "
           "values) and returns the status as an int (0 = ok, bit flags of mechbal.Status). Every "
           "argument must be a C-contiguous float64 numpy array of n values; nothing is copied or "
           "allocated.")
      .def("run", &controller_run<Controller>, py::arg("q"), py::arg("v"), py::arg("q_des"),
           py::arg("v_des"), py::arg("a_des"),
           "N consecutive ticks in one call: q, v [rad or m, rad/s or m/s], q_des, v_des, "
           "a_des, each (N, n) -> {'joint_torque': (N, n) [N m or N], 'status': (N,) per tick}")
      .def("reset", &Controller::reset, "Forget the held command (zero torque).");
  for (const char* method : {"step", "step_into", "run"})
    cls.def(
        method,
        [method](const py::object& self, const py::args& args, const py::kwargs& kwargs) {
          return call_with_renamed_kwargs(self, method, args, kwargs);
        },
        deprecated_doc);
}

/// The input range of a joint controller from the Python keyword arguments.
inline JointInputRange joint_input_range(double max_position, double max_speed,
                                         double max_acceleration) {
  JointInputRange r;
  r.max_position = max_position;
  r.max_speed = max_speed;
  r.max_acceleration = max_acceleration;
  return r;
}

/// new Controller over any dynamics back end, from Python arguments (the Python model object is
/// kept alive by py::keep_alive in the binding).
template <typename Model>
ComputedTorque* make_computed_torque(Model& model, const Array& kp, const Array& kd,
                                     const pybind11::object& torque_limit, double max_position,
                                     double max_speed, double max_acceleration) {
  // sizes are checked by the constructor (std::invalid_argument naming computed_torque.kp, ...)
  const Eigen::VectorXd limit =
      torque_limit.is_none() ? Eigen::VectorXd()
                             : vector_arg(to_real_array(torque_limit), "torque_limit", -1);
  return new ComputedTorque(model, vector_arg(kp, "kp", -1), vector_arg(kd, "kd", -1), limit,
                            joint_input_range(max_position, max_speed, max_acceleration));
}

}  // namespace mechbal::pyb

#define MECHBAL_JOINT_RANGE_ARGS                                                          \
  pybind11::arg("max_position") = ::mechbal::JointInputRange{}.max_position,               \
  pybind11::arg("max_speed") = ::mechbal::JointInputRange{}.max_speed,                     \
  pybind11::arg("max_acceleration") = ::mechbal::JointInputRange{}.max_acceleration
