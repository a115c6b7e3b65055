#include "ident/arx_frequency_response.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace imscal::ident {

FrequencyResponse frequency_response(const ArxModel& model, std::span<const double> frequency_hz) {
  const double sample_time_s = model.sample_time_s();
  const double nyquist_hz = 0.5 / sample_time_s;
  const int dead_time = model.structure().dead_time;
  FrequencyResponse response;
  for (double f : frequency_hz) {
    // A tiny relative slack so that a grid ending exactly at Nyquist passes despite rounding.
    if (!(f >= 0.0 && f <= nyquist_hz * (1.0 + 1e-12)))
      throw std::invalid_argument("frequency_response: " + std::to_string(f) +
                                  " Hz is outside [0, Nyquist = " + std::to_string(nyquist_hz) +
                                  " Hz]");
    const double omega_t = 2.0 * std::numbers::pi * f * sample_time_s;  // rad per sample
    const std::complex<double> z_inv = std::polar(1.0, -omega_t);
    std::complex<double> a_sum = 1.0, b_sum = 0.0, power = 1.0;  // power = z^-k
    for (Eigen::Index k = 0; k < model.b().size(); ++k) {
      b_sum += model.b()[k] * power;
      power *= z_inv;
    }
    power = z_inv;
    for (Eigen::Index k = 0; k < model.a().size(); ++k) {
      a_sum += model.a()[k] * power;
      power *= z_inv;
    }
    const std::complex<double> delay = std::polar(1.0, -omega_t * dead_time);
    const std::complex<double> joint = delay * b_sum / a_sum;
    response.frequency_hz.push_back(f);
    response.joint.push_back(joint);
    response.joint_error.push_back(delay - joint);
  }
  return response;
}

std::vector<double> log_spaced_frequencies_hz(double f_min_hz, double nyquist_hz, int n) {
  if (!(f_min_hz > 0.0 && nyquist_hz > f_min_hz && n >= 2))
    throw std::invalid_argument("log_spaced_frequencies_hz: need 0 < f_min < Nyquist, n >= 2");
  std::vector<double> f(static_cast<std::size_t>(n));
  const double ratio = std::log(nyquist_hz / f_min_hz);
  for (int i = 0; i < n; ++i) f[std::size_t(i)] = f_min_hz * std::exp(ratio * i / (n - 1));
  f.back() = nyquist_hz;
  return f;
}

}  // namespace imscal::ident
