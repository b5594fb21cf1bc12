#pragma once
/// \file detail/tree.hpp
/// Internal passes over a MechanismModel shared by the algorithm files: input checks, joint
/// positions through the gear couplings, placement of every link, the recursive Newton-Euler
/// forward pass and the composite-inertia backward pass. Everything here works in the
/// joint-aligned link frames L_i of model.hpp (the joint moves about / along local z).
/// noexcept and allocation-free.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include "mechbal/detail/link_subset.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

/// The per-link passes below are called once per tick on every link: GCC's inliner, short of
/// budget in a translation unit that grew (algorithms.cpp), left Eigen's 3x3 products as calls
/// inside them (every call spills the pass's registers: inverse dynamics 15-20 % slower). flatten
/// inlines everything these passes call, whatever the size of the unit that instantiates them.
#if defined(__GNUC__) || defined(__clang__)
#define MECHBAL_FLATTEN __attribute__((flatten))
#else
#define MECHBAL_FLATTEN
#endif

namespace mechbal::detail {

/// w x e_z without the multiplications by zero.
inline Vec3 cross_ez(const Vec3& w) noexcept { return Vec3(w.y(), -w.x(), 0.0); }

using LocalRotation = MechanismModel::LocalRotation;

/// R^T v and R v for a link's rotation R relative to its parent (LinkWork::rotation) as it acts
/// (K: model.local_rotation): the identity costs nothing; along an axis k of the parent's frame,
/// R e_z = +-e_k and R's first two columns lie in the other two rows (i, j), so four
/// multiplications and one sign instead of nine. The products left out are those with R's exact
/// zeros, so the results are R^T v and R v.
template <LocalRotation K>
struct AxisRows {  // k, and the other two rows i < j
  static constexpr int k = K == LocalRotation::along_x ? 0 : K == LocalRotation::along_y ? 1 : 2;
  static constexpr int i = k == 0 ? 1 : 0;
  static constexpr int j = k == 2 ? 1 : 2;
};

template <LocalRotation K>
inline Vec3 to_child(const Mat3& R, const Vec3& v) noexcept {
  if constexpr (K == LocalRotation::identity) {
    return v;
  } else if constexpr (K == LocalRotation::general) {
    return R.transpose() * v;
  } else {
    using A = AxisRows<K>;
    return Vec3(R(A::i, 0) * v(A::i) + R(A::j, 0) * v(A::j), R(A::i, 1) * v(A::i) + R(A::j, 1) * v(A::j),
                R(A::k, 2) * v(A::k));
  }
}

template <LocalRotation K>
inline Vec3 to_parent(const Mat3& R, const Vec3& v) noexcept {
  if constexpr (K == LocalRotation::identity) {
    return v;
  } else if constexpr (K == LocalRotation::general) {
    return R * v;
  } else {
    using A = AxisRows<K>;
    Vec3 out;
    out(A::i) = R(A::i, 0) * v.x() + R(A::i, 1) * v.y();
    out(A::j) = R(A::j, 0) * v.x() + R(A::j, 1) * v.y();
    out(A::k) = R(A::k, 2) * v.z();
    return out;
  }
}

/// P R for a rotation P (a parent's in O) and a link's R, as to_child.
template <LocalRotation K>
inline void times_local(const Mat3& P, const Mat3& R, Mat3& out) noexcept {
  if constexpr (K == LocalRotation::identity) {
    out = P;
  } else if constexpr (K == LocalRotation::general) {
    out.noalias() = P * R;
  } else {
    using A = AxisRows<K>;
    out.col(0) = R(A::i, 0) * P.col(A::i) + R(A::j, 0) * P.col(A::j);
    out.col(1) = R(A::i, 1) * P.col(A::i) + R(A::j, 1) * P.col(A::j);
    out.col(2) = R(A::k, 2) * P.col(A::k);
  }
}

/// f(std::integral_constant<LocalRotation, K>{}) with K = `kind`: one branch per link, then code
/// specialised for its rotation.
template <typename F>
inline void with_local_rotation(LocalRotation kind, F&& f) noexcept {
  switch (kind) {
    case LocalRotation::along_x:
      f(std::integral_constant<LocalRotation, LocalRotation::along_x>{});
      break;
    case LocalRotation::along_y:
      f(std::integral_constant<LocalRotation, LocalRotation::along_y>{});
      break;
    case LocalRotation::along_z:
      f(std::integral_constant<LocalRotation, LocalRotation::along_z>{});
      break;
    case LocalRotation::identity:
      f(std::integral_constant<LocalRotation, LocalRotation::identity>{});
      break;
    case LocalRotation::general:
    default:  // (every value is listed: this tells the compiler that f always runs)
      f(std::integral_constant<LocalRotation, LocalRotation::general>{});
      break;
  }
}

inline bool data_matches(const MechanismModel& model, const MechanismData& data) noexcept {
  return data.dof == model.dof() && data.num_links == model.num_links() &&
         data.num_bodies == model.num_bodies() && data.num_frames == model.num_frames() &&
         data.num_springs == model.num_springs() &&
         static_cast<int>(data.work.size()) == model.num_links();
}

/// True when every entry of x (a vector or a matrix of doubles) is finite: inlined where Eigen's
/// allFinite (x - x compared with itself entry by entry) was left as a call in a big translation
/// unit. The input checks and the algorithms' result checks (finite_result) share it. An entry is
/// infinite or NaN exactly when its exponent bits are all ones; adding 2^52 to those bits then
/// carries into the sign bit, so one OR over the entries answers for all of them, in integer
/// operations without a branch or a comparison per entry (vectorised over contiguous storage).
template <typename Derived>
inline bool all_finite(const Eigen::DenseBase<Derived>& x) noexcept {
  static_assert(std::is_same<typename Derived::Scalar, double>::value, "all_finite: doubles only");
  constexpr std::uint64_t kExponent = 0x7ff0000000000000ull, kUnit = 0x0010000000000000ull;
  const Derived& m = x.derived();
  std::uint64_t bad = 0;
  if constexpr ((Eigen::internal::traits<Derived>::Flags & Eigen::DirectAccessBit) != 0) {
    if (m.innerStride() == 1 && (m.cols() == 1 || m.rows() == 1 || m.outerStride() == m.rows())) {
      const double* p = m.data();
      for (Eigen::Index k = 0; k < m.size(); ++k) {
        std::uint64_t b;
        std::memcpy(&b, p + k, sizeof b);
        bad |= (b & kExponent) + kUnit;
      }
      return (bad >> 63) == 0;
    }
  }
  for (Eigen::Index j = 0; j < m.cols(); ++j) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      const double v = m.coeff(i, j);
      std::uint64_t b;
      std::memcpy(&b, &v, sizeof b);
      bad |= (b & kExponent) + kUnit;
    }
  }
  return (bad >> 63) == 0;
}

