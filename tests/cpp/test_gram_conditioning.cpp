// The reactionless controllers' damping decision and reported condition (detail::gram_extremes,
// control/detail/gram_extremes.hpp) against accurate singular values: K's own, from a long double
// Jacobi SVD (cond K = sqrt(lmax / lmin) of its Gram matrix). Near-singular Gram matrices of every
// shape the controllers meet (2 x 2 and 3 x 3, square, wide and tall K), conditions 1e2 to 1e9
// with one small singular value, two (clustered or not), the two largest clustered, conditions
// right at max_condition, and exactly singular K of rank 0, 1 and 2. Also Eigen's 3 x 3 closed
// form against the error bound the decision relies on.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mechbal/control/detail/gram_extremes.hpp"

using namespace mechbal;

namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();
using MatrixL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;

/// cond(K) = s_max / s_min over its min(rows, cols) singular values (infinity when s_min = 0),
/// from a long double two-sided Jacobi SVD of the double K.
long double accurate_condition(const Eigen::MatrixXd& K) {
  const MatrixL KL = K.cast<long double>();
  Eigen::JacobiSVD<MatrixL> svd(KL);
  const auto& s = svd.singularValues();  // descending
  const long double smin = s(s.size() - 1);
  return smin > 0.0L ? s(0) / smin : std::numeric_limits<long double>::infinity();
}

/// Its Gram matrix's eigenvalues (ascending) in long double.
Eigen::Matrix<long double, Eigen::Dynamic, 1> accurate_gram_eigenvalues(const Eigen::MatrixXd& K) {
  const MatrixL KL = K.cast<long double>();
  const MatrixL G = K.rows() < K.cols() ? MatrixL(KL * KL.transpose()) : MatrixL(KL.transpose() * KL);
  Eigen::SelfAdjointEigenSolver<MatrixL> eig(G, Eigen::EigenvaluesOnly);
  return eig.eigenvalues();
}

struct Sample {
  Eigen::MatrixXd K;
  std::string kind;
};

/// K = U diag(s) V^T (U: rows x g, V: cols x g with orthonormal columns, g = min(rows, cols)),
/// scaled by 10^[-3, 3].
Eigen::MatrixXd with_singular_values(std::mt19937& rng, int rows, int cols, const Eigen::VectorXd& s) {
  std::normal_distribution<double> normal;
  const int g = static_cast<int>(s.size());
  const auto orthonormal = [&](int n) {
    Eigen::MatrixXd A(n, n);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
    return Eigen::MatrixXd(Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ()).leftCols(g).eval();
  };
  const Eigen::MatrixXd U = orthonormal(rows), V = orthonormal(cols);
  std::uniform_real_distribution<double> exponent(-3.0, 3.0);
  return std::pow(10.0, exponent(rng)) * U * s.asDiagonal() * V.transpose();
}

