#pragma once
// The sim-to-real gap of raw IMU signals ("the IMS signals synthesised from the robot's
// reported motion"): on a tool-mounted IMU record (calib/tool_imu_record.hpp), "sim" is the
// angular rate the robot's reported tool poses imply (calib::robot_tool_rate, in the tool frame
// T), "real" is the gyro as read, and the gap per gyro sample is
//
//   g(t) = w_meas(t) - w_model(t),   w_model(t) = K R^T w_T(t - dt) + b, each axis clipped at the
//                                                  rail where the sensor saturates   [rad/s]
//
// starting from the naive model (R = I, K = I, dt = 0, b = 0, no clipping). First the unit check
// (calib::check_tool_imu_record: |gyro as labelled| / |robot rate|): a ratio further from 1 than
// the check's scale tolerance is a unit or scale error (the LSM9DS0 reads 1/64 of the labelled
// deg/s); it is reported as the first step, a scale error, and both records' gyros are divided by
// it before any gap is measured, so that the gap is in the robot's rate units and the other
// effects are weighed against what the sensor sees, not against a signal 64 times too small
// (where predicting almost nothing looks like a 98 % fit). The candidate effects
// are the terms of that model: time offset dt between the streams, axis misalignment R (sensor
// axes in the tool), scale factors K (per axis), bias b, saturation (the rails of
// calib::check_tool_imu_record), and the sensor noise (a floor: the white part of the residual,
// from its sample-to-sample differences; no model shrinks it). They are added greedily: each
// step fits the model with the effects chosen so far plus one more on the training record and
// keeps the one that shrinks the held-out record's gap most (a second sequence of the same
// sensor: the effects are properties of the installation, not of one run), while that shrinks it
// by at least `min_gain_percent`. Spans where the sensor did not record the robot's motion at
// all (calib::ToolImuFindingKind::kSensorMissedMotion) are left out of both records and reported.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/tool_imu_record.hpp"

namespace imscal::eval {

enum class ImuGapEffect { kTimeOffset, kAxisMisalignment, kScaleFactors, kBias, kSaturation };
inline constexpr int kImuGapEffectCount = 5;
const char* to_string(ImuGapEffect effect);

struct ImuGapModel {
  double time_offset_s = 0.0;  // t_sensor = t_robot + dt
  Eigen::Matrix3d R_T_S = Eigen::Matrix3d::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();  // K, sensor axes [1]
  Eigen::Vector3d bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d rail_rad_s = Eigen::Vector3d::Constant(1e300);  // |reading| limit per axis
};

struct ImuGapStep {
  ImuGapEffect effect;
  double heldout_rms_rad_s = 0.0;          // after this step
  double heldout_shrinkage_percent = 0.0;  // of the naive gap (after the unit check), cumulative
  std::string size;                        // the fitted effect in words
  bool from_unit_check = false;            // the unit check's scale error (the gap's baseline: 0 %)
};

struct ImuGapDiagnosis {
  // |gyro as labelled| / |robot rate| of the training record when the unit check calls it a unit
  // or scale error, else 1; the gyros are divided by it before the gap is measured.
  double unit_scale = 1.0;
  double heldout_rms_as_labelled_rad_s = 0.0;  // naive gap of the gyro as read, for the record
  // Naive gap (all three axes) after the unit check, in the robot's rate units; the gaps, the
  // steps' RMS and the noise floor below are all in these units.
  double training_rms_rad_s = 0.0, heldout_rms_rad_s = 0.0;
  std::vector<ImuGapStep> steps;            // kept greedy steps, in order
  std::vector<ImuGapEffect> not_supported;  // tried, never kept
  ImuGapModel model;  // after the kept steps, for the gyro as labelled (unit scale included)
  double heldout_noise_rad_s = 0.0;  // white noise floor of the held-out residual, per axis RMS
  double heldout_rms_modelled_rad_s = 0.0;
  // Seconds left out of each record: motion the sensor did not record (data defects found by
  // calib::check_tool_imu_record, kSensorMissedMotion), reported instead of modelled.
  double excluded_training_s = 0.0, excluded_heldout_s = 0.0;
  std::string verdict;  // plain words
};

struct ImuGapOptions {
  double max_abs_time_offset_s = 0.5;
  double time_offset_step_s = 0.002;
  double min_gain_percent = 2.0;  // a step must shrink the held-out gap by this much more
  calib::ToolImuCheckOptions check;
};

// Gap RMS of the record under the model [rad/s, all three axes], over the gyro samples where the
// robot's rate is known (and, with saturation modelled, the reading is not on a rail).
double imu_gap_rms(const calib::ToolImuRecord& record, const calib::RobotRateSeries& rate,
                   const ImuGapModel& model);

ImuGapDiagnosis diagnose_imu_gap(const calib::ToolImuRecord& training,
                                 const calib::ToolImuRecord& heldout,
                                 const ImuGapOptions& options = {});

}  // namespace imscal::eval
