#pragma once
// A robot motion program: a start pose and a list of segments (rests, PTP joint moves, Cartesian
// lines and circles of the flange H in the base R, payload changes), read from YAML and turned
// into the sampled desired joint path by sim/motion_planner.hpp.
//
// File format (datasets/programs/*.yaml; every key is checked, unknown keys are refused):
//
//   name: seed-line                      # free text
//   start_joints_deg: [0, -90, 90, 0, 45, 0]   # start pose q(0) [deg], at rest
//   profile: jerk_limited                # default for every move: trapezoidal | jerk_limited
//   joint_acceleration_deg_s2: [6 numbers]  # max joint accelerations (the robot file has none)
//   joint_jerk_deg_s3: [6 numbers]       # max joint jerks; required for jerk_limited PTP moves
//   payload: {name: none, mass_kg: 0, com_m: [0, 0, 0]}   # carried at the start (optional;
//                                        # default: none, 0 kg); also inertia_kg_m2 (optional,
//                                        # [ixx, iyy, izz, ixy, ixz, iyz] about the com, frame T)
//   segments:                            # each item is a map with exactly one key, the kind:
//     - rest: {duration_s: 5, label: "settle"}
//     - ptp:                             # synchronised joint move, straight line in joint space
//         joints_deg: [6 numbers]        #   target joints, or
//         pose: {xyz_mm: [x, y, z], rpy_deg: [r, p, y]}  # target flange pose T_R_H: IK solution
//                                        #   nearest (per joint, within the limits) to the
//                                        #   current joints
//         velocity_scale: 1.0            #   fraction (0, 1] of each joint's max velocity
//         acceleration_scale: 1.0        #   fraction (0, 1] of the max accelerations (and jerks)
//         profile: trapezoidal           #   optional override of the default profile
//         label: "A1 +"                  #   optional; generated ("ptp 3") if absent
//     - lin:                             # straight line of the flange origin
//         to: {xyz_mm: [x, y, z], rpy_deg: [r, p, y]}   # absolute target (rpy_deg optional), or
//         by: {xyz_mm: [dx, dy, dz]}     #   relative to the current flange position, in R
//         velocity_m_s: 0.4              #   path velocity (cruise)
//         acceleration_m_s2: 1.0         #   path acceleration
//         jerk_m_s3: 10                  #   path jerk (jerk_limited only)
//         orientation: constant          #   constant (default) | slerp (to rpy_deg of `to`)
//         profile, label                 #   as for ptp
//     - circ:                            # arc through a via point to a target (one circle)
//         via_mm: [x, y, z]
//         to: {xyz_mm: [x, y, z], rpy_deg: [...]}        # rpy_deg only with orientation: slerp
//         velocity_m_s, acceleration_m_s2, jerk_m_s3, orientation, profile, label
//     - circle:                          # arc about a centre, starting at the current position
//         centre_mm: [x, y, z]           #   the current flange position must lie on the circle
//         normal: [nx, ny, nz]           #   axis (any length); positive turn by the right hand
//         radius_mm: 100                 #   checked against the current position (1e-6 m)
//         angle_deg: 360                 #   turn angle (default 360: full circle), may be < 0
//         velocity_m_s, acceleration_m_s2, jerk_m_s3, profile, label   # orientation constant
//     - payload: {name: box16, mass_kg: 16, com_m: [0, 0, 0.1], inertia_kg_m2: [...]}
//                                        # switch the carried load (frame T); only at the program
//                                        # start or right after a rest
//
// Units in the file as the keys say (deg, mm, m/s); SI in memory. Cartesian poses are of the
// flange H in the robot base R, rpy as in calib::pose_from_xyz_rpy (R = Rz(y) Ry(p) Rx(r)).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/motion_profile.hpp"

namespace imscal {
class ConfigNode;
}

namespace imscal::sim {

enum class ProgramStepKind {
  kRest,
  kPtp,
  kLinear,
  kCircleThroughVia,
  kCircleAboutCentre,
  kPayload
};
enum class OrientationMode { kConstant, kSlerp };

// Cartesian profile of a LIN/CIRC move along its arc length.
struct PathLimits {
  double velocity_m_s = 0.0;
  double acceleration_m_s2 = 0.0;
  double jerk_m_s3 = 0.0;  // 0 when not given
};

struct ProgramStep {
  ProgramStepKind kind = ProgramStepKind::kRest;
  std::string label;
  std::size_t line = 0;   // in the program file, for messages
  std::size_t index = 0;  // position in MotionProgram::steps
  ProfileKind profile = ProfileKind::kJerkLimited;

  double duration_s = 0.0;  // rest

  // ptp: exactly one of the two targets.
  std::optional<calib::JointVector> target_joints_rad;
  std::optional<Eigen::Isometry3d> target_pose;  // T_R_H
  double velocity_scale = 1.0;
  double acceleration_scale = 1.0;

  // lin / circ: target position (absolute, or an offset in R when target_is_offset), and the
  // target orientation (only used with kSlerp).
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  bool target_is_offset = false;
  std::optional<Eigen::Matrix3d> target_rotation;
  Eigen::Vector3d via_m = Eigen::Vector3d::Zero();  // circ
  // circle about a centre
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double radius_m = 0.0;
  double angle_rad = 2.0 * M_PI;
  PathLimits path;
  OrientationMode orientation = OrientationMode::kConstant;

  Payload payload;  // payload change
};

struct MotionProgram {
  std::string name;
  std::string source;  // the file, for messages
  calib::JointVector start_joints_rad = calib::JointVector::Zero();
  ProfileKind default_profile = ProfileKind::kJerkLimited;
  calib::JointVector max_acceleration_rad_s2 = calib::JointVector::Zero();
  std::optional<calib::JointVector> max_jerk_rad_s3;
  Payload initial_payload;  // default: "none", 0 kg
  std::vector<ProgramStep> steps;
};

MotionProgram load_motion_program(const std::filesystem::path& file);
MotionProgram parse_motion_program(const ConfigNode& root);

const char* to_string(ProgramStepKind kind);

}  // namespace imscal::sim