std::vector<Sample> samples(double max_condition) {
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
  const std::vector<std::pair<int, int>> shapes = {{2, 2}, {3, 3}, {3, 3}, {2, 4}, {3, 5}, {3, 6}, {4, 3}, {6, 3}, {5, 2}};
  std::vector<Sample> out;
  for (const auto& [rows, cols] : shapes) {
    const int g = std::min(rows, cols);
    for (int n = 0; n < 400; ++n) {
      Eigen::VectorXd s(g);
      std::string kind;
      const int which = n % 5;
      // the smallest singular value: cond 1e2..1e9, or within 1e-7..1e-1 of max_condition
      const double c = which == 4 ? max_condition * (1.0 + (n % 2 ? 1.0 : -1.0) * log_uniform(1e-7, 1e-1))
                                  : log_uniform(1e2, 1e9);
      if (g == 2) {
        s << 1.0, 1.0 / c;
        kind = which == 4 ? "at max_condition" : "one small";
      } else if (which == 0 || which == 4) {
        s << 1.0, log_uniform(std::min(1.0, std::max(1e-2, 10.0 / c)), 1.0), 1.0 / c;  // s2 >= 10 s3
        kind = which == 4 ? "at max_condition" : "one small";
      } else if (which == 1) {  // two small, apart
        s << 1.0, std::min(1.0, log_uniform(2.0, 1e3) / c), 1.0 / c;
        kind = "two small";
      } else if (which == 2) {  // two small, clustered
        s << 1.0, (1.0 + log_uniform(1e-9, 1e-1)) / c, 1.0 / c;
        kind = "two small, clustered";
      } else {  // the two largest clustered
        s << 1.0, 1.0 - log_uniform(1e-10, 1e-2), 1.0 / c;
        kind = "two largest clustered";
      }
      out.push_back({with_singular_values(rng, rows, cols, s), kind});
    }
    // well conditioned
    for (int n = 0; n < 50; ++n) {
      Eigen::VectorXd s(g);
      for (int i = 0; i < g; ++i) s(i) = log_uniform(1e-2, 1.0);
      s(0) = 1.0;
      out.push_back({with_singular_values(rng, rows, cols, s), "well conditioned"});
    }
    // exactly singular: integer entries (exact products), rank g - 1 and 1, and K = 0
    std::uniform_int_distribution<int> small(-9, 9);
    for (int n = 0; n < 40; ++n) {
      const int rank = n % 2 ? 1 : g - 1;
      Eigen::MatrixXd A(rows, rank), B(rank, cols);
      for (int i = 0; i < A.size(); ++i) A.data()[i] = small(rng);
      for (int i = 0; i < B.size(); ++i) B.data()[i] = small(rng);
      out.push_back({A * B, "exactly singular"});
    }
    out.push_back({Eigen::MatrixXd::Zero(rows, cols), "zero"});
  }
  return out;
}

bool g3_or_2(const Eigen::MatrixXd& K) { return std::min(K.rows(), K.cols()) <= 3; }

/// The controllers' decision from the extremes (ReactionlessController::factorise).
bool damped(double lmin, double lmax, double max_condition) {
  return !(lmax > 0.0 && lmin > 0.0 && std::sqrt(lmax / lmin) <= max_condition);
}

}  // namespace

