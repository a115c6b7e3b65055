#include "eval/gap_validation.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <optional>

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
  for (std::size_t i = 0; i < f.folds.size(); ++i) {
    std::vector<Eigen::Index> rest;
    for (std::size_t j = 0; j < f.folds.size(); ++j)
      if (j != i) rest.insert(rest.end(), f.folds[j].begin(), f.folds[j].end());
    std::sort(rest.begin(), rest.end());
    f.complements.push_back(std::move(rest));
  }
  return f;
}

namespace {

// The validation error by the column-pivoted QR on the rows `fit` (the fallback of the normal
// equations: ill-conditioned or rank-deficient columns).
double qr_validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                         const std::vector<Eigen::Index>& fit,
                         const std::vector<Eigen::Index>& check) {
  const Eigen::Index p = columns.cols();
  // Gathered column by column (a column-major matrix's rows are strided).
  Eigen::MatrixXd x = columns(fit, Eigen::all);
  Eigen::VectorXd b(x.rows());
  for (std::size_t i = 0; i < fit.size(); ++i) b[Eigen::Index(i)] = y[std::size_t(fit[i])];
  // Column scaling keeps the QR well conditioned for columns of very different sizes.
  Eigen::VectorXd scale(p);
  for (Eigen::Index c = 0; c < p; ++c) {
    scale[c] = x.col(c).norm() > 0.0 ? x.col(c).norm() : 1.0;
    x.col(c) /= scale[c];
  }
  // Decomposed in place: x is not used after.
  const Eigen::ColPivHouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(x);
  const Eigen::VectorXd theta = qr.solve(b).cwiseQuotient(scale);
  // Each check row's residual, the columns summed in their order (the terms of an
  // ill-conditioned fit may cancel: no quadratic form).
  double sse = 0.0;
  for (std::size_t i = 0; i < check.size(); ++i) {
    double predicted = 0.0;
    for (Eigen::Index c = 0; c < p; ++c) predicted += columns(check[i], c) * theta[c];
    const double r = y[std::size_t(check[i])] - predicted;
    sse += r * r;
  }
  return sse;
}

// The fit on all folds but `i`, from the folds' Gram matrices; nullopt when ill-conditioned.
std::optional<GramSolution> fold_fit(const std::vector<Eigen::MatrixXd>& grams, std::size_t i) {
  Eigen::MatrixXd fit = Eigen::MatrixXd::Zero(grams[i].rows(), grams[i].cols());
  for (std::size_t j = 0; j < grams.size(); ++j)
    if (j != i) fit += grams[j];
  return solve_normal_equations(fit);
}

}  // namespace

double validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<Eigen::Index>& fit,
                      const std::vector<Eigen::Index>& check) {
  if (const auto solution = solve_normal_equations(augmented_gram(columns, y, fit)))
    return sse_of_gram(augmented_gram(columns, y, check), solution->theta);
  return qr_validation_sse(columns, y, fit, check);
}

double cross_validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                            const TrainingFolds& folds) {
  std::vector<Eigen::MatrixXd> grams;
  for (const auto& fold : folds.folds) grams.push_back(augmented_gram(columns, y, fold));
  double sse = 0.0;
  for (std::size_t i = 0; i < folds.folds.size(); ++i) {
    if (const auto solution = fold_fit(grams, i))
      sse += sse_of_gram(grams[i], solution->theta);
    else
      sse += qr_validation_sse(columns, y, folds.complements[i], folds.folds[i]);
  }
  return sse;
}

double cross_validation_sse(const std::vector<Eigen::MatrixXd>& columns,
                            const std::vector<std::vector<double>>& y, const TrainingFolds& folds) {
  if (const auto j = only_joint(columns)) return cross_validation_sse(columns[*j], y[*j], folds);
  const std::vector<std::size_t> joints = joints_with_columns(columns);
  std::vector<Eigen::MatrixXd> grams;
  for (const auto& fold : folds.folds) {
    const Eigen::Index p = columns[joints.front()].cols();
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p + 1, p + 1);
    for (std::size_t j : joints) add_augmented_gram(columns[j], y[j], fold, a);
    grams.push_back(std::move(a));
  }
  double sse = 0.0;
  std::optional<StackedJoints> stacked;  // for the QR, only when needed
  for (std::size_t i = 0; i < folds.folds.size(); ++i) {
    if (const auto solution = fold_fit(grams, i)) {
      sse += sse_of_gram(grams[i], solution->theta);
      continue;
    }
    if (!stacked) stacked = stack_joints(columns, y);
    const Eigen::Index n = columns[joints.front()].rows();
    sse += qr_validation_sse(stacked->x, stacked->y,
                             stacked_rows(folds.complements[i], joints.size(), n),
                             stacked_rows(folds.folds[i], joints.size(), n));
  }
  return sse;
}

}  // namespace imscal::eval
