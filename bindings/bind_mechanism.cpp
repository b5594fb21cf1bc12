// pybind11 glue of the general mechanism model (model.hpp, data.hpp, algorithm/*.hpp): the
// description types, the validated model, and every algorithm in batch over (N, dof) arrays in one
// C++ call. Per-instant status arrays; an instant with bad input or a non-finite result gives NaN
// (rotations: the identity) and its flag, never zeros that pass for a result, never memory that was
// not written. Python's mechbal.Mechanism wraps these.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "reaction_bounds.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/loops.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/regressor.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/algorithm/springs.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

using StatusArray = py::array_t<std::uint32_t>;
using CVec = Eigen::Map<const Eigen::VectorXd>;

Eigen::Isometry3d to_isometry(const Eigen::Matrix4d& T, const char* field) {
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12) {
    throw py::value_error(std::string(field) + ": last row of a homogeneous transform must be [0, 0, 0, 1]");
  }
  Eigen::Isometry3d X;
  X.matrix() = T;
  return X;
}

/// Row k of a C-contiguous (N, n) array (valid for n = 0 too).
const double* row(const Array& a, py::ssize_t k) { return a.data() + k * a.shape(1); }

/// Runs `fn(k, data) -> Status` for each instant, then `write(k, data, ok)`; instants whose result
/// is not finite are flagged out_of_range and written as NaN (write gets ok = false).
template <typename Fn, typename Finite, typename Write>
StatusArray run_batch(const MechanismModel& model, py::ssize_t N, Fn fn, Finite finite, Write write) {
  MechanismData data(model);
  StatusArray status(N);
  auto st = status.mutable_unchecked<1>();
  {
    py::gil_scoped_release release;
    for (py::ssize_t k = 0; k < N; ++k) {
      Status s = fn(k, data);
      if (s == Status::ok && !finite(data)) s = Status::out_of_range;
      st(k) = static_cast<std::uint32_t>(s);
      write(k, data, s == Status::ok);
    }
  }
  return status;
}

/// What a failed instant's values read: NaN (never a zero that passes for a result).
constexpr double kFailed = std::numeric_limits<double>::quiet_NaN();

template <typename Matrix>
void put(Array& out, py::ssize_t k, const Matrix& value, bool ok) {
  double* dst = out.mutable_data(k);
  // the whole row of `out`: a failed instant's value may never have been sized (a quadratic
  // result whose algorithm refused the input before sizing it)
  const py::ssize_t n = out.shape(0) > 0 ? out.size() / out.shape(0) : 0;
  if (!ok || static_cast<py::ssize_t>(value.size()) != n) {
    std::fill(dst, dst + n, kFailed);
    return;
  }
  // row-major copy of an Eigen (column-major) matrix
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      dst, value.rows(), value.cols()) = value;
}

void put3(Array& out, py::ssize_t k, py::ssize_t j, const Vec3& v, bool ok) {
  double* dst = out.mutable_data(k, j);
  for (int i = 0; i < 3; ++i) dst[i] = ok ? v(i) : kFailed;
}

void put33(Array& out, py::ssize_t k, py::ssize_t j, const Mat3& R, bool ok) {
  double* dst = out.mutable_data(k, j);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) dst[3 * r + c] = ok ? R(r, c) : (r == c ? 1.0 : 0.0);  // identity
}

bool finite_wrench(const MechanismData& d) {
  return d.shaking.force.allFinite() && d.shaking.moment.allFinite() &&
         d.shaking.linear_momentum.allFinite() && d.shaking.angular_momentum.allFinite();
}

