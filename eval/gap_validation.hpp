#pragma once
// The cross-validation inside the training rows that chooses the nonlinear shape of a candidate
// effect (eval/gap_candidates.hpp) and the joints its coupling reaches (eval/gap_coupling.hpp):
// the training rows are cut into chunks of consecutive training rows, dealt to the folds in
// turn; a set of columns is fitted on all folds but one and judged on that one, for each fold.
// Unlike a BIC it needs no count of independent rows (the residuals are coloured), and it sees
// whether a shape carries over to other motion.
#include <Eigen/Core>
#include <vector>

#include "eval/gap_signals.hpp"

namespace imscal::eval {

struct TrainingFolds {
  std::vector<std::vector<Eigen::Index>> folds;  // sample indices per fold
  bool usable() const { return folds.size() > 1 && !folds.back().empty(); }
};
TrainingFolds training_folds(const GapSignals& signals, const std::vector<bool>& training);

// Sum of squared residuals on the rows `check` of the fold fit of columns to y on the rows `fit`
// (parameters only: no sigma is needed to choose a shape): the truncated LS fit of
// eval/gap_fold_fit.hpp, the columns scaled over the fit and check rows.
double validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<Eigen::Index>& fit, const std::vector<Eigen::Index>& check);

// The validation error summed over the folds: each fold's Gram matrix is formed once and the
// folds' fits are summed from them (eval/gap_fold_fit.hpp).
double cross_validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                            const TrainingFolds& folds);

// A shape's physical bound in its fold fits (CandidateShape::level_signal and level_lower, on the
// shape's own joint; eval/gap_bounds.hpp). No signal: unbounded.
struct ValidationLevel {
  std::size_t joint = 0;
  const Eigen::VectorXd* signal = nullptr;
  double lower = 0.0;
};

// The same for one parameter vector over several joints (the rows of every joint that has
// columns, eval/gap_joint_stack.hpp; the folds' rows on each), each fold fit within `level`.
double cross_validation_sse(const std::vector<Eigen::MatrixXd>& columns,
                            const std::vector<std::vector<double>>& y, const TrainingFolds& folds,
                            const ValidationLevel& level = {});

}  // namespace imscal::eval
