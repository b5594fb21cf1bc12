#include "mechbal/control/reactionless.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"
#include "mechbal/control/detail/gram_extremes.hpp"
#include "mechbal/detail/placed.hpp"
#include "mechbal/detail/tree.hpp"

namespace mechbal {

namespace {

/// Relative residual of a least-squares solve above which the cancelled components were not
/// cancelled (rounding leaves ~1e-15 of |r| where the equations agree).
constexpr double kUnmetResidual = 1e-8;

/// Status::singular when M x leaves more than kUnmetResidual |r| of r (no allocation: k <= 6).
Status unmet(const Eigen::MatrixXd& M, const Eigen::VectorXd& x, const Eigen::Ref<const Eigen::VectorXd>& r) noexcept {
  double residual = 0.0, scale = 0.0;
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    const double e = M.row(i).dot(x) - r(i);
    residual += e * e;
    scale += r(i) * r(i);
  }
  return residual > kUnmetResidual * kUnmetResidual * scale ? Status::singular : Status::ok;
}


[[noreturn]] void fail(const std::string& field, const std::string& what, double value) {
  std::ostringstream msg;
  msg << field << " " << what << ", got " << value;
  throw std::invalid_argument(msg.str());
}

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

constexpr double huge = std::numeric_limits<double>::max();

/// The flags of `s` that are also in `keep`.
constexpr Status only(Status s, Status keep) noexcept {
  return static_cast<Status>(static_cast<std::uint32_t>(s) & static_cast<std::uint32_t>(keep));
}
constexpr Status hard = Status::solver_error | Status::out_of_range | Status::non_finite_input;

bool failed(Status s) noexcept {
  return has(s, Status::solver_error) || has(s, Status::bad_size) || has(s, Status::non_finite_input) ||
         has(s, Status::out_of_range);
}

/// The fields both reactionless controllers (joint space and operational space) share, checked
/// in this order; std::invalid_argument naming the first bad one and its value.
void validate_shared_fields(std::uint32_t cancel, double rate_hz, double damping, double max_condition,
                            double max_rate) {
  if (cancel == 0u || (cancel & ~cancel_both) != 0u)
    fail("reactionless.cancel", "must select at least one of the six momentum components (bit mask 1..63)",
         static_cast<double>(cancel));
  if (!(rate_hz >= 1.0 && rate_hz <= 1e6)) fail("reactionless.rate_hz", "must be in [1, 1e6] Hz", rate_hz);
  if (!(damping > 0.0 && damping < 1.0)) fail("reactionless.damping", "must be in (0, 1)", damping);
  if (!(std::isfinite(max_condition) && max_condition > 1.0))
    fail("reactionless.max_condition", "must be finite and > 1", max_condition);
  if (!(max_rate > 0.0)) fail("reactionless.max_rate", "must be > 0 (+inf: no limit)", max_rate);
}

/// The smallest and largest eigenvalues of a small symmetric positive semi-definite matrix (at most
/// 6 x 6): Eigen's closed forms for 1 x 1 to 3 x 3 (computeDirect: a few hundred flops where the
/// iterative tridiagonal QR costs about 500 ns at 3 x 3), the iterative solver `fallback` for
/// larger matrices and whenever the closed form finds the matrix ill-conditioned (lmin < 1e-6
/// lmax), where its absolute error (up to ~sqrt(eps) lmax near a double root: see
/// closed_form3_error) would matter to the condition number. The controllers call it through
/// gram_extremes, which needs it only for Gram matrices above 3 x 3 or from more than
/// max_minor_side columns.
template <typename Small, typename Solver>
void extreme_eigenvalues(const Small& S, Solver& fallback, double& lmin, double& lmax) noexcept {
  const Eigen::Index n = S.rows();
  if (n == 1) {
    lmin = lmax = S(0, 0);
    return;
  }
  if (n == 2 || n == 3) {
    if (n == 2) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> direct;
      direct.computeDirect(Eigen::Matrix2d(S.template topLeftCorner<2, 2>()), Eigen::EigenvaluesOnly);
      lmin = direct.eigenvalues()(0);
      lmax = direct.eigenvalues()(1);
    } else {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> direct;
      direct.computeDirect(Eigen::Matrix3d(S.template topLeftCorner<3, 3>()), Eigen::EigenvaluesOnly);
      lmin = direct.eigenvalues()(0);
      lmax = direct.eigenvalues()(2);
    }
    if (lmax > 0.0 && lmin >= 1e-6 * lmax) return;  // well-conditioned (also false on NaN)
  }
  fallback.compute(S, Eigen::EigenvaluesOnly);
  const auto& lambda = fallback.eigenvalues();  // ascending
  lmin = lambda(0);
  lmax = lambda(lambda.size() - 1);
}

/// Unit roundoff of double (u = eps / 2).
constexpr double unit = std::numeric_limits<double>::epsilon() / 2.0;

/// The closed forms' error bounds, relative to lmax, on any eigenvalue they give.
/// 2 x 2 (Eigen's computeDirect: shift by the mean, scale, lambda = mean +- sqrt(...)): lmax is a
/// sum of non-negative terms, a few roundings: 8 eps covers it. 3 x 3 (the trigonometric method on
/// the shifted and scaled matrix B, max |B_ij| = 1): the characteristic polynomial's coefficients
/// carry absolute errors of a few eps (B's entries are at most 1), and every step is well
/// conditioned except theta = atan2(sqrt(q), b) / 3 where two roots meet (q -> 0): there an error
/// e_q ~ 5 eps in q moves sqrt(q), hence theta, by up to sqrt(e_q) / (3 rho^(3/2)), and with
/// rho^2 = |B|_F^2 / 6 >= 1/6 and the roots 2 rho cos(theta + 2 pi j / 3) (rho <= 1.23) each
/// root by at most 2 rho sqrt(e_q) / (3 rho^(3/2)) <= 1.3 sqrt(5 eps) = 2.9 sqrt(eps) in B's units,
/// the scale being at most lmax. 8 sqrt(eps) lmax (1.2e-7 lmax) bounds every root with margin.
/// This absolute error is why the closed form's lmin cannot settle a decision at max_condition =
/// 1e4 (lmin = 1e-8 lmax there).
constexpr double closed_form2_error = 8.0 * std::numeric_limits<double>::epsilon();
constexpr double closed_form3_error = 8.0 * 1.4901161193847656e-08;  // 8 sqrt(eps)
/// Eigen's iterative solver (Householder tridiagonalisation, implicit QR): backward stable, each
/// eigenvalue within a small multiple of eps lmax of the computed Gram matrix's.
constexpr double iterative_error = 16.0 * std::numeric_limits<double>::epsilon();
/// The largest matrix side whose minors are summed (Cauchy-Binet): C(8, 3) = 56 determinants.
constexpr int max_minor_side = 8;

/// e_{g-1} and e_g (the elementary symmetric functions) of the eigenvalues of the g x g Gram
/// matrix W W^T (W: g x n, g = 2 or 3, g <= n) from W's minors, each with a bound on its rounding
/// error: by Cauchy-Binet, e_j is the sum of the squares of W's j x j minors. A minor's rounding
/// error is relative to the sum of its products' magnitudes (2 x 2: 2u (|ad| + |bc|); 3 x 3 by
/// cofactors: 5u times its permanent of |W|; taken 3u and 6u), not to the Gram matrix's norm, so
/// e_g = det(W W^T) keeps its relative accuracy where det(W W^T) from the Gram matrix itself loses
/// it: for a square 3 x 3 W with singular values s1 >= s2 >= s3 the relative error of det W is
/// about u s1^2 / (s2 s3), that of det(W^T W) computed from W^T W u s1^4 / (s2 s3)^2.
/// (For g = 2, e_{g-1} = e_1 is not needed and left 0.)
struct GramInvariants {
  double low = 0.0, low_error = 0.0;  ///< e_{g-1}
  double top = 0.0, top_error = 0.0;  ///< e_g
};

template <class At>
GramInvariants gram_invariants(const At& w, int g, int n) noexcept {
  GramInvariants e;
  int low_terms = 0, top_terms = 0;
  const auto add = [](double& sum, double& error, double m, double bound) {
    sum += m * m;
    error += (2.0 * std::abs(m) + bound) * bound;
  };
  if (g == 2) {
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b) {
        const double p = w(0, a) * w(1, b), q = w(0, b) * w(1, a);
        add(e.top, e.top_error, p - q, 3.0 * unit * (std::abs(p) + std::abs(q)));
        ++top_terms;
      }
  } else {
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        for (int r = 0; r < 3; ++r)
          for (int s = r + 1; s < 3; ++s) {
            const double p = w(r, a) * w(s, b), q = w(r, b) * w(s, a);
            add(e.low, e.low_error, p - q, 3.0 * unit * (std::abs(p) + std::abs(q)));
            ++low_terms;
          }
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        for (int c = b + 1; c < n; ++c) {
          // along row 0, with rows 1 and 2's 2 x 2 minors
          const double bc = w(1, b) * w(2, c) - w(1, c) * w(2, b);
          const double ac = w(1, a) * w(2, c) - w(1, c) * w(2, a);
          const double ab = w(1, a) * w(2, b) - w(1, b) * w(2, a);
          const double pbc = std::abs(w(1, b) * w(2, c)) + std::abs(w(1, c) * w(2, b));
          const double pac = std::abs(w(1, a) * w(2, c)) + std::abs(w(1, c) * w(2, a));
          const double pab = std::abs(w(1, a) * w(2, b)) + std::abs(w(1, b) * w(2, a));
          const double det = w(0, a) * bc - w(0, b) * ac + w(0, c) * ab;
          const double perm = std::abs(w(0, a)) * pbc + std::abs(w(0, b)) * pac + std::abs(w(0, c)) * pab;
          add(e.top, e.top_error, det, 6.0 * unit * perm);
          ++top_terms;
        }
  }
  // the squares' and the sum's own roundings
  e.low_error += (low_terms + 2) * unit * e.low;
  e.top_error += (top_terms + 2) * unit * e.top;
  return e;
}

