#pragma once
// The model-error model of the gap ("where" by frequency; Ljung, "Model validation and
// model error modeling", 1999): per joint, a linear FIR model from the input of the error model,
// the desired joint angle q_d, to the gap g,
//
//   g(k) = c + sum_{i=0}^{n-1} b_i q_d(k - i m)        (m: tap spacing in samples)
//
// fitted by least squares on the training rows (SVD, so that input directions the motion does
// not excite keep an enormous variance; inflated for the coloured residual as
// eval/gap_candidates.hpp fit_columns does), with its frequency response
//
//   G(f) = sum_i b_i exp(-j 2 pi f i m T)               [rad of gap per rad of q_d]
//
// and a confidence band from the parameter covariance (first order: var |G| = grad^T Cov grad).
// Where the band excludes zero, the gap depends linearly on the motion at that frequency: an
// unmodelled dynamic effect of the error model. Where it includes zero at every frequency, the
// gap is not a linear function of the input (noise, or a nonlinear effect such as backlash,
// which the candidates test). The held-out share of the gap it explains says how much that is.
//
// References (docs/references.md): [Ljung1999MEM] (model error modelling).
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace imscal::eval {

struct ModelErrorOptions {
  std::size_t taps = 12;         // FIR length n
  std::size_t tap_spacing = 5;   // m [samples]: 10 ms at 2 ms, 120 ms memory
  std::size_t frequencies = 24;  // log-spaced points of the response, 0.1 Hz .. 1/(2 m T)
  double band_sigma = 2.0;       // half-width of the confidence band [sigma] (~95 %)
};

struct FrequencyPoint {
  double frequency_hz = 0.0;
  double magnitude = 0.0;           // |G| [rad/rad]
  double phase_rad = 0.0;           // arg G
  double magnitude_sigma = 0.0;     // 1 sigma of |G| (first order)
  double lower = 0.0, upper = 0.0;  // |G| -+ band_sigma sigma, lower clipped at 0
  // G != 0 at this frequency: chi² of (Re G, Im G) under their covariance above the level
  // (0.01 for one frequency; in a fitted model's grid 0.01 shared over its frequencies).
  bool significant = false;
};

struct ModelErrorModel {
  double tap_period_s = 0.0;        // m T
  Eigen::VectorXd taps, tap_sigma;  // b_i and 1 sigma [rad/rad]
  Eigen::MatrixXd tap_covariance;   // of b (inflated as the sigma)
  double offset_rad = 0.0;          // c
  std::vector<FrequencyPoint> response;
  double heldout_explained_percent = 0.0;  // 100 (1 - RMS(g - model) / RMS(g)) on held-out rows
  bool significant = false;                // some frequency's band excludes zero
};

// Fits the model on the rows flagged `training`, judges it on the others (held-out share; 0 when
// there are none). The lags restart at every run (rows whose lags reach before their run's start
// are left out of the fit). Throws std::invalid_argument on size mismatches.
ModelErrorModel fit_model_error_model(const std::vector<double>& input,
                                      const std::vector<double>& gap,
                                      const std::vector<std::pair<std::size_t, std::size_t>>& runs,
                                      double cycle_s, const std::vector<bool>& training,
                                      const ModelErrorOptions& options = {});

// chi² of (Re G(f), Im G(f)) of FIR taps b with covariance Cov (2 dof; 1 dof where Im G is 0).
double response_chi2(const Eigen::VectorXd& taps, const Eigen::MatrixXd& covariance,
                     double tap_period_s, double frequency_hz);

// The response of FIR taps b (spacing tap_period_s) at f, with its first-order magnitude sigma.
FrequencyPoint fir_response(const Eigen::VectorXd& taps, const Eigen::MatrixXd& covariance,
                            double tap_period_s, double frequency_hz, double band_sigma);

}  // namespace imscal::eval
