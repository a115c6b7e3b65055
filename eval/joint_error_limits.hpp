#pragma once
// A joint_errors.csv's three angles per joint against the robot's joint limits
// (core/joint_limit_plausibility.hpp).
#include <cstddef>
#include <string>

#include "ident/joint_error_io.hpp"
#include "robot/robot_description.hpp"

namespace imscal::eval {

// How many samples lie beyond a limit (warned); InputError naming file, line and column beyond
// the margin.
std::size_t check_joint_error_limits(const ident::JointErrorLog& log, const std::string& file,
                                     const calib::RobotDescription& robot);

}  // namespace imscal::eval
