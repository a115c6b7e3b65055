#pragma once
// The joint angles of the files a command reads against its robot's joint limits
// (core/joint_limit_plausibility.hpp): a joint_errors.csv's three angles per joint, a tracker
// pose file's joints.
#include <string>

#include "calib/robot_description.hpp"
#include "calib/robot_log.hpp"
#include "calib/tracker_poses.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::tools {

// Each returns how many samples lie beyond a limit (warned); InputError beyond the margin. A
// robot log: calib::check_robot_log_joint_limits.
std::size_t check_joint_error_limits(const ident::JointErrorLog& log, const std::string& file,
                                     const calib::RobotDescription& robot);
std::size_t check_tracker_pose_limits(const calib::TrackerPoses& poses,
                                      const calib::RobotDescription& robot);

}  // namespace imscal::tools
