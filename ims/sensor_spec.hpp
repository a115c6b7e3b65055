#pragma once
// The stochastic description of an IMS (a data sheet in numbers), from which the errors of one
// unit are drawn (ims/imu_noise.hpp). YAML, units in the key names (1 g = 9.80665 m/s^2):
//
//   name: "..."
//   gyro:
//     angle_random_walk_deg_per_sqrt_h: 0.002     # white rate noise density
//     bias_instability:                           # sum of first-order Gauss-Markov processes
//       - {sigma_deg_per_h: 0.003, correlation_time_s: 300}
//     turn_on_bias_sigma_deg_per_h: 0.005         # constant per run, drawn once
//     scale_factor_sigma_ppm: 5
//     misalignment_sigma_arcsec: 5                # each of the 6 off-diagonal terms
//     quantization_lsb_arcsec: 1.0                # LSB of the angle increment output (0: none)
//     range_deg_per_s: 400                        # saturation of the rate (0: none)
//   accelerometer:
//     velocity_random_walk_ug_per_sqrt_hz: 5
//     bias_instability: [{sigma_ug: 10, correlation_time_s: 300}]
//     turn_on_bias_sigma_ug: 25
//     scale_factor_sigma_ppm: 50
//     misalignment_sigma_arcsec: 10
//     quantization_lsb_m_per_s: 1e-5              # LSB of the velocity increment output
//     range_g: 20
//
// Every key is required except bias_instability (default: none); unknown keys are refused.
#include <filesystem>
#include <string>
#include <vector>

#include "core/config_node.hpp"

namespace imscal::ims {

// First-order Gauss-Markov bias: db/dt = -b / tau + w, stationary standard deviation sigma.
struct GaussMarkovTerm {
  double sigma = 0.0;               // [rad/s] or [m/s^2]
  double correlation_time_s = 1.0;  // tau [s]
};

// One triad in SI: gyro in rad and s, accelerometer in m and s.
struct TriadSpec {
  double white_noise_density = 0.0;  // [rad/s/sqrt(Hz)] = [rad/sqrt(s)], or [m/s^2/sqrt(Hz)]
  std::vector<GaussMarkovTerm> bias_instability;
  double turn_on_bias_sigma = 0.0;  // [rad/s] or [m/s^2]
  double scale_factor_sigma = 0.0;  // [1]
  double misalignment_sigma = 0.0;  // [rad]
  double quantization_lsb = 0.0;    // increment LSB [rad] or [m/s]; 0: not quantised
  double range = 0.0;               // max |rate| [rad/s] or |specific force| [m/s^2]; 0: none
};

struct SensorSpec {
  std::string name;
  TriadSpec gyro;
  TriadSpec acc;
};

SensorSpec parse_sensor_spec(const ConfigNode& config);
SensorSpec load_sensor_spec(const std::filesystem::path& file);

}  // namespace imscal::ims