py::dict kinematics_batch(const MechanismModel& model, const Array& q, const Array& v, const Array& a) {
  const auto N = batch_rows(model.dof(), {{q, "q"}, {v, "v"}, {a, "a"}});
  const py::ssize_t B = model.num_bodies(), L = model.num_links(), F = model.num_frames();
  Array com = make_array({N, B, 3}), com_v = make_array({N, B, 3}), com_a = make_array({N, B, 3}),
        rot = make_array({N, B, 3, 3}), w = make_array({N, B, 3}), al = make_array({N, B, 3}),
        lrot = make_array({N, L, 3, 3}), lpos = make_array({N, L, 3}),
        frames = make_array({N, F, 4, 4});
  auto status = run_batch(
      model, N,
      [&](py::ssize_t k, MechanismData& d) {
        const auto n = static_cast<Eigen::Index>(model.dof());
        return forward_kinematics(model, d, CVec(row(q, k), n), CVec(row(v, k), n),
                                  CVec(row(a, k), n));
      },
      [&](const MechanismData& d) {
        for (const auto& s : d.body_states) {
          if (!s.com.allFinite() || !s.com_acceleration.allFinite() || !s.angular_acceleration.allFinite() ||
              !s.com_velocity.allFinite() || !s.angular_velocity.allFinite()) {
            return false;
          }
        }
        return true;
      },
      [&](py::ssize_t k, const MechanismData& d, bool ok) {
        for (py::ssize_t b = 0; b < B; ++b) {
          const auto& s = d.body_states[static_cast<std::size_t>(b)];
          put3(com, k, b, s.com, ok);
          put3(com_v, k, b, s.com_velocity, ok);
          put3(com_a, k, b, s.com_acceleration, ok);
          put3(w, k, b, s.angular_velocity, ok);
          put3(al, k, b, s.angular_acceleration, ok);
          put33(rot, k, b, s.rotation, ok);
        }
        for (py::ssize_t l = 0; l < L; ++l) {
          put33(lrot, k, l, d.link_rotation[static_cast<std::size_t>(l)], ok);
          put3(lpos, k, l, d.link_position[static_cast<std::size_t>(l)], ok);
        }
        for (py::ssize_t f = 0; f < F; ++f) {
          double* dst = frames.mutable_data(k, f);
          const Eigen::Matrix4d T = d.frame_placements[static_cast<std::size_t>(f)].matrix();
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) dst[4 * r + c] = ok ? T(r, c) : (r == c ? 1.0 : 0.0);
        }
      });
  py::dict out;
  out["com"] = com;
  out["com_velocity"] = com_v;
  out["com_acceleration"] = com_a;
  out["rotation"] = rot;
  out["angular_velocity"] = w;
  out["angular_acceleration"] = al;
  out["link_rotation"] = lrot;
  out["link_position"] = lpos;
  out["frame_placement"] = frames;
  out["status"] = status;
  return out;
}

/// Batch of an algorithm with a vector or matrix result held in `data.*member`.
template <typename Member, typename Fn>
py::dict matrix_batch(const MechanismModel& model, py::ssize_t N, py::ssize_t rows, py::ssize_t cols,
                      bool vector, const char* name, Member member, Fn fn) {
  Array out = vector ? make_array({N, rows}) : make_array({N, rows, cols});
  auto status = run_batch(
      model, N, fn, [&](const MechanismData& d) { return (d.*member).allFinite(); },
      [&](py::ssize_t k, const MechanismData& d, bool ok) { put(out, k, d.*member, ok); });
  py::dict result;
  result[name] = out;
  result["status"] = status;
  return result;
}

