#include "mechbal/control/kdl_chain.hpp"

#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace mechbal {

// The one definition of the base's vtable and typeinfo (declared extern in the header).
template class SupportWrenchDynamics<KdlChainDynamics>;

namespace {

[[noreturn]] void not_a_chain(const std::string& why) {
  throw std::invalid_argument("KdlChainDynamics: the model is not a serial chain: " + why);
}

// One moving link of the chain as KDL sees it: the joint that moves it and its lumped inertia.
struct ChainLink {
  std::string name;
  JointType type = JointType::revolute;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< parent link frame -> joint frame
  Vec3 axis = Vec3::UnitZ();
  double mass = 0.0;
  Vec3 com = Vec3::Zero();        ///< in the link frame
  Mat3 inertia = Mat3::Zero();    ///< about the centre of mass, in the link frame
};

// The general model's links 1..n (joint k moves link k + 1), bodies lumped per link.
std::vector<ChainLink> chain_of(const MechanismModel& model) {
  const int nl = model.num_links();
  if (nl < 2) not_a_chain("it has no joint");
  if (model.num_springs() > 0) not_a_chain("it has springs, which KDL does not model (use MechanismDynamics)");
  if (!model.is_serial_chain()) {
    // name the first link that breaks the chain
    const auto& joints = model.description().joints;  // depth-first: joint l - 1 moves link l
    for (int l = 1; l < nl; ++l) {
      const Joint& j = joints[static_cast<std::size_t>(l - 1)];
      if (model.parent(l) != l - 1) {
        not_a_chain("link '" + j.name + "' hangs from '" + model.link_name(model.parent(l)) +
                    "', not from '" + model.link_name(l - 1) + "' (a tree with branches)");
      }
      if (model.joint_type(l) == JointType::fixed) {
        not_a_chain("joint '" + j.name + "' is fixed (fold its bodies into '" +
                    model.link_name(l - 1) + "' to use KDL)");
      }
      if (!j.mimic_joint.empty()) {
        not_a_chain("joint '" + j.name + "' is gear-coupled to '" + j.mimic_joint +
                    "' (no coordinate of its own)");
      }
    }
    not_a_chain("its coordinates are not one per joint in link order");
  }
  std::vector<ChainLink> links(static_cast<std::size_t>(nl - 1));
  std::vector<double> mass(static_cast<std::size_t>(nl), 0.0);
  std::vector<Vec3> first_moment(static_cast<std::size_t>(nl), Vec3::Zero());
  for (int b = 0; b < model.num_bodies(); ++b) {
    const auto l = static_cast<std::size_t>(model.body_link(b));
    mass[l] += model.body(b).mass;
    first_moment[l] += model.body(b).mass * model.body(b).com;
  }
  for (int l = 1; l < nl; ++l) {
    ChainLink& s = links[static_cast<std::size_t>(l - 1)];
    s.name = model.link_name(l);
    s.type = model.joint_type(l);
    s.origin = model.placement(l);
    s.axis = model.axis(l);
    const auto k = static_cast<std::size_t>(l);
    s.mass = mass[k];
    s.com = mass[k] > 0.0 ? Vec3(first_moment[k] / mass[k]) : Vec3::Zero();
  }
  for (int b = 0; b < model.num_bodies(); ++b) {
    const int l = model.body_link(b);
    if (l == 0) continue;
    ChainLink& s = links[static_cast<std::size_t>(l - 1)];
    const Body& body = model.body(b);
    const Vec3 d = body.com - s.com;  // parallel axes to the lumped centre of mass
    s.inertia += body.inertia + body.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
  }
  for (ChainLink& s : links) s.inertia = 0.5 * (s.inertia + s.inertia.transpose()).eval();
  return links;
}

KDL::Frame to_kdl(const Eigen::Isometry3d& T) {
  const Mat3 R = T.linear();
  const Vec3 p = T.translation();
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                  R(2, 1), R(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

// Link inertia given in F_i, re-expressed in the KDL segment's tip frame T_tip (relative to F_i).
KDL::RigidBodyInertia to_kdl_inertia(const ChainLink& j, const Eigen::Isometry3d& F_to_tip) {
  const Mat3& I = j.inertia;
  const KDL::RigidBodyInertia in_F(
      j.mass, KDL::Vector(j.com.x(), j.com.y(), j.com.z()),
      KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
  return to_kdl(F_to_tip) * in_F;
}

// Builds the KDL chain; with `virtual_base` six motionless joints come first.
KDL::Chain build_chain(const std::vector<ChainLink>& links, bool virtual_base) {
  KDL::Chain chain;
  const std::size_t n = links.size();
  KDL::Frame first_tip = to_kdl(links[0].origin);
  if (virtual_base) {
    const KDL::Joint::JointType types[6] = {KDL::Joint::TransX, KDL::Joint::TransY,
                                            KDL::Joint::TransZ, KDL::Joint::RotX,
                                            KDL::Joint::RotY,   KDL::Joint::RotZ};
    for (int k = 0; k < 6; ++k) {
      chain.addSegment(KDL::Segment(KDL::Joint(types[k]),
                                    k == 5 ? first_tip : KDL::Frame::Identity()));
    }
  } else {
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::Fixed), first_tip));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const ChainLink& j = links[i];
    const Eigen::Isometry3d next =
        i + 1 < n ? links[i + 1].origin : Eigen::Isometry3d::Identity();
    const KDL::Vector axis(j.axis.x(), j.axis.y(), j.axis.z());
    const KDL::Joint joint(j.name, KDL::Vector::Zero(), axis,
                           j.type == JointType::revolute ? KDL::Joint::RotAxis
                                                         : KDL::Joint::TransAxis);
    chain.addSegment(KDL::Segment(j.name, joint, to_kdl(next), to_kdl_inertia(j, next.inverse())));
  }
  return chain;
}

}  // namespace

