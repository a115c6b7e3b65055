#include "eval/gap_validation.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

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

double validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
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
  // Each check row's prediction summed over the columns in their order, as a row's dot product
  // sums them, but column by column.
  Eigen::VectorXd predicted = Eigen::VectorXd::Zero(Eigen::Index(check.size()));
  for (Eigen::Index c = 0; c < p; ++c)
    for (std::size_t i = 0; i < check.size(); ++i) {
      const double term = columns(check[i], c) * theta[c];
      predicted[Eigen::Index(i)] = c == 0 ? term : predicted[Eigen::Index(i)] + term;
    }
  double sse = 0.0;
  for (std::size_t i = 0; i < check.size(); ++i) {
    const double r = y[std::size_t(check[i])] - predicted[Eigen::Index(i)];
    sse += r * r;
  }
  return sse;
}

double cross_validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                            const TrainingFolds& folds) {
  double sse = 0.0;
  for (std::size_t i = 0; i < folds.folds.size(); ++i)
    sse += validation_sse(columns, y, folds.complements[i], folds.folds[i]);
  return sse;
}

}  // namespace imscal::eval