/// Sizes and finiteness of up to three state vectors (null = not used).
inline Status check_state(const MechanismModel& model, const MechanismData& data,
                          const Eigen::Ref<const Eigen::VectorXd>* q,
                          const Eigen::Ref<const Eigen::VectorXd>* v = nullptr,
                          const Eigen::Ref<const Eigen::VectorXd>* a = nullptr) noexcept {
  if (!data_matches(model, data)) return Status::bad_size;
  const Eigen::Index n = model.dof();
  if ((q && q->size() != n) || (v && v->size() != n) || (a && a->size() != n)) return Status::bad_size;
  if ((q && !all_finite(*q)) || (v && !all_finite(*v)) || (a && !all_finite(*a))) {
    return Status::non_finite_input;
  }
  return Status::ok;
}

/// Joint position, velocity, acceleration of every link from the independent coordinates.
/// With Subset, `only` (not null) restricts it to its links (as place).
template <bool Velocity, bool Acceleration, bool Subset = false>
inline void joint_state(const MechanismModel& model, MechanismData& data,
                        const Eigen::Ref<const Eigen::VectorXd>& q,
                        const Eigen::Ref<const Eigen::VectorXd>& v,
                        const Eigen::Ref<const Eigen::VectorXd>& a, const LinkSubset* only = nullptr) noexcept {
  const int count = Subset ? static_cast<int>(only->links.size()) : model.num_links() - 1;
  for (int i = 0; i < count; ++i) {
    const int l = Subset ? only->links[static_cast<std::size_t>(i)] : i + 1;
    const auto k = static_cast<std::size_t>(l);
    const int c = model.coordinate(l);
    if (c < 0) {
      data.joint_position[k] = data.joint_velocity[k] = data.joint_acceleration[k] = 0.0;
      continue;
    }
    const double r = model.coordinate_ratio(l);
    data.joint_position[k] = r * q(c) + model.coordinate_offset(l);
    data.joint_velocity[k] = Velocity ? r * v(c) : 0.0;
    data.joint_acceleration[k] = Acceleration ? r * a(c) : 0.0;
  }
}

