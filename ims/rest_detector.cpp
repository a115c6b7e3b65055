#include "ims/rest_detector.hpp"

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"

namespace imscal::ims {
namespace {

// Per-sample angular rate [rad/s] and specific force [m/s^2].
struct Rates {
  std::vector<Eigen::Vector3d> gyro;
  std::vector<Eigen::Vector3d> acc;
  // Running sums of the increments and of time: sum_*[i] = over samples [0, i).
  std::vector<Eigen::Vector3d> sum_gyro, sum_acc;
  std::vector<double> sum_time;
  double mean_dt_s = 0.0;
};

Rates rates_of(const ImuSeries& imu) {
  Rates rates;
  const std::size_t n = imu.samples.size();
  rates.gyro.resize(n);
  rates.acc.resize(n);
  rates.sum_gyro.assign(n + 1, Eigen::Vector3d::Zero());
  rates.sum_acc.assign(n + 1, Eigen::Vector3d::Zero());
  rates.sum_time.assign(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const ImuSample& s = imu.samples[i];
    const double dt = i == 0 ? imu.nominal_dt_s : s.t_s - imu.samples[i - 1].t_s;
    if (!(dt > 0.0)) {
      throw InputError(imu.source, imu.first_data_line ? imu.first_data_line + i : 0, "t_s",
                       "time stamps must increase");
    }
    const bool increments = imu.quantity == ImuQuantity::kIncrements;
    rates.gyro[i] = increments ? Eigen::Vector3d(s.gyro / dt) : s.gyro;
    rates.acc[i] = increments ? Eigen::Vector3d(s.acc / dt) : s.acc;
    rates.sum_gyro[i + 1] = rates.sum_gyro[i] + rates.gyro[i] * dt;
    rates.sum_acc[i + 1] = rates.sum_acc[i] + rates.acc[i] * dt;
    rates.sum_time[i + 1] = rates.sum_time[i] + dt;
  }
  rates.mean_dt_s =
      n > 1 ? (imu.samples.back().t_s - imu.samples.front().t_s) / double(n - 1) : imu.nominal_dt_s;
  return rates;
}

// Mean rate and specific force over samples [first, last] and the 1-sigma of each axis of them
// at rest: white noise density^2 / T plus the quantisation residuals at both ends, LSB^2/6/T^2.
struct BlockMean {
  Eigen::Vector3d gyro, acc;
  double gyro_sigma = 0.0, acc_sigma = 0.0;
};

BlockMean block_mean(const Rates& rates, std::size_t first, std::size_t last,
                     const RestDetectorOptions& o) {
  const double T = rates.sum_time[last + 1] - rates.sum_time[first];
  const auto sigma = [T](double density, double lsb) {
    return std::sqrt(density * density / T + lsb * lsb / (6.0 * T * T));
  };
  return {(rates.sum_gyro[last + 1] - rates.sum_gyro[first]) / T,
          (rates.sum_acc[last + 1] - rates.sum_acc[first]) / T,
          sigma(o.gyro_noise_density_rad_per_sqrt_s, o.gyro_quantization_lsb_rad),
          sigma(o.acc_noise_density_m_s_per_sqrt_s, o.acc_quantization_lsb_m_s)};
}

// Whether the block differs from the reference by more than threshold_sigmas of their noise.
bool block_deviates(const BlockMean& block, const BlockMean& reference, double threshold_sigmas) {
  const double gyro_sigma = std::hypot(block.gyro_sigma, reference.gyro_sigma);
  const double acc_sigma = std::hypot(block.acc_sigma, reference.acc_sigma);
  return (block.gyro - reference.gyro).norm() > threshold_sigmas * gyro_sigma ||
         (block.acc - reference.acc).norm() > threshold_sigmas * acc_sigma;
}

// Trims the ends of a candidate rest [first, last] while a block of `block` samples at the end
// differs from the mean of the middle half of the candidate: the slow onsets and ends of smooth
// motions pass the window test but drift away from the resting signal.
void trim_run(const Rates& rates, std::size_t& first, std::size_t& last, std::size_t block,
              const RestDetectorOptions& o) {
  if (last - first + 1 < 4 * block) return;
  const std::size_t quarter = (last - first + 1) / 4;
  const BlockMean reference = block_mean(rates, first + quarter, last - quarter, o);
  while (last - first + 1 > block && block_deviates(block_mean(rates, last + 1 - block, last, o),
                                                    reference, o.threshold_sigmas)) {
    --last;
  }
  while (last - first + 1 > block && block_deviates(block_mean(rates, first, first + block - 1, o),
                                                    reference, o.threshold_sigmas)) {
    ++first;
  }
}

}  // namespace

RestDetection detect_rest(const ImuSeries& imu, const EarthModel& earth,
                          const RestDetectorOptions& options) {
  if (!(options.gyro_noise_density_rad_per_sqrt_s > 0.0) ||
      !(options.acc_noise_density_m_s_per_sqrt_s > 0.0)) {
    throw InputError(imu.source, 0, "noise density", "rest detection needs positive densities");
  }
  const Rates rates = rates_of(imu);
  const std::size_t n = imu.samples.size();
  const double dt = rates.mean_dt_s;
  const std::size_t half =
      std::max<std::size_t>(1, std::size_t(std::lround(options.window_s / dt / 2.0)));
  const std::size_t window = 2 * half + 1;
  const std::size_t edge_block =
      std::max<std::size_t>(1, std::size_t(std::lround(options.edge_block_s / dt)));
  if (n < window) {
    throw InputError(imu.source, 0, "samples", "record shorter than one rest-detection window");
  }
  // Per-sample noise of the rates: white part density / sqrt(dt); quantisation with the
  // residual carried makes each increment err by the difference of two residuals, uniform on
  // +-LSB/2 each: variance LSB^2 / 6.
  const auto per_sample_sigma = [dt](double density, double lsb) {
    return std::sqrt(density * density / dt + lsb * lsb / (6.0 * dt * dt));
  };
  const double sigma_gyro = per_sample_sigma(options.gyro_noise_density_rad_per_sqrt_s,
                                             options.gyro_quantization_lsb_rad);
  const double sigma_acc =
      per_sample_sigma(options.acc_noise_density_m_s_per_sqrt_s, options.acc_quantization_lsb_m_s);
  const double dof = 6.0 * double(window - 1);
  const double scatter_threshold = dof + options.threshold_sigmas * std::sqrt(2.0 * dof);
  // Noise of a magnitude of a window mean: sigma / sqrt(n) along the mean's direction.
  const double rate_tolerance = options.gyro_bias_bound_rad_s +
                                options.threshold_sigmas * sigma_gyro / std::sqrt(double(window));
  const double force_tolerance = options.acc_bias_bound_m_s2 +
                                 options.threshold_sigmas * sigma_acc / std::sqrt(double(window));
  const double earth_rate = earth.earth_rate_W().norm();
  const double gravity = earth.normal_gravity_magnitude();

  RestDetection detection;
  detection.at_rest.assign(n, false);
  // Window [first, first + window) for every first; marks all its samples when rest-like.
  for (std::size_t first = 0; first + window <= n; ++first) {
    Eigen::Vector3d mean_gyro = Eigen::Vector3d::Zero(), mean_acc = Eigen::Vector3d::Zero();
    for (std::size_t j = first; j < first + window; ++j) {
      mean_gyro += rates.gyro[j];
      mean_acc += rates.acc[j];
    }
    mean_gyro /= double(window);
    mean_acc /= double(window);
    if (std::abs(mean_gyro.norm() - earth_rate) > rate_tolerance ||
        std::abs(mean_acc.norm() - gravity) > force_tolerance) {
      continue;
    }
    double scatter = 0.0;
    for (std::size_t j = first; j < first + window; ++j) {
      scatter += (rates.gyro[j] - mean_gyro).squaredNorm() / (sigma_gyro * sigma_gyro) +
                 (rates.acc[j] - mean_acc).squaredNorm() / (sigma_acc * sigma_acc);
    }
    if (scatter > scatter_threshold) continue;
    std::fill(detection.at_rest.begin() + std::ptrdiff_t(first),
              detection.at_rest.begin() + std::ptrdiff_t(first + window), true);
  }

  for (std::size_t i = 0; i < n;) {
    if (!detection.at_rest[i]) {
      ++i;
      continue;
    }
    std::size_t last = i;
    while (last + 1 < n && detection.at_rest[last + 1]) ++last;
    const std::size_t run_end = last;
    std::size_t first = i;
    trim_run(rates, first, last, edge_block, options);
    std::fill(detection.at_rest.begin() + std::ptrdiff_t(i),
              detection.at_rest.begin() + std::ptrdiff_t(run_end + 1), false);
    RestInterval interval{first, last, imu.samples[first].t_s, imu.samples[last].t_s};
    if (interval.duration_s() >= options.min_rest_s) {
      detection.intervals.push_back(interval);
      std::fill(detection.at_rest.begin() + std::ptrdiff_t(first),
                detection.at_rest.begin() + std::ptrdiff_t(last + 1), true);
    }
    i = run_end + 1;
  }
  return detection;
}

}  // namespace imscal::ims