/// The smallest and largest eigenvalues of the Gram matrix G = W W^T (W: g x n through `w`, G
/// computed from it by the caller), accurate enough for the damping decision at max_condition
/// (lmin against lmax / max_condition^2) and, when `reported`, for the reported condition
/// sqrt(lmax / lmin) (to 1e-6 relative on lmin, or as accurately as the iterative solver), without
/// iterating where an interval on lmin settles both. Returns whether the iterative solver ran.
///
/// g = 2, 3 and n <= max_minor_side: lmax from the closed form (relative error d = the closed
/// form's bound: the largest root is never the one lost to cancellation). Then lmin:
/// - g = 2: lmin = e_2 / lmax (det G = lmin lmax), relative error ~ that of e_2 plus d.
/// - g = 3, closed-form lmin >= lmax / 4: the closed form (absolute error <= d lmax).
/// - g = 3 otherwise, by deflation: r = lmid lmin = e_3 / lmax, s = lmid + lmin = (e_2 - r) /
///   lmax (no cancellation: r / (e_2 - r) <= lmin / lmax < 1/4), lmid = (s + sqrt(s^2 - 4r)) / 2
///   (>= s / 2), lmin = r / lmid. Relative errors of e_2, e_3 and lmax (small: lmax is either
///   well apart from lmid, or lmid is well apart from lmin and s^2 - 4r does not cancel) carry
///   over; where lmid and lmin meet, s^2 - 4r cancels and the square root turns an error e into
///   sqrt(e), so the bounds are propagated at run time, absolute, step by step, with lmin <=
///   sqrt(lmid lmin) and lmin <= s / 2 as further upper bounds.
/// The interval [lo, hi] on the true lmin settles the decision unless it overlaps lmax /
/// max_condition^2 widened by d; for a reported condition, the interval must also be within 1e-6
/// relative of lmin or narrower than the iterative solver's error. Otherwise (and for g > 3, or
/// n > max_minor_side) the iterative solver decides (extreme_eigenvalues).
template <class At, typename Small, typename Solver>
bool gram_extremes(const At& w, int g, int n, const Small& G, double max_condition, bool reported, Solver& fallback,
                   double& lmin, double& lmax) noexcept {
  if (!(g == 2 || g == 3) || n > max_minor_side) {
    extreme_eigenvalues(G, fallback, lmin, lmax);
    return g > 3 || !(lmax > 0.0 && lmin >= 1e-6 * lmax);
  }
  double l0 = 0.0, d = 0.0;
  if (g == 2) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> direct;
    direct.computeDirect(Eigen::Matrix2d(G.template topLeftCorner<2, 2>()), Eigen::EigenvaluesOnly);
    l0 = direct.eigenvalues()(0);
    lmax = direct.eigenvalues()(1);
    d = closed_form2_error;
  } else {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> direct;
    direct.computeDirect(Eigen::Matrix3d(G.template topLeftCorner<3, 3>()), Eigen::EigenvaluesOnly);
    l0 = direct.eigenvalues()(0);
    lmax = direct.eigenvalues()(2);
    d = closed_form3_error;
  }
  if (!(lmax > 0.0 && lmax <= huge)) {  // G = 0 (or not finite: the caller checked)
    lmin = l0;
    return false;
  }
  // the usual, well-conditioned case: the closed form's lmin, within d lmax, settles the decision
  // (and, for a reported condition, is accurate to 1e-6 relative) without K's minors, whose
  // C(n, 3) determinants cost a wide K (a 7-joint arm's) more than the rest of the solve
  const double threshold = lmax / (max_condition * max_condition);  // damped iff lmin < threshold
  if ((l0 - d * lmax > threshold * (1.0 + d) && (!reported || d * lmax <= 1e-6 * l0)) ||
      (!reported && l0 + d * lmax < threshold * (1.0 - d))) {
    lmin = l0;
    return false;
  }
  const GramInvariants e = gram_invariants(w, g, n);
  double lo = 0.0, hi = 0.0;
  if (g == 2) {
    lmin = e.top / lmax;
    const double err = e.top_error / lmax + lmin * (d + 2.0 * unit);
    lo = lmin - err;
    hi = lmin + err;
  } else if (l0 >= 0.25 * lmax) {
    lmin = l0;
    lo = lmin - d * lmax;
    hi = lmin + d * lmax;
  } else {
    const double r = e.top / lmax;
    const double er = e.top_error / lmax + r * (d + 2.0 * unit);
    const double s = std::max(e.low - r, 0.0) / lmax;
    const double es = (e.low_error + er) / lmax + s * (d + 3.0 * unit);
    const double disc = s * s - 4.0 * r;
    const double ed = (2.0 * s + es) * es + 4.0 * er + 4.0 * unit * (s * s + 4.0 * r);
    const double root = std::sqrt(std::max(disc, 0.0));
    const double eroot = root > 0.0 ? std::min(std::sqrt(ed), ed / root) : std::sqrt(ed);
    const double mid = 0.5 * (s + root);
    const double emid = 0.5 * (es + eroot) + unit * mid;
    lmin = mid > 0.0 ? r / mid : 0.0;
    hi = std::min(0.5 * (s + es), std::sqrt(r + er));
    if (mid > emid) hi = std::min(hi, (r + er) / (mid - emid));
    lo = (r - er) / (mid + emid);
    hi *= 1.0 + 4.0 * unit;
    lo *= 1.0 - 4.0 * unit;
  }
  lo = std::max(lo, 0.0);
  bool settled = hi < threshold * (1.0 - d) || lo > threshold * (1.0 + d);
  if (settled && reported) settled = hi - lo <= 2e-6 * lmin || 0.5 * (hi - lo) <= iterative_error * lmax;
  if (settled) return false;
  fallback.compute(G, Eigen::EigenvaluesOnly);
  const auto& lambda = fallback.eigenvalues();  // ascending
  lmax = lambda(lambda.size() - 1);
  lmin = std::min(std::max(lambda(0), lo), hi);  // the true lmin is in [lo, hi]
  return true;
}

/// A x for the 6 x n momentum matrix, column by column at fixed height (Eigen's dynamic
/// matrix-vector product goes through a blocked kernel whose setup costs more at these sizes).
Vec6 momentum_times(const Eigen::MatrixXd& A, const Eigen::VectorXd& x) noexcept {
  Vec6 h = Vec6::Zero();
  for (Eigen::Index c = 0; c < A.cols(); ++c) h += Eigen::Map<const Vec6>(A.data() + 6 * c) * x(c);
  return h;
}

/// y = C x (the n x na loop projection), over x's nonzero entries.
void project_actuated(const Eigen::MatrixXd& C, const Eigen::VectorXd& x, Eigen::VectorXd& y) noexcept {
  y.setZero();
  for (Eigen::Index i = 0; i < C.cols(); ++i) {
    const double xi = x(i);
    if (xi != 0.0) y += xi * C.col(i);
  }
}

}  // namespace

namespace detail {

GramExtremes gram_extremes(const Eigen::MatrixXd& K, double max_condition, bool reported) {
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  if (K.rows() < 1 || K.cols() < 1 || K.rows() > 6 || K.cols() > 6 || !K.allFinite())
    fail("gram_extremes: K must be finite, 1 to 6 rows and columns");
  const bool wide = K.rows() < K.cols();
  const Small G = wide ? Small(K * K.transpose()) : Small(K.transpose() * K);
  const int g = static_cast<int>(G.rows()), n = static_cast<int>(wide ? K.cols() : K.rows());
  Eigen::SelfAdjointEigenSolver<Small> fallback(g);
  GramExtremes out;
  if (wide) {
    out.iterated = mechbal::gram_extremes([&](int i, int j) { return K(i, j); }, g, n, G, max_condition, reported,
                                          fallback, out.lmin, out.lmax);
  } else {
    out.iterated = mechbal::gram_extremes([&](int i, int j) { return K(j, i); }, g, n, G, max_condition, reported,
                                          fallback, out.lmin, out.lmax);
  }
  return out;
}

}  // namespace detail

std::uint32_t momentum_component(const std::string& name) noexcept {
  if (name == "moment") return cancel_moment;
  if (name == "force") return cancel_force;
  if (name == "both") return cancel_both;
  if (name == "force_x") return force_x;
  if (name == "force_y") return force_y;
  if (name == "force_z") return force_z;
  if (name == "moment_x") return moment_x;
  if (name == "moment_y") return moment_y;
  if (name == "moment_z") return moment_z;
  return 0u;
}

