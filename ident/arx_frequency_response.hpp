#pragma once
// Frequency response of an identified joint model (paper, equation 2) on the unit circle,
// z = exp(j 2π f T):
//
//   G(f)  = z^-d B(z^-1) / A(z^-1)    desired angle q_d -> reached angle q̂ (the joint's dynamics)
//   E(f)  = z^-d - G(f)               desired angle q_d -> joint error Δq̂ = q_d(k-d) - q̂(k)
//
// with A(z^-1) = 1 + a_1 z^-1 + ... + a_na z^-na and B(z^-1) = b_0 + ... + b_{nb-1} z^-(nb-1).
// For a stable model this is the steady-state gain and phase for a sinusoidal desired angle.
#include <complex>
#include <span>
#include <vector>

#include "ident/arx_model.hpp"

namespace imscal::ident {

struct FrequencyResponse {
  std::vector<double> frequency_hz;
  std::vector<std::complex<double>> joint;        // G(f): q_d -> q̂
  std::vector<std::complex<double>> joint_error;  // E(f): q_d -> Δq̂
};

// Frequencies must lie in [0, Nyquist] = [0, 1 / (2 T)] (std::invalid_argument otherwise).
FrequencyResponse frequency_response(const ArxModel& model, std::span<const double> frequency_hz);

// n log-spaced frequencies from f_min to the Nyquist frequency of the model (n >= 2, f_min > 0).
std::vector<double> log_spaced_frequencies_hz(double f_min_hz, double nyquist_hz, int n);

}  // namespace imscal::ident
