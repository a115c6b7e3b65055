#pragma once
// Deterministic errors of the two sensor triads (gyros, accelerometers), the model used both to
// synthesise raw data from truth and to correct raw data on read:
//
//   raw = (I + diag(scale_factor) + misalignment) * true + bias            (rates)
//   raw = (I + diag(scale_factor) + misalignment) * true + bias * dt       (increments over dt)
//
// `true` is in the orthogonal sensor frame S (ims/frames.hpp). misalignment is a 3x3 matrix of
// small angles [rad] with a zero diagonal: entry (i, j) is how much of the true component along
// S axis j the sensor of axis i picks up (its sensitive axis tilted towards j) — six independent
// terms, no assumption that the triad is rotated rigidly. scale_factor is dimensionless
// (1e-6 = 1 ppm). bias is [rad/s] for gyros, [m/s^2] for accelerometers.
// correct() is the exact inverse: true = A^-1 (raw - bias [* dt]).
//
// YAML form (units in the key names; 1 g = 9.80665 m/s^2, the standard gravity):
//   gyro:
//     bias_deg_per_h: [x, y, z]
//     scale_factor_ppm: [x, y, z]
//     misalignment_arcsec: [[0, xy, xz], [yx, 0, yz], [zx, zy, 0]]
//   accelerometer:
//     bias_ug: [x, y, z]
//     scale_factor_ppm: [x, y, z]
//     misalignment_arcsec: [[0, xy, xz], [yx, 0, yz], [zx, zy, 0]]
// Every key is optional (zero when absent); unknown keys are refused.
#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "core/config_node.hpp"
#include "core/units.hpp"
#include "ims/imu_data.hpp"

namespace imscal::ims {

// Conversions of the file units used by the sensor YAML files into SI.
namespace sensor_units {
inline constexpr double kRadPerSecPerDegPerHour = kRadPerDeg / 3600.0;
inline constexpr double kMetrePerSec2PerMicroG = kStandardGravity_m_s2 * 1e-6;
inline constexpr double kPerPpm = 1e-6;
}  // namespace sensor_units

struct TriadErrors {
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();          // [rad/s] or [m/s^2]
  Eigen::Vector3d scale_factor = Eigen::Vector3d::Zero();  // [1]
  Eigen::Matrix3d misalignment = Eigen::Matrix3d::Zero();  // [rad], zero diagonal

  // A = I + diag(scale_factor) + misalignment.
  Eigen::Matrix3d sensitivity() const;
  // interval_s multiplies the bias: the interval for increments, 1.0 for rates.
  Eigen::Vector3d apply(const Eigen::Vector3d& true_value, double interval_s) const;
  Eigen::Vector3d correct(const Eigen::Vector3d& raw_value, double interval_s) const;
};

struct SensorErrorModel {
  TriadErrors gyro;
  TriadErrors acc;

  // One sample; interval_s is that of an increment sample (ignored for rates).
  ImuSample apply(const ImuSample& true_sample, ImuQuantity quantity, double interval_s) const;
  ImuSample correct(const ImuSample& raw_sample, ImuQuantity quantity, double interval_s) const;
};

// Whole series. For increments, the interval of sample k is t_k - t_{k-1}, and that of the first
// sample is series.nominal_dt_s (ims/imu_data.hpp). Everything but the samples is copied.
ImuSeries apply(const ImuSeries& truth, const SensorErrorModel& errors);
ImuSeries correct(const ImuSeries& raw, const SensorErrorModel& errors);
// The same, sample by sample in place (no second copy of a long record; the same values).
ImuSeries correct(ImuSeries&& raw, const SensorErrorModel& errors);
// The interval of sample i as used above [s].
double sample_interval(const ImuSeries& series, std::size_t i);

// YAML (format above). Throws InputError naming the file, line and key on bad input, including
// a non-zero diagonal of a misalignment matrix.
SensorErrorModel parse_sensor_error_model(const ConfigNode& config);
SensorErrorModel load_sensor_error_model(const std::filesystem::path& file);
// The same format, with every key, numbers to 17 significant digits (round-trips exactly
// through parse up to the unit conversions, i.e. to ~1e-16 relative).
std::string to_yaml(const SensorErrorModel& errors);

}  // namespace imscal::ims
