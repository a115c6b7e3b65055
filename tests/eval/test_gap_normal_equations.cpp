// The normal equations of the gap diagnosis' fits (eval/gap_normal_equations.hpp) and the
// cross-validation and fits built on them (eval/gap_validation.hpp, eval/gap_candidates.hpp),
// against an independent truth: Eigen's column-pivoted QR on explicitly gathered rows, and the
// residuals summed row by row.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <random>

#include "eval/gap_candidates.hpp"
#include "eval/gap_normal_equations.hpp"
#include "eval/gap_validation.hpp"
#include "tests/eval/scaled_ls_problem.hpp"

namespace imscal::eval {
namespace {

constexpr Eigen::Index kSamples = 900;

using Problem = test::ScaledLsProblem;

Problem random_problem(std::uint64_t seed) {
  return test::scaled_ls_problem(
      seed, {kSamples, {1e-3, 1.0, 1e3, 1e-6}, 0.1, Eigen::Vector4d(2e3, -0.5, 1e-3, 4e5)});
}

// Runs of consecutive rows with gaps, as the folds' chunks are.
std::vector<Eigen::Index> chunked_rows(Eigen::Index first, Eigen::Index chunk, Eigen::Index step) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index b = first; b < kSamples; b += step)
    for (Eigen::Index k = b; k < std::min(b + chunk, kSamples); ++k) rows.push_back(k);
  return rows;
}

// The QR solution on the gathered rows, its columns scaled as the diagnosis scales them.
Eigen::VectorXd qr_theta(const Eigen::MatrixXd& x, const std::vector<double>& y,
                         const std::vector<Eigen::Index>& rows) {
  Eigen::MatrixXd xs = x(rows, Eigen::all);
  Eigen::VectorXd b(xs.rows());
  for (std::size_t i = 0; i < rows.size(); ++i) b[Eigen::Index(i)] = y[std::size_t(rows[i])];
  const Eigen::VectorXd scale = xs.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < xs.cols(); ++c) xs.col(c) /= scale[c];
  return xs.colPivHouseholderQr().solve(b).cwiseQuotient(scale);
}

double direct_sse(const Eigen::MatrixXd& x, const std::vector<double>& y,
                  const std::vector<Eigen::Index>& rows, const Eigen::VectorXd& theta) {
  double sse = 0.0;
  for (Eigen::Index k : rows) {
    const double r = y[std::size_t(k)] - x.row(k).dot(theta);
    sse += r * r;
  }
  return sse;
}

// Two folds of chunks of `chunk` rows, every `step` rows each.
TrainingFolds two_folds(Eigen::Index chunk, Eigen::Index step) {
  TrainingFolds folds;
  folds.folds = {chunked_rows(0, chunk, step), chunked_rows(chunk, chunk, step)};
  return folds;
}

// The validation error of each fold's QR fit on the other, summed.
double qr_cross_validation_sse(const Problem& p, const TrainingFolds& folds) {
  double sse = 0.0;
  for (std::size_t i = 0; i < 2; ++i)
    sse += direct_sse(p.x, p.y, folds.folds[i], qr_theta(p.x, p.y, folds.folds[1 - i]));
  return sse;
}

