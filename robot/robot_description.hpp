#pragma once
// The description of a 6-axis serial robot: kinematics (Denavit-Hartenberg, standard or
// modified), joint limits, the flange frame H after joint 6 and a tool/sensor mounted on it, and
// for simulation the link inertias, the drives (gear, motor, elasticity, backlash, friction) and
// the joint-controller gains.
//
// Frames: R robot base; 0..6 the DH link frames (frame i is fixed to link i); H the flange
// (KUKA $FLANGE: z out of the flange face); T the mounted tool (for the IMS: the sensor frame S).
// T_R_0 places DH frame 0 in R, T_6_H the flange on link 6, T_H_T the tool on the flange.
//
// Units are SI inside (m, rad, kg, N m); the YAML file uses degrees where the key says so
// (`alpha_deg`, `limit_deg`, `backlash_deg`, `rpy_deg`). See datasets/robots/kr16.yaml for the
// file format; every key is checked, unknown keys are refused (InputError with file/line/key).
//
// References (docs/references.md): [DH1955], [Craig1986], [Spong2006].
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>

namespace imscal {
class ConfigNode;
}

namespace imscal::calib {

inline constexpr int kJointCount = 6;
using JointVector = Eigen::Matrix<double, kJointCount, 1>;  // joint angles [rad]

// Standard DH (Denavit-Hartenberg 1955; Spong): A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i),
// joint i turns about z_{i-1}. Modified DH (Craig 1986): A_i = Rx(alpha_{i-1}) Tx(a_{i-1})
// Rz(theta_i) Tz(d_i), joint i turns about z_i; row i then holds a_{i-1}, alpha_{i-1}, d_i.
// In both, theta_i = q_i + offset_i.
enum class DhConvention { kStandard, kModified };

struct DhParameters {
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double d_m = 0.0;
  double offset_rad = 0.0;  // theta_i = q_i + offset_i
};

// The purely kinematic part: what forward/inverse kinematics and the calibration need.
struct KinematicModel {
  DhConvention convention = DhConvention::kStandard;
  Eigen::Isometry3d T_R_0 = Eigen::Isometry3d::Identity();  // DH frame 0 in the base R
  std::array<DhParameters, kJointCount> dh{};
  Eigen::Isometry3d T_6_H = Eigen::Isometry3d::Identity();  // flange in DH frame 6
  JointVector lower_limit_rad = JointVector::Constant(-M_PI);
  JointVector upper_limit_rad = JointVector::Constant(M_PI);
};

// Mass properties of a rigid body; com and inertia in the axes of the body's own frame (DH frame
// i for link i, frame T for the tool), inertia about the centre of mass.
struct RigidBodyParameters {
  double mass_kg = 0.0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();
};

// One drive: motor -> gear (ratio N: motor angle = N * joint angle) -> elastic output.
// Stiffness, damping, backlash and friction act on the joint (output) side.
struct DriveParameters {
  double gear_ratio = 1.0;
  double motor_inertia_kg_m2 = 0.0;   // rotor + gear input, about the motor axis (motor side)
  double stiffness_nm_per_rad = 0.0;  // gear torsional stiffness (output side)
  double damping_nm_s_per_rad = 0.0;  // gear structural damping (output side)
  double backlash_rad = 0.0;          // full width of the play (dead zone is +-backlash/2)
  double coulomb_nm = 0.0;            // Coulomb friction torque (output side)
  double viscous_nm_s_per_rad = 0.0;  // viscous friction (output side)
};

// Cascaded joint controller (joint-side units): position P -> velocity PI -> torque.
//   w_cmd = qd_dot * velocity_feedforward + kp_position * (q_d - q_m)
//   tau   = kp_velocity * (w_cmd - q_m_dot) + ki_velocity * integral(w_cmd - q_m_dot)
// where q_m = motor angle / gear ratio (the internal sensor), tau the joint-side drive torque.
struct JointControllerGains {
  double kp_position_1_s = 0.0;
  double kp_velocity_nm_s_per_rad = 0.0;
  double ki_velocity_nm_per_rad = 0.0;
  double velocity_feedforward = 1.0;  // dimensionless, 0..1
  double torque_limit_nm = 0.0;       // joint-side drive torque limit, > 0
};

struct JointDescription {
  std::string name;
  double max_velocity_rad_s = 0.0;
  RigidBodyParameters link;  // link i, in DH frame i
  DriveParameters drive;
  JointControllerGains controller;
};

struct ToolDescription {
  std::string name;
  Eigen::Isometry3d T_H_T = Eigen::Isometry3d::Identity();
  RigidBodyParameters body;  // in frame T
};

struct RobotDescription {
  std::string name;
  std::string source;  // file it was read from (for messages)
  double nominal_payload_kg = 0.0;
  double reach_m = 0.0;               // stated reach of the wrist centre from axis 1 (information)
  double controller_cycle_s = 0.002;  // joint-controller / interpolation cycle
  KinematicModel kinematics;
  std::array<JointDescription, kJointCount> joints;
  ToolDescription tool;
};

// Reads and validates a robot description; any problem -> InputError(file, line, key, why).
// A file ending in `.urdf` is read as a URDF (robot/urdf_robot.hpp) with its optional side file.
RobotDescription load_robot_description(const std::filesystem::path& file);
// The same from a parsed YAML root (lets tests feed text through ConfigNode::load_string).
RobotDescription parse_robot_description(const ConfigNode& root);

// Readers of the parts of a robot file, shared with the URDF side file (same keys and checks).
DriveParameters read_drive_parameters(const ConfigNode& node);
JointControllerGains read_controller_gains(const ConfigNode& node);
RigidBodyParameters read_rigid_body(const ConfigNode& node);      // mass_kg, com_m, inertia_kg_m2
Eigen::Isometry3d read_pose_xyz_rpy_deg(const ConfigNode& node);  // xyz_m, rpy_deg

// x-y-z fixed-axis roll/pitch/yaw as in URDF: R = Rz(yaw) Ry(pitch) Rx(roll) [rad].
Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, const Eigen::Vector3d& rpy_rad);

}  // namespace imscal::calib
