#pragma once
// The config of `imscal calibrate` (datasets/calibration/calibrate-default.yaml, format in
// datasets/FORMAT.md §16): where the sensor spec and the robot come from (the command line may
// override), the payload, rest detection and trimming, the bundle's options, the prior sigmas and
// the thresholds of the mounting validation. Units in the key names (deg, mm, ug, deg/h); SI
// inside. Every section and key is optional (defaults below); unknown keys are refused.
//
//   imscal-calibration-config: 1
//   sensor: ../sensors/navigation-grade.yaml      # relative to this file
//   robot: ../robots/kr16.yaml
//   unit_calibration: unit.yaml                   # the IMS unit's lab calibration (optional)
//   payload: {mass_kg: 0.0, com_mm: [0, 0, 0]}    # in the tool frame T
//   rests: {min_duration_s: 2.0, trim_s: 0.5, max_joint_spread_deg: 0.0172,
//           settle_tolerance_deg: 0, detector_threshold_sigmas: 5.0}
//   time_offset: {max_abs_offset_s: 0.5}
//   bundle: {estimate_time_offset: true, estimate_scale_factors: false, huber_scale_sigma: 3,
//            outlier_threshold_sigma: 4, rate_window_s: 0.02, min_rate_deg_s: 2.9,
//            max_iterations: 100, sparse: true, estimate_deflection_scale: true,
//            deflection_scale_sigma: 1.0}
//   priors: {gyro_bias_sigma_deg_per_h: ..., acc_bias_sigma_ug: ...,   # default: the spec's
//            deflection_uncertainty_fraction: 0.05, joint_sigma_floor_urad: 5}
//   validation: {halves: true, segments: true, segment_rests: 5, ...thresholds}
//   joint_errors: true
//   first_rest_position_m: [0, 0, 0]              # sensor at rest 1 from the site point, ENU
//   heading_reference: {yaw_deg: 30.0, sigma_deg: 0.01}  # surveyed yaw of T_W_R (optional)
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>

#include "calib/frame_calibration.hpp"
#include "calib/mounting_validation.hpp"
#include "core/config_node.hpp"
#include "ims/sensor_spec.hpp"

namespace imscal::calib {

struct PayloadConfig {
  double mass_kg = 0.0;
  Eigen::Vector3d com_T_m = Eigen::Vector3d::Zero();  // centre of mass in the tool frame T
};

struct RestConfig {
  double min_duration_s = 2.0;  // shorter rests are not used
  double trim_s = 0.5;          // cut at both ends of every detected rest
  // Largest spread of the robot's joint readings over a rest [rad]: the arm may still creep
  // (the bundle models that from the readings, RestObservation::q_creep_*), but not move.
  double max_joint_spread_rad = 3e-4;
  // Rests are used from where the joint readings have settled within this of their final value
  // (calib/rest_poses.hpp) [rad]; 0: not checked.
  double settle_tolerance_rad = 0.0;
  double detector_threshold_sigmas = 5.0;  // ims/rest_detector.hpp
};

struct PriorConfig {
  // Bias priors; empty: from the sensor spec (turn-on sigma and bias instability in quadrature).
  std::optional<double> gyro_bias_sigma_rad_s;
  std::optional<double> acc_bias_sigma_m_s2;
  // Prior 1-sigma of the rest joint angles after the static deflection correction: a fraction
  // of the correction, and a floor [rad].
  double deflection_uncertainty_fraction = 0.05;
  double joint_sigma_floor_rad = 5e-6;
};

struct CalibrationConfig {
  std::string file;                                  // where it was read from ("" for the defaults)
  std::optional<std::filesystem::path> sensor_file;  // resolved against the config's folder
  std::optional<std::filesystem::path> robot_file;
  // The IMS unit's lab (or data-sheet) calibration: scale factors and misalignments of both
  // triads in the format of ims/sensor_error_model.hpp (as `imscal mechanize --sensor-errors`
  // takes it). `imscal calibrate` corrects the raw record with it (ims::correct) before anything
  // else; its biases, usually zero, are subtracted too, and the bundle estimates what remains.
  std::optional<std::filesystem::path> unit_calibration_file;
  PayloadConfig payload;
  RestConfig rests;
  double max_abs_time_offset_s = 0.5;  // search range of the initial time offset
  FrameCalibrationOptions bundle;
  PriorConfig priors;
  MountingValidationOptions validation;
  bool joint_errors = true;  // compute and write joint_errors.csv
  // The sensor at the first rest relative to the site point, in W (ENU) [m]: only for the
  // gravity field (0.3 ug per metre of height); a tape-measure value is plenty.
  Eigen::Vector3d first_rest_position_W_m = Eigen::Vector3d::Zero();
  // A surveyed heading of the robot base with its 1-sigma (calib/frame_calibration.hpp,
  // HeadingReference): a prior on T_W_R's yaw; absent: the IMS alone (Earth rate).
  std::optional<HeadingReference> heading_reference;
};

// InputError(file, line, key) for bad values; unknown keys refused.
CalibrationConfig parse_calibration_config(const ConfigNode& root);
CalibrationConfig load_calibration_config(const std::filesystem::path& file);

// The bundle's noise model from the sensor spec and the priors: white-noise densities from the
// spec; bias sigmas from the priors, or else sqrt(turn-on^2 + sum of bias-instability sigma^2);
// the accelerometer bias's drift PSD from the spec's bias instability (sum of 2 sigma^2 / tau);
// quantisation LSBs from the spec.
ImuNoiseModel imu_noise_model(const ims::SensorSpec& spec, const PriorConfig& priors);

}  // namespace imscal::calib
