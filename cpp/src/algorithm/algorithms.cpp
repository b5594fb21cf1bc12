// The algorithms over a MechanismModel (one public header each in mechbal/algorithm/).
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/regressor.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/algorithm/springs.hpp"
#include "mechbal/detail/placed.hpp"
#include "mechbal/detail/tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mechbal {

namespace {

using detail::check_state;

/// ok when every value of the result is finite; a finite input whose result overflowed gives
/// Status::out_of_range (docs/architecture.md, Data flow: never ok with a non-finite output).
template <typename... T>
Status finite_result(const T&... results) noexcept {
  return (detail::all_finite(results) && ...) ? Status::ok : Status::out_of_range;
}

/// World quantities of links, bodies and frames from the L-frame work buffers.
void world_kinematics(const MechanismModel& model, MechanismData& data) noexcept {
  const int nl = model.num_links();
  for (int l = 0; l < nl; ++l) {
    const auto k = static_cast<std::size_t>(l);
    const auto& W = data.work[k];
    const Mat3& R = W.world_rotation;
    data.link_rotation[k].noalias() = R * model.link_constants(l).aligned.transpose();
    data.link_position[k] = W.world_position;
    data.link_angular_velocity[k].noalias() = R * W.w;
    data.link_velocity[k].noalias() = R * W.vel;
    data.link_angular_acceleration[k].noalias() = R * W.alpha;
    data.link_acceleration[k].noalias() = R * W.acc;
  }
  for (int b = 0; b < model.num_bodies(); ++b) {
    const auto k = static_cast<std::size_t>(model.body_link(b));
    BodyState& s = data.body_states[static_cast<std::size_t>(b)];
    const Mat3& R = data.link_rotation[k];
    const Vec3& w = data.link_angular_velocity[k];
    const Vec3& al = data.link_angular_acceleration[k];
    const Vec3 r = R * model.bodies()[static_cast<std::size_t>(b)].com;
    s.com = data.link_position[k] + r;
    s.com_velocity = data.link_velocity[k] + w.cross(r);
    s.com_acceleration = data.link_acceleration[k] + al.cross(r) + w.cross(w.cross(r));
    s.rotation = R;
    s.angular_velocity = w;
    s.angular_acceleration = al;
  }
  for (int f = 0; f < model.num_frames(); ++f) {
    const auto k = static_cast<std::size_t>(model.frame_link(f));
    Eigen::Isometry3d T;
    T.linear() = data.link_rotation[k];
    T.translation() = data.link_position[k];
    T.makeAffine();
    data.frame_placements[static_cast<std::size_t>(f)] = T * model.frame(f).placement;
  }
}

bool kinematics_finite(const MechanismData& data) noexcept {
  for (std::size_t l = 0; l < data.link_position.size(); ++l) {
    if (!data.link_position[l].allFinite() || !data.link_rotation[l].allFinite() ||
        !data.link_velocity[l].allFinite() || !data.link_angular_velocity[l].allFinite() ||
        !data.link_acceleration[l].allFinite() || !data.link_angular_acceleration[l].allFinite()) {
      return false;
    }
  }
  return true;
}

/// Sum of m c over all links (the base's bodies included), in O.
Vec3 mass_moment(const MechanismModel& model, const MechanismData& data) noexcept {
  Vec3 mc = Vec3::Zero();
  for (int l = 0; l < model.num_links(); ++l) {
    const auto& c = model.link_constants(l);
    const auto& W = data.work[static_cast<std::size_t>(l)];
    mc += c.mass * W.world_position + W.world_rotation * c.first_moment;
  }
  return mc;
}

using detail::add_link_momentum;

/// Momenta about O of all links, from a forward pass with velocities, and with Wrenches their
/// rates: the sum of every link's Newton-Euler wrench (moment about its origin n_o, so about O:
/// n_o + p x f). One sweep over the links for both (each sum in link order).

/// Momenta = false: the wrenches only (data.shaking's momenta left as they were).
template <bool Wrenches, bool Momenta = true>
void sum_links(const MechanismModel& model, MechanismData& data) noexcept {
  Vec3 P = Vec3::Zero(), H = Vec3::Zero(), F = Vec3::Zero(), M = Vec3::Zero();
  // (the links with mass or inertia only: the others' terms are zeros)
  for (const int l : model.inertial_links()) {
    const auto& c = model.link_constants(l);
    const auto& W = data.work[static_cast<std::size_t>(l)];
    if (Momenta) add_link_momentum(c, W, W.w, W.vel, P, H);
    if (Wrenches) {
      const Vec3 f = W.world_rotation * W.force;
      F += f;
      M += W.world_rotation * W.moment + W.world_position.cross(f);
    }
  }
  if (Momenta) {
    data.shaking.linear_momentum = P;
    data.shaking.angular_momentum = H;
  }
  if (Wrenches) {
    data.shaking.force = F;
    data.shaking.moment = M;
  }
}

/// With springs: data.spring_torque = K(q) from placed links, added to tau. The base's entry of
/// the backward pass needs nothing: it is the rate of momentum minus the weights, the whole wrench
/// the base exerts on the moving links, through their joints and the springs anchored to it
/// (data.spring_base_force/moment is the springs' part). Nothing without springs.
void add_springs(const MechanismModel& model, MechanismData& data, Eigen::VectorXd& tau) noexcept {
  if (model.num_springs() == 0) return;
  data.spring_torque.setZero();
  detail::spring_forces<true>(model, data, data.spring_torque);
  tau += data.spring_torque;
}

}  // namespace

