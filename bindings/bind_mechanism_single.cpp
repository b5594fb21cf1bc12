// pybind11 glue of the per-sample calls of mechbal.Mechanism (issue 26): one instant straight from
// float64 arrays to the algorithm, in a MechanismData allocated once per Python Mechanism.
//
// Each call returns the result when its arguments are already in the algorithms' form (numpy
// arrays of dof native float64 values, 1-D, C-contiguous, aligned) and the instant is accepted
// (status ok, finite result); otherwise it returns None and computes nothing the caller sees.
// mechbal.Mechanism then takes its general path (the batch bindings of bind_mechanism.cpp), which
// converts, checks and raises with the messages of the batch API: the fast path changes the cost
// of a call, never its result or its errors. The GIL is held throughout (the data is shared by the
// calls of one Python object).
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "reaction_bounds.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

using CMap = Eigen::Map<const Eigen::VectorXd>;
using RowMajorMap = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

/// The model (kept alive through its Python object) and the MechanismData of one Mechanism.
class SingleSample {
 public:
  SingleSample(const py::object& model, const py::object& status_ok, const py::object& wrench_type)
      : owner_(model), status_ok_(status_ok), wrench_type_(wrench_type), model_(model.cast<const MechanismModel*>()), data_(*model_),
        n_(model_->dof()), bounds_(*model_) {}

  py::object inverse_dynamics(py::handle q, py::handle v, py::handle a) {
    const double *pq = vec(q), *pv = vec(v), *pa = vec(a);
    if (!pq || !pv || !pa) return py::none();
    if (mechbal::inverse_dynamics(*model_, data_, CMap(pq, n_), CMap(pv, n_), CMap(pa, n_)) != Status::ok ||
        !data_.joint_torque.allFinite())
      return py::none();
    return vector_result(data_.joint_torque);
  }

  py::object gravity_torque(py::handle q) {
    const double* pq = vec(q);
    if (!pq || mechbal::gravity_torque(*model_, data_, CMap(pq, n_)) != Status::ok ||
        !data_.gravity_torque.allFinite())
      return py::none();
    return vector_result(data_.gravity_torque);
  }

  py::object mass_matrix(py::handle q) {
    const double* pq = vec(q);
    if (!pq || mechbal::mass_matrix(*model_, data_, CMap(pq, n_)) != Status::ok ||
        !data_.mass_matrix.allFinite())
      return py::none();
    py::object out = new_float64_array({n_, n_});
    RowMajorMap(float64_array_data(out), n_, n_) = data_.mass_matrix;
    return out;
  }

  py::object center_of_mass(py::handle q) {
    const double* pq = vec(q);
    if (!pq || mechbal::center_of_mass(*model_, data_, CMap(pq, n_)) != Status::ok ||
        !data_.center_of_mass.allFinite())
      return py::none();
    return vector_result(data_.center_of_mass);
  }

  /// A `wrench_type` (mechbal.ShakingWrench, a frozen dataclass) with its fields shaking_force,
  /// shaking_moment, linear_momentum, angular_momentum and status (`status_ok`) set as
  /// wrench_type(**fields) sets them, without the Python-level __init__ (a third of the call).
  /// Accepted exactly when the general path accepts: finite reactions too, base_reaction running
  /// only when their bounds (reaction_bounds.hpp) cannot tell, as in the general path.
  py::object shaking_wrench(py::handle q, py::handle v, py::handle a) {
    const double *pq = vec(q), *pv = vec(v), *pa = vec(a);
    if (!pq || !pv || !pa) return py::none();
    const auto& d = data_;
    const CMap qm(pq, n_), vm(pv, n_), am(pa, n_);
    if (mechbal::shaking_wrench(*model_, data_, qm, vm, am) != Status::ok) return py::none();
    if (!bounds_.surely_finite(data_)) {  // the general path's verdict, computed
      if (base_reaction(*model_, data_, qm, vm, am) != Status::ok ||
          !(d.base_reaction.force.allFinite() && d.base_reaction.moment.allFinite() &&
            d.support_reaction.force.allFinite() && d.support_reaction.moment.allFinite()))
        return py::none();
    }
    // the names made once (leaked on purpose: static objects would outlive the interpreter)
    static PyObject* const keys[5] = {PyUnicode_InternFromString("shaking_force"),
                                      PyUnicode_InternFromString("shaking_moment"),
                                      PyUnicode_InternFromString("linear_momentum"),
                                      PyUnicode_InternFromString("angular_momentum"),
                                      PyUnicode_InternFromString("status")};
    static PyObject* const no_args = PyTuple_New(0);
    // the values first: allocating the result (a GC-tracked object) may run a collection, whose
    // finalizers may call this Mechanism again and overwrite data_
    Vec3 values[4] = {d.shaking.force, d.shaking.moment, d.shaking.linear_momentum, d.shaking.angular_momentum};
    // wrench_type(**fields) without its __init__: object.__new__, then object.__setattr__ per field
    auto* type = reinterpret_cast<PyTypeObject*>(wrench_type_.ptr());
    py::object result = py::reinterpret_steal<py::object>(PyBaseObject_Type.tp_new(type, no_args, nullptr));
    if (!result) throw py::error_already_set();
    // the four vectors are the rows of one (4, 3) array (as the general path's are rows of its
    // batch arrays): one data allocation instead of four
    py::object block = new_float64_array({4, 3});
    double* p = float64_array_data(block);
    for (int i = 0; i < 4; ++i) {
      Eigen::Map<Vec3>(p + 3 * i) = values[i];
      py::object row = row_view(block, p + 3 * i, 3);
      if (PyObject_GenericSetAttr(result.ptr(), keys[i], row.ptr()) != 0) throw py::error_already_set();
    }
    if (PyObject_GenericSetAttr(result.ptr(), keys[4], status_ok_.ptr()) != 0) throw py::error_already_set();
    return result;
  }

