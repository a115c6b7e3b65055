#include "calib/attitude_filter.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/input_error.hpp"
#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {

AttitudeTrack run_attitude_filter(const ToolImuRecord& record,
                                  const RotationCalibration& calibration,
                                  const AttitudeFilterOptions& options) {
  if (!record.has_raw_imu) {
    throw InputError(record.file, 0, "gyro_x_dps", "the attitude filter needs raw gyro columns");
  }
  const auto& t = record.t_s;
  // Start at the first sample with a robot pose (and not a zero placeholder row).
  std::size_t start = 0;
  Eigen::Quaterniond q_B_T;
  while (start < t.size() &&
         (t[start] < options.start_time_s || record.gyro_rad_s[start].isZero(0.0) ||
          !robot_orientation_at(record, t[start] - calibration.time_offset_s, q_B_T))) {
    ++start;
  }
  if (start + 1 >= t.size()) {
    throw InputError(record.file, 0, "robot_qw", "no robot pose to initialise the attitude from");
  }
  const Eigen::Matrix3d R_T_S = calibration.q_T_S.toRotationMatrix();
  auto rate_T = [&](std::size_t k) -> Eigen::Vector3d {
    return R_T_S * calibrated_rate_S(calibration, record.gyro_rad_s[k]);
  };

  AttitudeTrack track;
  track.t_s.push_back(t[start]);
  track.q_B_T.push_back(q_B_T);
  track.aided.push_back(false);
  for (std::size_t k = start; k + 1 < t.size(); ++k) {
    const double dt = t[k + 1] - t[k];
    // Trapezoidal rate over the interval; across a long gap hold the last sample's rate.
    Eigen::Vector3d omega_T =
        dt > options.max_step_s ? rate_T(k) : Eigen::Vector3d(0.5 * (rate_T(k) + rate_T(k + 1)));
    bool aided = false;
    if (options.use_gravity) {
      const Eigen::Vector3d f_T = R_T_S * record.acc_m_s2[k + 1];
      const double f_norm = f_T.norm();
      if (std::abs(f_norm - kStandardGravity_m_s2) <
              options.max_specific_force_deviation * kStandardGravity_m_s2 &&
          omega_T.norm() < options.max_rate_for_aiding_rad_s) {
        const Eigen::Vector3d up_T = q_B_T.conjugate() * calibration.up_B;
        // Turning the estimate by +(f x up_expected) about T moves up_expected towards f.
        omega_T += options.gravity_gain_rad_s * (f_T / f_norm).cross(up_T);
        aided = true;
      }
    }
    q_B_T = (q_B_T * ims::quat_exp<double>(omega_T * dt)).normalized();
    track.t_s.push_back(t[k + 1]);
    track.q_B_T.push_back(q_B_T);
    track.aided.push_back(aided);
  }
  return track;
}

}  // namespace imscal::calib
