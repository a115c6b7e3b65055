#pragma once
// Orientation of the robot's tool from a calibrated tool-mounted MEMS IMU (no magnetometer):
// the gyro, corrected by the rotation calibration (bias removed, scale divided out, mapped to
// the tool frame by R_T_S), is integrated; the accelerometers pull the tilt towards gravity
// with a complementary (Mahony-style proportional) correction.
//
//   omega_T = R_T_S * ((gyro_S - b) ./ k)
//   f_T     = R_T_S * acc_S,  expected up_T = R_B_T^T * up_B
//   q_B_T  <- q_B_T * exp((omega_T + gain * (f_T/|f_T| x up_T)) * dt)
//
// The correction is applied only while |f| is within `max_specific_force_deviation` of 1 g and
// the tool turns slower than `max_rate_for_aiding_rad_s` (the robot's own accelerations and the
// centripetal acceleration of the sensor's lever arm would pull the tilt the wrong way). Heading
// about up_B is not observable from gravity: it is pure gyro integration.
// Initialised from the robot's pose at the start of the sequence (at the first sensor sample,
// robot time t - offset).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"

namespace imscal::calib {

struct AttitudeFilterOptions {
  // Proportional gain of the gravity correction [rad/s per unit misalignment]: 0.05 rad/s is a
  // 20 s time constant, long against the robot's accelerations (< 1 s) and short against the
  // drift of a calibrated MEMS gyro over a 20-30 s run.
  double gravity_gain_rad_s = 0.05;
  double max_specific_force_deviation = 0.05;  // fraction of 1 g
  double max_rate_for_aiding_rad_s = 0.5;
  bool use_gravity = true;
  // Steps longer than this (gaps in the record) are bridged by holding the last rate [s].
  double max_step_s = 1.0;
  // Sensor time at which to start (from the robot's pose there); default: the first sample.
  double start_time_s = -1e300;
};

struct AttitudeTrack {
  std::vector<double> t_s;                // sensor clock
  std::vector<Eigen::Quaterniond> q_B_T;  // tool in the robot base, estimated
  std::vector<bool> aided;                // gravity correction applied at this step
};

AttitudeTrack run_attitude_filter(const ToolImuRecord& record,
                                  const RotationCalibration& calibration,
                                  const AttitudeFilterOptions& options = {});

}  // namespace imscal::calib
