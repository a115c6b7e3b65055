#pragma once
// The measurement as a candidate explanation of the whole gap: is the gap within what the IMS
// chain's own error explains? The chain's error has two parts (eval/gap_measurement_prior.hpp):
// the frames' and sensor errors, whose joint-space signatures are known (the columns a_jk of
// GapSignals::ImsChainColumns: mounting, gyro bias, world-fixed rate, and q̇_d for the clock
// offset) with their covariance P from the calibration, and the smoother's noise floor sigma_j.
//
//   fit       p = argmin  sum_j sum_k (g_jk - a_jk p)^2 / (sigma_j^2 tau_j) + p^T P^-1 p
//             on the training rows (MAP with the calibration's covariance as prior; tau_j the
//             gap's integrated autocorrelation time: its samples are not independent), solved in
//             the prior's whitened coordinates p = V L^(1/2) z (P = V L V^T), |z|^2 = p^T P^+ p
//   per joint chi2_j = sum_k r_jk^2 / sigma_j^2 / tau_j over the held-out rows (r the gap less the
//             fitted measurement), with dof_j = m_j / tau_j effective samples
//   prior     chi2_p = |z|^2 with rank(P) degrees of freedom (the frames fitted beyond their
//             sigma would be a calibration that does not hold)
//   within    no test rejects at the Šidák-corrected level 1 - (1 - alpha)^(1/tests): a gap
//             concentrated in one joint is not hidden by the others
//   expected  RMS_j = sqrt(sigma_j^2 + mean_k a_jk P a_jk^T): what the measurement alone leaves
//
// Upper tail of chi2 by the Wilson-Hilferty cube-root normal approximation (relative error of the
// tail below 1e-2 for dof >= 3 down to p ~ 1e-6, far below the levels used).
//
// References (docs/references.md): [WilsonHilferty1931].
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/gap_signals.hpp"

namespace imscal::eval {

struct MeasurementJoint {
  double gap_rms_rad = 0.0;       // held-out
  double residual_rms_rad = 0.0;  // held-out, after the fitted measurement
  double expected_rms_rad = 0.0;  // what the measurement explains (floor and frames)
  double noise_floor_rad = 0.0;
  double chi2 = 0.0, dof = 0.0, p_value = 1.0;
};

struct MeasurementBudget {
  bool known = false;   // a noise floor was given
  bool frames = false;  // with the frames' covariance (else the floor alone)
  std::vector<MeasurementJoint> joints;
  std::vector<std::string> parameter_names;
  std::vector<double> parameters, prior_sigma;  // the fitted chain errors and their prior 1-sigma
  double prior_chi2 = 0.0, prior_dof = 0.0, prior_p_value = 1.0;
  double chi2 = 0.0, dof = 0.0, p_value = 1.0;  // all tests summed
  double corrected_alpha = 0.0;
  bool within = false;
  std::string source;
};

// Upper tail P(X >= chi2) of a chi-squared variable with `dof` degrees of freedom (> 0).
double chi2_upper_tail(double chi2, double dof);

// Integrated autocorrelation time of x on the rows `rows` (consecutive rows only), summed up to
// the first non-positive correlation or `max_lag` lags; >= 1.
double integrated_autocorrelation_time(const std::vector<double>& x,
                                       const std::vector<std::size_t>& rows, std::size_t max_lag);

// The budget of s.measurement (known == false without a floor); training rows as the diagnosis's,
// which alternate in blocks of block_s [s] (the longest lag of the autocorrelation times).
MeasurementBudget measurement_budget(const GapSignals& s, const std::vector<bool>& training,
                                     double block_s, double alpha);

// "The gap is within what the measurement explains: ..." or "... beyond ...", with the figures.
std::string measurement_in_words(const GapSignals& s, const MeasurementBudget& b);
nlohmann::json measurement_json(const GapSignals& s, const MeasurementBudget& b);

}  // namespace imscal::eval
