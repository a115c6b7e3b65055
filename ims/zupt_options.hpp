#pragma once
// Options of the zero-velocity smoother (ims/zupt_smoother.hpp): the sensor's stochastic model,
// the rest pseudo-measurements and the propagation interval. Fill the sensor part from the data
// sheet with zupt_options_from_spec(); the rest of the fields describe the robot at standstill.
#include <Eigen/Core>
#include <limits>

#include "ims/rest_detector.hpp"
#include "ims/sensor_spec.hpp"

namespace imscal::ims {

struct ZuptOptions {
  // --- sensor noise, the same for the three axes of each triad ---
  double gyro_noise_density_rad_per_sqrt_s = 0.0;  // angle random walk
  double acc_noise_density_m_s_per_sqrt_s = 0.0;   // velocity random walk
  // LSB of the increment outputs (quantised with the residual carried, ims/imu_noise.hpp): adds
  // LSB^2/6 to the variance of each increment but does not accumulate [rad], [m/s]; 0: none.
  double gyro_quantization_lsb_rad = 0.0;
  double acc_quantization_lsb_m_s = 0.0;
  // Bias processes: first-order Gauss-Markov, stationary 1-sigma `*_bias_instability`,
  // correlation time `*_correlation_time_s`; an infinite correlation time means no in-run
  // change of the bias.
  double gyro_bias_instability_rad_s = 0.0;
  double gyro_bias_correlation_time_s = std::numeric_limits<double>::infinity();
  double acc_bias_instability_m_s2 = 0.0;
  double acc_bias_correlation_time_s = std::numeric_limits<double>::infinity();
  // Initial bias estimates and their 1-sigma (turn-on bias and the stationary in-run part).
  Eigen::Vector3d initial_gyro_bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_acc_bias_m_s2 = Eigen::Vector3d::Zero();
  double initial_gyro_bias_sigma_rad_s = 0.0;
  double initial_acc_bias_sigma_m_s2 = 0.0;

  // --- rest pseudo-measurements: properties of the robot at standstill ---
  // Residual velocity of the flange at standstill (servo jitter, vibration) [m/s].
  double zero_velocity_sigma_m_s = 1e-5;
  // Residual angular rate at standstill [rad/s], added in quadrature to the gyro noise.
  double zero_angular_rate_sigma_rad_s = 0.0;
  // The zero-rate update averages the gyros over each rest without its first and last
  // `zero_rate_edge_margin_s`: the slow ends of smooth motions that the rest detector lets in
  // turn the sensor by ~1e-5 rad, enough to bias a 0.5 s mean by 20x the quantisation noise.
  double zero_rate_edge_margin_s = 0.1;
  // Likewise the zero-velocity updates skip the first and last `zero_velocity_edge_margin_s` of
  // each detected rest.
  double zero_velocity_edge_margin_s = 0.0;
  // Updates whose normalised innovation squared exceeds this are rejected: motion the rest
  // detector cannot see (constant velocity without rotation, e.g. a linear move at cruise
  // speed) and outliers. 30.7: chi-square(3) quantile at 1 - 1e-6.
  // A zero-velocity update is gated only while the estimated speed exceeds
  // `gate_min_speed_m_s`: slower "motion" is taken as rest, so that a filter whose velocity has
  // drifted (unmodelled sensor errors) is pulled back instead of locked out by the gate.
  double innovation_gate_chi2 = 30.7;
  double gate_min_speed_m_s = 1e-3;

  // Interval of the covariance propagation and of the zero-velocity updates [s]; the nominal
  // state is mechanised at every sample regardless.
  double propagation_interval_s = 0.01;

  // Rest detection; its noise densities and bias bounds are filled from the fields above when
  // left at zero (bias bound: 3 sigma of the initial bias).
  RestDetectorOptions rest;
};

// The sensor part from a data sheet. Several Gauss-Markov terms of a triad are merged into one
// with the summed variance and the summed driving noise (2 sigma^2 / tau), i.e. the same
// stationary variance and the same short-term growth.
ZuptOptions zupt_options_from_spec(const SensorSpec& spec);

}  // namespace imscal::ims
