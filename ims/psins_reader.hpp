#pragma once
// Reader of PSINS-format strapdown IMU logs (Gongmin Yan's PSINS toolbox, `*.imu` text files):
// increment counts per sample, with three header lines that give the initial state, the site,
// the sampling interval, the local g and the scale factors.
//
// File layout (lines starting with '%' are comments, blank lines are skipped):
//   header line 1: pitch0 [deg], roll0 [deg], yaw0 [deg], VE0, VN0, VU0 [m/s]  ("maybe inaccurate")
//   header line 2: latitude0 [deg], longitude0 [deg], height0 [m], t0 [s], interval [ms], g [m/s^2]
//   header line 3: gyro scale x, y, z [arcsec/count], acc scale x, y, z [ug*s/count]
//   then one line per sample: gyro x y z, acc x y z as integer counts of the increments over
//   that sample interval.
//
// Sensor frame S: the file's own axes, kept unchanged: X right, Y forward, Z up (PSINS's
// conventional "X-Right, Y-Forward, Z-Up" mounting on the vehicle). PSINS attitude angles use
// R_W_S = Rz(yaw) * Rx(pitch) * Ry(roll) with W = ENU and yaw counter-clockwise from North of
// the Y axis (so yaw0 = -90 deg means Y points East).
//
// Units: gyro increment [rad] = count * scale_arcsec * pi / (180 * 3600); velocity increment
// [m/s] = count * scale_ug_s * 1e-6 * g, with the g of header line 2 (the file's own "g").
// Time: sample k (k = 1, 2, ...) is the increment over (t0 + (k-1) dt, t0 + k dt] and is stamped
// at its end, t0 + k dt (ims/imu_data.hpp).
#include <Eigen/Core>
#include <filesystem>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"

namespace imscal::ims {

struct PsinsHeader {
  // Initial attitude stated by the file, PSINS convention above [deg].
  double initial_pitch_deg = 0.0;
  double initial_roll_deg = 0.0;
  double initial_yaw_deg = 0.0;  // counter-clockwise from North of the Y axis
  Eigen::Vector3d initial_velocity_enu_m_s = Eigen::Vector3d::Zero();
  Site site;
  double t0_s = 0.0;
  double interval_s = 0.0;    // sampling interval (the file gives ms)
  double gravity_m_s2 = 0.0;  // the file's g, used for the accelerometer scale
  Eigen::Vector3d gyro_scale_arcsec_per_count = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_scale_ug_s_per_count = Eigen::Vector3d::Zero();
  std::size_t header_lines[3] = {0, 0, 0};  // 1-based line numbers of the three header lines
};

// Reads the whole file into increments in SI units (quantity kIncrements, site set, metadata
// holding the header values with units in their names). Throws InputError (file, line, field)
// on a missing or short header line, a wrong column count, a non-numeric or non-integer value,
// a NaN, an implausible header value or a file without samples.
ImuSeries read_psins(const std::filesystem::path& path, PsinsHeader* header = nullptr);

}  // namespace imscal::ims
