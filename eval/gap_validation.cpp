#include "eval/gap_validation.hpp"

#include <algorithm>
#include <cmath>

#include "eval/gap_fold_fit.hpp"
#include "eval/gap_joint_stack.hpp"
#include "eval/gap_normal_equations.hpp"

namespace imscal::eval {

namespace {

// Chunks of 1 s (the training blocks' length, eval/gap_diagnosis.hpp) dealt to two folds: each fit
// is judged on motion it did not see.
constexpr double kFoldChunkS = 1.0;
constexpr std::size_t kFoldCount = 2;

}  // namespace

TrainingFolds training_folds(const GapSignals& s, const std::vector<bool>& training) {
  const std::size_t chunk =
      std::max<std::size_t>(1, std::size_t(std::lround(kFoldChunkS / s.cycle_s)));
  TrainingFolds f;
  f.folds.resize(kFoldCount);
  std::size_t count = 0;
  for (std::size_t k = 0; k < training.size(); ++k)
    if (training[k]) f.folds[(count++ / chunk) % kFoldCount].push_back(Eigen::Index(k));
  return f;
}

double validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<Eigen::Index>& fit,
                      const std::vector<Eigen::Index>& check) {
  const Eigen::MatrixXd fit_gram = augmented_gram(columns, y, fit);
  const Eigen::MatrixXd check_gram = augmented_gram(columns, y, check);
  const Eigen::Index p = columns.cols();
  const Eigen::VectorXd scale =
      (fit_gram + check_gram).diagonal().head(p).cwiseMax(0.0).cwiseSqrt();
  return sse_of_gram(check_gram, truncated_fit(fit_gram, scale, {}));
}

double cross_validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                            const TrainingFolds& folds) {
  std::vector<Eigen::MatrixXd> grams;
  for (const auto& fold : folds.folds) grams.push_back(augmented_gram(columns, y, fold));
  return folds_validation_sse(grams, {});
}

namespace {

// The fold fits' bounds of `level` on the columns x of its joint: per fold, the sums of u x_c and
// u² over the fold's rows.
std::vector<FoldBound> level_bounds(const Eigen::MatrixXd& x, const ValidationLevel& level,
                                    const TrainingFolds& folds) {
  const Eigen::VectorXd& u = *level.signal;
  std::vector<Eigen::VectorXd> cross;
  std::vector<double> uu;
  for (const auto& fold : folds.folds) {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(x.cols());
    double sum = 0.0;
    for (Eigen::Index k : fold) {
      c.noalias() += u[k] * x.row(k).transpose();
      sum += u[k] * u[k];
    }
    cross.push_back(std::move(c));
    uu.push_back(sum);
  }
  return fold_bounds(cross, uu, level.lower);
}

}  // namespace

double cross_validation_sse(const std::vector<Eigen::MatrixXd>& columns,
                            const std::vector<std::vector<double>>& y, const TrainingFolds& folds,
                            const ValidationLevel& level) {
  const std::vector<std::size_t> joints = joints_with_columns(columns);
  if (joints.empty()) return 0.0;
  const Eigen::Index p = columns[joints.front()].cols();
  std::vector<Eigen::MatrixXd> grams;
  for (const auto& fold : folds.folds) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p + 1, p + 1);
    for (std::size_t j : joints) add_augmented_gram(columns[j], y[j], fold, a);
    grams.push_back(std::move(a));
  }
  std::vector<FoldBound> bounds;
  if (level.signal && level.signal->size() > 0 && level.joint < columns.size() &&
      columns[level.joint].size() > 0)
    bounds = level_bounds(columns[level.joint], level, folds);
  return folds_validation_sse(grams, bounds);
}

}  // namespace imscal::eval
