#include "mechbal/disc_arm.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "mechbal/rigid_body.hpp"

namespace mechbal {

namespace {

[[noreturn]] void fail(std::size_t d, const char* field, const std::string& what) {
  std::ostringstream msg;
  msg << "discs[" << d << "]." << field << " " << what;
  throw std::invalid_argument(msg.str());
}

}  // namespace

DiscArmDynamics::DiscArmDynamics(ChainModel chain, std::vector<DiscSpec> discs)
    : chain_(std::move(chain)), discs_(std::move(discs)), ws_(chain_) {
  const int n = chain_.dof();
  if (n < 1 || n > max_dof) {
    std::ostringstream msg;
    msg << "chain must have 1.." << max_dof << " joints (got " << n << ")";
    throw std::invalid_argument(msg.str());
  }
  for (std::size_t d = 0; d < discs_.size(); ++d) {
    DiscSpec& s = discs_[d];
    std::ostringstream v;
    if (s.carrier < 0 || s.carrier >= n) {
      v << "must be a link index in [0, " << n - 1 << "] (got " << s.carrier << ")";
      fail(d, "carrier", v.str());
    }
    if (s.joint < 0 || s.joint >= n) {
      v << "must be a joint index in [0, " << n - 1 << "] (got " << s.joint << ")";
      fail(d, "joint", v.str());
    }
    if (!std::isfinite(s.ratio)) {
      v << "must be finite (got " << s.ratio << ")";
      fail(d, "ratio", v.str());
    }
    if (!normalize_axis(s.axis)) {
      v << "must be a finite vector of norm >= 1e-12 (got " << s.axis.transpose() << ")";
      fail(d, "axis", v.str());
    }
    RigidBody rb;
    rb.inertia_body = s.inertia.asDiagonal();
    const std::string field = "discs[" + std::to_string(d) + "]";
    validate_rigid_body(rb, field.c_str());
  }
  zero_ = VecN::Zero(n);
  M_ = MatN::Zero(n, n);
  v_ = VecN::Zero(n);
  g_ = VecN::Zero(n);
}

Status DiscArmDynamics::compute(const Eigen::Ref<const Eigen::VectorXd>& q,
                                const Eigen::Ref<const Eigen::VectorXd>& qd) noexcept {
  const int n = chain_.dof();
  // Bias accelerations (dJ/dt qd) are the accelerations at qdd = 0. The link motion overflowing
  // (out_of_range) leaves the workspace at rest: nothing below would mean anything.
  const Status kinematics = chain_kinematics(chain_, q, qd, zero_, ws_);
  if (kinematics != Status::ok) return kinematics;
  M_.setZero();
  v_.setZero();
  g_.setZero();
  const auto& joints = chain_.joints();
  Jac Jv(3, n), Jw(3, n);
  // Joint axes and axis points in the base frame.
  Jac z(3, n), o(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Isometry3d& F = ws_.frames[static_cast<std::size_t>(i)];
    z.col(i) = F.linear() * joints[static_cast<std::size_t>(i)].axis;
    o.col(i) = F.translation();
  }
  // Links: Newton-Euler subsystems coupled by p_b = J_b qd.
  for (int k = 0; k < n; ++k) {
    const JointSpec& jk = joints[static_cast<std::size_t>(k)];
    const BodyState& st = ws_.states[static_cast<std::size_t>(k)];
    Jv.setZero();
    Jw.setZero();
    for (int i = 0; i <= k; ++i) {
      if (joints[static_cast<std::size_t>(i)].type == JointType::revolute) {
        Jw.col(i) = z.col(i);
        Jv.col(i) = z.col(i).cross(st.com - o.col(i));
      } else {
        Jv.col(i) = z.col(i);
      }
    }
    const double m = jk.link.mass;
    const Mat3 Iw = st.rotation * jk.link.inertia_body * st.rotation.transpose();
    const Vec3& w = st.angular_velocity;
    M_.noalias() += m * Jv.transpose() * Jv;
    M_.noalias() += Jw.transpose() * Iw * Jw;
    const Vec3 lin = m * st.com_acceleration;                                 // M_b c_b (linear)
    const Vec3 ang = Iw * st.angular_acceleration + w.cross(Iw * w);         // M_b c_b + v_b
    v_.noalias() += Jv.transpose() * lin;
    v_.noalias() += Jw.transpose() * ang;
    g_.noalias() -= Jv.transpose() * (m * chain_.gravity());                  // g_b = -m g
  }
  // Discs: body-frame angular velocity omega_d = R_d^T (omega_c + ratio qd_j a) (A° = 1).
  for (const DiscSpec& d : discs_) {
    const BodyState& c = ws_.states[static_cast<std::size_t>(d.carrier)];
    const Mat3 Rd = c.rotation * Eigen::AngleAxisd(d.ratio * q(d.joint), d.axis).toRotationMatrix();
    const Vec3 a = c.rotation * d.axis;
    Jw.setZero();
    for (int i = 0; i <= d.carrier; ++i)
      if (joints[static_cast<std::size_t>(i)].type == JointType::revolute) Jw.col(i) = z.col(i);
    Jw.col(d.joint) += d.ratio * a;
    const Vec3 spin = d.ratio * qd(d.joint) * a;
    const Jac Jd = Rd.transpose() * Jw;  // fixed capacity: no allocation
    const Vec3 bias = Rd.transpose() * (c.angular_acceleration + c.angular_velocity.cross(spin));
    const Vec3 wb = Rd.transpose() * (c.angular_velocity + spin);
    const Vec3 Jm = d.inertia;
    M_.noalias() += Jd.transpose() * Jm.asDiagonal() * Jd;
    const Vec3 h = Jm.cwiseProduct(bias) + wb.cross(Jm.cwiseProduct(wb));
    v_.noalias() += Jd.transpose() * h;
  }
  return Status::ok;
}

Status DiscArmDynamics::evaluate(const Eigen::Ref<const Eigen::VectorXd>& q,
                                 const Eigen::Ref<const Eigen::VectorXd>& qd,
                                 Eigen::Ref<Eigen::MatrixXd> mass,
                                 Eigen::Ref<Eigen::VectorXd> velocity_terms,
                                 Eigen::Ref<Eigen::VectorXd> gravity_terms) noexcept {
  const int n = chain_.dof();
  if (q.size() != n || qd.size() != n || mass.rows() != n || mass.cols() != n ||
      velocity_terms.size() != n || gravity_terms.size() != n)
    return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite()) return Status::non_finite_input;
  if (const Status s = compute(q, qd); s != Status::ok) return s;
  if (!M_.allFinite() || !v_.allFinite() || !g_.allFinite()) return Status::out_of_range;
  mass = M_;
  velocity_terms = v_;
  gravity_terms = g_;
  return Status::ok;
}

Status DiscArmDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                         const Eigen::Ref<const Eigen::VectorXd>& qd,
                                         const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                         Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  const int n = chain_.dof();
  if (q.size() != n || qd.size() != n || qdd.size() != n || tau.size() != n)
    return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite() || !qdd.allFinite()) return Status::non_finite_input;
  if (const Status s = compute(q, qd); s != Status::ok) return s;
  const VecN t = M_ * qdd + v_ + g_;
  if (!t.allFinite()) return Status::out_of_range;  // finite input that overflowed; tau untouched
  tau = t;
  return Status::ok;
}

}  // namespace mechbal
