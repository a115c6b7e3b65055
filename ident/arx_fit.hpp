#pragma once
// Least-squares fit of one joint's ARX model (ident/arx_structure.hpp) from one or more data
// segments (separate runs; no regressor crosses a segment boundary).
//
// Regression: y(k) = φ(k)ᵀ θ + e(k),  φ(k) = [-y(k-1) .. -y(k-na), u(k-d) .. u(k-d-nb+1),
// x_e(k-d) .. x_e(k-d-nx+1) for every further input e], θ = [a_1..a_na, b_0..b_{nb-1}, c],
// rows k = max_lag .. n-1 of every segment (or k = first_row .. n-1 of a given Gram matrix).
//
// How it is solved (numerically sound and fast on millions of samples):
//  1. The Gram matrix [Φ y]ᵀ[Φ y] is built without forming Φ. Its entries are lagged correlation
//     sums Σ_k s1(k-l1) s2(k-l2); one row of them per signal pair is computed by blocked dot
//     products over the data (one cache-friendly pass), the rest follow by the sliding update
//     E(l1+1, l2+1) = E(l1, l2) + s1(k0-1-l1) s2(k0-1-l2) - s1(n-1-l1) s2(n-1-l2).
//     Cost ≈ 2 (na + nb) dot products of the segment length plus O(p²) sliding updates per
//     segment (order 32 on 1 M samples: ~75 ms CPU for the whole fit, bench/bench_arx.cpp).
//  2. The columns are scaled to unit norm and the condition number κ of the scaled Gram matrix
//     is computed (symmetric eigenvalues, p ≤ ~200 so this is cheap). Then, by κ:
//       κ ≤ max_condition_normal_equations (1e10): Cholesky of the scaled normal equations and
//         one refinement step (3.);
//       κ ≤ max_condition_refined_normal_equations (1e14): the same Cholesky, with the refinement
//         iterated until its step reaches the rounding level of a backward-stable solver;
//       otherwise (or when that refinement stops contracting): a streamed Householder QR of
//         [Φ y] in row blocks (R of the rows so far stacked on the next block, never the whole Φ
//         in memory; ≈ 2 N p² flops, ~25× slower than the Cholesky path at order 32 and ~100×
//         at the 185 coefficients of the default inverse model).
//  3. Iterative refinement θ += (ΦᵀΦ)⁻¹ Φᵀr with r = y - Φθ computed from the data (one blocked
//     pass, O(N p)). Why it may replace the QR up to κ = 1e14: with the residual taken from the
//     data, each step shrinks the solution's error by about κ × 1.1e-16 (the Cholesky factor's
//     relative error; 0.011 at 1e14), and the iteration's fixed point is Φ⁺ applied to the
//     rounding of r, ‖δθ‖ ≲ √κ ε ‖θ‖ in the scaled basis: the accuracy of a QR solution
//     (Björck, Numerical Methods for Least Squares Problems, 1996, sec. 2.9; Higham, Accuracy
//     and Stability of Numerical Algorithms, 2002, ch. 20). At κ ≈ 1e11-4e13, the default inverse
//     model's regressors (60 lags of a smooth model torque), 2-3 steps get there (measured).
//  4. The residual sum of squares comes from the data, so that it and σ² = RSS / (N - p) do not
//     suffer from the cancellation of yᵀy - θᵀΦᵀy: the last refinement pass gives ‖r‖² of the θ
//     before its step δ, and RSS(θ + δ) = ‖r‖² - 2 δᵀΦᵀr + δᵀΦᵀΦδ adds only terms of the step's
//     small size (no further pass; one pass when no refinement step was taken). The parameter
//     covariance is σ² (ΦᵀΦ)⁻¹ (standard deviations = sqrt of its diagonal).
//
// The model has no constant term (as in the paper): signals with a large offset and little
// motion make the regressors nearly collinear; the condition number in the result shows it.
//
// References (docs/references.md): [Ljung1999] (least squares), [Bjorck1996], [Higham2002]
// (refinement, accuracy of least-squares solvers).
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
  kAuto,             // by the scaled condition: normal equations, refined ones, or QR
  kNormalEquations,  // always Cholesky (throws if the Gram matrix is not positive definite)
  kQr,               // always the streamed Householder QR
  // Cholesky with the refinement iterated to convergence (falls back to QR when it does not
  // contract, e.g. at κ ≈ 6e17, tests/ident/test_arx_fit.cpp)
  kRefinedNormalEquations,
};

const char* to_string(LeastSquaresMethod method);

struct ArxFitOptions {
  LeastSquaresMethod method = LeastSquaresMethod::kAuto;
  // Largest condition number of the column-scaled Gram matrix for which kAuto trusts the normal
  // equations: their relative error is about condition × 1.1e-16, so 1e10 keeps ~6 digits in
  // the worst case (QR keeps about twice as many digits as the normal equations).
  double max_condition_normal_equations = 1e10;
  // Largest scaled condition for which kAuto takes the iterated refinement (step 3 of the header)
  // instead of the QR: a step then contracts the error by ≤ 1e14 × 1.1e-16 ≈ 0.011.
  double max_condition_refined_normal_equations = 1e14;
  // Steps of iterative refinement after the solve (either method): θ += (ΦᵀΦ)⁻¹ Φᵀr with the
  // residual r recomputed from the data (one pass each). One step brings the normal-equation
  // solution to QR-level accuracy for condition numbers up to max_condition_normal_equations,
  // and takes the rounding of the streamed QR out of a QR solution.
  int refinement_steps = 1;
  // The iterated refinement (kRefinedNormalEquations): at most this many steps; it has converged
  // when a step is below 8 √κ ε of θ (scaled basis), the rounding level of a backward-stable
  // solver, and it is given up for the QR when a step is not at most half the one before.
  int max_refinement_steps = 12;
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
  int refinement_steps = 0;  // refinement steps taken (each one pass over the data)
};

// Throws std::invalid_argument for a bad structure, mismatched segment sizes or fewer rows than
// parameters, std::runtime_error if the regressors are rank deficient (no excitation).
ArxFitResult fit_arx(std::span<const IoSegment> segments, const ArxStructure& structure,
                     const ArxFitOptions& options = {});

// The same fit from the Gram matrix of these segments built already (e.g. by an order sweep,
// ident/order_selection.hpp, whose lag set holds every candidate's): its rows k >= first_row of
// every segment are the regression rows. Throws std::invalid_argument when its lag set does not
// hold the structure's lags or first_row < structure.max_lag().
ArxFitResult fit_arx(std::span<const IoSegment> segments, const ArxStructure& structure,
                     const LaggedGram& gram, const ArxFitOptions& options = {});

// Residual sum of squares of θ = [a; b] on the rows k >= structure.max_lag() of every segment,
// computed from the data (one pass).
double residual_sum_of_squares(std::span<const IoSegment> segments, const ArxStructure& structure,
                               const Eigen::VectorXd& theta);

}  // namespace imscal::ident
