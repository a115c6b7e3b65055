#pragma once
// The gyro bias a tool-IMU record's rests measure: the mean gyro reading over the samples where
// the robot stands still, with its 1 sigma. At rest the gyro reads its bias alone
// (gyro = K * 0 + b), so the rests are a direct measurement of b, independent of the scale,
// coupling and alignment that the motion windows confound it with.
// Sigma per axis: the larger of the samples' standard error (white noise) and the scatter of the
// separate rests' means over the root of their count (a bias that wanders between rests).
#include <Eigen/Core>
#include <cstddef>

#include "calib/tool_imu_record.hpp"

namespace imscal::calib {

struct GyroRestBias {
  Eigen::Vector3d mean_rad_s = Eigen::Vector3d::Zero();   // as labelled units -> SI, S axes
  Eigen::Vector3d sigma_rad_s = Eigen::Vector3d::Zero();  // 1 sigma of the mean
  std::size_t sample_count = 0;
  std::size_t rest_count = 0;  // separate spans of stillness
};

// Samples where the robot rate stays below rest_rate_rad_s over +-0.1 s around t - time_offset_s
// (the robot is not just passing through zero rate), up to max_time_s of the sensor clock;
// zero placeholder rows left out. False when fewer than 10 such samples exist (`out` then
// unchanged).
bool gyro_rest_bias(const ToolImuRecord& record, double time_offset_s, double rest_rate_rad_s,
                    GyroRestBias& out, double max_time_s = 1e300);

}  // namespace imscal::calib
