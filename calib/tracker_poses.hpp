#pragma once
// Poses of a robot measured by a laser tracker (datasets/FORMAT.md, "Tracker poses"): per row the
// six joint angles and the position of the tracker's target (a retro-reflector or 6-DoF probe on
// the tool) in the tracker's own frame. A numeric table (core/numeric_table.hpp) with
//   q1_*_rad .. q6_*_rad     joint angles [rad]: for joint i the one column whose name starts
//                            with `q<i>_` and ends with `_rad` (`q1_rad`, `q1_shoulder_pan_rad`)
//   meas_x_mm, meas_y_mm, meas_z_mm    target position in the tracker frame [mm]
// and optionally the commanded target pose in the robot base (goal_x_m .. goal_z_m [m],
// goal_roll_rad, goal_pitch_rad, goal_yaw_rad: R = Rz(yaw) Ry(pitch) Rx(roll)) and the measured
// target attitude (meas_rx_deg, meas_ry_deg, meas_rz_deg: R = Rx(rx) Ry(ry) Rz(rz), moving axes).
// Other columns are ignored. The layout is that of the IPA UR10 data set
// (tests/data/real/ipa-ur10/SOURCE.md).
#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "robot/robot_description.hpp"

namespace imscal::calib {

struct TrackerPose {
  std::size_t line = 0;  // 1-based line in the file, for messages
  JointVector q_rad = JointVector::Zero();
  Eigen::Vector3d p_tracker_m = Eigen::Vector3d::Zero();
  std::optional<Eigen::Matrix3d> R_tracker;  // measured attitude, when the columns are present
  std::optional<Eigen::Isometry3d> goal;     // commanded pose in the base, when present
};

struct TrackerPoses {
  std::string file;
  std::vector<TrackerPose> poses;
};

// InputError (file, line, field) for a missing column, an ambiguous joint column, a joint angle
// beyond ±4π or a position beyond 100 m (a unit mistake), and every structural error of the table.
TrackerPoses read_tracker_poses(const std::filesystem::path& file);

}  // namespace imscal::calib
