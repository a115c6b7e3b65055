#pragma once
// Detection of rest (standstill of the sensor relative to the Earth) from the IMS signals alone.
//
// At rest the gyros read the Earth rate and the accelerometers the reaction to gravity, both
// constant in S, plus white noise. For every window of `window_s` centred on a sample, the
// generalised likelihood ratio test of "constant signal + white noise of the known level"
// against "anything else" reduces to the scatter about the window means,
//   T = sum_j |w_j - mean w|^2 / sigma_w^2 + sum_j |f_j - mean f|^2 / sigma_f^2,
// which is chi-square with 6 (n - 1) degrees of freedom at rest (sigma = per-sample noise of
// the rates: density^2 / dt plus the quantisation's LSB^2 / (6 dt^2)). A window is rest-like when T
// stays below the mean of that distribution plus `threshold_sigmas` of its standard deviations, and
// when the mean rate and specific-force magnitudes match the Earth rate and gravity (this catches
// rotations and accelerations that are constant over the window). A sample is at rest when some
// rest-like window contains it. Smooth motions start and end so gently that such windows reach
// into them, so each run is then trimmed at both ends while the mean of its end block
// (`edge_block_s`) differs from the mean of the run's middle half by more than
// `threshold_sigmas` of their noise (increments are summed there, so the quantisation residuals
// enter only at the block ends). Runs shorter than `min_rest_s` are dropped.
//
// Not detectable from the IMS alone: motion at constant velocity without rotation. The smoother
// guards against it by gating the zero-velocity update (ims/zupt_smoother.hpp).
#include <cstddef>
#include <vector>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"

namespace imscal::ims {

struct RestDetectorOptions {
  // White-noise densities of the sensors, from the sensor spec.
  double gyro_noise_density_rad_per_sqrt_s = 0.0;  // angle random walk
  double acc_noise_density_m_s_per_sqrt_s = 0.0;   // velocity random walk
  // LSB of the quantised increments [rad], [m/s] (residual carried: each increment gets
  // LSB^2/6 of extra variance); 0: none.
  double gyro_quantization_lsb_rad = 0.0;
  double acc_quantization_lsb_m_s = 0.0;
  // Largest bias magnitude expected [rad/s], [m/s^2]: the tolerance of the magnitude tests.
  double gyro_bias_bound_rad_s = 0.0;
  double acc_bias_bound_m_s2 = 0.0;
  double window_s = 0.02;  // length of the test window
  // Threshold in standard deviations of the statistic at rest (about 1e-6 false alarms per
  // window for 5 with the window above).
  double threshold_sigmas = 5.0;
  // Length of the end blocks compared with the middle of a candidate rest (see above).
  double edge_block_s = 0.05;
  double min_rest_s = 0.2;  // shorter runs are not reported as rest
};

struct RestInterval {
  std::size_t first_sample = 0;  // index into ImuSeries::samples, inclusive
  std::size_t last_sample = 0;   // inclusive
  double begin_s = 0.0;          // time of first_sample
  double end_s = 0.0;            // time of last_sample
  double duration_s() const { return end_s - begin_s; }
};

struct RestDetection {
  std::vector<bool> at_rest;            // per sample
  std::vector<RestInterval> intervals;  // the runs of at_rest, in time order
};

// Needs increments (ImuQuantity::kIncrements) or rates (a whole ImuSeries or a part of one);
// memory that does not grow with the record but for `at_rest`. Throws InputError for a record too
// short for one window or non-positive noise densities.
RestDetection detect_rest(const ImuSamples& imu, const EarthModel& earth,
                          const RestDetectorOptions& options);

}  // namespace imscal::ims
