#pragma once
// Validation statistics of an identified ARX model, as system-identification tools report them:
//
//  * fit [%] = 100 (1 - ‖y - ŷ‖ / ‖y - mean(y)‖) (normalised RMSE fit) for the one-step-ahead
//    prediction and for the free-run simulation (100 = perfect, 0 = no better than the mean);
//  * residual whiteness: normalised autocorrelation ρ_e(τ), τ = 1..max_lag, against the band
//    ±z/√N (z = 2.58: 99 % for a white residual);
//  * input-residual independence: normalised cross-correlation ρ_eu(τ) = R_eu(τ)/√(R_e(0) R_u(0)),
//    R_eu(τ) = mean of e(k) u(k-τ), τ = -max_lag..max_lag, against ±z √(Σ_k ρ_e(k) ρ_u(k)) / √N
//    (k = -max_lag..max_lag): the asymptotic standard deviation of √N ρ_eu when e is white or
//    independent of u (Ljung, System Identification, 2nd ed., §16.6), so a coloured input does not
//    raise false alarms.
// Residual and input are demeaned before correlating. Samples are the rows k >= max_lag of every
// segment; lagged products never reach across a segment boundary.
//
// A test passes when (1) the number of lags outside the band is at most allowed_outside: the
// smallest count that a white residual exceeds with probability < α (binomial over the lags, as
// if independent; α = 1 % for z = 2.58), so a correct model is not failed whenever one of 25 lags
// strays, which the per-lag band alone would do ~22 % of the time; and (2) no lag exceeds the
// family-wise band (Šidák: per-lag level 1 − (1 − α)^(1/lags)), so one gross violation — a
// missing dead-time lag with correlation 0.9 — fails the test on its own. For a correct model
// each rule fails with probability below α.
//
// References (docs/references.md): [Ljung1999] (residual tests), [Sidak1967] (family-wise band).
#include <cstddef>
#include <span>
#include <vector>

#include "ident/arx_model.hpp"
#include "ident/arx_structure.hpp"

namespace imscal::ident {

struct CorrelationTest {
  std::vector<int> lags;
  std::vector<double> correlation;  // normalised, one per lag
  double band = 0.0;                // per-lag band: |correlation| <= band is inside
  double family_band = 0.0;         // no |correlation| may exceed this (family-wise level α)
  double max_abs_correlation = 0.0;
  int outside_count = 0;
  int allowed_outside = 0;
  bool passed = false;
};

struct ValidationOptions {
  int max_lag = 25;
  double band_z = 2.58;  // two-sided normal quantile of the band (2.58: 99 %)
};

struct ArxValidationReport {
  std::size_t sample_count = 0;  // N, rows k >= max_lag over all segments
  double one_step_fit_percent = 0.0;
  double simulation_fit_percent = 0.0;
  double residual_rms = 0.0;  // of the one-step residual [rad]
  CorrelationTest residual_whiteness;
  CorrelationTest input_residual;
};

// NRMSE fit in percent of estimate against measured (same size, at least 2 samples).
double fit_percent(std::span<const double> measured, std::span<const double> estimate);

// Residual autocorrelation test; residuals: one span per segment.
CorrelationTest residual_whiteness_test(const std::vector<std::span<const double>>& residuals,
                                        const ValidationOptions& options = {});

// Input-residual cross-correlation test; inputs[i] is aligned sample by sample with residuals[i].
CorrelationTest input_residual_test(const std::vector<std::span<const double>>& residuals,
                                    const std::vector<std::span<const double>>& inputs,
                                    const ValidationOptions& options = {});

// All of the above for a model on validation data (segments of separate runs). The simulation
// starts each segment from its first max_lag measured outputs.
ArxValidationReport validate_arx(const ArxModel& model, std::span<const IoSegment> segments,
                                 const ValidationOptions& options = {});

}  // namespace imscal::ident