void validate_reactionless_config(const ReactionlessConfig& c) {
  if (c.balancing_joints.empty()) fail("reactionless.balancing_joints must name at least one joint");
  if (c.integrator != ReactionlessIntegrator::euler && c.integrator != ReactionlessIntegrator::rk4)
    fail("reactionless.integrator", "must be euler or rk4", static_cast<double>(c.integrator));
  validate_shared_fields(c.cancel, c.rate_hz, c.damping, c.max_condition, c.max_rate);
  if (!(c.max_acceleration > 0.0))
    fail("reactionless.max_acceleration", "must be > 0 (+inf: no limit)", c.max_acceleration);
  if (!(std::isfinite(c.home_gain) && c.home_gain >= 0.0))
    fail("reactionless.home_gain", "must be finite and >= 0", c.home_gain);
  if (!(std::isfinite(c.limit_gain) && c.limit_gain >= 0.0))
    fail("reactionless.limit_gain", "must be finite and >= 0", c.limit_gain);
  if (c.home.size() != 0 && !c.home.allFinite()) fail("reactionless.home must be finite");
  if (!(c.max_momentum > 0.0)) fail("reactionless.max_momentum", "must be > 0 (+inf: no limit)", c.max_momentum);
  if (!(c.max_moment > 0.0)) fail("reactionless.max_moment", "must be > 0 (+inf: no limit)", c.max_moment);
  validate_joint_input_range(c.task_range, "reactionless.task_range");
}

ReactionlessController::ReactionlessController(MechanismModel model, const ReactionlessConfig& config,
                                               const Eigen::VectorXd& q0, const Eigen::VectorXd& v0,
                                               const Eigen::VectorXd& q_guess)
    : ReactionlessController(std::make_shared<const MechanismModel>(std::move(model)), config, q0, v0, q_guess) {}

ReactionlessController::ReactionlessController(std::shared_ptr<const MechanismModel> model,
                                               const ReactionlessConfig& config, const Eigen::VectorXd& q0,
                                               const Eigen::VectorXd& v0, const Eigen::VectorXd& q_guess)
    : model_(std::move(model)), config_(config), data_(*model_) {
  build(q0, v0, q_guess);
}

void ReactionlessController::build(const Eigen::VectorXd& q0, const Eigen::VectorXd& v0,
                                   const Eigen::VectorXd& q_guess) {
  validate_reactionless_config(config_);
  const MechanismModel& m = *model_;
  dt_ = 1.0 / config_.rate_hz;
  n_ = m.dof();
  na_ = m.num_actuated();
  closed_ = m.is_closed();
  if (!closed_ && m.num_passive() > 0)
    fail("actuated: an open mechanism with passive joints ('" + m.coordinate_name(m.passive_coordinates()[0]) +
         "') cannot be driven by the reactionless controller: actuate every joint");
  const auto& actuated = m.actuated_coordinates();
  std::vector<bool> is_balancing(static_cast<std::size_t>(na_), false);
  for (std::size_t i = 0; i < config_.balancing_joints.size(); ++i) {
    const std::string& name = config_.balancing_joints[i];
    const std::string field = "reactionless.balancing_joints[" + std::to_string(i) + "]";
    int coordinate = -1;
    for (int c = 0; c < n_; ++c)
      if (m.coordinate_name(c) == name) coordinate = c;
    if (coordinate < 0) {
      std::string known;
      for (int a : actuated) known += (known.empty() ? "" : ", ") + m.coordinate_name(a);
      fail(field + ": '" + name + "' is not a joint coordinate of the mechanism (actuated joints: " + known + ")");
    }
    const auto it = std::find(actuated.begin(), actuated.end(), coordinate);
    if (it == actuated.end()) fail(field + ": '" + name + "' is a passive joint; balancing joints must be actuated");
    const auto index = static_cast<std::size_t>(it - actuated.begin());
    if (is_balancing[index]) fail(field + ": '" + name + "' is listed twice");
    is_balancing[index] = true;
  }
  task_.clear();
  balancing_.clear();
  task_coord_.clear();
  balancing_coord_.clear();
  for (int i = 0; i < na_; ++i) {
    const int c = actuated[static_cast<std::size_t>(i)];
    if (is_balancing[static_cast<std::size_t>(i)]) {
      balancing_.push_back(i);
      balancing_coord_.push_back(c);
    } else {
      task_.push_back(i);
      task_coord_.push_back(c);
    }
  }
  nb_ = static_cast<int>(balancing_.size());
  nt_ = static_cast<int>(task_.size());
  rows_.clear();
  for (int r = 0; r < 6; ++r)
    if (config_.cancel & (1u << r)) rows_.push_back(r);
  k_ = static_cast<int>(rows_.size());
  wide_ = nb_ > k_;
  square_ = nb_ == k_;

  // a balancing coordinate on the path of a loop's frame moves the loops: C and c depend on it
  balancing_in_loops_ = false;
  for (int l = 0; l < m.num_loops(); ++l) {
    for (int f : {m.loop_frame_a(l), m.loop_frame_b(l)}) {
      for (int link = m.frame_link(f); link > 0; link = m.parent(link)) {
        const int c = m.coordinate(link);
        if (c >= 0 && std::find(balancing_coord_.begin(), balancing_coord_.end(), c) != balancing_coord_.end())
          balancing_in_loops_ = true;
      }
    }
  }

  // the links a balancing joint moves: those of its coordinate (gear couplings included) and all
  // their descendants (links are listed parents first)
  subtree_.member.assign(static_cast<std::size_t>(m.num_links()), 0);
  subtree_.links.clear();
  for (int l = 1; l < m.num_links(); ++l) {
    const int c = m.coordinate(l);
    const bool own = c >= 0 && std::find(balancing_coord_.begin(), balancing_coord_.end(), c) != balancing_coord_.end();
    if (own || subtree_.member[static_cast<std::size_t>(m.parent(l))]) {
      subtree_.member[static_cast<std::size_t>(l)] = 1;
      subtree_.links.push_back(l);
    }
  }

  rate_limit_.resize(nb_);
  lower_.resize(nb_);
  upper_.resize(nb_);
  for (int j = 0; j < nb_; ++j) {
    const int c = balancing_coord_[static_cast<std::size_t>(j)];
    rate_limit_(j) = config_.velocity_limits ? std::min(config_.max_rate, m.velocity_limits()(c)) : config_.max_rate;
    lower_(j) = m.lower_limits()(c);
    upper_(j) = m.upper_limits()(c);
  }
  if (q0.size() != na_)
    fail("q0 must have " + std::to_string(na_) + " values (the actuated coordinates), got " + std::to_string(q0.size()));
  if (v0.size() != 0 && v0.size() != na_)
    fail("v0 must have " + std::to_string(na_) + " values (the actuated coordinates), got " + std::to_string(v0.size()));
  if (q_guess.size() != 0 && q_guess.size() != n_)
    fail("q_guess must have " + std::to_string(n_) + " values (every coordinate), got " + std::to_string(q_guess.size()));
  if (q_guess.size() != 0 && !q_guess.allFinite()) fail("q_guess must be finite");
  if (config_.home.size() != 0 && config_.home.size() != nb_)
    fail("reactionless.home must have " + std::to_string(nb_) + " values (one per balancing joint), got " +
         std::to_string(config_.home.size()));
  home_ = config_.home.size() != 0 ? config_.home : Eigen::VectorXd(Eigen::VectorXd::Zero(nb_));

  // buffers
  q_full_ = q_guess.size() != 0 ? q_guess : Eigen::VectorXd(Eigen::VectorXd::Zero(n_));
  q_act_ = Eigen::VectorXd::Zero(na_);
  stage_q_ = Eigen::VectorXd::Zero(nt_);
  stage_v_ = Eigen::VectorXd::Zero(nt_);
  v_act_ = Eigen::VectorXd::Zero(na_);
  a_act_ = Eigen::VectorXd::Zero(na_);
  v_full_ = Eigen::VectorXd::Zero(n_);
  a_full_ = Eigen::VectorXd::Zero(n_);
  vt_full_ = Eigen::VectorXd::Zero(n_);
  c_full_ = Eigen::VectorXd::Zero(n_);
  bias_now_ = bias_before_ = bias_earlier_ = Eigen::VectorXd::Zero(n_);
  vt_act_ = Eigen::VectorXd::Zero(na_);
  Ab_ = Eigen::MatrixXd::Zero(6, nb_);
  Kb_ = Eigen::MatrixXd::Zero(k_, nb_);
  kb_work_ = Eigen::VectorXd::Zero(k_);
  for (Eigen::VectorXd* v : {&x_, &z_, &v_b_, &a_b_, &k1_, &k2_, &k3_, &k4_, &q_stage_, &r_nb_, &q_b_})
    *v = Eigen::VectorXd::Zero(nb_);
  r_ = SmallVector::Zero(k_);
  y_ = SmallVector::Zero(std::min(k_, nb_) == nb_ && !wide_ ? nb_ : k_);
  const int g = wide_ ? k_ : nb_;
  if (g > 6) fail("reactionless: internal size error");
  gram_ = Small::Identity(g, g);
  eig_.compute(gram_, Eigen::EigenvaluesOnly);
  llt_.compute(gram_);
  if (square_) {
    lu_.compute(Small(Small::Identity(k_, k_)));
    inv3_.setIdentity();
  }
  command_.q = command_.v = command_.a = Eigen::VectorXd::Zero(na_);
  command_.q_full = command_.v_full = command_.a_full = Eigen::VectorXd::Zero(n_);
  command_.next_balancing = Eigen::VectorXd::Zero(nb_);

  const Eigen::VectorXd v_start = v0.size() != 0 ? v0 : Eigen::VectorXd(Eigen::VectorXd::Zero(na_));
  const Status s = reset(q0, v_start);
  if (s != Status::ok && s != Status::singular) {
    std::ostringstream msg;
    msg << "q0: the start cannot be used (" << status_name(s) << ")";
    if (has(s, Status::solver_error)) msg << ": the loops cannot be assembled there (give q_guess near the assembly)";
    if (has(s, Status::out_of_range)) msg << ": beyond reactionless.task_range or max_momentum";
    throw std::invalid_argument(msg.str());
  }
  if (config_.home.size() == 0) home_ = q_b_;
}