struct KdlChainDynamics::Impl {
  Impl(const std::vector<ChainLink>& links, const Vec3& gravity)
      : full(build_chain(links, true)),
        plain(build_chain(links, false)),
        grav(gravity.x(), gravity.y(), gravity.z()),
        rne(full, grav),
        dyn(plain, grav),
        q_full(full.getNrOfJoints()),
        qd_full(full.getNrOfJoints()),
        qdd_full(full.getNrOfJoints()),
        tau_full(full.getNrOfJoints()),
        f_ext(full.getNrOfSegments(), KDL::Wrench::Zero()),
        q(plain.getNrOfJoints()),
        qd(plain.getNrOfJoints()),
        out(plain.getNrOfJoints()),
        M(plain.getNrOfJoints()) {}
  KDL::Chain full, plain;
  KDL::Vector grav;
  KDL::ChainIdSolver_RNE rne;
  KDL::ChainDynParam dyn;
  KDL::JntArray q_full, qd_full, qdd_full, tau_full;
  KDL::Wrenches f_ext;
  KDL::JntArray q, qd, out;
  KDL::JntSpaceInertiaMatrix M;
};

KdlChainDynamics::KdlChainDynamics(const MechanismModel& model)
    : impl_(std::make_unique<Impl>(chain_of(model), model.gravity())), dof_(model.dof()) {}

KdlChainDynamics::~KdlChainDynamics() = default;

Status KdlChainDynamics::inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                                          Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                                          Vec3* support_moment) noexcept {
  if (q.size() != dof_ || qd.size() != dof_ || qdd.size() != dof_ || tau.size() != dof_) {
    return Status::bad_size;
  }
  if (!q.allFinite() || !qd.allFinite() || !qdd.allFinite()) return Status::non_finite_input;
  Impl& m = *impl_;
  m.q_full.data.head<6>().setZero();
  m.qd_full.data.head<6>().setZero();
  m.qdd_full.data.head<6>().setZero();
  m.q_full.data.tail(dof_) = q;
  m.qd_full.data.tail(dof_) = qd;
  m.qdd_full.data.tail(dof_) = qdd;
  if (m.rne.CartToJnt(m.q_full, m.qd_full, m.qdd_full, m.f_ext, m.tau_full) < 0) {
    return Status::solver_error;
  }
  if (!m.tau_full.data.allFinite()) return Status::out_of_range;  // outputs untouched
  tau = m.tau_full.data.tail(dof_);
  if (support_force) *support_force = m.tau_full.data.segment<3>(0);
  if (support_moment) *support_moment = m.tau_full.data.segment<3>(3);
  return Status::ok;
}

Status KdlChainDynamics::mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q,
                                     Eigen::Ref<Eigen::MatrixXd> M) noexcept {
  if (q.size() != dof_ || M.rows() != dof_ || M.cols() != dof_) return Status::bad_size;
  if (!q.allFinite()) return Status::non_finite_input;
  impl_->q.data = q;
  if (impl_->dyn.JntToMass(impl_->q, impl_->M) < 0) return Status::solver_error;
  if (!impl_->M.data.allFinite()) return Status::out_of_range;
  M = impl_->M.data;
  return Status::ok;
}

Status KdlChainDynamics::coriolis(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd,
                                  Eigen::Ref<Eigen::VectorXd> c) noexcept {
  if (q.size() != dof_ || qd.size() != dof_ || c.size() != dof_) return Status::bad_size;
  if (!q.allFinite() || !qd.allFinite()) return Status::non_finite_input;
  impl_->q.data = q;
  impl_->qd.data = qd;
  if (impl_->dyn.JntToCoriolis(impl_->q, impl_->qd, impl_->out) < 0) return Status::solver_error;
  if (!impl_->out.data.allFinite()) return Status::out_of_range;
  c = impl_->out.data;
  return Status::ok;
}

Status KdlChainDynamics::gravity(const Eigen::Ref<const Eigen::VectorXd>& q,
                                 Eigen::Ref<Eigen::VectorXd> g) noexcept {
  if (q.size() != dof_ || g.size() != dof_) return Status::bad_size;
  if (!q.allFinite()) return Status::non_finite_input;
  impl_->q.data = q;
  if (impl_->dyn.JntToGravity(impl_->q, impl_->out) < 0) return Status::solver_error;
  if (!impl_->out.data.allFinite()) return Status::out_of_range;
  g = impl_->out.data;
  return Status::ok;
}

}  // namespace mechbal