// ---- kinematics ---------------------------------------------------------------------------------

Status forward_kinematics(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  detail::forward_pass<false, false, false, false>(model, data);
  world_kinematics(model, data);
  return kinematics_finite(data) ? Status::ok : Status::out_of_range;
}

Status forward_kinematics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                          const ConstVector& v) noexcept {
  if (Status s = check_state(model, data, &q, &v); s != Status::ok) return s;
  detail::joint_state<true, false>(model, data, q, v, v);
  detail::place(model, data);
  detail::forward_pass<true, false, false, false>(model, data);
  world_kinematics(model, data);
  return kinematics_finite(data) ? Status::ok : Status::out_of_range;
}

Status forward_kinematics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                          const ConstVector& v, const ConstVector& a) noexcept {
  if (Status s = check_state(model, data, &q, &v, &a); s != Status::ok) return s;
  detail::joint_state<true, true>(model, data, q, v, a);
  detail::place(model, data);
  detail::forward_pass<true, true, false, false>(model, data);
  world_kinematics(model, data);
  return kinematics_finite(data) ? Status::ok : Status::out_of_range;
}

Status frame_placement(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                       int frame) noexcept {
  if (frame < 0 || frame >= model.num_frames()) return Status::bad_size;
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  // what forward_kinematics (and so the batch kinematics) would accept: every link placed finite,
  // every body's centre finite (link_rotation and body com computed as in world_kinematics)
  double reach = 0.0;  // the largest |coordinate| of a link origin
  for (int l = 0; l < model.num_links(); ++l) {
    const auto& W = data.work[static_cast<std::size_t>(l)];
    if (!W.world_position.allFinite() || !W.world_rotation.allFinite()) return Status::out_of_range;
    reach = std::max(reach, W.world_position.cwiseAbs().maxCoeff());
  }
  // |R c| <= |c|_1 for a rotation R: a body's centre can only overflow when that sum is near the
  // largest double, and is computed then
  constexpr double kSafe = 1e307;
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Vec3& com = model.bodies()[static_cast<std::size_t>(b)].com;
    if (reach <= kSafe && com.lpNorm<1>() <= kSafe) continue;
    const int l = model.body_link(b);
    const auto& W = data.work[static_cast<std::size_t>(l)];
    const Mat3 R = W.world_rotation * model.link_constants(l).aligned.transpose();
    if (!(W.world_position + R * com).allFinite()) return Status::out_of_range;
  }
  const int l = model.frame_link(frame);
  const auto& W = data.work[static_cast<std::size_t>(l)];
  Eigen::Isometry3d T;
  T.linear().noalias() = W.world_rotation * model.link_constants(l).aligned.transpose();
  T.translation() = W.world_position;
  T.makeAffine();
  data.frame_placements[static_cast<std::size_t>(frame)] = T * model.frame(frame).placement;
  return Status::ok;
}

