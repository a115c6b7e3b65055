#include "calib/gyro_rest_bias.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace imscal::calib {

namespace {

bool robot_still_at(const RobotRateSeries& robot, double t_s, double rest_rate_rad_s) {
  for (double dt : {-0.1, 0.0, 0.1}) {
    Eigen::Vector3d w;
    if (!robot_rate_at(robot, t_s + dt, w) || w.norm() > rest_rate_rad_s) return false;
  }
  return true;
}

// Per rest (a run of consecutive still samples), the sum of its readings and its count.
struct RestSum {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t count = 0;
};

}  // namespace

bool gyro_rest_bias(const ToolImuRecord& record, double time_offset_s, double rest_rate_rad_s,
                    GyroRestBias& out, double max_time_s) {
  const RobotRateSeries robot = robot_tool_rate(record);
  std::vector<RestSum> rests;
  std::vector<std::size_t> samples;
  bool in_rest = false;
  for (std::size_t k = 0; k < record.t_s.size() && record.t_s[k] <= max_time_s; ++k) {
    // The first samples of a record may be zero placeholders (the files' first row is all zero).
    const bool still = robot_still_at(robot, record.t_s[k] - time_offset_s, rest_rate_rad_s) &&
                       !record.gyro_rad_s[k].isZero(0.0);
    if (!still) {
      in_rest = false;
      continue;
    }
    if (!in_rest) rests.emplace_back();
    in_rest = true;
    rests.back().sum += record.gyro_rad_s[k];
    ++rests.back().count;
    samples.push_back(k);
  }
  if (samples.size() < 10) return false;
  const double n = static_cast<double>(samples.size());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k : samples) mean += record.gyro_rad_s[k];
  mean /= n;
  Eigen::Vector3d scatter = Eigen::Vector3d::Zero();
  for (std::size_t k : samples) scatter += (record.gyro_rad_s[k] - mean).cwiseAbs2();
  Eigen::Vector3d sigma = (scatter / (n * (n - 1.0))).cwiseSqrt();
  if (rests.size() >= 2) {
    const double m = static_cast<double>(rests.size());
    Eigen::Vector3d between = Eigen::Vector3d::Zero();
    for (const RestSum& rest : rests) {
      between += (rest.sum / static_cast<double>(rest.count) - mean).cwiseAbs2();
    }
    sigma = sigma.cwiseMax((between / (m * (m - 1.0))).cwiseSqrt());
  }
  out.mean_rad_s = mean;
  out.sigma_rad_s = sigma;
  out.sample_count = samples.size();
  out.rest_count = rests.size();
  return true;
}

}  // namespace imscal::calib
