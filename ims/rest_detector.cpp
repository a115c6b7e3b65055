#include "ims/rest_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/input_error.hpp"

namespace imscal::ims {
namespace {

// Angular rate [rad/s] and specific force [m/s^2] of sample i, and its interval dt [s].
struct SampleRates {
  Eigen::Vector3d gyro, acc;
  double dt_s = 0.0;
};

SampleRates rates_of(const ImuSamples& imu, std::size_t i) {
  const ImuSample& s = imu.samples[i];
  const double dt = imu.interval_s(i);
  if (!(dt > 0.0)) {
    throw InputError(imu.source, imu.first_data_line ? imu.first_data_line + i : 0, "t_s",
                     "time stamps must increase");
  }
  const bool increments = imu.quantity == ImuQuantity::kIncrements;
  return {increments ? Eigen::Vector3d(s.gyro / dt) : s.gyro,
          increments ? Eigen::Vector3d(s.acc / dt) : s.acc, dt};
}

// Running sums of the increments and of time over samples [0, i). Only every kStride-th is
// kept; the others are summed again from there when asked for (the same additions in the same
// order, so bit for bit the values of a whole array of them), a few strides cached: memory that
// does not grow with the record.
class RunningSums {
 public:
  struct Sums {
    Eigen::Vector3d gyro = Eigen::Vector3d::Zero(), acc = Eigen::Vector3d::Zero();
    double time_s = 0.0;
  };

  // Checks the time stamps (InputError at the first that does not increase).
  explicit RunningSums(const ImuSamples& imu) : imu_(imu) {
    Sums sum;
    for (std::size_t i = 0; i < imu.samples.size(); ++i) {
      if (i % kStride == 0) kept_.push_back(sum);
      add(sum, i);
    }
    kept_.push_back(sum);  // the end, for a last stride of kStride samples
  }

  // The sums over [0, i), 0 <= i <= samples.
  const Sums& at(std::size_t i) {
    const std::size_t stride = i / kStride;
    for (const Cached& c : cache_)
      if (c.stride == stride && !c.sums.empty()) return c.sums[i - stride * kStride];
    Cached& c = cache_[next_slot_];
    next_slot_ = (next_slot_ + 1) % cache_.size();
    c.stride = stride;
    c.sums.reserve(kStride + 1);
    c.sums.assign(1, kept_[stride]);
    const std::size_t end = std::min(imu_.samples.size(), (stride + 1) * kStride);
    for (std::size_t k = stride * kStride; k < end; ++k) add(c.sums.emplace_back(c.sums.back()), k);
    return c.sums[i - stride * kStride];
  }

 private:
  static constexpr std::size_t kStride = 4096;
  struct Cached {
    std::size_t stride = 0;
    std::vector<Sums> sums;  // over [0, stride kStride + j) at j
  };

  void add(Sums& sum, std::size_t i) const {
    const SampleRates r = rates_of(imu_, i);
    sum.gyro = sum.gyro + r.gyro * r.dt_s;
    sum.acc = sum.acc + r.acc * r.dt_s;
    sum.time_s = sum.time_s + r.dt_s;
  }

