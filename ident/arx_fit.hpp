#pragma once
// Least-squares fit of one joint's ARX model (ident/arx_structure.hpp) from one or more data
// segments (separate runs; no regressor crosses a segment boundary).
//
// Regression: y(k) = φ(k)ᵀ θ + e(k),  φ(k) = [-y(k-1) .. -y(k-na), u(k-d) .. u(k-d-nb+1),
// x_e(k-d) .. x_e(k-d-nx+1) for every further input e], θ = [a_1..a_na, b_0..b_{nb-1}, c],
// rows k = max_lag .. n-1 of every segment.
//
// How it is solved (numerically sound and fast on millions of samples):
//  1. The Gram matrix [Φ y]ᵀ[Φ y] is built without forming Φ. Its entries are lagged correlation
//     sums Σ_k s1(k-l1) s2(k-l2); one row of them per signal pair is computed by blocked dot
//     products over the data (one cache-friendly pass), the rest follow by the sliding update
//     E(l1+1, l2+1) = E(l1, l2) + s1(k0-1-l1) s2(k0-1-l2) - s1(n-1-l1) s2(n-1-l2).
//     Cost ≈ 2 (na + nb) dot products of the segment length plus O(p²) sliding updates per
//     segment (order 32 on 1 M samples: ~75 ms CPU for the whole fit, bench/bench_arx.cpp).
//  2. The columns are scaled to unit norm and the condition number of the scaled Gram matrix
//     is computed (symmetric eigenvalues, p ≤ ~100 so this is cheap). When it is at most
//     ArxFitOptions::max_condition_normal_equations the scaled normal equations are solved by
//     Cholesky; otherwise (or on request) a streamed Householder QR of [Φ y] in row blocks is
//     used (R of the rows so far stacked on the next block, never the whole Φ in memory;
//     ≈ 2 N p² flops, ~25× slower than the Cholesky path at order 32).
//  3. After a Cholesky solve, one step of iterative refinement θ += (ΦᵀΦ)⁻¹ Φᵀr with r = y - Φθ
//     computed from the data (one blocked pass) removes most of the normal equations' extra error.
//  4. The residuals are recomputed from the data (one pass), so the residual sum of squares and
//     σ² = RSS / (N - p) do not suffer from the cancellation of yᵀy - θᵀΦᵀy, and the parameter
//     covariance is σ² (ΦᵀΦ)⁻¹ (standard deviations = sqrt of its diagonal).
//
// The model has no constant term (as in the paper): signals with a large offset and little
// motion make the regressors nearly collinear; the condition number in the result shows it.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <span>

#include "ident/arx_model.hpp"
#include "ident/arx_structure.hpp"

namespace imscal::ident {

// The lags held by a LaggedGram: outputs y(k-0) .. y(k-output_lag_max) (lag 0 is the regression
// target), inputs u(k-input_lag_min) .. u(k-input_lag_max) and, for each of extra_count further
// inputs, x_e(k-input_lag_min) .. x_e(k-extra_lag_max).
struct LagSet {
  int output_lag_max = 0;
  int input_lag_min = 0;
  int input_lag_max = 0;
  int extra_count = 0;
  std::array<int, kMaxExtraInputs> extra_lag_max{};  // of each further input (>= input_lag_min)

  int output_columns() const { return output_lag_max + 1; }
  int input_columns() const { return input_lag_max - input_lag_min + 1; }
  int extra_columns(int e) const { return extra_lag_max[std::size_t(e)] - input_lag_min + 1; }
  int columns() const {
    int sum = output_columns() + input_columns();
    for (int e = 0; e < extra_count; ++e) sum += extra_columns(e);
    return sum;
  }
  // Column of y(k-lag) / u(k-lag) / x_e(k-lag) in LaggedGram::gram.
  int output_column(int lag) const { return lag; }
  int input_column(int lag) const { return output_columns() + lag - input_lag_min; }
  int extra_column(int e, int lag) const {
    int first = output_columns() + input_columns();
    for (int i = 0; i < e; ++i) first += extra_columns(i);
    return first + lag - input_lag_min;
  }
  int max_lag() const {
    int m = output_lag_max > input_lag_max ? output_lag_max : input_lag_max;
    for (int e = 0; e < extra_count; ++e) m = std::max(m, extra_lag_max[std::size_t(e)]);
    return m;
  }
};

// Σ over the rows k = first_row .. n-1 of every segment of c(k) c(k)ᵀ, where c(k) holds the
// lagged samples of LagSet in its column order.
struct LaggedGram {
  LagSet lags;
  int first_row = 0;
  std::size_t row_count = 0;  // rows summed over all segments
  Eigen::MatrixXd gram;       // symmetric, lags.columns() square
};

// first_row must be >= lags.max_lag(); segments shorter than first_row + 1 add nothing.
LaggedGram build_lagged_gram(std::span<const IoSegment> segments, const LagSet& lags,
                             int first_row);

enum class LeastSquaresMethod {
  kAuto,             // Cholesky of the scaled normal equations, QR if too ill-conditioned
  kNormalEquations,  // always Cholesky (throws if the Gram matrix is not positive definite)
  kQr,               // always the streamed Householder QR
};

struct ArxFitOptions {
  LeastSquaresMethod method = LeastSquaresMethod::kAuto;
  // Largest condition number of the column-scaled Gram matrix for which kAuto trusts the normal
  // equations: their relative error is about condition × 1.1e-16, so 1e10 keeps ~6 digits in
  // the worst case (QR keeps about twice as many digits as the normal equations).
  double max_condition_normal_equations = 1e10;
  // Steps of iterative refinement after the solve (either method): θ += (ΦᵀΦ)⁻¹ Φᵀr with the
  // residual r recomputed from the data (one pass each). One step brings the normal-equation
  // solution to QR-level accuracy for condition numbers up to the limit above, and takes the
  // rounding of the streamed QR out of a QR solution.
  int refinement_steps = 1;
  double sample_time_s = 0.002;
};

struct ArxFitResult {
  ArxModel model;
  Eigen::VectorXd parameter_std;  // σ of θ = [a; b; c]
  Eigen::MatrixXd covariance;     // of θ
  double residual_sum_of_squares = 0.0;
  double residual_variance = 0.0;  // RSS / (N - p), the estimate of σ_e²
  std::size_t row_count = 0;       // N, regression rows over all segments
  double scaled_condition = 0.0;   // condition number of the column-scaled ΦᵀΦ
  LeastSquaresMethod method_used = LeastSquaresMethod::kNormalEquations;
};

// Throws std::invalid_argument for a bad structure, mismatched segment sizes or fewer rows than
// parameters, std::runtime_error if the regressors are rank deficient (no excitation).
ArxFitResult fit_arx(std::span<const IoSegment> segments, const ArxStructure& structure,
                     const ArxFitOptions& options = {});

// Residual sum of squares of θ = [a; b] on the rows k >= structure.max_lag() of every segment,
// computed from the data (one pass).
double residual_sum_of_squares(std::span<const IoSegment> segments, const ArxStructure& structure,
                               const Eigen::VectorXd& theta);

}  // namespace imscal::ident
