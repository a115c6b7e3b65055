#pragma once
// The rotation part of a tool-IMU calibration: R_T_S (the sensor frame S in the robot's tool
// frame T), the gyro bias, optionally the gyro scale factors, and the time offset between the
// sensor clock and the robot pose's clock, from a tool-IMU record (calib/tool_imu_record.hpp).
//
// Measurement model (per gyro sample, S axes):
//   gyro_S = K * omega_S + b,    omega_T = R_T_S * omega_S,
// with K = diag(k) + the symmetric cross-coupling c of the gyro's axes (its antisymmetric part is
// a rotation, held by R_T_S; the scale-factor and cross-coupling matrix of [Groves2013] 4.4),
// and an instant stamped t by the robot is stamped t + offset_s by the sensor.
// Residuals: over short windows [t_a, t_b] of sensor samples, the gyro-integrated rotation
// (corrected for b and k, mapped through R_T_S) against the robot's relative tool rotation
// between t_a - offset and t_b - offset; the residual is the rotation vector of their difference
// [rad]. Robust loss (Cauchy), Ceres with the quaternion manifold for R_T_S, numeric derivatives
// (the robot pose is interpolated in time, and the offset moves the interpolation).
// Initial values without user guesses: the offset by cross-correlation of |omega|, R_T_S by the
// Kabsch fit of rate vectors, the scale from |gyro| / |robot rate| (all from
// check_tool_imu_record), the bias from the samples where the robot stands still; optionally
// those rests stay in the fit as a prior on the bias (RotationCalibrationOptions::rest_bias_prior).
// Uncertainty (1 sigma): by a bootstrap that resamples whole motion segments (the residuals are
// correlated in time and depend on the motion), with a robust spread, beside ceres::Covariance
// scaled by the residual variance.
// References: [Groves2013] 4.4; [Kunsch1989]; [DavisonHinkley1997] 2.4; [RousseeuwCroux1993].
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <string>

#include "calib/gyro_rest_bias.hpp"
#include "calib/tool_imu_record.hpp"