Status ReactionlessController::reset(const Eigen::Ref<const Eigen::VectorXd>& q0,
                                     const Eigen::Ref<const Eigen::VectorXd>& v0) noexcept {
  if (q0.size() != na_ || v0.size() != na_) return Status::bad_size;
  if (!q0.allFinite() || !v0.allFinite()) return Status::non_finite_input;
  if (na_ > 0 && (q0.cwiseAbs().maxCoeff() > config_.task_range.max_position ||
                  v0.cwiseAbs().maxCoeff() > config_.task_range.max_speed))
    return Status::out_of_range;
  Status st = Status::ok;
  stage_cache_ = false;
  q_act_ = q0;
  v_act_ = v0;
  a_act_.setZero();
  if (closed_) {
    Eigen::VectorXd& q = q_full_;
    st = closed_motion(*model_, data_, q_act_, v_act_, a_act_, q, config_.loop_options);
    if (failed(st)) return st;
    v_full_ = data_.closed_velocity;
  } else {
    q_full_ = q_act_;
    v_full_ = v_act_;
  }
  // (momentum() places the links: an open model's q_full_ was not placed yet)
  if (momentum(*model_, data_, q_full_, v_full_) != Status::ok) return Status::out_of_range;
  Vec6 h;
  h << data_.shaking.linear_momentum, data_.shaking.angular_momentum;
  if (h.cwiseAbs().maxCoeff() > config_.max_momentum) return Status::out_of_range;
  target_ = h;
  target_rate_.setZero();
  for (int j = 0; j < nb_; ++j) q_b_(j) = q0(balancing_[static_cast<std::size_t>(j)]);
  command_.q = q0;
  command_.v = v0;
  command_.a.setZero();
  command_.q_full = q_full_;
  command_.v_full = v_full_;
  command_.a_full.setZero();
  command_.next_balancing = q_b_;
  command_.momentum = h;
  command_.shaking_force.setZero();
  command_.shaking_moment.setZero();
  command_.condition = 1.0;
  command_.status = Status::ok;
  return only(st, Status::singular);
}

Status ReactionlessController::set_target(const Vec6& momentum, const Vec6& momentum_rate) noexcept {
  if (!momentum.allFinite() || !momentum_rate.allFinite()) return Status::non_finite_input;
  if (momentum.cwiseAbs().maxCoeff() > config_.max_momentum ||
      momentum_rate.cwiseAbs().maxCoeff() > config_.max_moment)
    return Status::out_of_range;
  target_ = momentum;
  target_rate_ = momentum_rate;
  return Status::ok;
}

Status ReactionlessController::evaluate(const Eigen::Ref<const Eigen::VectorXd>& q_t,
                                        const Eigen::VectorXd& q_b, bool acceleration) noexcept {
  for (int i = 0; i < nt_; ++i) q_act_(task_[static_cast<std::size_t>(i)]) = q_t(i);
  for (int j = 0; j < nb_; ++j) q_act_(balancing_[static_cast<std::size_t>(j)]) = q_b(j);
  Status st = Status::ok;
  if (closed_) {
    // positions (warm-started from the last solve), C and c (c with the current velocity guess)
    // (without balancing joints in the loops, c comes from task_momentum's pass below)
    st = acceleration && balancing_in_loops_
             ? closed_motion(*model_, data_, q_act_, v_act_, a_act_, q_full_, config_.loop_options)
             : closed_velocity_motion(*model_, data_, q_act_, v_act_, q_full_, config_.loop_options);
    if (failed(st)) return st;
    if (balancing_in_loops_) {
      // C [v_t; 0]: the balancing joints' columns of C reach passive coordinates
      vt_act_ = v_act_;
      for (const int j : balancing_) vt_act_(j) = 0.0;
      project_actuated(data_.loop_projection, vt_act_, vt_full_);
    } else {
      // the balancing joints move no loop: their columns of C are unit vectors, and the solve's
      // C v_act is the task's motion plus the balancing rates on their own coordinates
      vt_full_ = data_.closed_velocity;
      for (const int c : balancing_coord_) vt_full_(c) = 0.0;
    }
  } else {
    q_full_ = q_act_;
    vt_full_ = v_act_;  // an open model's coordinates are its actuated ones, in order
    for (const int c : balancing_coord_) vt_full_(c) = 0.0;
  }
  if (!balancing_in_loops_) return st | task_momentum(true, closed_ && (acceleration || bias_count_ < 3));
  // the solve left the links placed at its solution q_full_: no second placement
  const Status sm = detail::momentum_matrix_placed(*model_, data_);
  if (sm != Status::ok) return st | sm;
  // K_b = A C_b (the balancing joints' columns of C reach passive coordinates), K_t v_t = A vt
  const Eigen::MatrixXd& A = data_.momentum_matrix;
  for (int j = 0; j < nb_; ++j) {
    c_full_ = data_.loop_projection.col(balancing_[static_cast<std::size_t>(j)]);
    Ab_.col(j) = momentum_times(A, c_full_);
  }
  for (int i = 0; i < k_; ++i) Kb_.row(i) = Ab_.row(rows_[static_cast<std::size_t>(i)]);
  ht_ = momentum_times(A, vt_full_);
  return st;
}

Status ReactionlessController::task_momentum(bool whole, bool bias) noexcept {
  // the task's motion alone (vt_full_) on the links placed at q_full_. The links outside the
  // balancing subtrees move alike whatever the balancing joints do: after rebalance() (`whole`
  // false) their placements, velocities and momentum (rest_) are the last whole pass's, and only
  // the subtrees are placed and moved again. A loop solve left every link placed at q_full_.
  if (whole) {
    detail::joint_state<true, false>(*model_, data_, q_full_, vt_full_, vt_full_);
    if (!closed_) detail::place(*model_, data_);
  } else {
    detail::joint_state<true, false, true>(*model_, data_, q_full_, vt_full_, vt_full_, &subtree_);
    detail::place<true, detail::NoVisit, true>(*model_, data_, detail::NoVisit{}, &subtree_);
  }
  Vec6 inside;
  detail::velocity_momentum(*model_, data_, subtree_, whole, inside, rest_, bias && whole);
  // c from the links on the loops' paths, which the balancing joints do not move: their
  // velocities and accelerations are those of the whole motion
  Status st = Status::ok;
  if (bias && whole) st = detail::loop_acceleration_bias_placed(*model_, data_, config_.loop_options.refine_rcond);
  ht_ = rest_ + inside;
  detail::momentum_columns_placed(*model_, data_, subtree_, balancing_coord_, Ab_);
  for (int i = 0; i < k_; ++i) Kb_.row(i) = Ab_.row(rows_[static_cast<std::size_t>(i)]);
  return detail::all_finite(ht_) && detail::all_finite(Ab_) ? st : Status::out_of_range;
}

Status ReactionlessController::rebalance(const Eigen::VectorXd& q_b) noexcept {
  // same task pose as the last evaluate(): the loops' solution and C do not depend on the
  // balancing coordinates (they move no loop frame), only A does
  for (int j = 0; j < nb_; ++j) {
    q_act_(balancing_[static_cast<std::size_t>(j)]) = q_b(j);
    q_full_(balancing_coord_[static_cast<std::size_t>(j)]) = q_b(j);
    // the loop solve's warm start follows (its tangent predictor needs q == closed_position)
    if (closed_) data_.closed_position(balancing_coord_[static_cast<std::size_t>(j)]) = q_b(j);
  }
  return task_momentum(false);  // (vt_full_ is the last evaluate()'s: same task motion)
}