/// The visit that does nothing (place's default).
struct NoVisit {
  void operator()(int, const MechanismData::LinkWork&) const noexcept {}
};

/// place's pass. With Shortcuts: the rotations in O through times_local's shortcuts, one branch
/// per link; without, dense products throughout (a model with no axis-aligned link does not pay
/// the branch).
template <bool Shortcuts, bool World, class Visit, bool Subset>
MECHBAL_FLATTEN inline void place_as(const MechanismModel& model, MechanismData& data, Visit& visit,
                                     const LinkSubset* only) noexcept {
  const int count = Subset ? static_cast<int>(only->links.size()) : model.num_links() - 1;
  for (int i = 0; i < count; ++i) {
    const int l = Subset ? only->links[static_cast<std::size_t>(i)] : i + 1;
    const auto k = static_cast<std::size_t>(l);
    auto& w = data.work[k];
    const double qk = data.joint_position[k];
    const bool local = !(qk == w.placed_at);  // never placed: NaN
    if (local) {
      const auto& c = model.link_constants(l);
      switch (model.joint_type(l)) {
        case JointType::revolute: {
          // C_R Rz(q): only the first two columns change
          const double cs = std::cos(qk), sn = std::sin(qk);
          w.rotation.col(0) = cs * c.rotation.col(0) + sn * c.rotation.col(1);
          w.rotation.col(1) = cs * c.rotation.col(1) - sn * c.rotation.col(0);
          w.rotation.col(2) = c.rotation.col(2);
          w.translation = c.translation;
          break;
        }
        case JointType::prismatic:
          w.rotation = c.rotation;
          w.translation = c.translation + c.rotation.col(2) * qk;
          break;
        case JointType::fixed:
          w.rotation = c.rotation;
          w.translation = c.translation;
          break;
      }
      w.placed_at = qk;
      // the composites of every ancestor hold this link's old placement (composite_inertias);
      // a stale link's ancestors are all stale already
      for (int j = model.parent(l); j > 0 && data.work[static_cast<std::size_t>(j)].composite_current;
           j = model.parent(j)) {
        data.work[static_cast<std::size_t>(j)].composite_current = false;
      }
    }
    if (World) {
      const auto& p = data.work[static_cast<std::size_t>(model.parent(l))];
      w.world_moved = local || w.world_stale || p.world_moved;
      if (w.world_moved) {
        if constexpr (Shortcuts) {
          with_local_rotation(model.local_rotation(l), [&](auto kind) {
            times_local<decltype(kind)::value>(p.world_rotation, w.rotation, w.world_rotation);
          });
        } else {
          w.world_rotation.noalias() = p.world_rotation * w.rotation;
        }
        w.world_position = p.world_position + p.world_rotation * w.translation;
        w.world_stale = false;
        w.momentum_current = false;
      }
    } else if (local) {
      w.world_stale = true;  // world_* no longer that of rotation / translation
    }
    visit(l, static_cast<const MechanismData::LinkWork&>(w));
  }
}

/// Link placements relative to their parents and, with World, in O (L frames). The passes that
/// work in the links' own frames only (inverse dynamics, gravity, bias, mass matrix) skip World:
/// work[].world_* are then left as they were (and marked stale). `visit(l, work[l])` runs on each
/// link right after it is placed (in tree order, links 1..n-1), while its data is in cache: an
/// algorithm that needs one more quantity per placed link folds it into this pass instead of
/// sweeping the links again.
/// Incremental: a link whose joint position is the one its placement was last computed at
/// (LinkWork::placed_at) keeps its rotation and translation, and its pose in O when neither it
/// nor its parent moved since that pose was computed: an algorithm called at the q the links are
/// already placed at (shaking_wrench after closed_motion, the momentum matrix at a pose where
/// only a few joints moved) pays for the moved links only. The skipped values are exactly those
/// that would be recomputed (same inputs, same operations), so results are bit for bit the same.
/// With Subset, `only` (not null) restricts the pass to its links (their parents outside it keep
/// their placements, in O too).
template <bool World = true, class Visit = NoVisit, bool Subset = false>
inline void place(const MechanismModel& model, MechanismData& data, Visit&& visit = Visit{},
                  const LinkSubset* only = nullptr) noexcept {
  if (model.has_aligned_links()) {
    place_as<true, World, Visit, Subset>(model, data, visit, only);
  } else {
    place_as<false, World, Visit, Subset>(model, data, visit, only);
  }
}

