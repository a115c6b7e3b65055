// Shapes drawn from a pool of columns (eval/gap_shape_pool.hpp): their validation errors from the
// pool's Gram matrices against a second method, the least squares of each fold's stacked rows by
// a column-pivoted QR of the copied columns; the copied shapes' columns, zero blocks and level
// signal; and a rank-deficient shape.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include "eval/gap_shape_pool.hpp"

namespace imscal::eval {
namespace {

constexpr std::size_t kSamples = 3000;  // 6 s at 2 ms: 6 chunks of 1 s dealt to the 2 folds

GapSignals record(std::size_t joints) {
  GapSignals s;
  s.cycle_s = 0.002;
  s.runs = {{0, 1400}, {1400, kSamples}};
  for (std::size_t k = 0; k < kSamples; ++k) s.time_s.push_back(double(k) * s.cycle_s);
  const std::vector<std::string> names = {"A1", "A2", "A3"};
  s.joint_names.assign(names.begin(), names.begin() + std::ptrdiff_t(joints));
  return s;
}

// Smooth, well-conditioned columns (sines of several frequencies) and a gap of a few of them
// plus noise, per joint.
ShapePool pool_of(std::size_t joints, Eigen::Index width, std::vector<std::vector<double>>& y) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0.0, 0.1);
  ShapePool pool;
  y.assign(joints, std::vector<double>(kSamples));
  for (std::size_t j = 0; j < joints; ++j) {
    Eigen::MatrixXd m(Eigen::Index(kSamples), width);
    for (Eigen::Index c = 0; c < width; ++c)
      for (Eigen::Index k = 0; k < m.rows(); ++k)
        m(k, c) = std::sin(0.001 * double((c + 1) * (k + 40 * Eigen::Index(j))) + 0.3 * double(c));
    for (std::size_t k = 0; k < kSamples; ++k)
      y[j][k] = 0.5 * m(Eigen::Index(k), 0) - 0.2 * m(Eigen::Index(k), width - 1) + noise(rng);
    pool.columns.push_back(std::move(m));
  }
  return pool;
}

// The 2-fold validation error of the stacked columns ([joint], empty: none) by a
// column-pivoted QR of the other fold.
double validation_by_qr(const std::vector<Eigen::MatrixXd>& columns,
                        const std::vector<std::vector<double>>& y, const TrainingFolds& folds) {
  double sse = 0.0;
  for (std::size_t i = 0; i < folds.folds.size(); ++i) {
    std::vector<double> fit_y, check_y;
    std::vector<Eigen::VectorXd> rows_fit, rows_check;
    for (std::size_t j = 0; j < columns.size(); ++j) {
      if (columns[j].size() == 0) continue;
      for (Eigen::Index k : folds.folds[1 - i])  // two folds: the other is the fit
        rows_fit.push_back(columns[j].row(k).transpose()), fit_y.push_back(y[j][std::size_t(k)]);
      for (Eigen::Index k : folds.folds[i])
        rows_check.push_back(columns[j].row(k).transpose()),
            check_y.push_back(y[j][std::size_t(k)]);
    }
    const Eigen::Index p = rows_fit.front().size();
    Eigen::MatrixXd fit_x(Eigen::Index(rows_fit.size()), p);
    for (std::size_t r = 0; r < rows_fit.size(); ++r) fit_x.row(Eigen::Index(r)) = rows_fit[r];
    const Eigen::VectorXd theta = fit_x.colPivHouseholderQr().solve(
        Eigen::Map<const Eigen::VectorXd>(fit_y.data(), Eigen::Index(fit_y.size())));
    for (std::size_t r = 0; r < rows_check.size(); ++r) {
      const double e = check_y[r] - rows_check[r].dot(theta);
      sse += e * e;
    }
  }
  return sse;
}

