// pybind11 glue for serial arms with counter-rotating discs (Coutinho & Hess Coelho) and the
// decoupled joint controller. Conversion only: no logic.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "controller_step.hpp"
#include "mechbal/computed_torque.hpp"
#include "mechbal/decoupled_control.hpp"
#include "mechbal/disc_arm.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

using CVec = Eigen::Map<const Eigen::VectorXd>;

void bind_discs(py::module_& m) {
  py::class_<DiscSpec>(m, "DiscSpec",
                       "Counter-rotating disc carried by a link, driven at ratio * qd[joint]")
      .def(py::init([](const std::string& name, int carrier, int joint, const Array& axis,
                       double ratio, const Array& inertia) {
             DiscSpec d;
             d.name = name;
             d.carrier = carrier;
             d.joint = joint;
             d.axis = fixed_vector<3>(axis, "axis");
             d.ratio = ratio;
             d.inertia = fixed_vector<3>(inertia, "inertia");
             return d;
           }),
           py::arg("name"), py::arg("carrier"), py::arg("joint"), py::arg("axis"),
           py::arg("ratio"), py::arg("inertia"),
           "carrier/joint: 0-based indices; axis in the carrier frame; inertia: principal central "
           "moments in the disc frame [kg m^2] (mass lumped into the carrier link)")
      .def_readonly("name", &DiscSpec::name)
      .def_readonly("carrier", &DiscSpec::carrier)
      .def_readonly("joint", &DiscSpec::joint)
      .def_readonly("axis", &DiscSpec::axis)
      .def_readonly("ratio", &DiscSpec::ratio)
      .def_readonly("inertia", &DiscSpec::inertia);

  py::class_<DiscArmDynamics>(m, "DiscArmDynamics",
                              "Serial arm + discs by the coupling-matrix method (A° = 1), "
                              "evaluated per tick: M'(q), v'(q, qd), g'(q)")
      .def(py::init<ChainModel, std::vector<DiscSpec>>(), py::arg("chain"), py::arg("discs"))
      .def_property_readonly("dof", &DiscArmDynamics::dof)
      .def_property_readonly("discs", &DiscArmDynamics::discs)
      .def(
          "evaluate",
          [](DiscArmDynamics& d, const Array& q, const Array& qd) {
            const auto n = static_cast<py::ssize_t>(d.dof());
            require_shape(q, "q", {-1, n});
            const auto N = q.shape(0);
            require_shape(qd, "qd", {N, n});
            OutArray M = make_array({N, n, n}), v = make_array({N, n}), g = make_array({N, n});
            auto per_instant = make_status_array(N);
            Eigen::MatrixXd Mk(n, n);
            Eigen::VectorXd vk(n), gk(n);
            Status status = Status::ok;
            using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
            for (py::ssize_t k = 0; k < N; ++k) {
              const Status s = d.evaluate(CVec(q.data(k, 0), n), CVec(qd.data(k, 0), n), Mk, vk, gk);
              if (s != Status::ok) {
                Mk.setZero();
                vk.setZero();
                gk.setZero();
              }
              status |= s;
              per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
              Eigen::Map<RowMat>(M.mutable_data(k, 0, 0), n, n) = Mk;
              Eigen::Map<Eigen::VectorXd>(v.mutable_data(k, 0), n) = vk;
              Eigen::Map<Eigen::VectorXd>(g.mutable_data(k, 0), n) = gk;
            }
            py::dict out;
            out["mass"] = M;
            out["velocity"] = v;
            out["gravity"] = g;
            out["status"] = status;
            out["status_per_instant"] = per_instant;
            return out;
          },
          py::arg("q"), py::arg("qd"),
          "For N states (q, qd each (N, dof)): {'mass' (N, dof, dof), 'velocity' (N, dof), "
          "'gravity' (N, dof), 'status_per_instant' (N,), 'status' (OR)}; failed states give "
          "zeros")
      .def(
          "inverse_dynamics",
          [](DiscArmDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            const auto n = static_cast<py::ssize_t>(d.dof());
            require_shape(q, "q", {-1, n});
            const auto N = q.shape(0);
            require_shape(qd, "qd", {N, n});
            require_shape(qdd, "qdd", {N, n});
            OutArray tau = make_array({N, n});
            auto per_instant = make_status_array(N);
            Status status = Status::ok;
            for (py::ssize_t k = 0; k < N; ++k) {
              Eigen::Map<Eigen::VectorXd> t(tau.mutable_data(k, 0), n);
              const Status s = d.inverse_dynamics(CVec(q.data(k, 0), n), CVec(qd.data(k, 0), n),
                                                  CVec(qdd.data(k, 0), n), t);
              if (s != Status::ok) t.setZero();
              status |= s;
              per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
            }
            py::dict out;
            out["tau"] = tau;
            out["status"] = status;
            out["status_per_instant"] = per_instant;
            return out;
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "Joint torques (N, dof): {'tau', 'status_per_instant' (N,), 'status' (OR)}");

  // ComputedTorque is bound in bind_arm2dof.cpp; add the disc-arm back end to its constructors.
  auto ct = py::reinterpret_borrow<py::class_<ComputedTorque>>(m.attr("ComputedTorque"));
  ct.def(py::init(&make_computed_torque<DiscArmDynamics>), py::arg("model"), py::arg("kp"),
         py::arg("kd"), py::arg("torque_limit") = py::none(), MECHBAL_JOINT_RANGE_ARGS,
         py::keep_alive<1, 2>());

  py::class_<DecoupledJointController, JointController> dc(
      m, "DecoupledJointController",
      "tau_i = k_i (qdd_d + Kp e + Kd e') for a dynamically balanced arm (Coutinho & Hess Coelho "
      "eqs 15, 26, 36)");
  dc.def(py::init([](const Array& k, const Array& kp, const Array& kd,
                       const py::object& torque_limit, double max_position, double max_speed,
                       double max_acceleration) {
             const Eigen::VectorXd limit =
                 torque_limit.is_none()
                     ? Eigen::VectorXd()
                     : vector_arg(to_real_array(torque_limit), "torque_limit", -1);
             return DecoupledJointController(
                 vector_arg(k, "k", -1), vector_arg(kp, "kp", -1), vector_arg(kd, "kd", -1), limit,
                 joint_input_range(max_position, max_speed, max_acceleration));
           }),
           py::arg("k"), py::arg("kp"), py::arg("kd"), py::arg("torque_limit") = py::none(),
           MECHBAL_JOINT_RANGE_ARGS,
           "k, kp, kd: one value per joint; torque_limit: one per joint (default and +inf: mechbal "
           "default_torque_limit, 1e4); max_position, max_speed, max_acceleration: the input range "
           "of a tick (beyond it: the held command and Status.out_of_range)");
  dc.def_property_readonly("torque_limit", [](const DecoupledJointController& c) {
        return Eigen::VectorXd(c.torque_limit());
      })
      .def_property_readonly("dof", &DecoupledJointController::dof)
      .def_property_readonly("k", [](const DecoupledJointController& c) {
        return Eigen::VectorXd(c.k());
      })
      .def_property_readonly("last_command", [](const DecoupledJointController& c) {
        return Eigen::VectorXd(c.last_command());
      });
  bind_joint_controller_ticks<DecoupledJointController>(dc);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(50, discs, bind_discs);

}  // namespace mechbal::pyb
