#pragma once
// The check of a tool-mounted IMU record as `imscal check-tool-imu` runs it: every defect found
// (NaN rows, time steps, robot quaternions, gyro rails, scale/unit, time offset, lost motion,
// quaternion convention, axis misalignment; calib/tool_imu_record.hpp) and the rotation
// calibration (R_T_S, gyro bias and scale, time offset, 1 sigma; calib/rotation_calibration.hpp).
// The calibration (this record's own, or another record's with this run's clock offset and
// standstill bias) is applied to the gyro: every motion segment whose rotation the gyro lost by
// 5 deg or more is listed, and the orientation error against the robot's poses from the start
// and restarted after each lost span. With an AHRS record, its own error beside it, or the
// reason it is refused as a reference. A record the calibration cannot use is an InputError.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace imscal::calib {

struct ToolImuCheckSessionOptions {
  std::string imu;               // sensor CSV (t_s, gyro_*_dps, acc_*_g, robot_*)
  std::string xsens;             // AHRS CSV of the same path; empty: none
  std::string calibration_from;  // calibrate on this record and apply it to `imu`
  bool no_restart = false;       // the orientation error from the start only
};

// Receives the report's text as it is found, a line or a block at a time.
using TextSink = std::function<void(const std::string& text)>;

// Returns the report as JSON (angles in degrees; datasets/FORMAT.md).
nlohmann::json check_tool_imu_session(const ToolImuCheckSessionOptions& options,
                                      const TextSink& print);

}  // namespace imscal::calib