Status ReactionlessController::factorise(double* reported) noexcept {
  double ignored = 0.0;
  double& condition = reported ? *reported : ignored;
  if (wide_) {
    gram_.noalias() = Kb_ * Kb_.transpose();
  } else {
    gram_.noalias() = Kb_.transpose() * Kb_;
  }
  if (!gram_.allFinite()) {
    condition = huge;
    damped_ = true;
    gram_.setIdentity();
    llt_.compute(gram_);
    return Status::singular | Status::out_of_range;
  }
  double lmin = 0.0, lmax = 0.0;
  // Where the condition number is not reported (RK4's inner stages), a bound settles the damping
  // decision when it can, without the eigenvalues. The Gram matrix G (2 x 2 or 3 x 3, positive
  // semi-definite) has lmax <= tr G, and lmin >= det G / tr G (2 x 2) or 4 det G / (tr G)^2 (3 x 3:
  // the two largest eigenvalues' product is at most (tr G / 2)^2). When that bound on lmax / lmin
  // is within max_condition^2, so is the true ratio: no damping, as the eigenvalues would decide.
  // Otherwise they are computed (the damping needs lmax): gram_extremes, which settles the
  // decision near a singularity too without the iterative solver.
  const Eigen::Index g = gram_.rows();
  bool bounded = false;
  if (!reported && (g == 2 || g == 3)) {
    // det G less its rounding error's bound: the products' magnitudes are at most tr^g (|G_ij|
    // <= sqrt(G_ii G_jj) <= tr), 2 products of 2 roundings at 2 x 2, 6 products of 5 at 3 x 3
    const double tr = gram_.trace();
    const double det = g == 2 ? gram_(0, 0) * gram_(1, 1) - gram_(0, 1) * gram_(1, 0) - 4.0 * unit * tr * tr
                              : Eigen::Matrix3d(gram_.topLeftCorner<3, 3>()).determinant() - 30.0 * unit * tr * tr * tr;
    const double low = g == 2 ? det / tr : 4.0 * det / (tr * tr);
    bounded = tr > 0.0 && low > 0.0 && tr <= config_.max_condition * config_.max_condition * low;
    if (bounded) {
      lmax = tr;
      lmin = low;
    }
  }
  if (!bounded) {
    // the Gram matrix's eigenvalues, from K_b's minors and the closed forms where these settle
    // the decision (and the reported condition): near a singularity too, without iterating
    const int n = static_cast<int>(wide_ ? Kb_.cols() : Kb_.rows());
    if (wide_) {
      gram_extremes([this](int i, int j) { return Kb_(i, j); }, static_cast<int>(g), n, gram_, config_.max_condition,
                    reported != nullptr, eig_, lmin, lmax);
    } else {
      gram_extremes([this](int i, int j) { return Kb_(j, i); }, static_cast<int>(g), n, gram_, config_.max_condition,
                    reported != nullptr, eig_, lmin, lmax);
    }
  }
  if (!(lmax > 0.0)) {  // S K_b = 0: the balancing joints cannot act on the cancelled components
    condition = huge;
    damped_ = true;
    gram_.diagonal().array() += 1.0;  // any positive damping: the solution is zero
    llt_.compute(gram_);
    return Status::singular;
  }
  condition = lmin > 0.0 ? std::sqrt(lmax / lmin) : huge;
  if (condition <= config_.max_condition) {
    damped_ = false;
    if (square_) {
      // 3 x 3 (a wrist cancelling the moment): the inverse from cofactors, accurate to cond eps
      // like an LU at this condition (<= max_condition), where Eigen's dynamic LU dispatch costs
      // more than the factorisation itself
      if (k_ == 3) {
        inv3_ = Eigen::Matrix3d(Kb_).inverse();
      } else {
        lu_.compute(Small(Kb_));
      }
    } else {
      llt_.compute(gram_);
    }
    return Status::ok;
  }
  damped_ = true;
  gram_.diagonal().array() += config_.damping * config_.damping * lmax;
  llt_.compute(gram_);
  return Status::singular;
}

void ReactionlessController::solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::VectorXd& x) noexcept {
  for (int i = 0; i < k_; ++i) r_(i) = r(i);
  if (wide_) {
    y_ = llt_.solve(r_);
    x.noalias() = Kb_.transpose() * y_;
  } else if (square_ && !damped_) {
    if (k_ == 3) {
      y_ = inv3_ * Eigen::Vector3d(r_);
    } else {
      y_ = lu_.solve(r_);
    }
    x = y_;
  } else {
    SmallVector b(nb_);
    b.noalias() = Kb_.transpose() * r_;
    y_ = llt_.solve(b);
    x = y_;
  }
}

void ReactionlessController::project_null(const Eigen::VectorXd& z, Eigen::VectorXd& out) noexcept {
  // (I - K_b^T (K_b K_b^T + lambda^2)^-1 K_b) z
  SmallVector kz(k_);
  kz.noalias() = Kb_ * z;
  y_ = llt_.solve(kz);
  out = z;
  out.noalias() -= Kb_.transpose() * y_;
}

Status ReactionlessController::limit_rate(Eigen::VectorXd& v_b) const noexcept {
  double peak = 0.0;
  for (int j = 0; j < nb_; ++j) peak = std::max(peak, std::abs(v_b(j)) / rate_limit_(j));
  if (peak > 1.0) {
    v_b *= 1.0 / peak;  // direction kept
    return Status::saturated;
  }
  return Status::ok;
}

Status ReactionlessController::rates(const Vec6& h, const Eigen::VectorXd& q_b, Eigen::VectorXd& v_b,
                                     double* condition) noexcept {
  // r = S h* - S K_t v_t (ht_: the evaluation's, at these task rates)
  for (int i = 0; i < k_; ++i) {
    const int row = rows_[static_cast<std::size_t>(i)];
    kb_work_(i) = h(row) - ht_(row);
  }
  Status st = factorise(condition);
  solve(kb_work_, v_b);
  if (!wide_ && !square_ && !has(st, Status::singular)) {
    // more cancelled components than balancing joints: the least-squares rates cancel them only
    // where the equations agree (a planar arm's zero rows); a residual left is a tick that did
    // not cancel what was asked, flagged as such (issue 40: "cancel both" with one wheel)
    st |= unmet(Kb_, v_b, kb_work_.head(k_));
  }
  if (wide_ && (config_.home_gain > 0.0 || config_.limit_gain > 0.0)) {
    for (int j = 0; j < nb_; ++j) {
      double zj = -config_.home_gain * (q_b(j) - home_(j));
      if (config_.limit_gain > 0.0 && std::isfinite(lower_(j)) && std::isfinite(upper_(j)) && upper_(j) > lower_(j)) {
        const double mid = 0.5 * (lower_(j) + upper_(j)), half = 0.5 * (upper_(j) - lower_(j));
        zj -= config_.limit_gain * (q_b(j) - mid) / (half * half);
      }
      z_(j) = zj;
    }
    project_null(z_, x_);
    v_b += x_;
  }
  if (!v_b.allFinite()) {
    v_b.setZero();
    return st | Status::out_of_range;
  }
  return st | limit_rate(v_b);
}

Status ReactionlessController::hold(Status why) noexcept {
  for (int j = 0; j < nb_; ++j) command_.q(balancing_[static_cast<std::size_t>(j)]) = q_b_(j);
  command_.v.setZero();
  command_.a.setZero();
  command_.v_full.setZero();
  command_.a_full.setZero();
  command_.next_balancing = q_b_;
  command_.momentum.setZero();
  command_.shaking_force.setZero();
  command_.shaking_moment.setZero();
  command_.status = why;
  return why;
}

bool ReactionlessController::task_in_range(const Eigen::Ref<const Eigen::VectorXd>& q,
                                           const Eigen::Ref<const Eigen::VectorXd>& v,
                                           const Eigen::Ref<const Eigen::VectorXd>* a) const noexcept {
  if (nt_ == 0) return true;
  const JointInputRange& r = config_.task_range;
  return q.cwiseAbs().maxCoeff() <= r.max_position && v.cwiseAbs().maxCoeff() <= r.max_speed &&
         (a == nullptr || a->cwiseAbs().maxCoeff() <= r.max_acceleration);
}

Status ReactionlessController::step(const Eigen::Ref<const Eigen::VectorXd>& q_t,
                                    const Eigen::Ref<const Eigen::VectorXd>& v_t,
                                    const Eigen::Ref<const Eigen::VectorXd>& a_t,
                                    const Eigen::Ref<const Eigen::VectorXd>& q_t_half,
                                    const Eigen::Ref<const Eigen::VectorXd>& v_t_half,
                                    const Eigen::Ref<const Eigen::VectorXd>& q_t_next,
                                    const Eigen::Ref<const Eigen::VectorXd>& v_t_next) noexcept {
  if (config_.integrator == ReactionlessIntegrator::rk4)
    return tick(q_t, v_t, a_t, &q_t_half, &v_t_half, &q_t_next, &v_t_next);
  return tick(q_t, v_t, a_t, nullptr, nullptr, nullptr, nullptr);
}

Status ReactionlessController::step_euler(const Eigen::Ref<const Eigen::VectorXd>& q_t,
                                          const Eigen::Ref<const Eigen::VectorXd>& v_t,
                                          const Eigen::Ref<const Eigen::VectorXd>& a_t) noexcept {
  return tick(q_t, v_t, a_t, nullptr, nullptr, nullptr, nullptr);
}

