#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/rnea.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

using CVec = Eigen::Map<const Eigen::VectorXd>;

Eigen::VectorXd one_state(const RneChainDynamics& d, const Eigen::VectorXd& v, const char* name) {
  if (v.size() != d.dof()) {
    throw py::value_error(std::string(name) + " must have " + std::to_string(d.dof()) +
                          " values, got " + std::to_string(v.size()));
  }
  return v;
}

void bind_rnea(py::module_& m) {
  py::class_<RneChainDynamics, InverseDynamics>(
      m, "RneChainDynamics",
      "Joint-space dynamics of a ChainModel by mechbal's own recursive Newton-Euler (inverse "
      "dynamics, base support wrench) and composite rigid body algorithm (mass matrix)")
      .def(py::init<const ChainModel&>(), py::arg("model"))
      .def_property_readonly("dof", &RneChainDynamics::dof)
      .def(
          "inverse_dynamics",
          [](RneChainDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            const auto n = static_cast<py::ssize_t>(d.dof());
            require_shape(q, "q", {-1, n});
            const auto N = q.shape(0);
            require_shape(qd, "qd", {N, n});
            require_shape(qdd, "qdd", {N, n});
            Array tau = make_array({N, n}), F = make_array({N, 3}), M = make_array({N, 3});
            Status status = Status::ok;
            for (py::ssize_t k = 0; k < N; ++k) {
              Eigen::Map<Eigen::VectorXd> t(tau.mutable_data(k, 0), n);
              Vec3 f, mo;
              const Status s = d.inverse_dynamics(CVec(q.data(k, 0), n), CVec(qd.data(k, 0), n),
                                                  CVec(qdd.data(k, 0), n), t, &f, &mo);
              if (s != Status::ok) {
                t.setZero();
                f.setZero();
                mo.setZero();
              }
              status |= s;
              Eigen::Map<Eigen::Vector3d>(F.mutable_data(k, 0)) = f;
              Eigen::Map<Eigen::Vector3d>(M.mutable_data(k, 0)) = mo;
            }
            py::dict out;
            out["tau"] = tau;
            out["support_force"] = F;
            out["support_moment"] = M;
            out["status"] = status;
            return out;
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, "
          "support_moment about the base origin, (N, 3)); q, qd, qdd each (N, dof). Instants with "
          "non-finite input give zeros and set their flag in `status`.")
      .def(
          "mass_matrix",
          [](RneChainDynamics& d, const Eigen::VectorXd& q) {
            one_state(d, q, "q");
            Eigen::MatrixXd M(d.dof(), d.dof());
            if (d.mass_matrix(q, M) != Status::ok) throw py::value_error("q must be finite");
            return M;
          },
          py::arg("q"), "Mass matrix M(q) (dof, dof) by the composite rigid body algorithm")
      .def(
          "gravity",
          [](RneChainDynamics& d, const Eigen::VectorXd& q) {
            one_state(d, q, "q");
            Eigen::VectorXd g(d.dof());
            if (d.gravity(q, g) != Status::ok) throw py::value_error("q must be finite");
            return g;
          },
          py::arg("q"), "Gravity torques G(q)")
      .def(
          "bias",
          [](RneChainDynamics& d, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
            one_state(d, q, "q");
            one_state(d, qd, "qd");
            Eigen::VectorXd b(d.dof());
            if (d.bias(q, qd, b) != Status::ok) throw py::value_error("q and qd must be finite");
            return b;
          },
          py::arg("q"), py::arg("qd"), "Bias torques C(q, qd) qd + G(q)")
      .def(
          "coriolis",
          [](RneChainDynamics& d, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
            one_state(d, q, "q");
            one_state(d, qd, "qd");
            Eigen::VectorXd c(d.dof());
            if (d.coriolis(q, qd, c) != Status::ok) throw py::value_error("q and qd must be finite");
            return c;
          },
          py::arg("q"), py::arg("qd"), "Coriolis and centrifugal torques C(q, qd) qd");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(25, rnea, bind_rnea);

}  // namespace mechbal::pyb