TEST(GapNormalEquations, SolutionMatchesTheColumnPivotedQr) {
  const Problem p = random_problem(1);
  const std::vector<Eigen::Index> rows = chunked_rows(0, 50, 120);
  const auto solution = solve_normal_equations(augmented_gram(p.x, p.y, rows), true);
  ASSERT_TRUE(solution);
  const Eigen::VectorXd truth = qr_theta(p.x, p.y, rows);
  // Scaled, these columns have a condition number of a few: the normal equations' error is
  // ~eps kappa² ~ 1e-15 relative; 1e-10 leaves room for the summation order.
  for (Eigen::Index c = 0; c < truth.size(); ++c)
    EXPECT_NEAR(solution->theta[c], truth[c], 1e-10 * std::abs(truth[c])) << c;
  // The inverse of the scaled Gram matrix is an inverse.
  Eigen::MatrixXd xs = p.x(rows, Eigen::all);
  for (Eigen::Index c = 0; c < xs.cols(); ++c) xs.col(c) /= solution->scale[c];
  const Eigen::MatrixXd identity = solution->inverse_scaled_gram * (xs.transpose() * xs);
  EXPECT_LT((identity - Eigen::MatrixXd::Identity(4, 4)).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(GapNormalEquations, GramOfDisjointRowsAddsAndGivesTheResidualSum) {
  const Problem p = random_problem(2);
  const std::vector<Eigen::Index> a = chunked_rows(0, 40, 80), b = chunked_rows(40, 40, 80);
  const std::vector<Eigen::Index> all = chunked_rows(0, kSamples, kSamples);
  const Eigen::MatrixXd sum = augmented_gram(p.x, p.y, a) + augmented_gram(p.x, p.y, b);
  const Eigen::MatrixXd whole = augmented_gram(p.x, p.y, all);
  // Only the summation order differs (entries up to ~1e9 here: the 1e3 column squared).
  const Eigen::MatrixXd lower_diff = (sum - whole).triangularView<Eigen::Lower>();
  EXPECT_LT(lower_diff.cwiseAbs().maxCoeff(), 1e-12 * whole.cwiseAbs().maxCoeff());
  const Eigen::VectorXd theta = qr_theta(p.x, p.y, b);
  const double truth = direct_sse(p.x, p.y, a, theta);
  // The quadratic form cancels y'y against the fit: its error is ~eps y'y, y'y / sse ~ 1e7 here.
  EXPECT_NEAR(sse_of_gram(augmented_gram(p.x, p.y, a), theta), truth, 1e-7 * truth);
}

TEST(GapNormalEquations, RefusesIllConditionedOrZeroColumns) {
  Problem p = random_problem(3);
  const std::vector<Eigen::Index> all = chunked_rows(0, kSamples, kSamples);
  EXPECT_TRUE(solve_normal_equations(augmented_gram(p.x, p.y, all)));
  Problem collinear = p;  // column 3 = column 1 within 1e-6: kappa(X) ~ 1e6 after scaling
  std::mt19937_64 rng(4);
  std::normal_distribution<double> normal(0.0, 1e-6);
  for (Eigen::Index k = 0; k < kSamples; ++k) collinear.x(k, 3) = p.x(k, 1) * (1.0 + normal(rng));
  EXPECT_FALSE(solve_normal_equations(augmented_gram(collinear.x, collinear.y, all)));
  Problem zero = p;
  zero.x.col(2).setZero();
  EXPECT_FALSE(solve_normal_equations(augmented_gram(zero.x, zero.y, all)));
}

TEST(GapNormalEquations, ZeroColumnsOfAWideMatrixLeaveTheirEntriesAlone) {
  // A stacked fit's columns: this joint's four columns at the middle of twelve, the other joints'
  // blocks zero (the wide path leaves them out of the products). Truth: [X y]^T [X y] on the
  // gathered rows, by a plain matrix product. Tolerance 1e-12 of the entries' scale: the same
  // sums in another order.
  const Problem p = random_problem(11);
  Eigen::MatrixXd wide = Eigen::MatrixXd::Zero(kSamples, 12);
  wide.middleCols(5, 4) = p.x;
  const std::vector<Eigen::Index> rows = chunked_rows(3, 50, 120);
  Eigen::MatrixXd xy(Eigen::Index(rows.size()), 13);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    xy.row(Eigen::Index(i)).head(12) = wide.row(rows[i]);
    xy(Eigen::Index(i), 12) = p.y[std::size_t(rows[i])];
  }
  const Eigen::MatrixXd truth = xy.transpose() * xy;
  Eigen::MatrixXd gram = Eigen::MatrixXd::Constant(13, 13, 0.5);  // added to, as across joints
  add_augmented_gram(wide, p.y, rows, gram);
  for (Eigen::Index c = 0; c < 13; ++c)
    for (Eigen::Index d = 0; d <= c; ++d) {
      const double scale = std::sqrt(truth(c, c) * truth(d, d));
      EXPECT_NEAR(gram(c, d) - 0.5, truth(c, d), 1e-12 * std::max(scale, 1.0)) << c << "," << d;
    }
}

TEST(GapNormalEquations, CrossValidationMatchesFoldFitsByQr) {
  const Problem p = random_problem(5);
  const TrainingFolds folds = two_folds(30, 90);
  const double truth = qr_cross_validation_sse(p, folds);
  // As above: relative error ~eps y'y / sse.
  EXPECT_NEAR(cross_validation_sse(p.x, p.y, folds), truth, 1e-7 * truth);
  EXPECT_NEAR(validation_sse(p.x, p.y, folds.folds[1], folds.folds[0]),
              direct_sse(p.x, p.y, folds.folds[0], qr_theta(p.x, p.y, folds.folds[1])),
              1e-7 * truth);

  // The same parameters on two joints: the stack of their rows.
  const Problem q = random_problem(6);
  Eigen::MatrixXd stacked(2 * kSamples, 4);
  stacked << p.x, q.x;
  std::vector<double> y = p.y;
  y.insert(y.end(), q.y.begin(), q.y.end());
  const auto both = [&](const std::vector<Eigen::Index>& rows) {
    std::vector<Eigen::Index> out = rows;
    for (Eigen::Index k : rows) out.push_back(kSamples + k);
    return out;
  };
  double stacked_truth = 0.0;
  for (std::size_t i = 0; i < 2; ++i)
    stacked_truth += direct_sse(stacked, y, both(folds.folds[i]),
                                qr_theta(stacked, y, both(folds.folds[1 - i])));
  const std::vector<Eigen::MatrixXd> columns = {Eigen::MatrixXd(), p.x, q.x};
  const std::vector<std::vector<double>> gap = {{}, p.y, q.y};
  EXPECT_NEAR(cross_validation_sse(columns, gap, folds), stacked_truth, 1e-7 * stacked_truth);
}

TEST(GapNormalEquations, IllConditionedFitFallsBackToTheQrAndItsFoldFitsTruncate) {
  Problem p = random_problem(7);
  std::mt19937_64 rng(8);
  std::normal_distribution<double> normal(0.0, 1e-7);
  for (Eigen::Index k = 0; k < kSamples; ++k) p.x(k, 3) = p.x(k, 1) * (1.0 + normal(rng));
  std::vector<bool> use(std::size_t(kSamples), false);
  const std::vector<Eigen::Index> rows = chunked_rows(0, 50, 100);
  for (Eigen::Index k : rows) use[std::size_t(k)] = true;
  const LinearFit fit = fit_columns(p.x, p.y, use);
  // The QR's residual: the same to rounding although theta is poorly determined.
  const Eigen::VectorXd theta = qr_theta(p.x, p.y, rows);
  const double rms = std::sqrt(direct_sse(p.x, p.y, rows, theta) / double(rows.size()));
  EXPECT_NEAR(fit.rms, rms, 1e-9 * rms);
  // The validation's fold fits leave the direction x1 - x3, which the rows barely determine,
  // out (eval/gap_fold_fit.hpp): the fit of columns 0-2 by the QR, to the ~1e-7 the two columns
  // differ by (1e-5 of the error leaves room).
  const TrainingFolds folds = two_folds(30, 60);
  Problem three = p;
  three.x = p.x.leftCols(3);
  const double truth = qr_cross_validation_sse(three, folds);
  EXPECT_NEAR(cross_validation_sse(p.x, p.y, folds), truth, 1e-5 * truth);
}

TEST(GapNormalEquations, FitSigmaMatchesTheQrCovariance) {
  const Problem p = random_problem(9);
  std::vector<bool> use(std::size_t(kSamples), true);
  const LinearFit fit = fit_columns(p.x, p.y, use);
  const std::vector<Eigen::Index> all = chunked_rows(0, kSamples, kSamples);
  const Eigen::VectorXd theta = qr_theta(p.x, p.y, all);
  // Independent: s² (X^T X)^-1 from the QR's R, times the fit's own inflation.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(p.x);
  const Eigen::MatrixXd r = qr.matrixQR().topRows(4).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inverse = r.inverse();
  const double s2 = direct_sse(p.x, p.y, all, theta) / double(kSamples - 4);
  for (Eigen::Index c = 0; c < 4; ++c) {
    const double sigma = std::sqrt(s2 * r_inverse.row(c).squaredNorm()) * fit.inflation;
    EXPECT_NEAR(fit.parameters[c], theta[c], 1e-10 * std::abs(theta[c])) << c;
    EXPECT_NEAR(fit.sigma[c], sigma, 1e-9 * sigma) << c;
  }
}

}  // namespace
}  // namespace imscal::eval
