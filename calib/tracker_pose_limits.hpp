#pragma once
// A tracker pose file's joint angles against the robot's joint limits
// (core/joint_limit_plausibility.hpp).
#include <cstddef>

#include "calib/tracker_poses.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

// How many poses lie beyond a limit (warned); InputError naming file, line and column beyond the
// margin.
std::size_t check_tracker_pose_limits(const TrackerPoses& poses, const RobotDescription& robot);

}  // namespace imscal::calib