/// R S R^T of a symmetric S, computing the upper triangle only (45 multiplications, not 54).
inline Mat3 rotate_symmetric(const Mat3& R, const Mat3& S) noexcept {
  const Mat3 RS = R * S;
  Mat3 out;
  out(0, 0) = RS.row(0).dot(R.row(0));
  out(0, 1) = out(1, 0) = RS.row(0).dot(R.row(1));
  out(0, 2) = out(2, 0) = RS.row(0).dot(R.row(2));
  out(1, 1) = RS.row(1).dot(R.row(1));
  out(1, 2) = out(2, 1) = RS.row(1).dot(R.row(2));
  out(2, 2) = RS.row(2).dot(R.row(2));
  return out;
}

/// rotate_symmetric for a link's rotation R relative to its parent as it acts (K, as to_child):
/// S itself for the identity; along an axis k, the products with R's zeros left out (R S R^T's
/// entries in row and column k are S_zz and the sign of R_kz times R's 2 x 2 block applied to S's
/// third column; the other four R's block around S's upper-left 2 x 2): 20 multiplications, not 45,
/// and the same values.
template <LocalRotation K>
inline Mat3 rotate_symmetric_as(const Mat3& R, const Mat3& S) noexcept {
  if constexpr (K == LocalRotation::identity) {
    return S;
  } else if constexpr (K == LocalRotation::general) {
    return rotate_symmetric(R, S);
  } else {
    using A = AxisRows<K>;
    constexpr int i = A::i, j = A::j, k = A::k;
    // (R S) on rows i, j, first two columns
    const double ti0 = R(i, 0) * S(0, 0) + R(i, 1) * S(1, 0), ti1 = R(i, 0) * S(0, 1) + R(i, 1) * S(1, 1);
    const double tj0 = R(j, 0) * S(0, 0) + R(j, 1) * S(1, 0), tj1 = R(j, 0) * S(0, 1) + R(j, 1) * S(1, 1);
    const double sign = R(k, 2);
    Mat3 out;
    out(i, i) = ti0 * R(i, 0) + ti1 * R(i, 1);
    out(i, j) = out(j, i) = ti0 * R(j, 0) + ti1 * R(j, 1);
    out(j, j) = tj0 * R(j, 0) + tj1 * R(j, 1);
    out(i, k) = out(k, i) = sign * (R(i, 0) * S(0, 2) + R(i, 1) * S(1, 2));
    out(j, k) = out(k, j) = sign * (R(j, 0) * S(0, 2) + R(j, 1) * S(1, 2));
    out(k, k) = S(2, 2);
    return out;
  }
}

/// Link l's Newton-Euler wrench (force, moment about its origin, in L_l) from its motion in L_l:
/// f = m acc + alpha x h + w x (w x h), n = I alpha + h x acc + w x (I w) (h = m c, I about the
/// origin). Velocity = false: the terms in w are left out (w = 0).
template <bool Velocity = true>
inline void link_wrench(const MechanismModel::LinkConstants& c, const Vec3& w, const Vec3& alpha, const Vec3& acc,
                        Vec3& force, Vec3& moment) noexcept {
  const Vec3& h = c.first_moment;
  force = c.mass * acc + alpha.cross(h);
  moment.noalias() = c.inertia_origin * alpha;
  moment += h.cross(acc);
  if (Velocity) {
    force += w.cross(w.cross(h));
    moment += w.cross(c.inertia_origin * w);
  }
}

/// Link l's momentum (linear, angular about O) from its velocities in L_l, added to P and H.
/// (w, vel: the link's velocities in L_l; passed apart from W so that a pass that has just
/// computed them hands them over in registers: forward_link)
inline void add_link_momentum(const MechanismModel::LinkConstants& c, const MechanismData::LinkWork& W, const Vec3& w,
                              const Vec3& vel, Vec3& P, Vec3& H) noexcept {
  const Vec3 p_local = c.mass * vel + w.cross(c.first_moment);
  const Vec3 h_local = c.inertia_origin * w + c.first_moment.cross(vel);
  const Vec3 p_world = W.world_rotation * p_local;
  P += p_world;
  H += W.world_rotation * h_local + W.world_position.cross(p_world);
}

/// The motion a link hands to its children in the forward pass (in its own L frame).
struct LinkMotion {
  Vec3 w, vel, acc, alpha;
};

