#pragma once
// The fits of the gap validation's folds (eval/gap_validation.hpp): each fold's columns fitted on
// the other folds' rows and judged on its own, from the folds' augmented Gram matrices
// (eval/gap_normal_equations.hpp).
//
// A fold fit must not extrapolate: a column nearly zero on the fit rows (a play's flank or a burst
// of motion that falls in the other fold) or a direction the fit rows barely determine would get a
// parameter of any size and carry it onto the check rows. So the fit is a truncated LS fit
// [Hansen1987]: the columns are scaled by their norms over the fit and the check rows together (a
// column's size is known on every row; only the gap on the check rows is withheld), and the
// eigen-directions of the scaled fit Gram matrix below 1 / kMaxGramCondition of the largest
// eigenvalue are left out (they predict nothing on the check rows). On well-determined columns it
// is the LS fit.
//
// A fold fit also keeps the candidate's physical bound (eval/gap_bounds.hpp: the level w^T theta,
// w the LS coefficient of the modelled gap on the effect's static signal over the fit rows, at
// least `lower`): a fit that breaks it is refitted with it active within the kept directions,
// theta = theta_t + P w (lower - w^T theta_t) / (w^T P w), P the truncated pseudo-inverse
// ([LawsonHanson1974], ch. 20). A shape whose fold fits are only good with an unphysical size is
// judged as the bounded final fit would be.
//
// References (docs/references.md): [Hansen1987], [LawsonHanson1974].
#include <Eigen/Core>
#include <vector>

namespace imscal::eval {

// A fold fit's physical bound: weights^T theta >= lower. Empty weights: unbounded.
struct FoldBound {
  Eigen::VectorXd weights;
  double lower = 0.0;
};

// The truncated, bounded LS fit held in the augmented Gram matrix `fit` (lower triangle) with the
// columns scaled by `scale` (their norms over the fit and check rows; a zero entry: a zero
// column, left out).
Eigen::VectorXd truncated_fit(const Eigen::MatrixXd& fit, const Eigen::VectorXd& scale,
                              const FoldBound& bound);

// The validation error summed over the folds, from each fold's augmented Gram matrix `grams`
// (lower triangle) and each fold fit's bound (`bounds`: one per fold, or empty: none).
double folds_validation_sse(const std::vector<Eigen::MatrixXd>& grams,
                            const std::vector<FoldBound>& bounds);

// The level weights of each fold fit (eval/gap_bounds.hpp) from each fold's sums over its rows of
// u x_c (`cross`, over the parameters) and u² (`uu`): the fit rows' sums, divided. Zero where u
// is zero on the fit rows.
std::vector<FoldBound> fold_bounds(const std::vector<Eigen::VectorXd>& cross,
                                   const std::vector<double>& uu, double lower);

}  // namespace imscal::eval