Status center_of_mass(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  // the mass moment summed while the links are placed (one sweep over their data, so the cost per
  // link stays flat when a long chain outgrows the cache), in mass_moment's order: the base first
  const auto& base = model.link_constants(0);
  const auto& w0 = data.work[0];
  Vec3 mc = base.mass * w0.world_position + w0.world_rotation * base.first_moment;
  detail::place(model, data, [&model, &mc](int l, const MechanismData::LinkWork& w) noexcept {
    const auto& c = model.link_constants(l);
    mc += c.mass * w.world_position + w.world_rotation * c.first_moment;
  });
  data.mass = model.total_mass();
  data.center_of_mass = data.mass > 0.0 ? Vec3(mc / data.mass) : Vec3::Zero();
  return finite_result(data.center_of_mass);
}

// ---- momentum and shaking wrench ----------------------------------------------------------------

namespace {

/// The shaking wrench from placed links and the joints' rates.
Status shaking_wrench_of_placed(const MechanismModel& model, MechanismData& data) noexcept {
  detail::forward_pass<true, true, false, true>(model, data);
  sum_links<true>(model, data);
  return finite_result(data.shaking.linear_momentum, data.shaking.angular_momentum, data.shaking.force,
                       data.shaking.moment);
}

}  // namespace

Status momentum(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                const ConstVector& v) noexcept {
  if (Status s = check_state(model, data, &q, &v); s != Status::ok) return s;
  detail::joint_state<true, false>(model, data, q, v, v);
  detail::place(model, data);
  detail::forward_pass<true, false, false, false>(model, data);
  sum_links<false>(model, data);
  return finite_result(data.shaking.linear_momentum, data.shaking.angular_momentum);
}

Status momentum_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  return detail::momentum_matrix_placed(model, data);
}

namespace {

/// Link l's term of its coordinate's momentum-matrix column (linear; angular about O): the
/// momentum of its subtree under a unit rate of its joint (times the gear ratio), from its
/// composite and its pose in O.
inline void add_column_term(const MechanismModel& model, const MechanismData::LinkWork& W, int l,
                            Eigen::Ref<detail::Vec6> column) noexcept {
  Vec3 P, L;  // momentum of the subtree under a unit joint rate, in L_l (L about its origin)
  if (model.joint_type(l) == JointType::revolute) {
    P = -detail::cross_ez(W.composite_first_moment);
    L = W.composite_inertia.col(2);
  } else {
    P = Vec3(0.0, 0.0, W.composite_mass);
    L = detail::cross_ez(W.composite_first_moment);
  }
  const double r = model.coordinate_ratio(l);
  const Vec3 Pw = W.world_rotation * P;
  column.head<3>() += r * Pw;
  column.tail<3>() += r * (W.world_rotation * L + W.world_position.cross(Pw));
}

}  // namespace

