#include "calib/tracker_pose_limits.hpp"

#include <fmt/format.h>

#include <string>
#include <vector>

#include "core/joint_limit_plausibility.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

std::size_t check_tracker_pose_limits(const TrackerPoses& poses, const RobotDescription& robot) {
  std::vector<std::vector<double>> values(kJointCount);
  std::vector<std::size_t> lines;
  for (const TrackerPose& pose : poses.poses) {
    lines.push_back(pose.line);
    for (int j = 0; j < kJointCount; ++j) values[std::size_t(j)].push_back(pose.q_rad[j]);
  }
  std::vector<JointAngleColumn> columns;
  for (std::size_t j = 0; j < std::size_t(kJointCount); ++j)
    columns.push_back({fmt::format("q{}_rad", j + 1), j, values[j]});
  const auto line_of = [&lines](std::size_t k) { return k < lines.size() ? lines[k] : 0; };
  return check_joint_limits(
      columns, joint_limits_of(robot),
      {poses.file, line_of, fmt::format("robot {} ({})", robot.name, robot.source)});
}

}  // namespace imscal::calib
