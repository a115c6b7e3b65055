#pragma once
// Least squares through the normal equations of the column-scaled regressors, for the many small
// fits of the gap diagnosis (eval/gap_validation.hpp, eval/gap_candidates.hpp). The augmented
// Gram matrix A = [X y]^T [X y] over a set of rows is a few matrix products over runs of
// consecutive rows (no copy of the rows), and the Gram matrices of disjoint row sets add: a
// cross-validation sums each fit's rows from one Gram matrix per fold, and a fold's validation
// error is the quadratic form [-theta; 1]^T A_fold [-theta; 1].
//
// The normal equations square the columns' condition number (the error of theta grows as
// eps kappa², against eps kappa for a QR, Higham 2002 ch. 20). A solution is only given when the
// condition number of the scaled Gram matrix is at most kMaxGramCondition (kappa(X) <= 1e4: theta
// within ~1e-8 of the QR's, relative); otherwise the final fits (eval/gap_candidates.hpp) fall back
// to their column-pivoted QR, which also handles a rank-deficient set of columns, and the
// validation's fold fits are truncated (eval/gap_fold_fit.hpp).
//
// References (docs/references.md): [Higham2002], [Bjorck1996].
#include <Eigen/Core>
#include <optional>
#include <vector>

namespace imscal::eval {

// Largest condition number of the column-scaled Gram matrix the normal equations are solved for.
inline constexpr double kMaxGramCondition = 1e8;

// Adds [x y]^T [x y] over the rows `rows` (ascending sample indices) to `a` ((p+1) x (p+1), p =
// x.cols(); the last row and column belong to y; only the lower triangle is written).
void add_augmented_gram(const Eigen::MatrixXd& x, const std::vector<double>& y,
                        const std::vector<Eigen::Index>& rows, Eigen::MatrixXd& a);

// [x y]^T [x y] over the rows `rows` (lower triangle).
Eigen::MatrixXd augmented_gram(const Eigen::MatrixXd& x, const std::vector<double>& y,
                               const std::vector<Eigen::Index>& rows);

// The LS solution of the normal equations held in the augmented Gram matrix `a` (lower triangle)
// with the columns scaled to unit norm, or nullopt when the scaled Gram matrix's condition number
// exceeds kMaxGramCondition or a column is zero on the rows. `with_inverse`: also the inverse of
// the scaled Gram matrix (the parameters' covariance up to the residual variance).
struct GramSolution {
  Eigen::VectorXd theta;                // unscaled parameters
  Eigen::VectorXd scale;                // the columns' norms on the rows
  Eigen::MatrixXd inverse_scaled_gram;  // (D^-1 X^T X D^-1)^-1, D = diag(scale)
};
std::optional<GramSolution> solve_normal_equations(const Eigen::MatrixXd& a,
                                                   bool with_inverse = false);

// Sum of squared residuals y - X theta over the rows of `a`: [-theta; 1]^T a [-theta; 1] (lower
// triangle), not below 0.
double sse_of_gram(const Eigen::MatrixXd& a, const Eigen::VectorXd& theta);

}  // namespace imscal::eval