  /// The (4, 4) placement in O of a named frame (link placements only; accepted exactly when the
  /// general path's kinematics is).
  py::object frame_placement(py::handle q, py::handle frame) {
    const double* pq = vec(q);
    const int f = frame_of(frame);
    if (!pq || f < 0 || mechbal::frame_placement(*model_, data_, CMap(pq, n_), f) != Status::ok)
      return py::none();
    py::object out = new_float64_array({4, 4});
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(float64_array_data(out)) =
        data_.frame_placements[static_cast<std::size_t>(f)].matrix();
    return out;
  }

  /// The (6, dof) Jacobian [v; w] of a named frame's origin, O's axes.
  py::object frame_jacobian(py::handle q, py::handle frame) {
    const double* pq = vec(q);
    const int f = frame_of(frame);
    if (!pq || f < 0 || mechbal::frame_jacobian(*model_, data_, CMap(pq, n_), f) != Status::ok ||
        !data_.frame_jacobian.allFinite())
      return py::none();
    py::object out = new_float64_array({6, n_});
    RowMajorMap(float64_array_data(out), 6, n_) = data_.frame_jacobian;
    return out;
  }

 private:
  const double* vec(py::handle h) const noexcept { return float64_vector(h, n_); }

  /// Index of the frame named by a str, -1 for anything else (the general path reports it). The
  /// last name's index is kept (a script passes the same str object every call).
  int frame_of(py::handle name) {
    if (name.ptr() == last_frame_name_.ptr()) return last_frame_;
    if (!PyUnicode_Check(name.ptr())) return -1;
    Py_ssize_t size = 0;
    const char* text = PyUnicode_AsUTF8AndSize(name.ptr(), &size);
    if (!text) {
      PyErr_Clear();
      return -1;
    }
    const int f = model_->frame_index(std::string(text, static_cast<std::size_t>(size)));
    last_frame_name_ = py::reinterpret_borrow<py::object>(name);  // str: immutable
    last_frame_ = f;
    return f;
  }

  /// A 1-D float64 view of n values at `data`, inside the array `base` (kept alive by the view).
  static py::object row_view(const py::object& base, double* data, py::ssize_t n) {
    namespace pd = py::detail;
    const auto& api = pd::npy_api::get();
    static PyObject* const float64 = api.PyArray_DescrFromType_(pd::npy_api::NPY_DOUBLE_);  // kept
    Py_INCREF(float64);  // stolen
    Py_intptr_t dim = n;
    constexpr int flags =
        pd::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | pd::npy_api::NPY_ARRAY_ALIGNED_ | pd::npy_api::NPY_ARRAY_WRITEABLE_;
    PyObject* v = api.PyArray_NewFromDescr_(api.PyArray_Type_, float64, 1, &dim, nullptr, data, flags, nullptr);
    if (!v) throw py::error_already_set();
    py::object view = py::reinterpret_steal<py::object>(v);
    if (api.PyArray_SetBaseObject_(v, base.inc_ref().ptr()) != 0) throw py::error_already_set();  // steals
    return view;
  }

  template <typename Vector>
  static py::object vector_result(const Vector& x) {
    py::object out = new_float64_array({static_cast<py::ssize_t>(x.size())});
    Eigen::Map<Eigen::VectorXd>(float64_array_data(out), x.size()) = x;
    return out;
  }

  py::object owner_, status_ok_, wrench_type_;
  py::object last_frame_name_;
  int last_frame_ = -1;
  const MechanismModel* model_;
  MechanismData data_;
  py::ssize_t n_;
  ReactionBounds bounds_;
};