/// One link's step of the forward pass (see forward_pass) from its parent's motion: velocity,
/// acceleration in its own L frame and, when Forces, its net wrench. Rates = false: the velocities
/// alone (w and, with OriginVelocity, vel), acc and alpha left as they were (the momenta need
/// nothing more).
/// `m` and `last`: the motion of the link stepped just before and its index (-1: none). When it
/// is l's parent (along a chain: most links), its motion is taken from `m`, in registers, not read
/// back from data.work, where it was just written: a load that straddles the parts of a vector
/// stored separately (z after x and y) waits for the stores to retire instead of forwarding
/// from them, which cost the passes a fifth of their time. On return `m` is l's motion and
/// `last` = l.
/// (forward_link for a link whose rotation acts as K)
template <LocalRotation K, bool Velocity, bool Acceleration, bool Forces, bool OriginVelocity, bool Rates>
inline void forward_link_as(const MechanismModel& model, MechanismData& data, int l, LinkMotion& m, int& last) noexcept {
  const auto k = static_cast<std::size_t>(l);
  const int parent = model.parent(l);
  if (parent != last) {
    const auto& P = data.work[static_cast<std::size_t>(parent)];
    if (Velocity) {
      m.w = P.w;
      if (OriginVelocity) m.vel = P.vel;
    }
    if (Rates) {
      m.acc = P.acc;
      m.alpha = P.alpha;
    }
  }
  auto& W = data.work[k];
  const Vec3& p = W.translation;
  const Mat3& R = W.rotation;
  Vec3 w = Vec3::Zero(), vel = Vec3::Zero(), acc = Vec3::Zero(), alpha = Vec3::Zero();
  if (Rates) {
    Vec3 a_lin = m.acc;
    if (Velocity || Acceleration) a_lin += m.alpha.cross(p);
    if (Velocity) a_lin += m.w.cross(m.w.cross(p));
    acc = to_child<K>(R, a_lin);
  }
  if (Velocity) {
    w = to_child<K>(R, m.w);
    if (OriginVelocity) vel = to_child<K>(R, Vec3(m.vel + m.w.cross(p)));
  }
  if (Rates && (Velocity || Acceleration)) alpha = to_child<K>(R, m.alpha);
  const double qd = Velocity ? data.joint_velocity[k] : 0.0;
  const double qdd = Acceleration ? data.joint_acceleration[k] : 0.0;
  switch (model.joint_type(l)) {
    case JointType::revolute:
      if (Velocity) {
        if (Rates) alpha += cross_ez(w) * qd;
        w.z() += qd;
      }
      if (Acceleration) alpha.z() += qdd;
      break;
    case JointType::prismatic:
      if (Velocity) {
        if (Rates) acc += cross_ez(w) * (2.0 * qd);
        if (OriginVelocity) vel.z() += qd;
      }
      if (Acceleration) acc.z() += qdd;
      break;
    case JointType::fixed:
      break;
  }
  W.w = w;
  if (OriginVelocity || !Velocity) W.vel = vel;
  if (Rates) {
    W.acc = acc;
    W.alpha = alpha;
  }
  m.w = w;
  m.vel = vel;
  if (Rates) {
    m.acc = acc;
    m.alpha = alpha;
  }
  last = l;
  if (Forces) link_wrench<Velocity>(model.link_constants(l), w, alpha, acc, W.force, W.moment);
}

template <bool Velocity, bool Acceleration, bool Forces, bool OriginVelocity = true, bool Rates = true>
inline void forward_link(const MechanismModel& model, MechanismData& data, int l, LinkMotion& m, int& last) noexcept {
  if constexpr (!Velocity && !Acceleration) {
    // (gravity alone: one rotated vector per link, where the branch to a shortcut costs more than
    // the multiplications it saves)
    forward_link_as<LocalRotation::general, Velocity, Acceleration, Forces, OriginVelocity, Rates>(model, data, l, m,
                                                                                                  last);
    return;
  }
  with_local_rotation(model.local_rotation(l), [&](auto kind) {
    forward_link_as<decltype(kind)::value, Velocity, Acceleration, Forces, OriginVelocity, Rates>(model, data, l, m,
                                                                                                 last);
  });
}

