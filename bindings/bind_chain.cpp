#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "array_checks.hpp"
#include "batch_inverse_dynamics.hpp"
#include "bindings.hpp"
#include "mechbal/control/kdl_chain.hpp"
#include "mechbal/model/serial_chain.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

Eigen::Isometry3d to_iso(const Eigen::Matrix4d& M) {
  Eigen::Isometry3d T;
  T.matrix() = M;
  return T;
}

void check_rows(const Array& a, const char* name, pybind11::ssize_t n) {
  require_shape(a, name, {-1, n});
}

}  // namespace

namespace {

void bind_chain(pybind11::module_& m) {
  py::enum_<JointType>(m, "JointType")
      .value("revolute", JointType::revolute)
      .value("prismatic", JointType::prismatic)
      .value("fixed", JointType::fixed);

  py::class_<JointSpec>(m, "JointSpec", "One joint of a serial chain and the link it moves")
      .def(py::init([](const std::string& name, JointType type, const Array& origin,
                       const Array& axis, double mass, const Array& com, const Array& inertia) {
             JointSpec j;
             j.name = name;
             j.type = type;
             j.origin = to_iso(fixed_matrix<4, 4>(origin, "origin"));
             j.axis = fixed_vector<3>(axis, "axis");
             j.link.mass = mass;
             j.link.inertia_body = fixed_matrix<3, 3>(inertia, "inertia");
             j.com = fixed_vector<3>(com, "com");
             return j;
           }),
           py::arg("name"), py::arg("type"), py::arg("origin"), py::arg("axis"), py::arg("mass"),
           py::arg("com"), py::arg("inertia"),
           "origin: 4x4 transform previous link frame -> joint frame at q=0; axis in the joint "
           "frame; com and inertia (about the centre of mass) in the link frame")
      .def_readonly("name", &JointSpec::name)
      .def_readonly("type", &JointSpec::type)
      .def_property_readonly("origin", [](const JointSpec& j) { return Eigen::Matrix4d(j.origin.matrix()); })
      .def_readonly("axis", &JointSpec::axis)
      .def_property_readonly("mass", [](const JointSpec& j) { return j.link.mass; })
      .def_readonly("com", &JointSpec::com)
      .def_property_readonly("inertia", [](const JointSpec& j) { return j.link.inertia_body; });

  py::class_<ChainModel>(m, "ChainModel", "Immutable, validated serial chain")
      .def(py::init([](std::vector<JointSpec> joints, const py::object& gravity,
                       const py::object& base) {
             const Vec3 g = gravity.is_none() ? Vec3(0.0, 0.0, -9.81)
                                              : fixed_vector<3>(to_real_array(gravity), "gravity");
             const Eigen::Matrix4d B = base.is_none()
                                           ? Eigen::Matrix4d::Identity()
                                           : fixed_matrix<4, 4>(to_real_array(base), "base");
             return ChainModel(std::move(joints), g, to_iso(B));
           }),
           py::arg("joints"), py::arg("gravity") = py::none(), py::arg("base") = py::none(),
           "gravity: (3,) [m/s^2], default (0, 0, -9.81); base: 4x4 transform, default identity")
      .def_property_readonly("dof", &ChainModel::dof)
      .def_property_readonly("joints", &ChainModel::joints)
      .def_property_readonly("gravity", &ChainModel::gravity)
      .def_property_readonly("masses", [](const ChainModel& c) {
        Eigen::VectorXd m(c.dof());
        for (int i = 0; i < c.dof(); ++i) m(i) = c.bodies()[i].mass;
        return m;
      });

  m.def(
      "chain_kinematics",
      [](const ChainModel& model, const Array& q, const Array& qd, const Array& qdd) {
        const auto n = static_cast<pybind11::ssize_t>(model.dof());
        check_rows(q, "q", n);
        const auto N = q.shape(0);
        require_shape(qd, "qd", {N, n});
        require_shape(qdd, "qdd", {N, n});
        OutArray com = make_array({N, n, 3}), vel = make_array({N, n, 3}),
                 acc = make_array({N, n, 3}), rot = make_array({N, n, 3, 3}),
                 w = make_array({N, n, 3}), al = make_array({N, n, 3}),
                 frames = make_array({N, n, 4, 4});
        auto per_instant = make_status_array(N);
        ChainWorkspace ws(model);
        Status status = Status::ok;
        using CVec = Eigen::Map<const Eigen::VectorXd>;
        using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
        using RowMat4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
        for (pybind11::ssize_t k = 0; k < N; ++k) {
          const Status s = chain_kinematics(model, CVec(q.data(k, 0), n), CVec(qd.data(k, 0), n),
                                            CVec(qdd.data(k, 0), n), ws);
          status |= s;
          per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
          for (pybind11::ssize_t i = 0; i < n; ++i) {
            const BodyState& st = ws.states[static_cast<std::size_t>(i)];
            const bool ok = s == Status::ok;
            Eigen::Map<Eigen::Vector3d>(com.mutable_data(k, i, 0)) = ok ? st.com : Vec3::Zero();
            Eigen::Map<Eigen::Vector3d>(vel.mutable_data(k, i, 0)) =
                ok ? st.com_velocity : Vec3::Zero();
            Eigen::Map<Eigen::Vector3d>(acc.mutable_data(k, i, 0)) =
                ok ? st.com_acceleration : Vec3::Zero();
            Eigen::Map<Eigen::Vector3d>(w.mutable_data(k, i, 0)) =
                ok ? st.angular_velocity : Vec3::Zero();
            Eigen::Map<Eigen::Vector3d>(al.mutable_data(k, i, 0)) =
                ok ? st.angular_acceleration : Vec3::Zero();
            Eigen::Map<RowMat3>(rot.mutable_data(k, i, 0, 0)) =
                ok ? st.rotation : Mat3::Identity();
            Eigen::Map<RowMat4>(frames.mutable_data(k, i, 0, 0)) =
                ok ? ws.frames[static_cast<std::size_t>(i)].matrix() : Eigen::Matrix4d::Identity();
          }
        }
        py::dict out;
        out["com"] = com;
        out["com_velocity"] = vel;
        out["com_acceleration"] = acc;
        out["rotation"] = rot;
        out["angular_velocity"] = w;
        out["angular_acceleration"] = al;
        out["frames"] = frames;
        out["status"] = status;
        out["status_per_instant"] = per_instant;
        return out;
      },
      py::arg("model"), py::arg("q"), py::arg("qd"), py::arg("qdd"),
      "Every link's motion in the base frame for N joint states (q, qd, qdd each (N, dof)). "
      "Returns a dict of arrays (N, dof, 3) / (N, dof, 3, 3) / frames (N, dof, 4, 4), "
      "status_per_instant (N,) and their OR, status; a failed instant (non-finite input, or motion "
      "that overflows: out_of_range) gives identity poses and zero motion.");

  py::class_<KdlChainDynamics, InverseDynamics>(m, "KdlChainDynamics",
                               "Joint-space dynamics of a ChainModel through Orocos KDL")
      .def(py::init<const ChainModel&>(), py::arg("model"))
      .def_property_readonly("dof", &KdlChainDynamics::dof)
      .def(
          "inverse_dynamics",
          [](KdlChainDynamics& d, const Array& q, const Array& qd, const Array& qdd) {
            return batch_inverse_dynamics(d, q, qd, qdd);
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "Joint torques (N, dof) and the wrench the base exerts on the chain (support_force, "
          "support_moment about the base origin, (N, 3)) by KDL's ChainIdSolver_RNE.")
      .def(
          "mass_matrix",
          [](KdlChainDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = vector_arg(q, "q", d.dof(), false, "one value per joint");
            Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d.dof(), d.dof());
            raise_unless_ok(d.mass_matrix(q_, M), "KdlChainDynamics.mass_matrix");
            return M;
          },
          py::arg("q"), "Mass matrix M(q) (dof, dof); ValueError for non-finite or overflowing q")
      .def(
          "coriolis",
          [](KdlChainDynamics& d, const Array& q, const Array& qd) {
            const Eigen::VectorXd q_ = vector_arg(q, "q", d.dof(), false, "one value per joint");
            const Eigen::VectorXd qd_ = vector_arg(qd, "qd", d.dof(), false, "one value per joint");
            Eigen::VectorXd c = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.coriolis(q_, qd_, c), "KdlChainDynamics.coriolis");
            return c;
          },
          py::arg("q"), py::arg("qd"), "Coriolis and centrifugal torques C(q, qd) qd")
      .def(
          "gravity",
          [](KdlChainDynamics& d, const Array& q) {
            const Eigen::VectorXd q_ = vector_arg(q, "q", d.dof(), false, "one value per joint");
            Eigen::VectorXd g = Eigen::VectorXd::Zero(d.dof());
            raise_unless_ok(d.gravity(q_, g), "KdlChainDynamics.gravity");
            return g;
          },
          py::arg("q"), "Gravity torques G(q)");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(20, chain, bind_chain);

}  // namespace mechbal::pyb