  const ImuSamples& imu_;
  std::vector<Sums> kept_;
  std::array<Cached, 4> cache_;
  std::size_t next_slot_ = 0;
};

// Mean rate and specific force over samples [first, last] and the 1-sigma of each axis of them
// at rest: white noise density^2 / T plus the quantisation residuals at both ends, LSB^2/6/T^2.
struct BlockMean {
  Eigen::Vector3d gyro, acc;
  double gyro_sigma = 0.0, acc_sigma = 0.0;
};

BlockMean block_mean(RunningSums& sums, std::size_t first, std::size_t last,
                     const RestDetectorOptions& o) {
  const RunningSums::Sums end = sums.at(last + 1);  // a copy: the next call may evict it
  const RunningSums::Sums& begin = sums.at(first);
  const double T = end.time_s - begin.time_s;
  const auto sigma = [T](double density, double lsb) {
    return std::sqrt(density * density / T + lsb * lsb / (6.0 * T * T));
  };
  return {(end.gyro - begin.gyro) / T, (end.acc - begin.acc) / T,
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
void trim_run(RunningSums& sums, std::size_t& first, std::size_t& last, std::size_t block,
              const RestDetectorOptions& o) {
  if (last - first + 1 < 4 * block) return;
  const std::size_t quarter = (last - first + 1) / 4;
  const BlockMean reference = block_mean(sums, first + quarter, last - quarter, o);
  while (last - first + 1 > block && block_deviates(block_mean(sums, last + 1 - block, last, o),
                                                    reference, o.threshold_sigmas)) {
    --last;
  }
  while (last - first + 1 > block && block_deviates(block_mean(sums, first, first + block - 1, o),
                                                    reference, o.threshold_sigmas)) {
    ++first;
  }
}

// The window test's thresholds (see the header).
struct WindowTest {
  std::size_t window = 0;                    // samples
  double sigma_gyro = 0.0, sigma_acc = 0.0;  // per-sample noise of the rates
  double scatter_threshold = 0.0;
  double rate_tolerance = 0.0, force_tolerance = 0.0;
  double earth_rate = 0.0, gravity = 0.0;
};

WindowTest window_test(double dt, const EarthModel& earth, const RestDetectorOptions& options) {
  WindowTest w;
  const std::size_t half =
      std::max<std::size_t>(1, std::size_t(std::lround(options.window_s / dt / 2.0)));
  w.window = 2 * half + 1;
  // Per-sample noise of the rates: white part density / sqrt(dt); quantisation with the
  // residual carried makes each increment err by the difference of two residuals, uniform on
  // +-LSB/2 each: variance LSB^2 / 6.
  const auto per_sample_sigma = [dt](double density, double lsb) {
    return std::sqrt(density * density / dt + lsb * lsb / (6.0 * dt * dt));
  };
  w.sigma_gyro = per_sample_sigma(options.gyro_noise_density_rad_per_sqrt_s,
                                  options.gyro_quantization_lsb_rad);
  w.sigma_acc =
      per_sample_sigma(options.acc_noise_density_m_s_per_sqrt_s, options.acc_quantization_lsb_m_s);
  const double dof = 6.0 * double(w.window - 1);
  w.scatter_threshold = dof + options.threshold_sigmas * std::sqrt(2.0 * dof);
  // Noise of a magnitude of a window mean: sigma / sqrt(n) along the mean's direction.
  w.rate_tolerance = options.gyro_bias_bound_rad_s +
                     options.threshold_sigmas * w.sigma_gyro / std::sqrt(double(w.window));
  w.force_tolerance = options.acc_bias_bound_m_s2 +
                      options.threshold_sigmas * w.sigma_acc / std::sqrt(double(w.window));
  w.earth_rate = earth.earth_rate_W().norm();
  w.gravity = earth.normal_gravity_magnitude();
  return w;
}

// Whether the window of rates from `rates` on (w.window of them) is rest-like.
bool rest_like(const SampleRates* rates, const WindowTest& w) {
  Eigen::Vector3d mean_gyro = Eigen::Vector3d::Zero(), mean_acc = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < w.window; ++j) {
    mean_gyro += rates[j].gyro;
    mean_acc += rates[j].acc;
  }
  mean_gyro /= double(w.window);
  mean_acc /= double(w.window);
  if (std::abs(mean_gyro.norm() - w.earth_rate) > w.rate_tolerance ||
      std::abs(mean_acc.norm() - w.gravity) > w.force_tolerance) {
    return false;
  }
  double scatter = 0.0;
  for (std::size_t j = 0; j < w.window; ++j) {
    scatter += (rates[j].gyro - mean_gyro).squaredNorm() / (w.sigma_gyro * w.sigma_gyro) +
               (rates[j].acc - mean_acc).squaredNorm() / (w.sigma_acc * w.sigma_acc);
  }
  return scatter <= w.scatter_threshold;
}

// Marks the samples of every rest-like window [first, first + window). The rates are computed
// block by block (kBlock windows, their rates and the window's overlap): memory that does not
// grow with the record.
void mark_rest_like_windows(const ImuSamples& imu, const WindowTest& w,
                            std::vector<bool>& at_rest) {
  constexpr std::size_t kBlock = 16384;
  const std::size_t n = imu.samples.size(), windows = n + 1 - w.window;
  std::vector<SampleRates> rates;
  rates.reserve(kBlock + w.window - 1);
  for (std::size_t begin = 0; begin < windows; begin += kBlock) {
    const std::size_t count = std::min(kBlock, windows - begin);
    rates.clear();
    for (std::size_t j = begin; j < begin + count + w.window - 1; ++j)
      rates.push_back(rates_of(imu, j));
    for (std::size_t f = 0; f < count; ++f) {
      if (!rest_like(rates.data() + f, w)) continue;
      std::fill(at_rest.begin() + std::ptrdiff_t(begin + f),
                at_rest.begin() + std::ptrdiff_t(begin + f + w.window), true);
    }
  }
}

}  // namespace

RestDetection detect_rest(const ImuSamples& imu, const EarthModel& earth,
                          const RestDetectorOptions& options) {
  if (!(options.gyro_noise_density_rad_per_sqrt_s > 0.0) ||
      !(options.acc_noise_density_m_s_per_sqrt_s > 0.0)) {
    throw InputError(imu.source, 0, "noise density", "rest detection needs positive densities");
  }
  RunningSums sums(imu);
  const std::size_t n = imu.samples.size();
  const double dt =
      n > 1 ? (imu.samples.back().t_s - imu.samples.front().t_s) / double(n - 1) : imu.nominal_dt_s;
  const WindowTest test = window_test(dt, earth, options);
  const std::size_t edge_block =
      std::max<std::size_t>(1, std::size_t(std::lround(options.edge_block_s / dt)));
  if (n < test.window) {
    throw InputError(imu.source, 0, "samples", "record shorter than one rest-detection window");
  }
  RestDetection detection;
  detection.at_rest.assign(n, false);
  mark_rest_like_windows(imu, test, detection.at_rest);

  for (std::size_t i = 0; i < n;) {
    if (!detection.at_rest[i]) {
      ++i;
      continue;
    }
    std::size_t last = i;
    while (last + 1 < n && detection.at_rest[last + 1]) ++last;
    const std::size_t run_end = last;
    std::size_t first = i;
    trim_run(sums, first, last, edge_block, options);
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