/// Forward pass: velocity, acceleration of every link in its own L frame and, when Forces, the
/// net wrench each link needs (force, moment about its origin). Gravity enters as an upward
/// acceleration -g of the base (Luh et al.), so with Gravity the wrenches include the weights.
/// OriginVelocity = false skips the velocities of the link origins (work[].vel, left as they
/// were): the joint torques need only the angular velocities, the accelerations and the wrenches
/// (inverse dynamics, bias and Coriolis torques), while the momenta and frame motions need them.
template <bool Velocity, bool Acceleration, bool Gravity, bool Forces, bool OriginVelocity = true>
MECHBAL_FLATTEN inline void forward_pass(const MechanismModel& model, MechanismData& data) noexcept {
  auto& base = data.work[0];
  base.w.setZero();
  base.alpha.setZero();
  base.vel.setZero();
  if (Gravity) {
    base.acc = -model.gravity();
  } else {
    base.acc.setZero();
  }
  LinkMotion m{base.w, base.vel, base.acc, base.alpha};
  int last = 0;
  const int nl = model.num_links();
  if (model.has_aligned_links()) {
    for (int l = 1; l < nl; ++l) forward_link<Velocity, Acceleration, Forces, OriginVelocity>(model, data, l, m, last);
  } else {  // (no branch per link to a shortcut no link takes)
    for (int l = 1; l < nl; ++l) {
      forward_link_as<LocalRotation::general, Velocity, Acceleration, Forces, OriginVelocity, true>(model, data, l, m,
                                                                                                   last);
    }
  }
}

/// Backward pass: wrench transmitted by each joint (accumulated into work[l].force/moment; the
/// base's entry receives the wrench the base exerts on the moving links, in O), projected on the
/// joint axes and through the gear couplings into `tau` (size dof).
template <typename Tau>
MECHBAL_FLATTEN inline void backward_pass(const MechanismModel& model, MechanismData& data, Tau& tau) noexcept {
  data.work[0].force.setZero();
  data.work[0].moment.setZero();
  tau.setZero();
  for (int l = model.num_links() - 1; l >= 1; --l) {
    const auto& W = data.work[static_cast<std::size_t>(l)];
    const int c = model.coordinate(l);
    if (c >= 0) {
      const double t = model.joint_type(l) == JointType::revolute ? W.moment.z() : W.force.z();
      tau(c) += model.coordinate_ratio(l) * t;
    }
    auto& P = data.work[static_cast<std::size_t>(model.parent(l))];
    // (dense products: with the shortcuts of to_parent, the branch per link cost more than the
    // multiplications saved; gravity torques on Talos and Romeo were 4-8 % slower)
    const Vec3 f = W.rotation * W.force;
    P.force += f;
    P.moment += W.rotation * W.moment + W.translation.cross(f);
  }
}

