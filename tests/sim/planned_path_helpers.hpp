#pragma once
// What the planner tests share: the default robot (datasets/robots/kr16.yaml), loaded once; a
// test program from a header with the shipped programs' joint limits; a planned segment by its
// label and its sample range; the flange pose by forward kinematics (independent of the IK the
// planner used).
#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/config_node.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/motion_program.hpp"

namespace imscal::sim::test {

inline const calib::RobotDescription& robot() {
  static const calib::RobotDescription r =
      calib::load_robot_description(std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/kr16.yaml");
  return r;
}

// A generic start pose, away from the singularities (elbow bent 20 deg, wrist bent 50 deg), and
// the joint limits of the shipped programs (datasets/programs/seed-line.yaml).
inline constexpr const char* kHeader = R"(
name: test
start_joints_deg: [10, -60, 80, 20, 50, 30]
profile: jerk_limited
joint_acceleration_deg_s2: [200, 200, 250, 600, 600, 900]
joint_jerk_deg_s3: [2000, 2000, 2500, 6000, 6000, 9000]
)";

inline MotionProgram program(const std::string& segments, const char* header = kHeader) {
  return parse_motion_program(
      ConfigNode::load_string(std::string(header) + "segments:\n" + segments, "test.yaml"));
}

inline const PathSegment& segment(const DesiredJointPath& path, const std::string& label) {
  for (const auto& s : path.segments) {
    if (s.label == label) return s;
  }
  throw std::runtime_error("no segment " + label);
}

// Sample indices [first, last] of a segment (borders fall on samples).
inline std::pair<std::size_t, std::size_t> range(const DesiredJointPath& path,
                                                 const PathSegment& s) {
  return {static_cast<std::size_t>(std::lround(s.begin_s / path.cycle_s)),
          static_cast<std::size_t>(std::lround(s.end_s / path.cycle_s))};
}

inline Eigen::Isometry3d fk(const calib::JointVector& q) {
  return calib::forward_kinematics<double>(robot().kinematics, q);
}

}  // namespace imscal::sim::test
