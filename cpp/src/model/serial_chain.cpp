#include "mechbal/model/serial_chain.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mechbal {

namespace {
std::string joint_field(std::size_t i, const JointSpec& j, const char* field) {
  std::ostringstream s;
  s << "joints[" << i << "]";
  if (!j.name.empty()) s << " (" << j.name << ")";
  s << "." << field;
  return s.str();
}
}  // namespace

ChainModel::ChainModel(std::vector<JointSpec> joints, const Vec3& gravity,
                       const Eigen::Isometry3d& base)
    : joints_(std::move(joints)), gravity_(gravity), base_(base) {
  if (joints_.empty()) throw std::invalid_argument("joints must contain at least one joint");
  if (!gravity_.allFinite()) throw std::invalid_argument("gravity must be finite");
  if (!base_.matrix().allFinite()) throw std::invalid_argument("base must be finite");
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    JointSpec& j = joints_[i];
    if (j.type != JointType::revolute && j.type != JointType::prismatic) {
      throw std::invalid_argument(joint_field(i, j, "type") +
                                  " must be revolute or prismatic in a serial chain (use "
                                  "MechanismModel for fixed joints)");
    }
    if (!normalize_axis(j.axis)) {
      std::ostringstream m;
      m << joint_field(i, j, "axis") << " must be a finite vector of norm >= 1e-12, got ["
        << j.axis.transpose() << "]";
      throw std::invalid_argument(m.str());
    }
    if (!j.origin.matrix().allFinite()) {
      throw std::invalid_argument(joint_field(i, j, "origin") + " must be finite");
    }
    const Mat3 R = j.origin.linear();
    if ((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9) {
      throw std::invalid_argument(joint_field(i, j, "origin") + " rotation is not orthonormal");
    }
    if (!j.com.allFinite()) throw std::invalid_argument(joint_field(i, j, "com") + " must be finite");
    validate_rigid_body(j.link, joint_field(i, j, "link").c_str());
    bodies_.push_back(j.link);
  }
}

bool normalize_axis(Vec3& axis) noexcept {
  // scale by the largest component first: |axis| itself overflows for components near 1e155
  // and above (issue 14: an axis of 1e300 was normalised to zero)
  if (!axis.allFinite()) return false;
  const double peak = axis.cwiseAbs().maxCoeff();
  if (!(peak > 0.0)) return false;
  const Vec3 scaled = axis / peak;  // largest component exactly +-1
  const double n = scaled.norm();   // in [1, sqrt 3]
  if (!(peak * n >= 1e-12)) return false;
  axis = scaled / n;
  return true;
}

ChainWorkspace::ChainWorkspace(const ChainModel& model)
    : frames(static_cast<std::size_t>(model.dof()), Eigen::Isometry3d::Identity()),
      states(static_cast<std::size_t>(model.dof())) {}

Status chain_kinematics(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                        const Eigen::Ref<const Eigen::VectorXd>& qd,
                        const Eigen::Ref<const Eigen::VectorXd>& qdd,
                        ChainWorkspace& ws) noexcept {
  const int n = model.dof();
  if (q.size() != n || qd.size() != n || qdd.size() != n ||
      static_cast<int>(ws.states.size()) != n || static_cast<int>(ws.frames.size()) != n) {
    return Status::bad_size;
  }
  if (!q.allFinite() || !qd.allFinite() || !qdd.allFinite()) return Status::non_finite_input;

  Eigen::Isometry3d F = model.base();
  Vec3 w = Vec3::Zero(), alpha = Vec3::Zero();  // angular velocity/acceleration of F_{i-1}
  Vec3 v_o = Vec3::Zero(), a_o = Vec3::Zero();  // velocity/acceleration of F_{i-1}'s origin
  for (int i = 0; i < n; ++i) {
    const JointSpec& j = model.joints()[static_cast<std::size_t>(i)];
    const Eigen::Isometry3d P = F * j.origin;  // joint frame at q = 0
    const Vec3 r = P.translation() - F.translation();
    // Point of F_{i-1} at the joint origin.
    Vec3 v_p = v_o + w.cross(r);
    Vec3 a_p = a_o + alpha.cross(r) + w.cross(w.cross(r));
    const Vec3 z = P.linear() * j.axis;  // joint axis in the base frame
    if (j.type == JointType::revolute) {
      F = P * Eigen::AngleAxisd(q(i), j.axis);
      alpha += w.cross(z) * qd(i) + z * qdd(i);
      w += z * qd(i);
      v_o = v_p;
      a_o = a_p;
    } else {
      F = P * Eigen::Translation3d(j.axis * q(i));
      const Vec3 s = z * q(i);
      v_o = v_p + w.cross(s) + z * qd(i);
      a_o = a_p + alpha.cross(s) + w.cross(w.cross(s)) + 2.0 * w.cross(z) * qd(i) + z * qdd(i);
    }
    ws.frames[static_cast<std::size_t>(i)] = F;
    BodyState& st = ws.states[static_cast<std::size_t>(i)];
    const Vec3 rc = F.linear() * j.com;
    st.rotation = F.linear();
    st.com = F.translation() + rc;
    st.angular_velocity = w;
    st.angular_acceleration = alpha;
    st.com_velocity = v_o + w.cross(rc);
    st.com_acceleration = a_o + alpha.cross(rc) + w.cross(w.cross(rc));
  }
  // finite input can still overflow (a speed of 1e200 squared): never report ok with a
  // non-finite state, never leave one behind
  bool finite = true;
  for (int i = 0; i < n && finite; ++i) {
    const BodyState& st = ws.states[static_cast<std::size_t>(i)];
    finite = ws.frames[static_cast<std::size_t>(i)].matrix().allFinite() &&
             st.com_velocity.allFinite() && st.com_acceleration.allFinite() &&
             st.angular_velocity.allFinite() && st.angular_acceleration.allFinite();
  }
  if (!finite) {
    for (int i = 0; i < n; ++i) {
      ws.frames[static_cast<std::size_t>(i)] = Eigen::Isometry3d::Identity();
      ws.states[static_cast<std::size_t>(i)] = BodyState{};
    }
    return Status::out_of_range;
  }
  return Status::ok;
}

Eigen::Isometry3d modified_dh_origin(double a, double alpha, double d, double theta) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.rotate(Eigen::AngleAxisd(alpha, Vec3::UnitX()));
  T.translate(Vec3(a, 0.0, 0.0));
  T.translate(Vec3(0.0, 0.0, d));
  T.rotate(Eigen::AngleAxisd(theta, Vec3::UnitZ()));
  return T;
}

MechanismDescription chain_description(const ChainModel& model) {
  MechanismDescription d;
  d.gravity = model.gravity();
  std::string parent = d.root_name;
  for (int i = 0; i < model.dof(); ++i) {
    const JointSpec& js = model.joints()[static_cast<std::size_t>(i)];
    Joint j;
    j.name = js.name.empty() ? "joint" + std::to_string(i + 1) : js.name;
    j.type = js.type;
    j.parent = parent;
    j.placement = i == 0 ? model.base() * js.origin : js.origin;
    j.axis = js.axis;
    d.joints.push_back(j);
    d.bodies.push_back(Body{j.name, "link", j.name, js.link.mass, js.com, js.link.inertia_body});
    parent = j.name;
  }
  return d;
}

}  // namespace mechbal
