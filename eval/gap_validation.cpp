#include "eval/gap_validation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "eval/gap_joint_stack.hpp"
#include "eval/gap_normal_equations.hpp"

namespace imscal::eval {

namespace {

// Chunks of 1 s (the training blocks' length, eval/gap_diagnosis.hpp) dealt to two folds: each fit
// is judged on motion it did not see.
constexpr std::size_t kFoldCount = 2;
constexpr double kFoldChunkS = 1.0;

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

Eigen::VectorXd truncated_fit(const Eigen::MatrixXd& fit, const Eigen::MatrixXd& whole) {
  const Eigen::Index p = fit.rows() - 1;
  // 1 / the columns' norms on all rows; a column zero there stays out (its parameter 0).
  Eigen::VectorXd inverse_scale = Eigen::VectorXd::Zero(p);
  for (Eigen::Index c = 0; c < p; ++c)
    if (whole(c, c) > 0.0) inverse_scale[c] = 1.0 / std::sqrt(whole(c, c));
  const Eigen::MatrixXd g =
      inverse_scale.asDiagonal() *
      Eigen::MatrixXd(fit.topLeftCorner(p, p).selfadjointView<Eigen::Lower>()) *
      inverse_scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(g);
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(p);
  if (p == 0 || eigen.info() != Eigen::Success) return theta;
  const Eigen::VectorXd& lambda = eigen.eigenvalues();  // ascending
  const Eigen::VectorXd projected =
      eigen.eigenvectors().transpose() * inverse_scale.cwiseProduct(fit.row(p).head(p).transpose());
  Eigen::VectorXd z = Eigen::VectorXd::Zero(p);
  for (Eigen::Index k = 0; k < p; ++k)
    if (lambda[k] * kMaxGramCondition > lambda[p - 1]) z[k] = projected[k] / lambda[k];
  theta = (eigen.eigenvectors() * z).cwiseProduct(inverse_scale);
  return theta;
}

namespace {

// The validation error of fold `i`: the truncated fit on the other folds' Gram matrices, judged
// on fold i's.
double fold_sse(const std::vector<Eigen::MatrixXd>& grams, std::size_t i) {
  Eigen::MatrixXd fit = Eigen::MatrixXd::Zero(grams[i].rows(), grams[i].cols());
  for (std::size_t j = 0; j < grams.size(); ++j)
    if (j != i) fit += grams[j];
  return sse_of_gram(grams[i], truncated_fit(fit, fit + grams[i]));
}

double folds_sse(const std::vector<Eigen::MatrixXd>& grams) {
  double sse = 0.0;
  for (std::size_t i = 0; i < grams.size(); ++i) sse += fold_sse(grams, i);
  return sse;
}

}  // namespace

double validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<Eigen::Index>& fit,
                      const std::vector<Eigen::Index>& check) {
  return fold_sse({augmented_gram(columns, y, check), augmented_gram(columns, y, fit)}, 0);
}

double cross_validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                            const TrainingFolds& folds) {
  std::vector<Eigen::MatrixXd> grams;
  for (const auto& fold : folds.folds) grams.push_back(augmented_gram(columns, y, fold));
  return folds_sse(grams);
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
  return folds_sse(grams);
}

}  // namespace imscal::eval
