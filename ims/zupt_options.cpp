#include "ims/zupt_options.hpp"

#include <cmath>

namespace imscal::ims {
namespace {

struct MergedGaussMarkov {
  double sigma = 0.0;
  double correlation_time_s = std::numeric_limits<double>::infinity();
};

MergedGaussMarkov merge(const std::vector<GaussMarkovTerm>& terms) {
  double variance = 0.0, drive_psd = 0.0;
  for (const GaussMarkovTerm& term : terms) {
    variance += term.sigma * term.sigma;
    drive_psd += 2.0 * term.sigma * term.sigma / term.correlation_time_s;
  }
  MergedGaussMarkov merged;
  merged.sigma = std::sqrt(variance);
  if (drive_psd > 0.0) merged.correlation_time_s = 2.0 * variance / drive_psd;
  return merged;
}

}  // namespace

ZuptOptions zupt_options_from_spec(const SensorSpec& spec) {
  ZuptOptions options;
  options.gyro_noise_density_rad_per_sqrt_s = spec.gyro.white_noise_density;
  options.acc_noise_density_m_s_per_sqrt_s = spec.acc.white_noise_density;
  options.gyro_quantization_lsb_rad = spec.gyro.quantization_lsb;
  options.acc_quantization_lsb_m_s = spec.acc.quantization_lsb;
  const MergedGaussMarkov gyro = merge(spec.gyro.bias_instability);
  const MergedGaussMarkov acc = merge(spec.acc.bias_instability);
  options.gyro_bias_instability_rad_s = gyro.sigma;
  options.gyro_bias_correlation_time_s = gyro.correlation_time_s;
  options.acc_bias_instability_m_s2 = acc.sigma;
  options.acc_bias_correlation_time_s = acc.correlation_time_s;
  // The in-run part starts from its stationary distribution, independent of the turn-on bias.
  options.initial_gyro_bias_sigma_rad_s = std::hypot(spec.gyro.turn_on_bias_sigma, gyro.sigma);
  options.initial_acc_bias_sigma_m_s2 = std::hypot(spec.acc.turn_on_bias_sigma, acc.sigma);
  return options;
}

}  // namespace imscal::ims