namespace {

template <bool Accelerations>
MECHBAL_FLATTEN void velocity_momentum_pass(const MechanismModel& model, MechanismData& data,
                                            const detail::LinkSubset& links, bool whole, detail::Vec6& inside,
                                            detail::Vec6& rest) noexcept {
  data.work[0].w.setZero();
  data.work[0].vel.setZero();
  if (Accelerations) {
    data.work[0].acc.setZero();
    data.work[0].alpha.setZero();
  }
  Vec3 P[2] = {Vec3::Zero(), Vec3::Zero()}, H[2] = {Vec3::Zero(), Vec3::Zero()};
  const int count = whole ? model.num_links() - 1 : static_cast<int>(links.links.size());
  detail::LinkMotion m{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  int last = whole ? 0 : -1;  // (a subset's first link reads its parent's motion from data.work)
  for (int i = 0; i < count; ++i) {
    const int l = whole ? i + 1 : links.links[static_cast<std::size_t>(i)];
    detail::forward_link<true, false, false, true, Accelerations>(model, data, l, m, last);
    if (!model.has_inertia(l)) continue;  // adds nothing to the momenta
    const int in = links.member[static_cast<std::size_t>(l)] ? 1 : 0;
    add_link_momentum(model.link_constants(l), data.work[static_cast<std::size_t>(l)], m.w, m.vel, P[in], H[in]);
  }
  inside << P[1], H[1];
  if (whole) rest << P[0], H[0];
}

}  // namespace

void detail::velocity_momentum(const MechanismModel& model, MechanismData& data, const LinkSubset& links,
                               bool whole, Vec6& inside, Vec6& rest, bool accelerations) noexcept {
  if (accelerations && whole) {
    velocity_momentum_pass<true>(model, data, links, whole, inside, rest);
  } else {
    velocity_momentum_pass<false>(model, data, links, whole, inside, rest);
  }
}

MECHBAL_FLATTEN void detail::momentum_columns_placed(const MechanismModel& model, MechanismData& data,
                                                     const LinkSubset& links, const std::vector<int>& coordinates,
                                                     Eigen::Ref<Eigen::MatrixXd> columns) noexcept {
  detail::composite_inertias(model, data, &links);
  columns.setZero();
  for (const int l : links.links) {
    const int c = model.coordinate(l);
    for (std::size_t j = 0; j < coordinates.size(); ++j) {
      if (coordinates[j] == c) add_column_term(model, data.work[static_cast<std::size_t>(l)], l, columns.col(static_cast<Eigen::Index>(j)));
    }
  }
}

MECHBAL_FLATTEN Status detail::momentum_matrix_placed(const MechanismModel& model, MechanismData& data) noexcept {
  detail::composite_inertias(model, data);
  // Incremental: a link's term depends on its pose in O and its composite only, so a column is
  // recomputed (from zero, its links in the same order: bit for bit a full pass) when one of its
  // links moved in O or had its composite recomputed (LinkWork::momentum_current, cleared by
  // place and composite_inertias); the others keep their values. A reactionless controller that
  // turns its wrist re-derives the wrist's and its ancestors' columns, not the legs'.
  auto& stale = data.momentum_column_stale;
  const int nl = model.num_links();
  for (int l = 1; l < nl; ++l) {
    const int c = model.coordinate(l);
    if (c >= 0 && !data.work[static_cast<std::size_t>(l)].momentum_current) stale[static_cast<std::size_t>(c)] = 1;
  }
  for (Eigen::Index c = 0; c < data.momentum_matrix.cols(); ++c) {
    if (stale[static_cast<std::size_t>(c)]) data.momentum_matrix.col(c).setZero();
  }
  for (int l = 1; l < nl; ++l) {
    const int c = model.coordinate(l);
    if (c < 0 || !stale[static_cast<std::size_t>(c)]) continue;
    add_column_term(model, data.work[static_cast<std::size_t>(l)], l, data.momentum_matrix.col(c));
  }
  for (int l = 1; l < nl; ++l) data.work[static_cast<std::size_t>(l)].momentum_current = true;
  std::fill(stale.begin(), stale.end(), static_cast<unsigned char>(0));
  return finite_result(data.momentum_matrix);
}

Status shaking_wrench(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                      const ConstVector& v, const ConstVector& a) noexcept {
  if (Status s = check_state(model, data, &q, &v, &a); s != Status::ok) return s;
  detail::joint_state<true, true>(model, data, q, v, a);
  detail::place(model, data);
  return shaking_wrench_of_placed(model, data);
}

Status detail::shaking_wrench_placed(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                                     const ConstVector& v, const ConstVector& a, bool momenta) noexcept {
  detail::joint_state<true, true>(model, data, q, v, a);  // the rates (the positions are q's already)
  if (momenta) return shaking_wrench_of_placed(model, data);
  detail::forward_pass<true, true, false, true>(model, data);
  sum_links<true, false>(model, data);
  return finite_result(data.shaking.force, data.shaking.moment);
}

Status base_reaction(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                     const ConstVector& v, const ConstVector& a) noexcept {
  if (Status s = shaking_wrench(model, data, q, v, a); s != Status::ok) return s;
  // the links that do not move (the root and the links fixed to it) are the base's: their weight
  // is carried by the base itself, not through the moving mechanism's joints. Links are listed
  // parents first, so one walk up each link's path decides (bounded by the tree's depth).
  Vec3 mc_still = Vec3::Zero();
  double m_still = 0.0;
  for (int l = 0; l < model.num_links(); ++l) {
    int k = l;
    while (k > 0 && model.joint_type(k) == JointType::fixed) k = model.parent(k);
    if (k != 0) continue;  // moves
    const auto& c = model.link_constants(l);
    const auto& W = data.work[static_cast<std::size_t>(l)];
    mc_still += c.mass * W.world_position + W.world_rotation * c.first_moment;
    m_still += c.mass;
  }
  const Vec3 mc = mass_moment(model, data);
  const Vec3& g = model.gravity();
  data.mass = model.total_mass();
  data.center_of_mass = data.mass > 0.0 ? Vec3(mc / data.mass) : Vec3::Zero();
  data.base_reaction.force = data.shaking.force - (data.mass - m_still) * g;
  data.base_reaction.moment = data.shaking.moment - (mc - mc_still).cross(g);
  data.support_reaction.force = data.shaking.force - data.mass * g;
  data.support_reaction.moment = data.shaking.moment - mc.cross(g);
  return finite_result(data.base_reaction.force, data.base_reaction.moment, data.support_reaction.force,
                       data.support_reaction.moment);
}

// ---- inverse dynamics ---------------------------------------------------------------------------

Status inverse_dynamics(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                        const ConstVector& v, const ConstVector& a) noexcept {
  if (Status s = check_state(model, data, &q, &v, &a); s != Status::ok) return s;
  detail::joint_state<true, true>(model, data, q, v, a);
  detail::place_for_springs(model, data);
  detail::forward_pass<true, true, true, true, false>(model, data);
  detail::backward_pass(model, data, data.joint_torque);
  add_springs(model, data, data.joint_torque);
  return finite_result(data.joint_torque);
}

Status gravity_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place<false>(model, data);
  detail::forward_pass<false, false, true, true>(model, data);
  detail::backward_pass(model, data, data.gravity_torque);
  return finite_result(data.gravity_torque);
}