// The damping decision agrees with the accurate condition except within a relative band around
// max_condition: 1e-6, or the iterative solver's own resolution where it decides (its absolute
// error of ~16 eps lmax on lmin: 32 eps max_condition^2 relative on the condition). The reported
// condition agrees to 1e-6 relative, or to the iterative solver's resolution (16 eps cond^2) where
// that is coarser; beyond ~1e7 (where no Gram matrix in double resolves lmin) it must at least
// report the condition as large. With one small singular value (the wrist near its gimbal lock)
// the condition is resolved far beyond the iterative solver's reach, without it. The iterative solver is not run for a decision alone outside the
// band, except where the two smallest singular values cluster (there the determinant's error,
// through a square root, can reach the band).
TEST(GramConditioning, DecisionAndConditionAgreeWithAccurateSingularValues) {
  for (const double C : {1e2, 1e4, 1e6}) {
    const double band = std::max(1e-6, 32.0 * eps * C * C);
    int checked = 0, in_band = 0, iterated_decision = 0, iterated_report = 0, outside_band = 0;
    double worst_condition = 0.0;
    std::string worst_kind;
    for (const Sample& x : samples(C)) {
      const long double truth = accurate_condition(x.K);
      const bool truly_damped = !(truth <= C);
      const double off = static_cast<double>(std::abs(truth / C - 1.0L));
      const detail::GramExtremes decision = detail::gram_extremes(x.K, C, false);
      const detail::GramExtremes report = detail::gram_extremes(x.K, C, true);
      for (const detail::GramExtremes* e : {&decision, &report}) {
        if (off > band) {
          EXPECT_EQ(damped(e->lmin, e->lmax, C), truly_damped)
              << x.kind << " " << x.K.rows() << "x" << x.K.cols() << ": cond " << static_cast<double>(truth)
              << " at max_condition " << C << ", lmin " << e->lmin << " lmax " << e->lmax;
        } else {
          ++in_band;
        }
      }
      ++checked;
      if (off > 1e-2 && x.kind != "two small, clustered") {
        outside_band += 1;
        iterated_decision += decision.iterated;
      }
      iterated_report += report.iterated;
      // the reported condition
      const double cond = report.lmax > 0.0 && report.lmin > 0.0 ? std::sqrt(report.lmax / report.lmin)
                                                                  : std::numeric_limits<double>::infinity();
      const double t = static_cast<double>(truth);
      const double tol = 1e-6 + 16.0 * eps * t * t;
      const bool one_small = x.kind == "one small" || x.kind == "two largest clustered" || x.kind == "at max_condition";
      if (one_small && g3_or_2(x.K)) {
        // one small singular value (a wrist near its gimbal lock): K's minors resolve it to the
        // determinant's rounding, about 6u s1^2 / (s2 s3) <= 600 u cond relative here (s2 >= 1e-2
        // s1), up to cond 1e9, without the iterative solver
        EXPECT_LE(std::abs(cond / t - 1.0), 1e-6 + 300.0 * eps * t)
            << x.kind << " " << x.K.rows() << "x" << x.K.cols() << ": reported " << cond << ", accurate " << t;
        if (off > 1e-2) {
          EXPECT_FALSE(report.iterated) << x.kind << ": cond " << t;
        }
      }
      if (x.kind == "zero") {
        EXPECT_EQ(report.lmax, 0.0);
      } else if (tol < 0.5) {
        const double rel = std::abs(cond / t - 1.0);
        EXPECT_LE(rel, tol) << x.kind << " " << x.K.rows() << "x" << x.K.cols() << ": reported " << cond
                            << ", accurate " << t;
        if (rel > worst_condition) {
          worst_condition = rel;
          worst_kind = x.kind;
        }
      } else {
        EXPECT_GE(cond, 0.5 * std::min(t, 1.0 / std::sqrt(64.0 * eps)))
            << x.kind << " " << x.K.rows() << "x" << x.K.cols() << ": reported " << cond << ", accurate " << t;
      }
    }
    // the decision alone needs the iterative solver only near max_condition (a clustered pair of
    // small singular values aside): at most 1 % of the other cases
    EXPECT_LE(iterated_decision, outside_band / 100) << "max_condition " << C;
    std::printf("max_condition %g: %d matrices, %d decisions within the band %.2g, decisions iterated %d of %d "
                "outside 1e-2 of it, reports iterated %d; worst reported condition %.2g relative (%s)\n",
                C, checked, in_band, band, iterated_decision, outside_band, iterated_report, worst_condition,
                worst_kind.c_str());
  }
}

// Eigen's 3 x 3 closed form (computeDirect) stays within the bound gram_extremes assumes for it,
// 8 sqrt(eps) lmax on every eigenvalue, on the same matrices (near a double root too, where it
// loses half the digits), and the bound is not far from what it attains.
TEST(GramConditioning, ClosedFormWithinItsErrorBound) {
  double worst = 0.0;
  for (const Sample& x : samples(1e4)) {
    if (std::min(x.K.rows(), x.K.cols()) != 3) continue;
    const Eigen::Matrix3d G = x.K.rows() < x.K.cols() ? Eigen::Matrix3d(x.K * x.K.transpose())
                                                      : Eigen::Matrix3d(x.K.transpose() * x.K);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> direct;
    direct.computeDirect(G, Eigen::EigenvaluesOnly);
    const auto truth = accurate_gram_eigenvalues(x.K);
    const long double lmax = truth(2);
    if (!(lmax > 0.0L)) continue;
    for (int i = 0; i < 3; ++i) {
      const double err = static_cast<double>(std::abs(direct.eigenvalues()(i) - truth(i)) / lmax);
      EXPECT_LE(err, 8.0 * std::sqrt(eps)) << x.kind << ": eigenvalue " << i;
      worst = std::max(worst, err);
    }
  }
  std::printf("closed form 3 x 3: worst error %.2g lmax (bound %.2g)\n", worst, 8.0 * std::sqrt(eps));
  EXPECT_GT(worst, 1e-3 * 8.0 * std::sqrt(eps));  // a double root costs it ~sqrt(eps)
}