namespace imscal::calib {

// What the bootstrap of the 1 sigma resamples: whole motion segments (stop to stop) or moving
// blocks of bootstrap_block_s.
enum class SigmaResampling { kMotionSegments, kBlocks };

struct RotationCalibrationOptions {
  double window_s = 0.5;          // length of a residual window [s]
  double window_stride_s = 0.25;  // start-to-start spacing of the windows [s]
  // Windows whose sensor time steps exceed this are skipped (a gap cannot be integrated) [s];
  // so are windows overlapping ToolImuAnalysis::missed_motion_spans_s.
  double max_sample_step_s = 0.1;
  // Windows where the robot turns less than this are still used (they fix the bias); windows
  // with any sample at a confirmed gyro rail (ToolImuAnalysis::clipped_axes) are skipped.
  bool estimate_scale = true;  // per-axis scale factors k (else k fixed at the initial)
  // The gyro's axes' cross-coupling c (symmetric part of the misalignment; else c = 0).
  bool estimate_cross_coupling = true;
  double cauchy_scale_rad = 0.5 * M_PI / 180.0;  // robust loss scale on the residual [rad]
  // Robot angular rate below which a sample counts as "at rest" for the bias [rad/s].
  double rest_rate_rad_s = 0.01;
  // The rests' mean gyro reading (calib/gyro_rest_bias.hpp) as a prior on the bias b: a residual
  // (b - rest mean) / its 1 sigma per axis, scaled to the windows' RMS residual of a first solve
  // without it, so that both terms count in units of their own scatter. Off by default: on the
  // ABB path 3 records the free bias departs from the rests by a tool-frame rate that three
  // different sensors share (a property of the run, not of one gyro), and pinning it to the rests
  // helps one record and harms two (decision 0055).
  bool rest_bias_prior = false;
  int max_iterations = 100;
  // 1 sigma by a bootstrap of the windows, per component at least the covariance's (0
  // replicates: the covariance's alone, which takes the windows as independent). The units
  // resampled are whole motion segments (stop to stop) or moving blocks of bootstrap_block_s;
  // the seed makes the sigma repeatable.
  int bootstrap_replicates = 40;
  double bootstrap_block_s = 2.0;
  SigmaResampling sigma_resampling = SigmaResampling::kMotionSegments;
  // Motion segments as calib/orientation_losses.hpp judges them: robot |omega| above
  // segment_rate_rad_s [rad/s], at least min_segment_angle_rad of turn [rad].
  double segment_rate_rad_s = 0.05;
  double min_segment_angle_rad = 5.0 * M_PI / 180.0;
  unsigned bootstrap_seed = 1;
};

struct RotationCalibration {
  Eigen::Quaterniond q_T_S = Eigen::Quaterniond::Identity();
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();      // b, in S, as labelled units->SI
  Eigen::Vector3d gyro_scale = Eigen::Vector3d::Ones();           // k per S axis
  Eigen::Vector3d gyro_cross_coupling = Eigen::Vector3d::Zero();  // c_xy, c_xz, c_yz [-]
  double time_offset_s = 0.0;                                     // t_sensor = t_robot + offset
  // 1 sigma: rotation about the T axes [rad], bias [rad/s], scale [-], offset [s].
  Eigen::Vector3d sigma_rotation_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_scale = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_cross_coupling = Eigen::Vector3d::Zero();  // bootstrap only
  double sigma_time_offset_s = 0.0;
  bool sigma_from_bootstrap = false;  // else from the covariance (below)
  SigmaResampling sigma_resampling = SigmaResampling::kMotionSegments;  // the bootstrap's units
  std::size_t bootstrap_replicates = 0;                                 // replicates that solved
  std::size_t bootstrap_unit_count = 0;  // the units resampled (motion segments or blocks)
  bool covariance_ok = false;
  // 1 sigma of the covariance with independent windows, scaled by the residual variance.
  Eigen::Vector3d covariance_sigma_rotation_rad = Eigen::Vector3d::Zero();
  double covariance_sigma_time_offset_s = 0.0;
  // Gravity's specific force direction in the robot base B (unit, "up" as the accelerometer
  // sees it), averaged over rest samples: the attitude filter's aiding reference.
  Eigen::Vector3d up_B = Eigen::Vector3d::UnitZ();
  // The rests' gyro mean and its 1 sigma [rad/s, as labelled], and whether it entered the fit as
  // a prior (rest_bias_prior and at least 10 still samples).
  Eigen::Vector3d rest_bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_rest_bias_rad_s = Eigen::Vector3d::Zero();
  std::size_t rest_sample_count = 0;
  bool rest_bias_prior_used = false;
  std::size_t window_count = 0;
  std::size_t skipped_window_count = 0;
  double rms_residual_rad = 0.0;  // after the fit, over all windows
  double initial_rms_residual_rad = 0.0;
  std::size_t outlier_window_count = 0;  // residual above 3 Cauchy scales
  int iterations = 0;
  std::string summary;  // Ceres' brief report
};

// The gyro's scale-and-coupling matrix K (gyro_S = K * omega_S + b): diag(k) with the symmetric
// coupling c_xy, c_xz, c_yz off the diagonal. Its antisymmetric part would be a rotation, which
// R_T_S holds.
Eigen::Matrix3d gyro_scale_matrix(const Eigen::Vector3d& scale, const Eigen::Vector3d& coupling);

// The calibrated rate in S of one gyro reading: K^-1 * (reading - b).
Eigen::Vector3d calibrated_rate_S(const RotationCalibration& calibration,
                                  const Eigen::Vector3d& reading);

RotationCalibration calibrate_rotation(const ToolImuRecord& record, const ToolImuAnalysis& analysis,
                                       const RotationCalibrationOptions& options = {});

// The gyro bias [rad/s, S] from the samples where the robot stands still (robot rate below
// rest_rate_rad_s at t - time_offset_s), with a known scale: mean of gyro - k * 0. Returns false
// when fewer than 10 such samples exist (then bias is left unchanged).
bool gyro_bias_at_rest(const ToolImuRecord& record, double time_offset_s, double rest_rate_rad_s,
                       Eigen::Vector3d& bias_rad_s, double max_time_s = 1e300);

}  // namespace imscal::calib