Status bias_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                   const ConstVector& v) noexcept {
  if (Status s = check_state(model, data, &q, &v); s != Status::ok) return s;
  detail::joint_state<true, false>(model, data, q, v, v);
  detail::place_for_springs(model, data);
  detail::forward_pass<true, false, true, true, false>(model, data);
  detail::backward_pass(model, data, data.bias_torque);
  add_springs(model, data, data.bias_torque);
  return finite_result(data.bias_torque);
}

// ---- springs and potential energy ------------------------------------------------------------

Status spring_state(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  detail::spring_forces<false>(model, data, data.spring_torque);
  return std::isfinite(data.spring_energy) ? finite_result(data.spring_length, data.spring_tension)
                                           : Status::out_of_range;
}

Status spring_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  data.spring_torque.setZero();
  detail::spring_forces<true>(model, data, data.spring_torque);
  return finite_result(data.spring_torque, data.spring_length, data.spring_tension);
}

Status static_torque(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place_for_springs(model, data);
  detail::forward_pass<false, false, true, true>(model, data);
  detail::backward_pass(model, data, data.gravity_torque);
  data.spring_torque.setZero();
  if (model.num_springs() > 0) detail::spring_forces<true>(model, data, data.spring_torque);
  data.static_torque = data.gravity_torque + data.spring_torque;
  return finite_result(data.static_torque);
}

Status potential_energy(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  detail::spring_forces<false>(model, data, data.spring_torque);
  data.potential_energy = -model.gravity().dot(mass_moment(model, data)) + data.spring_energy;
  return std::isfinite(data.potential_energy) ? Status::ok : Status::out_of_range;
}

// ---- mass matrix --------------------------------------------------------------------------------

namespace {

/// One past the last link of the subtree rooted at link i: links are depth-first (model.hpp), so
/// the subtree is [i, end) and ends at the first later link whose parent comes before i.
inline int subtree_end(const MechanismModel& model, int i) noexcept {
  int end = i + 1;
  while (end < model.num_links() && model.parent(end) >= i) ++end;
  return end;
}

/// True when x is a finite double (a NaN fails the comparison).
inline bool finite(double x) noexcept { return std::abs(x) <= std::numeric_limits<double>::max(); }

}  // namespace