Status ReactionlessController::tick(const Eigen::Ref<const Eigen::VectorXd>& q_t,
                                    const Eigen::Ref<const Eigen::VectorXd>& v_t,
                                    const Eigen::Ref<const Eigen::VectorXd>& a_t,
                                    const Eigen::Ref<const Eigen::VectorXd>* q_half,
                                    const Eigen::Ref<const Eigen::VectorXd>* v_half,
                                    const Eigen::Ref<const Eigen::VectorXd>* q_next,
                                    const Eigen::Ref<const Eigen::VectorXd>* v_next) noexcept {
  const bool rk4 = q_half != nullptr;
  if (q_t.size() != nt_ || v_t.size() != nt_ || a_t.size() != nt_) return Status::bad_size;
  if (rk4 && (q_half->size() != nt_ || v_half->size() != nt_ || q_next->size() != nt_ || v_next->size() != nt_))
    return Status::bad_size;
  const bool finite = q_t.allFinite() && v_t.allFinite() && a_t.allFinite() &&
                      (!rk4 || (q_half->allFinite() && v_half->allFinite() && q_next->allFinite() &&
                                v_next->allFinite()));
  if (!finite) return hold(Status::non_finite_input);
  if (!task_in_range(q_t, v_t, &a_t) ||
      (rk4 && (!task_in_range(*q_half, *v_half, nullptr) || !task_in_range(*q_next, *v_next, nullptr))))
    return hold(Status::out_of_range);

  // ---- t_n: pose, rates, velocities. The task velocities first: the loops' acceleration bias c
  // that evaluate() leaves in data_ depends on them (not on balancing joints outside the loops)
  for (int i = 0; i < nt_; ++i) v_act_(task_[static_cast<std::size_t>(i)]) = v_t(i);
  const bool reuse = stage_cache_ && q_t == stage_q_ && v_t == stage_v_;  // exactly the last stage's
  stage_cache_ = false;
  Status st = reuse ? stage_cache_status_ | rebalance(q_b_) : evaluate(q_t, q_b_);
  if (failed(st)) return hold(only(st, hard));
  if (closed_ && !balancing_in_loops_) {  // c at t_n, and at the starts of the ticks before it
    bias_count_ = reuse ? std::min(bias_count_ + 1, 3) : 1;
    bias_earlier_.swap(bias_before_);
    bias_before_.swap(bias_now_);
    bias_now_ = data_.loop_acceleration_bias;
  }
  double cond = 1.0;
  st |= rates(target_, q_b_, k1_, &cond);
  if (has(st, Status::out_of_range)) return hold(Status::out_of_range);
  const bool rate_saturated = has(st, Status::saturated);
  for (int i = 0; i < nt_; ++i) {
    v_act_(task_[static_cast<std::size_t>(i)]) = v_t(i);
    a_act_(task_[static_cast<std::size_t>(i)]) = a_t(i);
  }
  for (int j = 0; j < nb_; ++j) {
    v_act_(balancing_[static_cast<std::size_t>(j)]) = k1_(j);
    a_act_(balancing_[static_cast<std::size_t>(j)]) = 0.0;
  }
  if (closed_) {
    if (balancing_in_loops_) {
      // C and c with the balancing rates (the position solve is converged: no iteration)
      const Status s = closed_motion(*model_, data_, q_act_, v_act_, a_act_, q_full_, config_.loop_options);
      if (failed(s)) return hold(only(s, hard));
      st |= only(s, Status::singular);
    }
    // without balancing joints in the loops, c does not depend on their rates
    project_actuated(data_.loop_projection, v_act_, v_full_);
    // a = c + C [a_t; 0] (a_act_'s balancing entries are still zero)
    project_actuated(data_.loop_projection, a_act_, a_full_);
    a_full_ += data_.loop_acceleration_bias;
  } else {
    v_full_ = v_act_;
    a_full_ = a_act_;
  }
  // ---- feed-forward: S K_b a_b = S dh*/dt - S K_t a_t - S W(q, v, c) = S dh*/dt - S W'
  // with W' = W(q, v, c + C [a_t; 0]) = W(q, v, c) + K_t a_t, the shaking wrench (the rate of
  // momentum) of the motion with the balancing joints' accelerations still zero.
  // the links are placed at q_full_ (evaluate(), or closed_motion just above, at the same q)
  if (const Status s = detail::shaking_wrench_placed(*model_, data_, q_full_, v_full_, a_full_, false); s != Status::ok)
    return hold(Status::out_of_range);
  Vec6 W;
  W << data_.shaking.force, data_.shaking.moment;
  // the command's momentum h = K v = K_t v_t + K_b v_b
  Vec6 h = ht_;
  for (int j = 0; j < nb_; ++j) h += k1_(j) * Ab_.col(j);
  for (int i = 0; i < k_; ++i) {
    const int row = rows_[static_cast<std::size_t>(i)];
    kb_work_(i) = target_rate_(row) - W(row);
  }
  solve(kb_work_, a_b_);  // same operator as the rates at t_n
  if (wide_ && (config_.home_gain > 0.0 || config_.limit_gain > 0.0)) {
    // the derivative of the null-space objective z along the rates (the projector's own
    // derivative is left out: a feed-forward term)
    for (int j = 0; j < nb_; ++j) {
      double zd = -config_.home_gain * k1_(j);
      if (config_.limit_gain > 0.0 && std::isfinite(lower_(j)) && std::isfinite(upper_(j)) && upper_(j) > lower_(j)) {
        const double half = 0.5 * (upper_(j) - lower_(j));
        zd -= config_.limit_gain * k1_(j) / (half * half);
      }
      z_(j) = zd;
    }
    project_null(z_, x_);
    a_b_ += x_;
  }
  if (!a_b_.allFinite()) return hold(Status::out_of_range);
  if (rate_saturated) {
    a_b_.setZero();  // the unsaturated formula no longer describes the commanded motion
  } else {
    const double peak = a_b_.cwiseAbs().maxCoeff();
    if (peak > config_.max_acceleration) {
      a_b_ *= config_.max_acceleration / peak;
      st |= Status::saturated;
    }
  }
  // a += C_b a_b, and the predicted wrench W' + K_b a_b
  Vec6 predicted = W;
  for (int j = 0; j < nb_; ++j) {
    const int b = balancing_[static_cast<std::size_t>(j)];
    a_act_(b) = a_b_(j);
    if (closed_) {
      a_full_ += a_b_(j) * data_.loop_projection.col(b);
    } else {
      a_full_(b) += a_b_(j);
    }
    predicted += a_b_(j) * Ab_.col(j);
  }
  if (!detail::all_finite(h) || !detail::all_finite(predicted)) return hold(Status::out_of_range);

  // the command at t_n (the stages below overwrite the model's data)
  command_.q = q_act_;
  command_.v = v_act_;
  command_.a = a_act_;
  command_.q_full = q_full_;
  command_.v_full = v_full_;
  command_.a_full = a_full_;
  command_.momentum = h;
  command_.shaking_force = predicted.head<3>();
  command_.shaking_moment = predicted.tail<3>();
  command_.condition = cond;

  // ---- integration to t_n + dt
  Eigen::VectorXd& next = command_.next_balancing;
  Status last_stage = Status::solver_error;  // RK4's evaluation at t_n + dt (for the next tick)
  if (rk4) {
    Status ss = Status::ok;
    // each stage's loop projection with the task's rates of that instant (c, at t_n + dt, is then
    // the next tick's: see stage_cache_)
    const auto task_rates = [this](const Eigen::Ref<const Eigen::VectorXd>& v) {
      for (int i = 0; i < nt_; ++i) v_act_(task_[static_cast<std::size_t>(i)]) = v(i);
    };
    // (stages 2 and 3 need K only: no acceleration level of the loops)
    q_stage_ = q_b_ + (0.5 * dt_) * k1_;
    task_rates(*v_half);
    ss |= evaluate(*q_half, q_stage_, false);
    if (!failed(ss)) ss |= rates(target_ + (0.5 * dt_) * target_rate_, q_stage_, k2_, nullptr);
    q_stage_ = q_b_ + (0.5 * dt_) * k2_;
    if (!failed(ss))
      ss |= !balancing_in_loops_ ? rebalance(q_stage_) : evaluate(*q_half, q_stage_, false);
    if (!failed(ss)) ss |= rates(target_ + (0.5 * dt_) * target_rate_, q_stage_, k3_, nullptr);
    q_stage_ = q_b_ + dt_ * k3_;
    task_rates(*v_next);
    if (closed_ && !balancing_in_loops_ && bias_count_ >= 3) {
      // c at t_n + dt/2 for the t_n + dt solve's warm start (the stage above computed none): the
      // parabola through c at t_n - 2 dt, t_n - dt, t_n
      data_.loop_acceleration_bias = 1.875 * bias_now_ - 1.25 * bias_before_ + 0.375 * bias_earlier_;
    }
    if (!failed(ss)) ss |= last_stage = evaluate(*q_next, q_stage_);
    if (!failed(ss)) ss |= rates(target_ + dt_ * target_rate_, q_stage_, k4_, nullptr);
    task_rates(v_t);
    if (failed(ss)) {
      return hold(only(ss, hard));
    }
    st |= ss;
    next = q_b_ + (dt_ / 6.0) * (k1_ + 2.0 * k2_ + 2.0 * k3_ + k4_);
  } else {
    next = q_b_ + dt_ * k1_;
  }
  if (!next.allFinite()) return hold(Status::out_of_range);
  if (config_.position_limits) {
    bool outside = false;
    for (int j = 0; j < nb_; ++j) outside = outside || next(j) < lower_(j) || next(j) > upper_(j);
    if (outside) {
      // hold the balancing joints where they are: the task goes on, the cancellation stops
      const Status s = evaluate(q_t, q_b_);
      if (failed(s)) return hold(only(s, hard));
      for (int j = 0; j < nb_; ++j) {
        v_act_(balancing_[static_cast<std::size_t>(j)]) = 0.0;
        a_act_(balancing_[static_cast<std::size_t>(j)]) = 0.0;
      }
      if (closed_) {
        const Status s2 = closed_motion(*model_, data_, q_act_, v_act_, a_act_, q_full_, config_.loop_options);
        if (failed(s2)) return hold(only(s2, hard));
        v_full_ = data_.closed_velocity;
        a_full_ = data_.closed_acceleration;
      } else {
        v_full_ = v_act_;
        a_full_ = a_act_;
      }
      if (shaking_wrench(*model_, data_, q_full_, v_full_, a_full_) != Status::ok) return hold(Status::out_of_range);
      command_.q = q_act_;
      command_.v = v_act_;
      command_.a = a_act_;
      command_.q_full = q_full_;
      command_.v_full = v_full_;
      command_.a_full = a_full_;
      command_.momentum << data_.shaking.linear_momentum, data_.shaking.angular_momentum;
      command_.shaking_force = data_.shaking.force;
      command_.shaking_moment = data_.shaking.moment;
      next = q_b_;
      command_.status = st | Status::saturated;
      return command_.status;
    }
  }
  q_b_ = next;
  command_.status = st;
  if (rk4 && !balancing_in_loops_ && !failed(last_stage)) {
    stage_cache_ = true;
    stage_cache_status_ = last_stage;
    stage_q_ = *q_next;
    stage_v_ = *v_next;
  }
  return st;
}

