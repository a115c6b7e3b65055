#include "tools/joint_limit_checks.hpp"

#include <fmt/format.h>

#include <vector>

#include "core/joint_limit_plausibility.hpp"

namespace imscal::tools {
namespace {

std::string limits_label(const calib::RobotDescription& robot) {
  return fmt::format("robot {} ({})", robot.name, robot.source);
}

std::function<std::size_t(std::size_t)> lines_of(const std::vector<std::size_t>& lines) {
  return [&lines](std::size_t k) { return k < lines.size() ? lines[k] : std::size_t(0); };
}

}  // namespace

std::size_t check_joint_error_limits(const ident::JointErrorLog& log, const std::string& file,
                                     const calib::RobotDescription& robot) {
  std::vector<JointAngleColumn> columns;
  for (std::size_t j = 0; j < log.joint_count() && j < std::size_t(calib::kJointCount); ++j) {
    const std::string& name = log.joint_names[j];
    columns.push_back({fmt::format("q_desired_{}_rad", name), j, log.q_desired_rad[j]});
    columns.push_back({fmt::format("q_measured_{}_rad", name), j, log.q_measured_rad[j]});
    columns.push_back({fmt::format("q_internal_{}_rad", name), j, log.q_internal_rad[j]});
  }
  return check_joint_limits(columns, calib::joint_limits_of(robot),
                            {file, lines_of(log.sample_lines), limits_label(robot)});
}

std::size_t check_tracker_pose_limits(const calib::TrackerPoses& poses,
                                      const calib::RobotDescription& robot) {
  std::vector<std::vector<double>> values(calib::kJointCount);
  std::vector<std::size_t> lines;
  for (const calib::TrackerPose& pose : poses.poses) {
    lines.push_back(pose.line);
    for (int j = 0; j < calib::kJointCount; ++j) values[std::size_t(j)].push_back(pose.q_rad[j]);
  }
  std::vector<JointAngleColumn> columns;
  for (std::size_t j = 0; j < std::size_t(calib::kJointCount); ++j)
    columns.push_back({fmt::format("q{}_rad", j + 1), j, values[j]});
  return check_joint_limits(columns, calib::joint_limits_of(robot),
                            {poses.file, lines_of(lines), limits_label(robot)});
}

}  // namespace imscal::tools