// One backward pass of the composite rigid body algorithm (Featherstone 2008, alg. 6.2) with
// Pinocchio's subtree blocks. work[l].force / .moment hold P_l / L_l, the momentum of link l's
// composite body under a unit rate of joint l (L about the frame's origin), carried up the tree:
// when link i is reached, the columns of its whole subtree are in L_i. Row i of M is S_i^T of
// every column of the subtree (the pairs (i, descendant): the support paths only; a branch's
// entries against another branch are never computed), then the subtree's columns move to the
// parent's frame with a rotation and a cross product each. The columns of a subtree do not depend
// on each other (no dependent chain of transforms per column, as a walk up from each link has).
// Gear couplings are applied as the pairs come, M(c_i, c_l) += r_i r_l S_i^T F_l: the projection
// G^T M_joint G without a dense product. Only the written entries are checked for finiteness.
Status mass_matrix(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place<false>(model, data);
  if (!MechanismData::size_dense(data.mass_matrix, model.dof(), model.dof())) return Status::out_of_range;
  detail::composite_inertias(model, data);
  Eigen::MatrixXd& M = data.mass_matrix;
  M.setZero();
  bool ok = true;
  const int nl = model.num_links();
  for (int i = nl - 1; i >= 1; --i) {
    auto& W = data.work[static_cast<std::size_t>(i)];
    const int end = subtree_end(model, i);
    const int ci = model.coordinate(i);
    if (ci >= 0) {
      const bool revolute = model.joint_type(i) == JointType::revolute;
      if (revolute) {
        W.moment = W.composite_inertia.col(2);
        W.force = -detail::cross_ez(W.composite_first_moment);
      } else {
        W.moment = detail::cross_ez(W.composite_first_moment);
        W.force = Vec3(0.0, 0.0, W.composite_mass);
      }
      const double ri = model.coordinate_ratio(i);
      double& d = M(ci, ci);
      d += ri * ri * (revolute ? W.moment.z() : W.force.z());
      ok &= finite(d);
      for (int l = i + 1; l < end; ++l) {
        const int cl = model.coordinate(l);
        if (cl < 0) continue;
        const auto& C = data.work[static_cast<std::size_t>(l)];
        const double value = ri * model.coordinate_ratio(l) * (revolute ? C.moment.z() : C.force.z());
        M(cl, ci) += value;
        double& e = M(ci, cl);
        e += value;
        ok &= finite(e);  // M(cl, ci) == M(ci, cl): both receive the same values
      }
    } else {
      W.force.setZero();
      W.moment.setZero();
    }
    const int parent = model.parent(i);
    if (parent == 0) continue;  // nothing above
    // a massless subtree (m = 0, zero inertia: composite_inertias does not carry it either):
    // its columns are zero in every frame
    if (W.composite_mass == 0.0 && W.composite_inertia.trace() == 0.0) continue;
    const Mat3& R = W.rotation;
    const Vec3& t = W.translation;
    detail::with_local_rotation(model.local_rotation(i), [&](auto kind) {
      constexpr auto K = decltype(kind)::value;
      for (int l = i; l < end; ++l) {
        auto& C = data.work[static_cast<std::size_t>(l)];
        const Vec3 P = detail::to_parent<K>(R, C.force);
        C.moment = detail::to_parent<K>(R, C.moment) + t.cross(P);
        C.force = P;
      }
    });
  }
  return ok ? Status::ok : Status::out_of_range;
}

// ---- Jacobians ----------------------------------------------------------------------------------

Status frame_jacobian(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                      int frame) noexcept {
  if (frame < 0 || frame >= model.num_frames()) return Status::bad_size;
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  detail::joint_state<false, false>(model, data, q, q, q);
  detail::place(model, data);
  detail::frame_jacobian_placed(model, data, frame, data.frame_jacobian);
  return finite_result(data.frame_jacobian);
}

// ---- regressors ---------------------------------------------------------------------------------