ReactionlessJointController::ReactionlessJointController(std::shared_ptr<const MechanismModel> model,
                                                         const ReactionlessConfig& config, const Eigen::VectorXd& q0,
                                                         const Eigen::VectorXd& kp, const Eigen::VectorXd& kd,
                                                         const Eigen::VectorXd& torque_limit,
                                                         const JointInputRange& range, const Eigen::VectorXd& q_guess)
    : dynamics_(model, q_guess),
      reactionless_(model, config, q0, Eigen::VectorXd(), q_guess),
      ct_(dynamics_, kp, kd, torque_limit, range) {
  const int nt = reactionless_.num_task();
  for (Eigen::VectorXd* v : {&q_t_, &v_t_, &a_t_, &q_h_, &v_h_, &q_n_, &v_n_}) *v = Eigen::VectorXd::Zero(nt);
}

Status ReactionlessJointController::step(const Eigen::Ref<const Eigen::VectorXd>& q,
                                         const Eigen::Ref<const Eigen::VectorXd>& qd,
                                         const Eigen::Ref<const Eigen::VectorXd>& q_des,
                                         const Eigen::Ref<const Eigen::VectorXd>& qd_des,
                                         const Eigen::Ref<const Eigen::VectorXd>& qdd_des,
                                         Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  const int na = dof();
  if (q.size() != na || qd.size() != na || q_des.size() != na || qd_des.size() != na || qdd_des.size() != na ||
      tau.size() != na)
    return Status::bad_size;
  const double h = 0.5 * reactionless_.dt(), H = reactionless_.dt();
  for (int i = 0; i < reactionless_.num_task(); ++i) {
    const int k = reactionless_.task_joints()[static_cast<std::size_t>(i)];
    q_t_(i) = q_des(k);
    v_t_(i) = qd_des(k);
    a_t_(i) = qdd_des(k);
    q_h_(i) = q_des(k) + h * qd_des(k) + 0.5 * h * h * qdd_des(k);
    v_h_(i) = qd_des(k) + h * qdd_des(k);
    q_n_(i) = q_des(k) + H * qd_des(k) + 0.5 * H * H * qdd_des(k);
    v_n_(i) = qd_des(k) + H * qdd_des(k);
  }
  Status s = reactionless_.step(q_t_, v_t_, a_t_, q_h_, v_h_, q_n_, v_n_);
  const ReactionlessCommand& c = reactionless_.command();
  return s | ct_.step(q, qd, c.q, c.v, c.a, tau);
}

// ---- operational-space mode -----------------------------------------------------------------

ReactionlessTaskController::ReactionlessTaskController(std::shared_ptr<const MechanismModel> model,
                                                       const TaskSpaceConfig& config, const Eigen::VectorXd& q0,
                                                       const Eigen::VectorXd& v0)
    : model_(std::move(model)), config_(config), data_(*model_) {
  const MechanismModel& m = *model_;
  if (m.is_closed() || m.num_passive() > 0)
    fail("task_frame: the operational-space mode drives open mechanisms with every joint actuated");
  frame_ = m.frame_index(config_.frame);
  if (frame_ < 0) {
    std::string known;
    for (int f = 0; f < m.num_frames(); ++f) known += (known.empty() ? "" : ", ") + m.frame(f).name;
    fail("task_frame: '" + config_.frame + "' is not a frame of the mechanism (frames: " + known + ")");
  }
  if (config_.task_rows == 0u || (config_.task_rows & ~cancel_both) != 0u)
    fail("task_rows", "must select at least one of the six twist components (bit mask 1..63)",
         static_cast<double>(config_.task_rows));
  validate_shared_fields(config_.cancel, config_.rate_hz, config_.damping, config_.max_condition, config_.max_rate);
  if (!(config_.max_twist > 0.0)) fail("max_twist", "must be > 0 (+inf: no limit)", config_.max_twist);
  if (!(config_.max_twist_rate > 0.0))
    fail("max_twist_rate", "must be > 0 (+inf: no limit)", config_.max_twist_rate);
  n_ = m.dof();
  dt_ = 1.0 / config_.rate_hz;
  for (int r = 0; r < 6; ++r) {
    if (config_.task_rows & (1u << r)) task_rows_.push_back(r);
    if (config_.cancel & (1u << r)) rows_.push_back(r);
  }
  if (q0.size() != n_ || !q0.allFinite())
    fail("q0 must have " + std::to_string(n_) + " finite values (every coordinate), got " + std::to_string(q0.size()));
  if (v0.size() != 0 && (v0.size() != n_ || !v0.allFinite()))
    fail("v0 must have " + std::to_string(n_) + " finite values, got " + std::to_string(v0.size()));
  // the start within the joints' declared position limits (an undeclared limit is none)
  for (Eigen::Index i = 0; i < n_; ++i) {
    const double lo = m.lower_limits()(i), hi = m.upper_limits()(i);
    if (q0(i) < lo || q0(i) > hi) {
      std::ostringstream s;
      s << "q0[" << i << "] (" << m.coordinate_name(static_cast<int>(i)) << ") = " << q0(i)
        << " is outside the joint's declared limits [" << lo << ", " << hi << "]";
      fail(s.str());
    }
  }
  const int nt = static_cast<int>(task_rows_.size()), k = static_cast<int>(rows_.size());
  for (Eigen::VectorXd* v : {&q_, &q_cmd_, &v_cmd_, &a_cmd_, &zero_, &a0_, &k1_, &k2_, &k3_, &k4_, &q_stage_, &v0_, &z_, &w_})
    *v = Eigen::VectorXd::Zero(n_);
  rate_limit_ = config_.velocity_limits ? Eigen::VectorXd(m.velocity_limits().cwiseMin(config_.max_rate))
                                        : Eigen::VectorXd(Eigen::VectorXd::Constant(n_, config_.max_rate));
  J_ = Eigen::MatrixXd::Zero(nt, n_);
  Jt_ = Eigen::MatrixXd::Zero(n_, 6);
  JpJ_ = Eigen::MatrixXd::Zero(n_, n_);
  N_ = Eigen::MatrixXd::Zero(n_, n_);
  M_ = Eigen::MatrixXd::Zero(k, n_);
  rt_ = Eigen::VectorXd::Zero(nt);
  rm_ = Eigen::VectorXd::Zero(k);
  // J has at most min(nt, n) independent rows; S A N at most the null space's dimension
  rank_J_ = std::min(nt, n_);
  rank_M_ = std::min<Eigen::Index>(k, n_ - rank_J_);
  for (MinNorm* f : {&task_, &null_}) {
    f->gram = Small::Identity(6, 6);
    f->inverse = Small::Identity(6, 6);
    f->eig.compute(f->gram);
    f->llt.compute(f->gram);
    for (SmallVector* v : {&f->y, &f->rhs, &f->scale, &f->projected}) *v = SmallVector::Zero(6);
  }
  q_ = q0;
  q_cmd_ = q0;
  const Eigen::VectorXd v_start = v0.size() ? v0 : Eigen::VectorXd(Eigen::VectorXd::Zero(n_));
  if (mechbal::momentum(m, data_, q0, v_start) != Status::ok) fail("q0, v0: the momentum at the start is not finite");
  target_ << data_.shaking.linear_momentum, data_.shaking.angular_momentum;
}

Status ReactionlessTaskController::factorise(MinNorm& f, const Eigen::MatrixXd& M, Eigen::Index rank) const noexcept {
  const Eigen::Index rows = M.rows();
  f.gram.resize(rows, rows);
  f.gram.noalias() = M * M.transpose();
  f.kind = MinNorm::Kind::zero;
  if (!f.gram.allFinite()) return Status::out_of_range;
  rank = std::min(rank, rows);
  if (rank == 0) return Status::ok;  // nothing can move these rows (an empty null space): x = 0
  if (rank == rows) {
    double lmin = 0.0, lmax = 0.0;
    gram_extremes([&M](int i, int j) { return M(i, j); }, static_cast<int>(rows), static_cast<int>(M.cols()), f.gram,
                  config_.max_condition, false, f.eig, lmin, lmax);
    if (!(lmax > 0.0)) return Status::singular;
    Status st = Status::ok;
    const double cond = lmin > 0.0 ? std::sqrt(lmax / lmin) : huge;
    if (cond > config_.max_condition) {
      f.gram.diagonal().array() += config_.damping * config_.damping * lmax;
      st = Status::singular;
    }
    f.llt.compute(f.gram);
    f.kind = MinNorm::Kind::cholesky;
    return st;
  }
  // more rows than M's rank can be: M M^T has rows - rank zero eigenvalues by construction (no
  // singularity); the least-squares, minimum-norm solution M^T (M M^T)^+ r over the others, whose
  // condition decides the damping as above
  f.eig.compute(f.gram, Eigen::ComputeEigenvectors);
  const auto& lambda = f.eig.eigenvalues();  // ascending
  const double lmax = lambda(rows - 1), lmin = lambda(rows - rank);
  if (!(lmax > 0.0)) return Status::singular;
  Status st = Status::ok;
  double damping = 0.0;
  if (!(lmin > 0.0 && std::sqrt(lmax / lmin) <= config_.max_condition)) {
    damping = config_.damping * config_.damping * lmax;
    st = Status::singular;
  }
  f.scale.resize(rows);
  for (Eigen::Index i = 0; i < rows; ++i) f.scale(i) = i >= rows - rank ? 1.0 / (lambda(i) + damping) : 0.0;
  f.kind = MinNorm::Kind::eigen;
  return st;
}

