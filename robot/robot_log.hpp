#pragma once
// The robot controller's log of a measurement run (robot.csv): every interpolation cycle the
// desired joint angles it commanded and the joint angles its internal sensors (motor encoders /
// gear ratio) reported, and the payload it was told it carries. Format: datasets/FORMAT.md §2.
//
//   # imscal-robot-log: 1
//   # robot: kr16
//   # cycle_s: 0.002
//   t_s,payload_kg,q_desired_A1_rad,...,q_desired_A6_rad,q_internal_A1_rad,...,q_internal_A6_rad
//
// Angles may also be given in degrees (`_deg` columns); the reader converts and says so.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/joint_limit_plausibility.hpp"
#include "core/spillable_vector.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

struct RobotLogSample {
  double t_s = 0.0;  // robot clock [s]
  double payload_kg = 0.0;
  JointVector q_desired_rad = JointVector::Zero();
  JointVector q_internal_rad = JointVector::Zero();
};

struct RobotLog {
  std::string robot_name;
  double cycle_s = 0.002;
  std::array<std::string, kJointCount> joint_names{"A1", "A2", "A3", "A4", "A5", "A6"};
  // In memory, or in a temporary file for a long log (core/spillable_vector.hpp).
  SpillableVector<RobotLogSample> samples;
  std::vector<std::size_t> sample_lines;  // 1-based file line of each sample (empty: not read)
};

void write_robot_log_csv(const std::filesystem::path& file, const RobotLog& log,
                         Overwrite overwrite);
std::string format_robot_log_csv(const RobotLog& log);

// Checks (InputError with file, line, field): the header lines, every column present once,
// finite numbers, time strictly increasing, no step longer than 1.5 cycles (a gap: the controller
// lost cycles, the log cannot be used as one run), steps shorter than 0.5 cycle (jitter beyond
// what a real-time controller produces), a negative payload. `expected_robot`, when not empty,
// must match the file's robot; `expected_by` names where it comes from, for the message.
// `samples_to_file`: the samples go to a temporary file as they are read (core/
// spillable_vector.hpp), for a command that holds a long log whole (calibrate).
RobotLog read_robot_log_csv(const std::filesystem::path& file,
                            const std::string& expected_robot = "",
                            const std::string& expected_by = "the robot description",
                            bool samples_to_file = false);

// The robot's joint limits by joint name (core/joint_limit_plausibility.hpp).
std::vector<JointLimit> joint_limits_of(const RobotDescription& robot);

// The log's desired and internal angles against the robot's joint limits: a warning beyond a
// limit, InputError (file, line, column, limit) beyond the margin. Returns the samples beyond.
std::size_t check_robot_log_joint_limits(const RobotLog& log, const std::string& file,
                                         const RobotDescription& robot);

}  // namespace imscal::calib
