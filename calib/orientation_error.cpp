#include "calib/orientation_error.hpp"

#include <cmath>

#include "calib/hand_eye.hpp"
#include "calib/time_offset.hpp"
#include "core/input_error.hpp"
#include "core/percentile.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {

OrientationErrorStats orientation_error(const ToolImuRecord& record, double time_offset_s,
                                        const std::vector<double>& t_s,
                                        const std::vector<Eigen::Quaterniond>& q_B_T_estimated) {
  OrientationErrorStats stats;
  std::vector<double> angles;
  angles.reserve(t_s.size());
  double sum_sq = 0.0;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    Eigen::Quaterniond q_robot;
    if (!robot_orientation_at(record, t_s[k] - time_offset_s, q_robot)) continue;
    const double angle = ims::rotation_angle_between(q_robot, q_B_T_estimated[k]);
    sum_sq += angle * angle;
    angles.push_back(angle);
    stats.max_rad = std::max(stats.max_rad, angle);
    stats.final_rad = angle;
    ++stats.sample_count;
  }
  if (stats.sample_count > 0) {
    stats.rms_rad = std::sqrt(sum_sq / stats.sample_count);
    stats.median_rad = percentile(angles, 50.0);
    stats.p90_rad = percentile(angles, 90.0);
  }
  return stats;
}

AhrsAlignment align_ahrs_to_robot(const ToolImuRecord& record, double max_abs_offset_s) {
  if (!record.has_sensor_orientation) {
    throw InputError(record.file, 0, "sens_q0", "the AHRS alignment needs sens_q0..3");
  }
  AhrsAlignment alignment;
  // Clock offset: |omega| of the robot pose against |omega| of the AHRS's own orientation
  // (differenced over neighbouring samples, stamped at the interval's middle).
  const RobotRateSeries robot = robot_tool_rate(record);
  RateMagnitudeSeries robot_magnitude{{}, {}, record.file + " robot pose"};
  for (std::size_t k = 0; k < robot.t_s.size(); ++k) {
    robot_magnitude.t_s.push_back(robot.t_s[k]);
    robot_magnitude.rate_rad_s.push_back(robot.omega_T_rad_s[k].norm());
  }
  RateMagnitudeSeries ahrs_magnitude{{}, {}, record.file + " AHRS orientation"};
  for (std::size_t k = 0; k + 1 < record.t_s.size(); ++k) {
    const double dt = record.t_s[k + 1] - record.t_s[k];
    ahrs_magnitude.t_s.push_back(0.5 * (record.t_s[k] + record.t_s[k + 1]));
    ahrs_magnitude.rate_rad_s.push_back(
        ims::rotation_angle_between(record.q_N_X[k], record.q_N_X[k + 1]) / dt);
  }
  TimeOffsetOptions offset_options;
  offset_options.max_abs_offset_s = max_abs_offset_s;
  offset_options.coarse_step_s = 0.005;
  const TimeOffsetResult offset =
      estimate_time_offset(robot_magnitude, ahrs_magnitude, offset_options);
  alignment.time_offset_s = offset.offset_s;
  alignment.time_offset_peak_correlation = offset.peak_correlation;

  // Pairs (robot R_B_T, AHRS R_N_X) at the same instant.
  std::vector<Eigen::Matrix3d> robot_R, ahrs_R;
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    Eigen::Quaterniond q_robot;
    if (!robot_orientation_at(record, record.t_s[k] - alignment.time_offset_s, q_robot)) continue;
    robot_R.push_back(q_robot.toRotationMatrix());
    ahrs_R.push_back(record.q_N_X[k].toRotationMatrix());
  }
  if (robot_R.size() < 3) {
    throw InputError(record.file, 0, "robot_qw", "fewer than 3 robot poses to align the AHRS");
  }
  // Alternating chordal means; start with R_X_T = I and R_B_N from the first pair. The AHRS's
  // quaternion convention is not named in the file: both readings (R_N_X and its transpose) are
  // fitted and the one with the smaller residual kept (generous to the AHRS).
  auto fit = [&](const std::vector<Eigen::Matrix3d>& ahrs, Eigen::Matrix3d& R_B_N,
                 Eigen::Matrix3d& R_X_T) {
    R_X_T = Eigen::Matrix3d::Identity();
    R_B_N = robot_R.front() * ahrs.front().transpose();
    int iteration = 0;
    for (; iteration < 200; ++iteration) {
      Eigen::Matrix3d sum_bn = Eigen::Matrix3d::Zero();
      for (std::size_t i = 0; i < robot_R.size(); ++i) {
        sum_bn += robot_R[i] * R_X_T.transpose() * ahrs[i].transpose();
      }
      const Eigen::Matrix3d new_B_N = nearest_rotation(sum_bn);
      Eigen::Matrix3d sum_xt = Eigen::Matrix3d::Zero();
      for (std::size_t i = 0; i < robot_R.size(); ++i) {
        sum_xt += ahrs[i].transpose() * new_B_N.transpose() * robot_R[i];
      }
      const Eigen::Matrix3d new_X_T = nearest_rotation(sum_xt);
      const double change = (new_B_N - R_B_N).norm() + (new_X_T - R_X_T).norm();
      R_B_N = new_B_N;
      R_X_T = new_X_T;
      if (change < 1e-12) break;
    }
    double cost = 0.0;
    for (std::size_t i = 0; i < robot_R.size(); ++i) {
      cost += (robot_R[i] - R_B_N * ahrs[i] * R_X_T).squaredNorm();
    }
    return std::make_pair(cost, iteration);
  };
  std::vector<Eigen::Matrix3d> ahrs_transposed;
  for (const auto& R : ahrs_R) ahrs_transposed.push_back(R.transpose());
  Eigen::Matrix3d R_B_N, R_X_T, R_B_N_alt, R_X_T_alt;
  const auto [cost, iterations] = fit(ahrs_R, R_B_N, R_X_T);
  const auto [cost_alt, iterations_alt] = fit(ahrs_transposed, R_B_N_alt, R_X_T_alt);
  alignment.ahrs_quaternion_conjugated = cost_alt < cost;
  if (alignment.ahrs_quaternion_conjugated) {
    R_B_N = R_B_N_alt;
    R_X_T = R_X_T_alt;
  }
  alignment.iterations = alignment.ahrs_quaternion_conjugated ? iterations_alt : iterations;
  alignment.q_B_N = Eigen::Quaterniond(R_B_N);
  alignment.q_X_T = Eigen::Quaterniond(R_X_T);
  alignment.t_s = record.t_s;
  for (const auto& q_file : record.q_N_X) {
    const Eigen::Quaterniond q_N_X =
        alignment.ahrs_quaternion_conjugated ? q_file.conjugate() : q_file;
    alignment.q_B_T.push_back((alignment.q_B_N * q_N_X * alignment.q_X_T).normalized());
  }
  return alignment;
}

}  // namespace imscal::calib