void ReactionlessTaskController::solve(MinNorm& f, const Eigen::MatrixXd& M, const Eigen::Ref<const Eigen::VectorXd>& r,
                                       Eigen::VectorXd& x) noexcept {
  const Eigen::Index rows = M.rows();
  if (f.kind == MinNorm::Kind::zero) {
    x.setZero();
    return;
  }
  f.rhs.resize(rows);
  for (Eigen::Index i = 0; i < rows; ++i) f.rhs(i) = r(i);
  if (f.kind == MinNorm::Kind::cholesky) {
    f.y = f.llt.solve(f.rhs);
  } else {
    const Small& V = f.eig.eigenvectors();
    f.projected.noalias() = V.transpose() * f.rhs;
    f.projected.array() *= f.scale.array();
    f.y.noalias() = V * f.projected;
  }
  x.noalias() = M.transpose() * f.y;
}

void ReactionlessTaskController::gram_inverse(MinNorm& f) noexcept {
  const Eigen::Index rows = f.gram.rows();
  f.inverse.resize(rows, rows);
  if (f.kind == MinNorm::Kind::zero) {
    f.inverse.setZero();
  } else if (f.kind == MinNorm::Kind::cholesky) {
    f.inverse.setIdentity();
    f.llt.solveInPlace(f.inverse);
  } else {
    const Small& V = f.eig.eigenvectors();
    f.inverse.noalias() = V * f.scale.asDiagonal() * V.transpose();
  }
}

Status ReactionlessTaskController::rates(const Eigen::VectorXd& q, const Vec6& twist, Eigen::VectorXd& v) noexcept {
  const MechanismModel& m = *model_;
  // one placement of the links at q for the frame Jacobian and the momentum matrix
  const Eigen::Ref<const Eigen::VectorXd> qr(q);
  if (detail::check_state(m, data_, &qr) != Status::ok) return Status::out_of_range;
  detail::joint_state<false, false>(m, data_, qr, qr, qr);
  detail::place(m, data_);
  detail::frame_jacobian_placed(m, data_, frame_, data_.frame_jacobian);
  if (!data_.frame_jacobian.allFinite()) return Status::out_of_range;
  if (detail::momentum_matrix_placed(m, data_) != Status::ok) return Status::out_of_range;
  for (std::size_t i = 0; i < task_rows_.size(); ++i) {
    J_.row(static_cast<Eigen::Index>(i)) = data_.frame_jacobian.row(task_rows_[i]);
    rt_(static_cast<Eigen::Index>(i)) = twist(task_rows_[i]);
  }
  Status st = factorise(task_, J_, rank_J_);
  if (has(st, Status::out_of_range)) return st;
  solve(task_, J_, rt_, v0_);  // v0 = J^+ x'
  // N = I - J^+ J, J^+ = J^T (J J^T)^+ (damped as v0's): columns of J^+ from the same factorisation
  const Eigen::Index nt = J_.rows();
  gram_inverse(task_);
  Jt_.leftCols(nt).noalias() = J_.transpose() * task_.inverse;
  JpJ_.noalias() = Jt_.leftCols(nt) * J_;
  N_ = -JpJ_;
  N_.diagonal().array() += 1.0;
  v = v0_;
  if (config_.null_space) {
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      M_.row(r).noalias() = data_.momentum_matrix.row(rows_[i]) * N_;
      rm_(r) = target_(rows_[i]) - data_.momentum_matrix.row(rows_[i]).dot(v0_);
    }
    const Status sm = factorise(null_, M_, rank_M_);
    if (has(sm, Status::out_of_range)) return st | sm;
    st |= sm;
    solve(null_, M_, rm_, z_);
    // more cancelled components than the null space's dimension: what the least squares leaves
    // is a tick that did not cancel what was asked (as ReactionlessController::rates)
    if (rank_M_ < M_.rows() && !has(sm, Status::singular)) st |= unmet(M_, z_, rm_);
    v.noalias() += N_ * z_;
  }
  if (!v.allFinite()) {
    v.setZero();
    return st | Status::out_of_range;
  }
  double peak = 0.0;
  for (int j = 0; j < n_; ++j) peak = std::max(peak, std::abs(v(j)) / rate_limit_(j));
  if (peak > 1.0) {
    v *= 1.0 / peak;
    st |= Status::saturated;
  }
  return st;
}

Status ReactionlessTaskController::acceleration(const Eigen::VectorXd& v, const Vec6& twist_rate, bool saturated) noexcept {
  const MechanismModel& m = *model_;
  // the links are placed at q_ (rates(q_, ...) just ran): one forward pass with the rates gives
  // W(q, v, 0) = (dA/dt) v, the shaking wrench of the rates alone, and J'v, the frame's
  // acceleration with zero joint accelerations
  if (detail::shaking_wrench_placed(m, data_, q_, v, zero_) != Status::ok) return Status::out_of_range;
  const detail::FrameMotion frame = detail::frame_motion(m, data_, frame_);
  Vec6 bias;
  bias << frame.acceleration, frame.angular_acceleration;
  Vec6 W;
  W << data_.shaking.force, data_.shaking.moment;
  const Eigen::Index nt = J_.rows();
  for (Eigen::Index i = 0; i < nt; ++i) {
    const int row = task_rows_[static_cast<std::size_t>(i)];
    rt_(i) = twist_rate(row) - bias(row);
  }
  a0_.noalias() = Jt_.leftCols(nt) * rt_;  // J^+ (x'' - J'v), J^+ of the rates at q_
  a_cmd_ = a0_;
  if (saturated) {
    a_cmd_.setZero();  // the scaled rates no longer follow the law: no feed-forward
  } else if (config_.null_space) {
    // S A N w = S dh*/dt - S W(q, v, 0) - S A a0 (a constant target: dh*/dt = 0), with S A N at q_
    // as the rates factorised it (its status is the rates')
    for (std::size_t i = 0; i < rows_.size(); ++i)
      rm_(static_cast<Eigen::Index>(i)) = -W(rows_[i]) - data_.momentum_matrix.row(rows_[i]).dot(a0_);
    solve(null_, M_, rm_, z_);
    a_cmd_.noalias() += N_ * z_;
  }
  if (!a_cmd_.allFinite()) return Status::out_of_range;
  Vec6 predicted;
  predicted.noalias() = data_.momentum_matrix * a_cmd_;
  predicted += W;
  if (!predicted.allFinite()) return Status::out_of_range;
  force_ = predicted.head<3>();
  moment_ = predicted.tail<3>();
  return Status::ok;
}

Status ReactionlessTaskController::step(const Vec6& twist, const Vec6& twist_half, const Vec6& twist_next) noexcept {
  Vec6 rate = (-3.0 * twist + 4.0 * twist_half - twist_next) / dt_;
  if (!rate.allFinite()) rate.setZero();  // the tick below reports the non-finite input
  return step(twist, rate, twist_half, twist_next);
}

Status ReactionlessTaskController::step(const Vec6& twist, const Vec6& twist_rate, const Vec6& twist_half,
                                        const Vec6& twist_next) noexcept {
  const bool rk4 = config_.integrator == ReactionlessIntegrator::rk4;
  const auto hold = [this](Status why) {
    q_cmd_ = q_;
    v_cmd_.setZero();
    a_cmd_.setZero();
    h_.setZero();
    twist_cmd_.setZero();
    force_.setZero();
    moment_.setZero();
    status_ = why;
    return why;
  };
  if (!twist.allFinite() || !twist_rate.allFinite() ||
      (rk4 && (!twist_half.allFinite() || !twist_next.allFinite())))
    return hold(Status::non_finite_input);
  if (twist.cwiseAbs().maxCoeff() > config_.max_twist || twist_rate.cwiseAbs().maxCoeff() > config_.max_twist_rate ||
      (rk4 && (twist_half.cwiseAbs().maxCoeff() > config_.max_twist || twist_next.cwiseAbs().maxCoeff() > config_.max_twist)))
    return hold(Status::out_of_range);
  Status st = rates(q_, twist, k1_);
  if (has(st, Status::out_of_range)) return hold(Status::out_of_range);
  // the command at t_n: momentum and twist of the commanded rates (data_ is at q_)
  h_.noalias() = data_.momentum_matrix * k1_;
  twist_cmd_.noalias() = data_.frame_jacobian * k1_;
  // the acceleration feed-forward at t_n (before the RK4 stages overwrite J^+, N and S A N)
  const Status sa = acceleration(k1_, twist_rate, has(st, Status::saturated));
  if (has(sa, Status::out_of_range)) return hold(Status::out_of_range);
  st |= sa;
  Eigen::VectorXd& next = q_stage_;
  if (rk4) {
    Status ss = Status::ok;
    w_ = q_ + (0.5 * dt_) * k1_;
    ss |= rates(w_, twist_half, k2_);
    w_ = q_ + (0.5 * dt_) * k2_;
    ss |= rates(w_, twist_half, k3_);
    w_ = q_ + dt_ * k3_;
    ss |= rates(w_, twist_next, k4_);
    if (has(ss, Status::out_of_range)) return hold(Status::out_of_range);
    st |= ss;
    next = q_ + (dt_ / 6.0) * (k1_ + 2.0 * k2_ + 2.0 * k3_ + k4_);
  } else {
    next = q_ + dt_ * k1_;
  }
  if (!next.allFinite()) return hold(Status::out_of_range);
  q_cmd_ = q_;
  v_cmd_ = k1_;
  q_ = next;
  status_ = st;
  return st;
}

}  // namespace mechbal