// ---- the calls: METH_FASTCALL builtin functions bound to a capsule of the SingleSample (a
// pybind11 method costs ~100 ns more per call than this, a third of a centre of mass) ----

/// Calls `fn(sample)` with nargs checked; C++ exceptions become Python ones.
template <int N, typename Fn>
PyObject* call(PyObject* capsule, Py_ssize_t nargs, const char* name, Fn fn) noexcept {
  if (nargs != N) {
    PyErr_Format(PyExc_TypeError, "%s() takes %d positional arguments (%zd given)", name, N, nargs);
    return nullptr;
  }
  auto* sample = static_cast<SingleSample*>(PyCapsule_GetPointer(capsule, PyCapsule_GetName(capsule)));
  if (!sample) return nullptr;
  try {
    return fn(*sample).release().ptr();
  } catch (py::error_already_set& e) {
    e.restore();
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
  }
  return nullptr;
}

PyObject* inverse_dynamics_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<3>(c, n, "inverse_dynamics", [x](SingleSample& s) { return s.inverse_dynamics(x[0], x[1], x[2]); });
}
PyObject* gravity_torque_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<1>(c, n, "gravity_torque", [x](SingleSample& s) { return s.gravity_torque(x[0]); });
}
PyObject* mass_matrix_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<1>(c, n, "mass_matrix", [x](SingleSample& s) { return s.mass_matrix(x[0]); });
}
PyObject* center_of_mass_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<1>(c, n, "center_of_mass", [x](SingleSample& s) { return s.center_of_mass(x[0]); });
}
PyObject* shaking_wrench_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<3>(c, n, "shaking_wrench", [x](SingleSample& s) { return s.shaking_wrench(x[0], x[1], x[2]); });
}
PyObject* frame_placement_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<2>(c, n, "frame_placement", [x](SingleSample& s) { return s.frame_placement(x[0], x[1]); });
}
PyObject* frame_jacobian_call(PyObject* c, PyObject* const* x, Py_ssize_t n) {
  return call<2>(c, n, "frame_jacobian", [x](SingleSample& s) { return s.frame_jacobian(x[0], x[1]); });
}

#define MECHBAL_FASTCALL(fn) reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fn)), METH_FASTCALL
PyMethodDef kCalls[] = {
    {"inverse_dynamics", MECHBAL_FASTCALL(inverse_dynamics_call), "inverse_dynamics(q, v, a) -> tau (dof,) or None"},
    {"gravity_torque", MECHBAL_FASTCALL(gravity_torque_call), "gravity_torque(q) -> G (dof,) or None"},
    {"mass_matrix", MECHBAL_FASTCALL(mass_matrix_call), "mass_matrix(q) -> M (dof, dof) or None"},
    {"center_of_mass", MECHBAL_FASTCALL(center_of_mass_call), "center_of_mass(q) -> c (3,) or None"},
    {"shaking_wrench", MECHBAL_FASTCALL(shaking_wrench_call),
     "shaking_wrench(q, v, a) -> wrench_type or None"},
    {"frame_placement", MECHBAL_FASTCALL(frame_placement_call), "frame_placement(q, frame) -> (4, 4) or None"},
    {"frame_jacobian", MECHBAL_FASTCALL(frame_jacobian_call), "frame_jacobian(q, frame) -> (6, dof) or None"},
};
#undef MECHBAL_FASTCALL

void bind_mechanism_single(py::module_& m) {
  m.def(
      "mechanism_single_sample",
      [](const py::object& model, const py::object& status_ok, const py::type& wrench_type) {
        model.cast<const MechanismModel&>();  // TypeError for anything else
        auto* sample = new SingleSample(model, status_ok, wrench_type);
        py::capsule owner(sample, [](void* p) { delete static_cast<SingleSample*>(p); });
        py::dict calls;
        for (auto& def : kCalls) {
          PyObject* f = PyCFunction_NewEx(&def, owner.ptr(), nullptr);
          if (!f) throw py::error_already_set();
          calls[def.ml_name] = py::reinterpret_steal<py::object>(f);
        }
        return calls;
      },
      py::arg("model"), py::arg("status_ok"), py::arg("wrench_type"),
      "The per-sample calls of a MechanismModel from float64 arrays (what mechbal.Mechanism uses "
      "first), sharing one MechanismData: {name: function}, each returning None when its arguments "
      "are not 1-D C-contiguous float64 numpy arrays of dof values, or the instant is rejected "
      "(the caller then takes its general path). shaking_wrench returns a `wrench_type` (a class "
      "with the fields shaking_force, shaking_moment, linear_momentum, angular_momentum and status, "
      "set without calling its __init__; status: `status_ok`).");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(31, mechanism_single, bind_mechanism_single);

}  // namespace mechbal::pyb
