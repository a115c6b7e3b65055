#pragma once
// Two inertial units on one vehicle, a slave IMU (gyro and accelerometer increments) and a master
// INS (attitude), as a tool-IMU record (calib/tool_imu_record.hpp), so that the rotation
// calibration (calib/rotation_calibration.hpp) estimates the slave's mounting in the master and
// the clock offset between the two streams from their angular rates. Roles: the master's body
// frame is the tool T, its navigation frame N the robot base B, the slave's frame the sensor S;
// R_T_S is the slave frame in the master frame and t_slave = t_master + time_offset_s.
//
// The gyros measure the rate against inertial space, the master's attitude is against the local
// level frame, which turns with the Earth and the vehicle's transport (15 deg/h + v/R, ~0.5 deg/h
// here): their mean goes into the gyro bias, the part that changes with the attitude stays below
// 1e-5 rad per 0.5 s window, far below the MEMS gyro's noise.
//
// Files (the PSINS transfer-alignment data set, tests/data/real/psins-fog-mems/SOURCE.md):
//   slave: t_s, dtheta_x_rad, dtheta_y_rad, dtheta_z_rad, dv_x_mps, dv_y_mps, dv_z_mps: angle and
//          velocity increments over (t − dt, t], stamped at the end; here the rate dθ/dt is
//          placed at the middle of its interval, t − dt/2, where it is the mean rate.
//   master: t_s, pitch_rad, roll_rad, yaw_rad (further columns ignored): PSINS attitude,
//          C_b^n = Rz(yaw) Rx(pitch) Ry(roll), n = East-North-Up.
// Both are numeric tables (core/numeric_table.hpp); problems are InputErrors naming file, line
// and column.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/tool_imu_record.hpp"

namespace imscal::calib {

struct IncrementImu {
  std::string file;
  std::vector<std::size_t> lines;
  std::vector<double> t_end_s;  // strictly increasing
  std::vector<Eigen::Vector3d> dtheta_rad, dv_m_s;
};

struct InsAttitude {
  std::string file;
  std::vector<double> t_s;  // strictly increasing
  std::vector<Eigen::Quaterniond> q_N_B;
};

IncrementImu read_increment_imu_csv(const std::filesystem::path& file);
InsAttitude read_psins_attitude_csv(const std::filesystem::path& file);

// PSINS attitude [rad] as C_b^n = Rz(yaw) Rx(pitch) Ry(roll).
Eigen::Quaterniond psins_attitude(double pitch_rad, double roll_rad, double yaw_rad);

// One row per slave sample from the second on (its interval needs the previous stamp), at the
// middle of its interval, with the master attitude slerped there (valid only within the
// master's span).
ToolImuRecord master_slave_record(const IncrementImu& slave, const InsAttitude& master);

}  // namespace imscal::calib
