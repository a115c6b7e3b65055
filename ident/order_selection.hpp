#pragma once
// Choice of the ARX orders (na, nb) and the dead time d of one joint over a grid, scored by
// AIC, BIC and the one-step prediction loss on hold-out validation data.
//
// Why a whole sweep costs little more than one fit:
//  * Every candidate is compared on the same regression rows k >= K (K = the largest lag of the
//    grid), so every candidate's normal equations are a sub-block of ONE lagged Gram matrix of
//    the largest lag set [y(k), y(k-1..k-na_max), u(k-d_min .. k-d_max-nb_max+1)]
//    (ident/arx_fit.hpp: built from lagged correlation sums with sliding updates, one pass over
//    the data). The validation data get a second Gram matrix of the same lag set.
//  * For each (d, nb) the columns are ordered [x_e(k-d) .. x_e(k-d-nx+1) for every further input,
//    u(k-d) .. u(k-d-nb+1), y(k-1) .. y(k-na_max)] and
//    the column-scaled block is Cholesky-factored once (L Lᵀ). Prefixes of this column order are
//    exactly the candidates (na = 0 .. na_max), and the Cholesky factor of a leading block is the
//    leading block of L (order recursion), so with z = L⁻¹ Φᵀy every
//    RSS(na) = yᵀy - Σ_{j < nb+na} z_j² comes from one factorisation; θ(na) is one triangular
//    back-substitution, and its validation loss is evaluated from the validation Gram entries
//    (yᵀy - 2θᵀΦᵀy + θᵀΦᵀΦθ) without touching the data again.
//    Cost: (d_max-d_min+1)·nb_max Cholesky factorisations of size ≤ nb_max + na_max.
//  * Numerical honesty: columns are scaled to unit norm; a pivot below min_relative_pivot of the
//    scaled diagonal marks that prefix and all longer ones as rank deficient (not chosen); the
//    chosen structure is refitted from the data with fit_arx (condition check, QR fallback, exact
//    residuals), on all the data (estimation and validation).
//
// Criteria with N estimation rows, p = na + nb (+ the further inputs' coefficients), V = RSS / N:
//   AIC = N ln V + 2p,   BIC = N ln V + p ln N,   validation = mean squared one-step error.
// BIC is the default: it is consistent (picks the true order with probability → 1 as N grows),
// AIC tends to over-fit.
//
// References (docs/references.md): [Akaike1974] (AIC), [Schwarz1978] (BIC), [Ljung1999].
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "ident/arx_fit.hpp"
#include "ident/arx_structure.hpp"

namespace imscal::ident {

struct OrderGrid {
  int na_min = 1, na_max = 32;
  int nb_min = 1, nb_max = 32;
  int dead_time_min = 0, dead_time_max = 8;
  // Coefficients of each further input (multi-input form; fixed, not swept: the further inputs
  // are the model torque, the direction of motion and the torque's sign, whose responses share
  // the poles of A(z)). The first as many as the data carry are used; each >= 1.
  std::array<int, kMaxExtraInputs> extra_taps{8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8};
};

enum class OrderCriterion { kAic, kBic, kValidation };

struct OrderSelectionOptions {
  OrderGrid grid;
  OrderCriterion criterion = OrderCriterion::kBic;
  // Used when no validation segments are given: the last fraction of every segment is held out
  // (0 disables the validation loss; then kValidation is refused).
  double validation_fraction = 0.3;
  // Smallest squared Cholesky pivot of the unit-diagonal (scaled) Gram block that is accepted:
  // below it the columns are numerically dependent (condition ≳ 1 / min_relative_pivot).
  double min_relative_pivot = 1e-12;
  ArxFitOptions final_fit;  // options of the refit of the chosen structure
};

// One point of the criterion curves.
struct OrderCandidate {
  ArxStructure structure;
  bool valid = false;  // false: rank deficient, not considered
  double loss = 0.0;   // V = RSS / N on the estimation rows
  double aic = 0.0;
  double bic = 0.0;
  double validation_loss = 0.0;  // mean squared one-step error on the validation rows (NaN: none)
};

struct OrderSelectionResult {
  ArxStructure chosen;
  OrderCriterion criterion = OrderCriterion::kBic;
  std::vector<OrderCandidate> candidates;  // every grid point, d outermost, then nb, then na
  std::size_t estimation_rows = 0;
  std::size_t validation_rows = 0;
  ArxFitResult final_fit;  // the chosen structure fitted on all the data
};

// The sweep alone, without the final fit (for callers that fit the chosen structure on other
// rows, e.g. ident/joint_identification.hpp, which fits each operating-point cell on its own rows).
struct OrderSweepResult {
  ArxStructure chosen;
  OrderCriterion criterion = OrderCriterion::kBic;
  std::vector<OrderCandidate> candidates;  // as OrderSelectionResult::candidates
  std::size_t estimation_rows = 0;
  std::size_t validation_rows = 0;
};
// estimation_gram: when given, receives the sweep's Gram matrix of the estimation rows (its lag
// set holds every candidate's lags; rows k >= the grid's largest lag), from which the chosen
// structure can be fitted on the same rows without another pass over the data
// (fit_arx(segments, structure, gram)).
OrderSweepResult sweep_arx_orders(std::span<const IoSegment> segments,
                                  const OrderSelectionOptions& options = {},
                                  std::span<const IoSegment> validation = {},
                                  LaggedGram* estimation_gram = nullptr);

// validation: separate validation runs; when empty, validation_fraction of every segment is
// held out instead. Throws std::invalid_argument for a bad grid or too little data.
OrderSelectionResult select_arx_order(std::span<const IoSegment> segments,
                                      const OrderSelectionOptions& options = {},
                                      std::span<const IoSegment> validation = {});

const char* to_string(OrderCriterion criterion);

}  // namespace imscal::ident