void bind_mechanism(py::module_& m) {
  py::enum_<JointType>(m, "JointType")
      .value("revolute", JointType::revolute)
      .value("prismatic", JointType::prismatic)
      .value("fixed", JointType::fixed);

  py::class_<Joint>(m, "Joint",
                    "One joint of a MechanismDescription; it moves the link of the same name "
                    "(model.hpp for frames and conventions)")
      .def(py::init([](const std::string& name, JointType type, const std::string& parent,
                       const Array& placement, const Array& axis, double lower,
                       double upper, double velocity_limit, double effort_limit,
                       const std::string& mimic_joint, double mimic_ratio, double mimic_offset) {
             Joint j;
             j.name = name;
             j.type = type;
             j.parent = parent;
             j.placement = to_isometry(fixed_matrix<4, 4>(placement, "placement"), "placement");
             j.axis = fixed_vector<3>(axis, "axis");
             j.lower = lower;
             j.upper = upper;
             j.velocity_limit = velocity_limit;
             j.effort_limit = effort_limit;
             j.mimic_joint = mimic_joint;
             j.mimic_ratio = mimic_ratio;
             j.mimic_offset = mimic_offset;
             return j;
           }),
           py::arg("name"), py::arg("type") = JointType::revolute, py::arg("parent") = "base",
           py::arg("placement") = Eigen::Matrix4d::Identity(), py::arg("axis") = Eigen::Vector3d::UnitZ(),
           py::arg("lower") = -std::numeric_limits<double>::infinity(),
           py::arg("upper") = std::numeric_limits<double>::infinity(),
           py::arg("velocity_limit") = std::numeric_limits<double>::infinity(),
           py::arg("effort_limit") = std::numeric_limits<double>::infinity(),
           py::arg("mimic_joint") = "", py::arg("mimic_ratio") = 1.0, py::arg("mimic_offset") = 0.0)
      .def_readonly("name", &Joint::name)
      .def_readonly("type", &Joint::type)
      .def_readonly("parent", &Joint::parent)
      .def_property_readonly("placement", [](const Joint& j) { return Eigen::Matrix4d(j.placement.matrix()); })
      .def_readonly("axis", &Joint::axis)
      .def_readonly("lower", &Joint::lower)
      .def_readonly("upper", &Joint::upper)
      .def_readonly("velocity_limit", &Joint::velocity_limit)
      .def_readonly("effort_limit", &Joint::effort_limit)
      .def_readonly("mimic_joint", &Joint::mimic_joint)
      .def_readonly("mimic_ratio", &Joint::mimic_ratio)
      .def_readonly("mimic_offset", &Joint::mimic_offset)
      .def("__repr__", [](const Joint& j) { return "<Joint " + j.name + " parent=" + j.parent + ">"; });

  py::class_<Body>(m, "Body", "A named rigid body on a link: mass [kg], centre of mass [m] and inertia "
                              "about it [kg m^2], both in the link frame")
      .def(py::init([](const std::string& name, const std::string& link, double mass,
                       const Array& com, const Array& inertia, const std::string& kind) {
             return Body{name, kind, link, mass, fixed_vector<3>(com, "com"), fixed_matrix<3, 3>(inertia, "inertia")};
           }),
           py::arg("name"), py::arg("link"), py::arg("mass"), py::arg("com") = Eigen::Vector3d::Zero(),
           py::arg("inertia") = Eigen::Matrix3d::Zero(), py::arg("kind") = "link")
      .def_readonly("name", &Body::name)
      .def_readonly("kind", &Body::kind)
      .def_readonly("link", &Body::link)
      .def_readonly("mass", &Body::mass)
      .def_readonly("com", &Body::com)
      .def_readonly("inertia", &Body::inertia)
      .def("__repr__", [](const Body& b) { return "<Body " + b.name + " on " + b.link + ">"; });

  py::class_<Frame>(m, "Frame", "A named frame on a link (placement in the link frame)")
      .def(py::init([](const std::string& name, const std::string& link, const Array& placement) {
             return Frame{name, link, to_isometry(fixed_matrix<4, 4>(placement, "placement"), "placement")};
           }),
           py::arg("name"), py::arg("link"), py::arg("placement") = Eigen::Matrix4d::Identity())
      .def_readonly("name", &Frame::name)
      .def_readonly("link", &Frame::link)
      .def_property_readonly("placement", [](const Frame& f) { return Eigen::Matrix4d(f.placement.matrix()); });

  py::enum_<LoopType>(m, "LoopType", "Loop-closure types (algorithm/loops.hpp)")
      .value("point", LoopType::point)
      .value("planar_point", LoopType::planar_point)
      .value("axis", LoopType::axis)
      .value("weld", LoopType::weld);

  py::class_<LoopConstraint>(m, "LoopConstraint", "A loop closure between two named frames")
      .def(py::init([](const std::string& name, LoopType type, const std::string& a, const std::string& b) {
             return LoopConstraint{name, type, a, b};
           }),
           py::arg("name"), py::arg("type"), py::arg("frame_a"), py::arg("frame_b"))
      .def_readonly("name", &LoopConstraint::name)
      .def_readonly("type", &LoopConstraint::type)
      .def_readonly("frame_a", &LoopConstraint::frame_a)
      .def_readonly("frame_b", &LoopConstraint::frame_b);

  py::class_<Spring>(m, "Spring",
                     "A linear spring between anchor A on link_a and anchor B on link_b (anchors in the "
                     "link frames [m]): count identical springs of rate [N/m] each, carrying preload [N] at "
                     "the anchor distance free_length [m], through a block and tackle of ratio pulley_ratio "
                     "(model.hpp)")
      .def(py::init([](const std::string& name, const std::string& link_a, const Array& anchor_a,
                       const std::string& link_b, const Array& anchor_b, double rate, double free_length,
                       double preload, int count, double pulley_ratio) {
             return Spring{name, link_a, fixed_vector<3>(anchor_a, "anchor_a"), link_b, fixed_vector<3>(anchor_b, "anchor_b"),
                           rate, free_length, preload, count, pulley_ratio};
           }),
           py::arg("name"), py::arg("link_a"), py::arg("anchor_a"), py::arg("link_b"), py::arg("anchor_b"),
           py::arg("rate"), py::arg("free_length") = 0.0, py::arg("preload") = 0.0, py::arg("count") = 1,
           py::arg("pulley_ratio") = 1.0)
      .def_readonly("name", &Spring::name)
      .def_readonly("link_a", &Spring::link_a)
      .def_readonly("anchor_a", &Spring::anchor_a)
      .def_readonly("link_b", &Spring::link_b)
      .def_readonly("anchor_b", &Spring::anchor_b)
      .def_readonly("rate", &Spring::rate)
      .def_readonly("free_length", &Spring::free_length)
      .def_readonly("preload", &Spring::preload)
      .def_readonly("count", &Spring::count)
      .def_readonly("pulley_ratio", &Spring::pulley_ratio)
      .def_property_readonly("equivalent_rate",
                             [](const Spring& sp) { return sp.count * sp.rate / (sp.pulley_ratio * sp.pulley_ratio); })
      .def("__repr__", [](const Spring& sp) { return "<Spring " + sp.name + " " + sp.link_a + " -> " + sp.link_b + ">"; });

  py::class_<MechanismDescription>(m, "MechanismDescription",
                                   "Joints, bodies, frames, gravity and loop closures: what a MechanismModel "
                                   "is built from")
      .def(py::init([](std::vector<Joint> joints, std::vector<Body> bodies, std::vector<Frame> frames,
                       const Array& gravity, const std::string& root_name,
                       std::vector<LoopConstraint> loops, std::vector<std::string> actuated,
                       std::vector<Spring> springs) {
             MechanismDescription d;
             d.springs = std::move(springs);
             d.joints = std::move(joints);
             d.bodies = std::move(bodies);
             d.frames = std::move(frames);
             d.gravity = fixed_vector<3>(gravity, "gravity");
             d.root_name = root_name;
             d.loops = std::move(loops);
             d.actuated = std::move(actuated);
             return d;
           }),
           py::arg("joints"), py::arg("bodies") = std::vector<Body>{}, py::arg("frames") = std::vector<Frame>{},
           py::arg("gravity") = Eigen::Vector3d(0.0, 0.0, -9.81), py::arg("root_name") = "base",
           py::arg("loops") = std::vector<LoopConstraint>{}, py::arg("actuated") = std::vector<std::string>{},
           py::arg("springs") = std::vector<Spring>{})
      .def_readonly("loops", &MechanismDescription::loops)
      .def_readonly("springs", &MechanismDescription::springs)
      .def_readonly("actuated", &MechanismDescription::actuated)
      .def_readonly("joints", &MechanismDescription::joints)
      .def_readonly("bodies", &MechanismDescription::bodies)
      .def_readonly("frames", &MechanismDescription::frames)
      .def_readonly("gravity", &MechanismDescription::gravity)
      .def_readonly("root_name", &MechanismDescription::root_name);

  py::class_<MechanismModel>(m, "MechanismModel",
                             "The validated general mechanism model (C++ mechbal::MechanismModel). Use "
                             "mechbal.Mechanism for the Python API.")
      .def(py::init([](MechanismDescription d) {
             try {
               return MechanismModel(std::move(d));
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }),
           py::arg("description"))
      .def_property_readonly("dof", &MechanismModel::dof)
      .def_property_readonly("num_links", &MechanismModel::num_links)
      .def_property_readonly("num_bodies", &MechanismModel::num_bodies)
      .def_property_readonly("num_frames", &MechanismModel::num_frames)
      .def_property_readonly("gravity", &MechanismModel::gravity)
      .def_property_readonly("total_mass", &MechanismModel::total_mass)
      .def_property_readonly("root_name", &MechanismModel::root_name)
      .def_property_readonly("description", &MechanismModel::description)
      .def_property_readonly("coordinate_names", &MechanismModel::coordinate_names)
      .def_property_readonly("is_serial_chain", &MechanismModel::is_serial_chain)
      .def_property_readonly("is_closed", &MechanismModel::is_closed)
      .def_property_readonly("num_constraints", &MechanismModel::num_constraints)
      .def_property_readonly("actuated_coordinates", &MechanismModel::actuated_coordinates)
      .def_property_readonly("passive_coordinates", &MechanismModel::passive_coordinates)
      .def_property_readonly("link_names",
                             [](const MechanismModel& mo) {
                               std::vector<std::string> n;
                               for (int l = 0; l < mo.num_links(); ++l) n.push_back(mo.link_name(l));
                               return n;
                             })
      .def_property_readonly("link_parents",
                             [](const MechanismModel& mo) {
                               std::vector<int> p;
                               for (int l = 0; l < mo.num_links(); ++l) p.push_back(mo.parent(l));
                               return p;
                             })
      .def_property_readonly("body_names",
                             [](const MechanismModel& mo) {
                               std::vector<std::string> n;
                               for (const auto& b : mo.bodies()) n.push_back(b.name);
                               return n;
                             })
      .def_property_readonly("body_links",
                             [](const MechanismModel& mo) {
                               std::vector<int> n;
                               for (int b = 0; b < mo.num_bodies(); ++b) n.push_back(mo.body_link(b));
                               return n;
                             })
      .def_property_readonly("frame_names",
                             [](const MechanismModel& mo) {
                               std::vector<std::string> n;
                               for (int f = 0; f < mo.num_frames(); ++f) n.push_back(mo.frame(f).name);
                               return n;
                             })
      .def_property_readonly("bodies", &MechanismModel::bodies)
      .def_property_readonly("springs", &MechanismModel::springs)
      .def_property_readonly("num_springs", &MechanismModel::num_springs)
      .def_property_readonly("spring_names",
                             [](const MechanismModel& mo) {
                               std::vector<std::string> n;
                               for (const auto& sp : mo.springs()) n.push_back(sp.name);
                               return n;
                             })
      .def_property_readonly("spring_links",
                             [](const MechanismModel& mo) {
                               std::vector<std::pair<int, int>> n;
                               for (int i = 0; i < mo.num_springs(); ++i) {
                                 n.emplace_back(mo.spring_constants(i).link_a, mo.spring_constants(i).link_b);
                               }
                               return n;
                             })
      .def("spring_index", &MechanismModel::spring_index, py::arg("name"))
      .def_property_readonly("lower_limits", &MechanismModel::lower_limits)
      .def_property_readonly("upper_limits", &MechanismModel::upper_limits)
      .def_property_readonly("velocity_limits", &MechanismModel::velocity_limits)
      .def_property_readonly("effort_limits", &MechanismModel::effort_limits)
      .def("frame_index", &MechanismModel::frame_index, py::arg("name"))
      .def("link_index", &MechanismModel::link_index, py::arg("name"))
      .def("body_index", &MechanismModel::body_index, py::arg("name"))
      .def(py::pickle(
          [](const MechanismModel& mo) { return py::make_tuple(mo.description()); },
          [](const py::tuple& t) { return MechanismModel(t[0].cast<MechanismDescription>()); }));

  m.def(
      "name_problem", [](const std::string& name) { return name_problem(name); }, py::arg("name"),
      "Why `name` (UTF-8 bytes or str) is not a valid name of the model, or '' when it is: the "
      "character set of names (docs/case_format.md, Names).");

  // ---- closed loops: actuated (N, na) in; q0 (dof,) the warm start of the first instant ----
  m.def(
      "mechanism_closed_motion",
      [](const MechanismModel& mo, const Array& qa, const Array& va, const Array& aa, const Array& q0,
         int max_iterations, double tolerance, double singular_rcond, bool dynamics) {
        const auto na = static_cast<py::ssize_t>(mo.num_actuated());
        const auto n = static_cast<py::ssize_t>(mo.dof());
        const auto N = batch_rows(na, {{qa, "q_actuated"}, {va, "v_actuated"}, {aa, "a_actuated"}});
        require_shape(q0, "q_guess", {n});
        if (max_iterations < 1 || max_iterations > 1000) {
          throw py::value_error("max_iterations must be in 1..1000, got " + std::to_string(max_iterations));
        }
        LoopSolveOptions opt;
        opt.max_iterations = max_iterations;
        opt.tolerance = tolerance;
        opt.singular_rcond = singular_rcond;
        Array Q = make_array({N, n}), V = make_array({N, n}), A = make_array({N, n}), F = make_array({N, na}),
              Cm = make_array({N, n, na});
        py::array_t<double> rcond(N), residual(N);
        py::array_t<std::int32_t> iterations(N);
        StatusArray status(N);
        {
          MechanismData d(mo);
          Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(q0.data(), n);
          // rows are independent: each starts from the last good solution (or the guess), so a
          // failed row never poisons the ones after it
          Eigen::VectorXd last_good = q;
          auto st = status.mutable_unchecked<1>();
          auto rc = rcond.mutable_unchecked<1>();
          auto rs = residual.mutable_unchecked<1>();
          auto it = iterations.mutable_unchecked<1>();
          py::gil_scoped_release release;
          for (py::ssize_t k = 0; k < N; ++k) {
            const CVec qk(row(qa, k), na), vk(row(va, k), na), ak(row(aa, k), na);
            q = last_good;
            Status s = dynamics ? closed_inverse_dynamics(mo, d, qk, vk, ak, q, opt)
                                : closed_motion(mo, d, qk, vk, ak, q, opt);
            const bool solved = !has(s, Status::solver_error) && !has(s, Status::bad_size) &&
                                !has(s, Status::non_finite_input);
            bool finite = solved && d.closed_velocity.allFinite() && d.closed_acceleration.allFinite() &&
                          (!dynamics || d.actuated_force.allFinite());
            if (solved && !finite) s |= Status::out_of_range;
            if (finite && q.allFinite()) last_good = q;
            st(k) = static_cast<std::uint32_t>(s);
            rc(k) = d.loop_rcond;
            rs(k) = d.loop_residual_norm;
            it(k) = d.loop_iterations;
            double* qo = Q.mutable_data(k);
            double* vo = V.mutable_data(k);
            double* ao = A.mutable_data(k);
            for (py::ssize_t i = 0; i < n; ++i) {
              qo[i] = solved ? q(i) : kFailed;
              vo[i] = finite ? d.closed_velocity(i) : kFailed;
              ao[i] = finite ? d.closed_acceleration(i) : kFailed;
            }
            double* fo = F.mutable_data(k);
            for (py::ssize_t i = 0; i < na; ++i) fo[i] = finite && dynamics ? d.actuated_force(i) : kFailed;
            put(Cm, k, d.loop_projection, finite);
          }
        }
        py::dict out;
        out["q"] = Q;
        out["v"] = V;
        out["a"] = A;
        if (dynamics) out["actuated_force"] = F;
        out["projection"] = Cm;
        out["rcond"] = rcond;
        out["residual"] = residual;
        out["iterations"] = iterations;
        out["status"] = status;
        return out;
      },
      py::arg("model"), py::arg("q_actuated"), py::arg("v_actuated"), py::arg("a_actuated"), py::arg("q_guess"),
      py::arg("max_iterations") = 50, py::arg("tolerance") = 1e-13, py::arg("singular_rcond") = 1e-7,
      py::arg("dynamics") = false,
      "Solve the loops along a motion of the actuated coordinates (each instant warm-starts the next): "
      "full q, v, a (N, dof), rcond of A°, residual, iterations and status per instant; with "
      "dynamics=True also the actuated forces C^T tau (N, na).");

  m.def(
      "mechanism_closed_mass_matrix",
      [](const MechanismModel& mo, const Array& qa, const Array& q0) {
        const auto na = static_cast<py::ssize_t>(mo.num_actuated());
        const auto n = static_cast<py::ssize_t>(mo.dof());
        require_shape(qa, "q_actuated", {-1, na});
        require_shape(q0, "q_guess", {n});
        const auto N = qa.shape(0);
        Array Mr = make_array({N, na, na}), G = make_array({N, na});
        StatusArray status(N);
        MechanismData d(mo);
        Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(q0.data(), n);
        Eigen::VectorXd last_good = q;  // rows independent, as in mechanism_closed_motion
        auto st = status.mutable_unchecked<1>();
        for (py::ssize_t k = 0; k < N; ++k) {
          q = last_good;
          Status s = closed_mass_matrix(mo, d, CVec(row(qa, k), na), q);
          const bool solved = !has(s, Status::solver_error) && !has(s, Status::bad_size) &&
                              !has(s, Status::non_finite_input) && !has(s, Status::out_of_range);
          const bool ok = solved && d.reduced_mass_matrix.allFinite() && d.actuated_gravity.allFinite();
          if (solved && !ok) s |= Status::out_of_range;
          if (ok && q.allFinite()) last_good = q;
          st(k) = static_cast<std::uint32_t>(s);
          put(Mr, k, d.reduced_mass_matrix, ok);
          put(G, k, d.actuated_gravity, ok);
        }
        py::dict out;
        out["reduced_mass_matrix"] = Mr;
        out["actuated_gravity"] = G;
        out["status"] = status;
        return out;
      },
      py::arg("model"), py::arg("q_actuated"), py::arg("q_guess"));

  m.def(
      "mechanism_closed_forward_dynamics",
      [](const MechanismModel& mo, const Array& qa_arg, const Array& va_arg, const Array& tau_arg,
         const Array& q0_arg) {
        const Eigen::VectorXd qa = vector_arg(qa_arg, "q_actuated", -1), va = vector_arg(va_arg, "v_actuated", -1),
                              tau = vector_arg(tau_arg, "tau_actuated", -1), q0 = vector_arg(q0_arg, "q_guess", -1);
        const auto na = mo.num_actuated();
        if (qa.size() != na || va.size() != na || tau.size() != na || q0.size() != mo.dof()) {
          throw py::value_error("q_actuated, v_actuated, tau_actuated must have " + std::to_string(na) +
                                " values and q_guess " + std::to_string(mo.dof()));
        }
        MechanismData d(mo);
        Eigen::VectorXd q = q0;
        const Status s = closed_forward_dynamics(mo, d, qa, va, tau, q);
        py::dict out;
        out["a_actuated"] = Eigen::VectorXd(d.actuated_acceleration);
        out["q"] = q;
        out["status"] = static_cast<std::uint32_t>(s);
        return out;
      },
      py::arg("model"), py::arg("q_actuated"), py::arg("v_actuated"), py::arg("tau_actuated"), py::arg("q_guess"));

  // ---- batch algorithms: arguments (N, dof); results (N, ...) and `status` (N,) ----
  m.def("mechanism_kinematics", &kinematics_batch, py::arg("model"), py::arg("q"), py::arg("v"),
        py::arg("a"),
        "Bodies' motion in O (com, com_velocity, com_acceleration (N,B,3), rotation (N,B,3,3) body "
        "to O, angular_velocity, angular_acceleration (N,B,3)), link frames (link_rotation, "
        "link_position) and named frames (frame_placement (N,F,4,4)).");

  m.def(
      "mechanism_inverse_dynamics",
      [](const MechanismModel& mo, const Array& q, const Array& v, const Array& a) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}, {v, "v"}, {a, "a"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, 1, true, "joint_torque", &MechanismData::joint_torque,
                            [&](py::ssize_t k, MechanismData& d) {
                              return inverse_dynamics(mo, d, CVec(row(q, k), n), CVec(row(v, k), n),
                                                      CVec(row(a, k), n));
                            });
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("a"));

  m.def(
      "mechanism_gravity_torque",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, 1, true, "gravity_torque", &MechanismData::gravity_torque,
                            [&](py::ssize_t k, MechanismData& d) {
                              return gravity_torque(mo, d, CVec(row(q, k), n));
                            });
      },
      py::arg("model"), py::arg("q"));

  m.def(
      "mechanism_static_torque",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, 1, true, "static_torque", &MechanismData::static_torque,
                            [&](py::ssize_t k, MechanismData& d) {
                              return static_torque(mo, d, CVec(row(q, k), n));
                            });
      },
      py::arg("model"), py::arg("q"), "G(q) + K(q): gravity and springs (N, dof)");

  m.def(
      "mechanism_springs",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        const py::ssize_t S = mo.num_springs();
        Array length = make_array({N, S}), tension = make_array({N, S}), torque = make_array({N, n}),
              energy = make_array({N}), potential = make_array({N});
        auto status = run_batch(
            mo, N,
            [&](py::ssize_t k, MechanismData& d) {
              const CVec qk(row(q, k), n);
              Status s = potential_energy(mo, d, qk);
              if (s == Status::ok) s = spring_torque(mo, d, qk);
              return s;
            },
            [](const MechanismData& d) {
              return d.spring_torque.allFinite() && d.spring_length.allFinite() && d.spring_tension.allFinite() &&
                     std::isfinite(d.spring_energy) && std::isfinite(d.potential_energy);
            },
            [&](py::ssize_t k, const MechanismData& d, bool ok) {
              put(length, k, d.spring_length, ok);
              put(tension, k, d.spring_tension, ok);
              put(torque, k, d.spring_torque, ok);
              energy.mutable_data()[k] = ok ? d.spring_energy : kFailed;
              potential.mutable_data()[k] = ok ? d.potential_energy : kFailed;
            });
        py::dict out;
        out["spring_length"] = length;
        out["spring_tension"] = tension;
        out["spring_torque"] = torque;
        out["spring_energy"] = energy;
        out["potential_energy"] = potential;
        out["status"] = status;
        return out;
      },
      py::arg("model"), py::arg("q"),
      "Springs over a batch of configurations (N, dof): spring_length (anchor distance d [m]) and "
      "spring_tension (T at the anchors [N]) (N, S), spring_torque K(q) = dV_s/dq (N, dof), "
      "spring_energy [J] and potential_energy (gravity plus springs [J]) (N,), status (N,)");

  m.def(
      "mechanism_bias_torque",
      [](const MechanismModel& mo, const Array& q, const Array& v) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}, {v, "v"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, 1, true, "bias_torque", &MechanismData::bias_torque,
                            [&](py::ssize_t k, MechanismData& d) {
                              return bias_torque(mo, d, CVec(row(q, k), n), CVec(row(v, k), n));
                            });
      },
      py::arg("model"), py::arg("q"), py::arg("v"));

  m.def(
      "mechanism_mass_matrix",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, n, false, "mass_matrix", &MechanismData::mass_matrix,
                            [&](py::ssize_t k, MechanismData& d) {
                              return mass_matrix(mo, d, CVec(row(q, k), n));
                            });
      },
      py::arg("model"), py::arg("q"));

  m.def(
      "mechanism_momentum_matrix",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, 6, n, false, "momentum_matrix", &MechanismData::momentum_matrix,
                            [&](py::ssize_t k, MechanismData& d) {
                              return momentum_matrix(mo, d, CVec(row(q, k), n));
                            });
      },
      py::arg("model"), py::arg("q"));

  m.def(
      "mechanism_frame_jacobian",
      [](const MechanismModel& mo, const Array& q, const std::string& frame) {
        const int f = mo.frame_index(frame);
        if (f < 0) throw py::value_error("frame: no frame named '" + frame + "'");
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, 6, n, false, "jacobian", &MechanismData::frame_jacobian,
                            [&](py::ssize_t k, MechanismData& d) {
                              return frame_jacobian(mo, d, CVec(row(q, k), n), f);
                            });
      },
      py::arg("model"), py::arg("q"), py::arg("frame"));

  m.def(
      "mechanism_torque_regressor",
      [](const MechanismModel& mo, const Array& q, const Array& v, const Array& a) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}, {v, "v"}, {a, "a"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, 10 * mo.num_bodies(), false, "regressor",
                            &MechanismData::torque_regressor, [&](py::ssize_t k, MechanismData& d) {
                              return torque_regressor(mo, d, CVec(row(q, k), n), CVec(row(v, k), n),
                                                      CVec(row(a, k), n));
                            });
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("a"));

  m.def(
      "mechanism_gravity_regressor",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, n, 10 * mo.num_bodies(), false, "regressor",
                            &MechanismData::gravity_regressor, [&](py::ssize_t k, MechanismData& d) {
                              return gravity_regressor(mo, d, CVec(row(q, k), n));
                            });
      },
      py::arg("model"), py::arg("q"));

  m.def(
      "mechanism_momentum_regressor",
      [](const MechanismModel& mo, const Array& q, const Array& v) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}, {v, "v"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        return matrix_batch(mo, N, 6, 10 * mo.num_bodies(), false, "regressor",
                            &MechanismData::momentum_regressor, [&](py::ssize_t k, MechanismData& d) {
                              return momentum_regressor(mo, d, CVec(row(q, k), n), CVec(row(v, k), n));
                            });
      },
      py::arg("model"), py::arg("q"), py::arg("v"));

  m.def(
      "mechanism_center_of_mass",
      [](const MechanismModel& mo, const Array& q) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        Array com = make_array({N, 3});
        auto status = run_batch(
            mo, N, [&](py::ssize_t k, MechanismData& d) { return center_of_mass(mo, d, CVec(row(q, k), n)); },
            [](const MechanismData& d) { return d.center_of_mass.allFinite(); },
            [&](py::ssize_t k, const MechanismData& d, bool ok) { put3(com, k, 0, d.center_of_mass, ok); });
        py::dict out;
        out["center_of_mass"] = com.reshape({N, py::ssize_t(3)});
        out["status"] = status;
        return out;
      },
      py::arg("model"), py::arg("q"));

  m.def(
      "mechanism_momentum",
      [](const MechanismModel& mo, const Array& q, const Array& v) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}, {v, "v"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        Array P = make_array({N, 3}), H = make_array({N, 3});
        auto status = run_batch(
            mo, N,
            [&](py::ssize_t k, MechanismData& d) { return momentum(mo, d, CVec(row(q, k), n), CVec(row(v, k), n)); },
            [](const MechanismData& d) {
              return d.shaking.linear_momentum.allFinite() && d.shaking.angular_momentum.allFinite();
            },
            [&](py::ssize_t k, const MechanismData& d, bool ok) {
              put3(P, k, 0, d.shaking.linear_momentum, ok);
              put3(H, k, 0, d.shaking.angular_momentum, ok);
            });
        py::dict out;
        out["linear_momentum"] = P;
        out["angular_momentum"] = H;
        out["status"] = status;
        return out;
      },
      py::arg("model"), py::arg("q"), py::arg("v"));

  m.def(
      "mechanism_shaking_wrench",
      [](const MechanismModel& mo, const Array& q, const Array& v, const Array& a, bool with_gravity) {
        const auto N = batch_rows(mo.dof(), {{q, "q"}, {v, "v"}, {a, "a"}});
        const auto n = static_cast<Eigen::Index>(mo.dof());
        const py::ssize_t NR = with_gravity ? N : 0;  // the reactions' arrays: only when asked for
        Array F = make_array({N, 3}), M = make_array({N, 3}), P = make_array({N, 3}), H = make_array({N, 3}),
              RF = make_array({NR, 3}), RM = make_array({NR, 3}), SF = make_array({NR, 3}),
              SM = make_array({NR, 3});
        // Without with_gravity the reactions are computed only when their bounds cannot tell that
        // they are finite: an instant is accepted exactly when base_reaction accepts it.
        const ReactionBounds bounds(mo);
        bool reactions = with_gravity;  // the reactions of the current instant were computed
        auto status = run_batch(
            mo, N,
            [&](py::ssize_t k, MechanismData& d) {
              const CVec qk(row(q, k), n), vk(row(v, k), n), ak(row(a, k), n);
              if (with_gravity) return base_reaction(mo, d, qk, vk, ak);
              const Status s = shaking_wrench(mo, d, qk, vk, ak);
              reactions = s == Status::ok && !bounds.surely_finite(d);
              return reactions ? base_reaction(mo, d, qk, vk, ak) : s;
            },
            [&](const MechanismData& d) {
              return finite_wrench(d) &&
                     (!reactions || (d.base_reaction.force.allFinite() && d.base_reaction.moment.allFinite() &&
                                     d.support_reaction.force.allFinite() && d.support_reaction.moment.allFinite()));
            },
            [&](py::ssize_t k, const MechanismData& d, bool ok) {
              put3(F, k, 0, d.shaking.force, ok);
              put3(M, k, 0, d.shaking.moment, ok);
              put3(P, k, 0, d.shaking.linear_momentum, ok);
              put3(H, k, 0, d.shaking.angular_momentum, ok);
              if (!with_gravity) return;
              put3(RF, k, 0, d.base_reaction.force, ok);
              put3(RM, k, 0, d.base_reaction.moment, ok);
              put3(SF, k, 0, d.support_reaction.force, ok);
              put3(SM, k, 0, d.support_reaction.moment, ok);
            });
        py::dict out;
        out["shaking_force"] = F;
        out["shaking_moment"] = M;
        out["linear_momentum"] = P;
        out["angular_momentum"] = H;
        if (with_gravity) {
          out["base_reaction_force"] = RF;
          out["base_reaction_moment"] = RM;
          out["support_reaction_force"] = SF;
          out["support_reaction_moment"] = SM;
        }
        out["status"] = status;
        return out;
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("a"), py::arg("with_gravity") = true);
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(30, mechanism, bind_mechanism);

}  // namespace mechbal::pyb
