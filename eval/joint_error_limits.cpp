#include "eval/joint_error_limits.hpp"

#include <fmt/format.h>

#include <vector>

#include "calib/robot_log.hpp"
#include "core/joint_limit_plausibility.hpp"

namespace imscal::eval {

std::size_t check_joint_error_limits(const ident::JointErrorLog& log, const std::string& file,
                                     const calib::RobotDescription& robot) {
  std::vector<JointAngleColumn> columns;
  for (std::size_t j = 0; j < log.joint_count() && j < std::size_t(calib::kJointCount); ++j) {
    const std::string& name = log.joint_names[j];
    columns.push_back({fmt::format("q_desired_{}_rad", name), j, log.q_desired_rad[j]});
    columns.push_back({fmt::format("q_measured_{}_rad", name), j, log.q_measured_rad[j]});
    if (log.has_q_internal())
      columns.push_back({fmt::format("q_internal_{}_rad", name), j, log.q_internal_rad[j]});
  }
  const std::vector<std::size_t>& lines = log.sample_lines;
  const auto line_of = [&lines](std::size_t k) { return k < lines.size() ? lines[k] : 0; };
  return check_joint_limits(
      columns, calib::joint_limits_of(robot),
      {file, line_of, fmt::format("robot {} ({})", robot.name, robot.source)});
}

}  // namespace imscal::eval
