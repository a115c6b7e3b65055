#pragma once
// Orientation error of an estimated tool orientation track against the robot's reported tool
// pose (the reference), and the alignment a commercial AHRS needs before it can be compared:
// an AHRS (XSENS MTi-30) reports its sensor frame X in its own navigation frame N, so
//   R_B_T(t) = R_B_N * R_N_X(t) * R_X_T
// with two constant unknown rotations. They are fitted by least squares on the same run that
// is evaluated (generous to the AHRS: the fit absorbs any constant error) by alternating chordal
// means of sum |R_B_T - R_B_N R_N_X R_X_T|_F^2, and the AHRS's clock offset against the robot by
// cross-correlation of the rate magnitudes (its own orientation differenced).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "calib/tool_imu_record.hpp"

namespace imscal::calib {

struct OrientationErrorStats {
  double rms_rad = 0.0;
  double median_rad = 0.0;
  double p90_rad = 0.0;  // 90th percentile (linear interpolation, core/percentile.hpp)
  double max_rad = 0.0;
  double final_rad = 0.0;  // at the last compared sample
  std::size_t sample_count = 0;
};

// Angle between q_B_T_estimated[k] (at sensor time t_s[k]) and the robot's orientation at
// t_s[k] - time_offset_s, over the samples where a robot pose exists.
OrientationErrorStats orientation_error(const ToolImuRecord& record, double time_offset_s,
                                        const std::vector<double>& t_s,
                                        const std::vector<Eigen::Quaterniond>& q_B_T_estimated);

struct AhrsAlignment {
  Eigen::Quaterniond q_B_N = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond q_X_T = Eigen::Quaterniond::Identity();
  double time_offset_s = 0.0;  // t_ahrs = t_robot + offset
  double time_offset_peak_correlation = 0.0;
  std::vector<double> t_s;                // AHRS clock
  std::vector<Eigen::Quaterniond> q_B_T;  // the AHRS's tool orientation after the alignment
  int iterations = 0;
  bool ahrs_quaternion_conjugated = false;  // the transposed reading fitted better
};

// Needs record.has_sensor_orientation. InputError when the rates cannot be correlated.
AhrsAlignment align_ahrs_to_robot(const ToolImuRecord& record, double max_abs_offset_s = 0.5);

}  // namespace imscal::calib