/// Composite mass, first moment and inertia about each link's origin (in L_i) of the subtree
/// rooted at every moving link (CRBA's backward pass; Featherstone 2008, alg. 6.2). The base's
/// entry (link 0) keeps only its own bodies: nothing above the joints uses the whole tree's
/// composite, and not carrying subtrees onto the base saves a transform per base child. Massless
/// subtrees (a tool frame's link) are not transformed either: they add nothing.
/// Incremental: a link's composite (in its own frame) depends only on the placements of the links
/// below it, so only the links marked stale by place() (LinkWork::composite_current: the
/// ancestors of a link whose placement changed) are recomputed, each from its own bodies and its
/// children in the same order as a full pass: bit for bit the same result.
/// `only` (or null: all): recompute its links alone (e.g. a controller's balancing subtrees, whose
/// columns of the momentum matrix need nothing else); the others keep their state, stale or not.
MECHBAL_FLATTEN inline void composite_inertias(const MechanismModel& model, MechanismData& data,
                                               const LinkSubset* only = nullptr) noexcept {
  const int nl = model.num_links();
  const int count = only ? static_cast<int>(only->links.size()) : nl;
  for (int i = 0; i < count; ++i) {
    const int l = only ? only->links[static_cast<std::size_t>(i)] : i;
    auto& W = data.work[static_cast<std::size_t>(l)];
    if (W.composite_current) continue;
    W.momentum_current = false;  // its momentum-matrix column follows its composite
    const auto& c = model.link_constants(l);
    W.composite_mass = c.mass;
    W.composite_first_moment = c.first_moment;
    W.composite_inertia = c.inertia_origin;
  }
  for (int i = count - 1; i >= 0; --i) {
    const int l = only ? only->links[static_cast<std::size_t>(i)] : i;
    if (l == 0) continue;
    const int parent = model.parent(l);
    if (parent == 0) continue;
    auto& P = data.work[static_cast<std::size_t>(parent)];
    if (P.composite_current || (only && !only->member[static_cast<std::size_t>(parent)])) continue;
    const auto& W = data.work[static_cast<std::size_t>(l)];
    // massless: m = 0 and a zero inertia (positive semi-definite with zero trace)
    if (W.composite_mass == 0.0 && W.composite_inertia.trace() == 0.0) continue;
    // I_O' = R I R^T + m ((p.p) 1 - p p^T) + 2 (p.h) 1 - h p^T - p h^T with h = R h_child,
    // on the six distinct entries of the symmetric result.
    const double m = W.composite_mass;
    const Vec3& p = W.translation;
    Vec3 h;
    Mat3 I;
    with_local_rotation(model.local_rotation(l), [&](auto kind) {
      constexpr LocalRotation K = decltype(kind)::value;
      h = to_parent<K>(W.rotation, W.composite_first_moment);
      I = rotate_symmetric_as<K>(W.rotation, W.composite_inertia);
    });
    const double diagonal = m * p.squaredNorm() + 2.0 * p.dot(h);
    const Vec3 mp_h = m * p + h;  // m p_r p_c + h_r p_c + p_r h_c = (m p + h)_r p_c + p_r h_c
    Mat3& C = P.composite_inertia;
    C(0, 0) += I(0, 0) + diagonal - (mp_h.x() * p.x() + p.x() * h.x());
    C(1, 1) += I(1, 1) + diagonal - (mp_h.y() * p.y() + p.y() * h.y());
    C(2, 2) += I(2, 2) + diagonal - (mp_h.z() * p.z() + p.z() * h.z());
    const double c01 = I(0, 1) - (mp_h.x() * p.y() + p.x() * h.y());
    const double c02 = I(0, 2) - (mp_h.x() * p.z() + p.x() * h.z());
    const double c12 = I(1, 2) - (mp_h.y() * p.z() + p.y() * h.z());
    C(0, 1) += c01;
    C(1, 0) += c01;
    C(0, 2) += c02;
    C(2, 0) += c02;
    C(1, 2) += c12;
    C(2, 1) += c12;
    P.composite_mass += m;
    P.composite_first_moment += mp_h;
  }
  for (int i = 0; i < count; ++i) {
    data.work[static_cast<std::size_t>(only ? only->links[static_cast<std::size_t>(i)] : i)].composite_current = true;
  }
}

/// World placement and motion of a named frame from placed links and a forward pass: origin
/// position, rotation (frame -> O), origin velocity and classical acceleration, angular velocity
/// and acceleration (whatever the forward pass computed; zeros without velocities).
struct FrameMotion {
  Vec3 position, velocity, acceleration, angular_velocity, angular_acceleration;
  Mat3 rotation;
};

inline FrameMotion frame_motion(const MechanismModel& model, const MechanismData& data, int frame) noexcept {
  const int l = model.frame_link(frame);
  const auto& W = data.work[static_cast<std::size_t>(l)];
  const Mat3 RF = W.world_rotation * model.link_constants(l).aligned.transpose();
  const auto& T = model.frame(frame).placement;
  FrameMotion m;
  const Vec3 r = RF * T.translation();
  m.position = W.world_position + r;
  m.rotation = RF * T.linear();
  m.angular_velocity = W.world_rotation * W.w;
  m.angular_acceleration = W.world_rotation * W.alpha;
  m.velocity = W.world_rotation * W.vel + m.angular_velocity.cross(r);
  m.acceleration = W.world_rotation * W.acc + m.angular_acceleration.cross(r) +
                   m.angular_velocity.cross(m.angular_velocity.cross(r));
  return m;
}

/// Calls f(c, s, p_k, revolute) for every joint k with a coordinate on the path from `link` to the
/// root (placed links): c its coordinate, s = ratio * z_k its axis in O scaled by the gear ratio
/// (the joint's rate per unit rate of c), p_k its origin in O. A revolute joint moves a point p of
/// the link by s x (p - p_k) and turns it by s; a prismatic one moves it by s. What the frame
/// Jacobians, point forces, regressors and loop rows have in common.
template <typename F>
inline void for_each_path_joint(const MechanismModel& model, const MechanismData& data, int link, F&& f) noexcept {
  for (int k = link; k >= 1; k = model.parent(k)) {
    const int c = model.coordinate(k);
    if (c < 0) continue;
    const auto& K = data.work[static_cast<std::size_t>(k)];
    f(c, Vec3(model.coordinate_ratio(k) * K.world_rotation.col(2)), K.world_position,
      model.joint_type(k) == JointType::revolute);
  }
}