TEST(GapShapePool, ValidationErrorsMatchTheQrOfTheCopiedColumns) {
  // Three kinds of shape: subsets of one joint's pool, a shape with its own parameters per joint
  // (the payload's, solved joint by joint) and one parameter vector shared by both joints. The
  // columns are well conditioned (kappa ~10), so the normal equations agree with the QR to
  // rounding: 1e-9 relative is far above it and far below any difference a shape's choice sees.
  const GapSignals s = record(2);
  std::vector<std::vector<double>> y;
  ShapePool pool = pool_of(2, 5, y);
  pool.shapes.push_back(local_pooled_shape(2, 1, "one joint", {0, 2, 4}, {"a", "b", "c"}));
  PooledShape own = local_pooled_shape(2, 0, "own per joint", {0, 4}, {"a0", "b0"});
  own.pool_columns[1] = {0, 4};
  own.first_parameter[1] = 2;
  own.parameter_names = {"a0", "b0", "a1", "b1"};
  pool.shapes.push_back(own);
  PooledShape shared = local_pooled_shape(2, 0, "shared", {1, 3}, {"a", "b"});
  shared.pool_columns[1] = {1, 3};
  pool.shapes.push_back(shared);
  const TrainingFolds folds = training_folds(s, std::vector<bool>(kSamples, true));
  ASSERT_TRUE(folds.usable());
  const std::vector<double> sse = pooled_cross_validation_sse(pool, y, folds);
  ASSERT_EQ(sse.size(), 3u);
  for (std::size_t i = 0; i < sse.size(); ++i) {
    const double truth = validation_by_qr(shape_from_pool(pool, i).columns, y, folds);
    EXPECT_NEAR(sse[i], truth, 1e-9 * truth) << pool.shapes[i].label;
  }
}

TEST(GapShapePool, CopiedShapeHasItsColumnsZeroBlocksAndLevelSignal) {
  std::vector<std::vector<double>> y;
  ShapePool pool = pool_of(3, 4, y);
  PooledShape own = local_pooled_shape(3, 0, "own", {3}, {"p0"});
  own.pool_columns[2] = {1};
  own.first_parameter[2] = 1;
  own.parameter_names = {"p0", "p2"};
  own.level_column = 2, own.level_joint = 2, own.level_lower = -0.5;
  pool.shapes.push_back(own);
  const CandidateShape sh = shape_from_pool(pool, 0);
  ASSERT_EQ(sh.columns.size(), 3u);
  EXPECT_EQ(sh.columns[1].size(), 0);  // the shape does not act on joint 1
  ASSERT_EQ(sh.columns[0].cols(), 2);
  EXPECT_EQ(sh.columns[0].col(0), pool.columns[0].col(3));
  EXPECT_TRUE(sh.columns[0].col(1).isZero(0.0));  // joint 2's parameter
  EXPECT_TRUE(sh.columns[2].col(0).isZero(0.0));  // joint 0's parameter
  EXPECT_EQ(sh.columns[2].col(1), pool.columns[2].col(1));
  EXPECT_EQ(sh.level_signal, pool.columns[2].col(2));
  EXPECT_EQ(sh.level_lower, -0.5);
  EXPECT_EQ(sh.parameter_names, (std::vector<std::string>{"p0", "p2"}));
}

TEST(GapShapePool, RankDeficientShapeIsTheFitOfItsSingleColumn) {
  // A column taken twice: the fold fits leave the zero eigen-direction out (eval/gap_fold_fit.hpp;
  // the same as the shape's own cross_validation_sse, bit for bit), and the fit is that of the
  // single column (the residual of an LS fit does not depend on the duplicate), to rounding.
  const GapSignals s = record(1);
  std::vector<std::vector<double>> y;
  ShapePool pool = pool_of(1, 3, y);
  pool.shapes.push_back(local_pooled_shape(1, 0, "twice", {0, 0}, {"a", "a_again"}));
  pool.shapes.push_back(local_pooled_shape(1, 0, "once", {0}, {"a"}));
  const TrainingFolds folds = training_folds(s, std::vector<bool>(kSamples, true));
  const std::vector<double> sse = pooled_cross_validation_sse(pool, y, folds);
  EXPECT_EQ(sse[0], cross_validation_sse(shape_from_pool(pool, 0).columns, y, folds));
  EXPECT_NEAR(sse[0], sse[1], 1e-9 * sse[1]);
}

}  // namespace
}  // namespace imscal::eval