namespace {

/// E_p x for the symmetric basis matrices of [Ixx, Ixy, Iyy, Ixz, Iyz, Izz].
inline Vec3 inertia_basis_times(int p, const Vec3& x) noexcept {
  switch (p) {
    case 0: return Vec3(x.x(), 0.0, 0.0);
    case 1: return Vec3(x.y(), x.x(), 0.0);
    case 2: return Vec3(0.0, x.y(), 0.0);
    case 3: return Vec3(x.z(), 0.0, x.x());
    case 4: return Vec3(0.0, x.z(), x.y());
    default: return Vec3(0.0, 0.0, x.z());
  }
}

/// Torque regressor of one link's inertial parameters (in F_l, about its origin) into
/// data.link_regressor (dof x 10), from a forward pass (with gravity when wanted).
void link_torque_regressor(const MechanismModel& model, MechanismData& data, int l) noexcept {
  const auto& W = data.work[static_cast<std::size_t>(l)];
  const Mat3& A = model.link_constants(l).aligned;
  const Vec3 w = A * W.w, al = A * W.alpha, acc = A * W.acc;  // in F_l
  const Mat3 RF = W.world_rotation * A.transpose();
  const Vec3& p = W.world_position;
  Eigen::Matrix<double, 6, 10> Y;  // wrench in O (force; moment about O) per parameter
  Y.setZero();
  Vec3 f, n;
  for (int col = 0; col < 10; ++col) {
    if (col == 0) {
      f = acc;
      n.setZero();
    } else if (col < 4) {
      const Vec3 e = Vec3::Unit(col - 1);
      f = al.cross(e) + w.cross(w.cross(e));
      n = e.cross(acc);
    } else {
      f.setZero();
      n = inertia_basis_times(col - 4, al) + w.cross(inertia_basis_times(col - 4, w));
    }
    const Vec3 fw = RF * f;
    Y.block<3, 1>(0, col) = fw;
    Y.block<3, 1>(3, col) = RF * n + p.cross(fw);
  }
  data.link_regressor.setZero();
  detail::for_each_path_joint(model, data, l, [&](int c, const Vec3& s, const Vec3& pk, bool revolute) {
    if (revolute) {
      // s . (n_O - p_k x f) = s . n_O - (p_k x f) . s = s . n_O - (s x p_k) . f
      const Vec3 sxp = s.cross(pk);
      for (int col = 0; col < 10; ++col) {
        data.link_regressor(c, col) += s.dot(Y.block<3, 1>(3, col)) - sxp.dot(Y.block<3, 1>(0, col));
      }
    } else {
      for (int col = 0; col < 10; ++col) data.link_regressor(c, col) += s.dot(Y.block<3, 1>(0, col));
    }
  });
}

template <bool Velocity, bool Acceleration>
void fill_torque_regressor(const MechanismModel& model, MechanismData& data, Eigen::MatrixXd& out) noexcept {
  detail::place(model, data);
  detail::forward_pass<Velocity, Acceleration, true, false>(model, data);
  for (int b = 0; b < model.num_bodies(); ++b) {
    const int l = model.body_link(b);
    if (l == 0) {
      out.middleCols<10>(10 * b).setZero();
      continue;
    }
    link_torque_regressor(model, data, l);
    out.middleCols<10>(10 * b) = data.link_regressor;
  }
}

}  // namespace

Status torque_regressor(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                        const ConstVector& v, const ConstVector& a) noexcept {
  if (Status s = check_state(model, data, &q, &v, &a); s != Status::ok) return s;
  if (!MechanismData::size_dense(data.torque_regressor, model.dof(), 10 * model.num_bodies())) {
    return Status::out_of_range;
  }
  detail::joint_state<true, true>(model, data, q, v, a);
  fill_torque_regressor<true, true>(model, data, data.torque_regressor);
  return finite_result(data.torque_regressor);
}

Status gravity_regressor(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept {
  if (Status s = check_state(model, data, &q); s != Status::ok) return s;
  if (!MechanismData::size_dense(data.gravity_regressor, model.dof(), 10 * model.num_bodies())) {
    return Status::out_of_range;
  }
  detail::joint_state<false, false>(model, data, q, q, q);
  fill_torque_regressor<false, false>(model, data, data.gravity_regressor);
  return finite_result(data.gravity_regressor);
}

Status momentum_regressor(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                          const ConstVector& v) noexcept {
  if (Status s = check_state(model, data, &q, &v); s != Status::ok) return s;
  detail::joint_state<true, false>(model, data, q, v, v);
  detail::place(model, data);
  detail::forward_pass<true, false, false, false>(model, data);
  for (int b = 0; b < model.num_bodies(); ++b) {
    auto Y = data.momentum_regressor.middleCols<10>(10 * b);
    const int l = model.body_link(b);
    Y.setZero();
    if (l == 0) continue;
    const auto& W = data.work[static_cast<std::size_t>(l)];
    const Mat3 RF = W.world_rotation * model.link_constants(l).aligned.transpose();
    const Vec3& p = W.world_position;
    const Vec3 w = W.world_rotation * W.w, vel = W.world_rotation * W.vel;
    const Vec3 w_local = RF.transpose() * w;
    // P = m v + w x R h;  H_O = p x P + (R h) x v + R I (R^T w)
    Y.block<3, 1>(0, 0) = vel;
    Y.block<3, 1>(3, 0) = p.cross(vel);
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = RF.col(k);
      const Vec3 P = w.cross(e);
      Y.block<3, 1>(0, 1 + k) = P;
      Y.block<3, 1>(3, 1 + k) = p.cross(P) + e.cross(vel);
    }
    for (int k = 0; k < 6; ++k) Y.block<3, 1>(3, 4 + k) = RF * inertia_basis_times(k, w_local);
  }
  return finite_result(data.momentum_regressor);
}

}  // namespace mechbal