/// Jacobian [v; w] (O axes) of the origin of `frame` into J (6 x dof), from placed links (world
/// poses computed).
template <typename Jac>
inline void frame_jacobian_placed(const MechanismModel& model, const MechanismData& data, int frame,
                                  Jac& J) noexcept {
  const int fl = model.frame_link(frame);
  const auto& F = data.work[static_cast<std::size_t>(fl)];
  const Vec3 origin = F.world_position + F.world_rotation * (model.link_constants(fl).aligned.transpose() *
                                                             model.frame(frame).placement.translation());
  J.setZero();
  for_each_path_joint(model, data, fl, [&](int c, const Vec3& s, const Vec3& pk, bool revolute) {
    if (revolute) {
      J.col(c).template head<3>() += s.cross(origin - pk);
      J.col(c).template tail<3>() += s;
    } else {
      J.col(c).template head<3>() += s;
    }
  });
}

/// place<true> when the model has springs (their anchors need world positions), place<false>
/// otherwise: a model without springs pays one branch.
inline void place_for_springs(const MechanismModel& model, MechanismData& data) noexcept {
  if (model.num_springs() > 0) {
    place<true>(model, data);
  } else {
    place<false>(model, data);
  }
}

/// Adds J_p(q)^T f to tau: the generalised force of a force f (in O) applied at the point p (in O)
/// of link `link`, through the joints from the link to the base (from placed links).
template <typename Tau>
inline void add_point_force(const MechanismModel& model, const MechanismData& data, int link, const Vec3& p,
                            const Vec3& f, Tau& tau) noexcept {
  for_each_path_joint(model, data, link, [&](int c, const Vec3& s, const Vec3& pk, bool revolute) {
    tau(c) += revolute ? s.dot((p - pk).cross(f)) : s.dot(f);
  });
}

/// Springs from placed links (world poses computed): data.spring_length, spring_tension,
/// spring_energy and the base's wrench through its springs (spring_base_force/moment); with
/// Torque, also tau += K(q) = dV_springs/dq = -(J_A^T f_A + J_B^T f_B), f_A = T u the force on
/// anchor A (u = (p_B - p_A) / d), f_B = -f_A. The force is K_eq (p_B - p_A) + (T_0 - K_eq L_0) u,
/// so a zero-free-length spring stays defined at d = 0; another spring at d = 0 has no direction
/// and its u is taken as zero there.
template <bool Torque, typename Tau>
inline void spring_forces(const MechanismModel& model, MechanismData& data, Tau& tau) noexcept {
  data.spring_energy = 0.0;
  data.spring_base_force.setZero();
  data.spring_base_moment.setZero();
  const int ns = model.num_springs();
  for (int s = 0; s < ns; ++s) {
    const auto& c = model.spring_constants(s);
    const auto& A = data.work[static_cast<std::size_t>(c.link_a)];
    const auto& B = data.work[static_cast<std::size_t>(c.link_b)];
    const Vec3 pa = A.world_position + A.world_rotation * c.anchor_a;
    const Vec3 pb = B.world_position + B.world_rotation * c.anchor_b;
    const Vec3 r = pb - pa;
    const double d = r.norm();
    const double x = d - c.free_length;
    data.spring_length(s) = d;
    data.spring_tension(s) = c.preload_tension + c.equivalent_rate * x;
    data.spring_energy += x * (c.preload_tension + 0.5 * c.equivalent_rate * x);
    const double offset = c.preload_tension - c.equivalent_rate * c.free_length;
    Vec3 fa = c.equivalent_rate * r;
    if (offset != 0.0 && d > 0.0) fa += (offset / d) * r;
    if (c.link_a == 0 && c.link_b != 0) {  // the base pulls B with -f_A
      data.spring_base_force -= fa;
      data.spring_base_moment -= pb.cross(fa);
    } else if (c.link_b == 0 && c.link_a != 0) {
      data.spring_base_force += fa;
      data.spring_base_moment += pa.cross(fa);
    }
    if (Torque) {
      add_point_force(model, data, c.link_a, pa, Vec3(-fa), tau);
      add_point_force(model, data, c.link_b, pb, fa, tau);
    }
  }
}

}  // namespace mechbal::detail
