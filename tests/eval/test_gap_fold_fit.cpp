// The gap validation's fold fits (eval/gap_fold_fit.hpp) against an independent truth: Eigen's
// column-pivoted QR on explicitly gathered rows, for the bounded fit on the null space of the
// bound's weights (Lawson & Hanson ch. 20: theta = theta_0 + N z), and for the truncated fit the
// LS fit without the column the fit rows do not see.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <random>
#include <vector>

#include "eval/gap_fold_fit.hpp"
#include "eval/gap_normal_equations.hpp"
#include "eval/gap_validation.hpp"
#include "tests/eval/scaled_ls_problem.hpp"

namespace imscal::eval {
namespace {

constexpr Eigen::Index kSamples = 600;

using Problem = test::ScaledLsProblem;

Problem random_problem(std::uint64_t seed) {
  return test::scaled_ls_problem(
      seed, {kSamples, {1e-3, 1.0, 1e2, 1e-5}, 0.3, Eigen::Vector4d(2e3, -0.5, 1e-3, 4e4)});
}

std::vector<Eigen::Index> all_rows() {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < kSamples; ++k) rows.push_back(k);
  return rows;
}

Eigen::VectorXd to_vector(const std::vector<double>& y) {
  return Eigen::Map<const Eigen::VectorXd>(y.data(), Eigen::Index(y.size()));
}

// min |y - X theta| subject to w^T theta = lower, by the QR of X N (N: the null space of w^T).
Eigen::VectorXd constrained_by_qr(const Problem& p, const Eigen::VectorXd& w, double lower) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr_w(w);
  const Eigen::MatrixXd q = qr_w.householderQ() * Eigen::MatrixXd::Identity(w.size(), w.size());
  const Eigen::MatrixXd null_space = q.rightCols(w.size() - 1);
  const Eigen::VectorXd theta0 = w * (lower / w.squaredNorm());
  const Eigen::VectorXd residual = to_vector(p.y) - p.x * theta0;
  const Eigen::VectorXd z = (p.x * null_space).colPivHouseholderQr().solve(residual);
  return theta0 + null_space * z;
}

TEST(GapFoldFit, BrokenBoundIsTheEqualityConstrainedLeastSquares) {
  const Problem p = random_problem(21);
  const Eigen::MatrixXd gram = augmented_gram(p.x, p.y, all_rows());
  const Eigen::VectorXd scale = gram.diagonal().head(4).cwiseSqrt();
  const Eigen::VectorXd unbounded = truncated_fit(gram, scale, {});
  const Eigen::VectorXd ls = p.x.colPivHouseholderQr().solve(to_vector(p.y));
  // Well conditioned after scaling (kappa of a few): the LS fit to ~eps kappa², 1e-9 relative
  // leaves room for the Gram sums' order.
  for (Eigen::Index c = 0; c < 4; ++c) EXPECT_NEAR(unbounded[c], ls[c], 1e-9 * std::abs(ls[c]));
  // A level on columns 0 and 1 (as a backlash's flank and its landing) bounded 10 % above the
  // fit's: the bound is active.
  const Eigen::Vector4d w(1e-3, 2.0, 0.0, 0.0);
  const double lower = 1.1 * w.dot(ls);
  const Eigen::VectorXd bounded = truncated_fit(gram, scale, {w, lower});
  const Eigen::VectorXd truth = constrained_by_qr(p, w, lower);
  for (Eigen::Index c = 0; c < 4; ++c)
    EXPECT_NEAR(bounded[c], truth[c], 1e-8 * std::abs(truth[c])) << c;
  EXPECT_NEAR(w.dot(bounded), lower, 1e-10 * std::abs(lower));
  // A bound that holds changes nothing.
  EXPECT_EQ(truncated_fit(gram, scale, {w, 0.9 * w.dot(ls)}), unbounded);
}

TEST(GapFoldFit, FoldBoundsAreTheFitRowsLevelCoefficients) {
  // Per fold the sums of u x_c and u²; fold i's fit uses the other folds' sums.
  const std::vector<Eigen::VectorXd> cross = {Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(3.0, 0.0),
                                              Eigen::Vector2d(0.5, 0.5)};
  const std::vector<double> uu = {1.0, 2.0, 4.0};
  const std::vector<FoldBound> b = fold_bounds(cross, uu, -0.25);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_DOUBLE_EQ(b[0].weights[0], 3.5 / 6.0);
  EXPECT_DOUBLE_EQ(b[0].weights[1], 0.5 / 6.0);
  EXPECT_DOUBLE_EQ(b[2].weights[0], 4.0 / 3.0);
  EXPECT_DOUBLE_EQ(b[2].lower, -0.25);
}

TEST(GapFoldFit, ColumnZeroOnTheFitRowsPredictsNothingOnTheCheckRows) {
  // Column 3 is zero on the first half (fold 0) and not on the second: fold 1's fit (on fold 0's
  // rows) cannot size it, and the truncated fit leaves it out, where a QR scaled on the fit rows
  // would give it any size. Truth: the QR fit of columns 0-2 on fold 0, judged on fold 1 row by
  // row; and fold 0 judged by the QR fit of all columns on fold 1.
  Problem p = random_problem(22);
  TrainingFolds folds;
  folds.folds.resize(2);
  for (Eigen::Index k = 0; k < kSamples; ++k) {
    if (k < kSamples / 2) p.x(k, 3) = 0.0;
    folds.folds[k < kSamples / 2 ? 0 : 1].push_back(k);
  }
  const auto sse_of = [&](const std::vector<Eigen::Index>& fit,
                          const std::vector<Eigen::Index>& check, Eigen::Index columns) {
    const Eigen::MatrixXd x = p.x(fit, Eigen::seqN(0, columns));
    Eigen::VectorXd b(x.rows());
    for (std::size_t i = 0; i < fit.size(); ++i) b[Eigen::Index(i)] = p.y[std::size_t(fit[i])];
    const Eigen::VectorXd theta = x.colPivHouseholderQr().solve(b);
    double sse = 0.0;
    for (Eigen::Index k : check) {
      const double r = p.y[std::size_t(k)] - p.x.row(k).head(columns).dot(theta);
      sse += r * r;
    }
    return sse;
  };
  const double truth =
      sse_of(folds.folds[1], folds.folds[0], 4) + sse_of(folds.folds[0], folds.folds[1], 3);
  // The quadratic form's error ~eps y'y / sse (~1e-12 here); 1e-8 leaves room.
  EXPECT_NEAR(cross_validation_sse(p.x, p.y, folds), truth, 1e-8 * truth);
}

}  // namespace
}  // namespace imscal::eval
