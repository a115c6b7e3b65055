#include "robot/robot_description.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "robot/urdf_robot.hpp"

namespace imscal::calib {
namespace {

// Numbers with a sign requirement; `what` completes "expected ...".
double number_at_least(const ConfigNode& parent, std::string_view key, double minimum,
                       bool strictly) {
  const ConfigNode node = parent.child(key);
  const double value = node.as_double();
  if (strictly ? !(value > minimum) : !(value >= minimum)) {
    node.fail(
        fmt::format("expected a number {} {}, got {}", strictly ? ">" : ">=", minimum, value));
  }
  return value;
}
double positive(const ConfigNode& parent, std::string_view key) {
  return number_at_least(parent, key, 0.0, true);
}
double non_negative(const ConfigNode& parent, std::string_view key) {
  return number_at_least(parent, key, 0.0, false);
}

std::string non_empty_string(const ConfigNode& parent, std::string_view key) {
  const ConfigNode node = parent.child(key);
  std::string value = node.as_string();
  if (value.empty()) node.fail("expected a non-empty string");
  return value;
}

// {xyz_m: [x, y, z], rpy_deg: [roll, pitch, yaw]} (the keys may sit in a larger map).
Eigen::Isometry3d read_pose(const ConfigNode& node) {
  const Eigen::Vector3d xyz = node.child("xyz_m").as_vector3();
  const Eigen::Vector3d rpy_deg = node.child("rpy_deg").as_vector3();
  return pose_from_xyz_rpy(xyz, rpy_deg * kRadPerDeg);
}

// inertia_kg_m2: [ixx, iyy, izz, ixy, ixz, iyz] about the centre of mass. A physical inertia
// tensor has non-negative principal moments obeying the triangle inequality.
Eigen::Matrix3d read_inertia(const ConfigNode& parent) {
  const ConfigNode node = parent.child("inertia_kg_m2");
  const std::vector<double> v = node.as_doubles();
  if (v.size() != 6) {
    node.fail(fmt::format("expected 6 numbers [ixx, iyy, izz, ixy, ixz, iyz], got {}", v.size()));
  }
  Eigen::Matrix3d inertia;
  inertia << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
  const Eigen::Vector3d moments =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvalues();  // ascending
  // Tolerance: 1e-9 of the largest moment absorbs rounding in hand-written values.
  const double tolerance = 1e-9 * std::max(1.0, moments.cwiseAbs().maxCoeff());
  if (moments.minCoeff() < -tolerance) node.fail("inertia has a negative principal moment");
  if (moments(0) + moments(1) < moments(2) - tolerance) {
    node.fail("principal moments violate the triangle inequality (no real body has them)");
  }
  return inertia;
}

RigidBodyParameters read_body(const ConfigNode& node) {
  RigidBodyParameters body;
  body.mass_kg = non_negative(node, "mass_kg");
  body.com_m = node.child("com_m").as_vector3();
  body.inertia_kg_m2 = read_inertia(node);
  return body;
}

DriveParameters read_drive(const ConfigNode& node) {
  node.require_only_keys({"gear_ratio", "motor_inertia_kg_m2", "stiffness_nm_per_rad",
                          "damping_nm_s_per_rad", "backlash_deg", "coulomb_nm",
                          "viscous_nm_s_per_rad"});
  DriveParameters drive;
  drive.gear_ratio = positive(node, "gear_ratio");
  drive.motor_inertia_kg_m2 = non_negative(node, "motor_inertia_kg_m2");
  drive.stiffness_nm_per_rad = positive(node, "stiffness_nm_per_rad");
  drive.damping_nm_s_per_rad = non_negative(node, "damping_nm_s_per_rad");
  drive.backlash_rad = non_negative(node, "backlash_deg") * kRadPerDeg;
  drive.coulomb_nm = non_negative(node, "coulomb_nm");
  drive.viscous_nm_s_per_rad = non_negative(node, "viscous_nm_s_per_rad");
  return drive;
}

JointControllerGains read_controller(const ConfigNode& node) {
  node.require_only_keys({"kp_position_1_s", "kp_velocity_nm_s_per_rad", "ki_velocity_nm_per_rad",
                          "velocity_feedforward", "torque_limit_nm"});
  JointControllerGains gains;
  gains.kp_position_1_s = positive(node, "kp_position_1_s");
  gains.kp_velocity_nm_s_per_rad = positive(node, "kp_velocity_nm_s_per_rad");
  gains.ki_velocity_nm_per_rad = non_negative(node, "ki_velocity_nm_per_rad");
  gains.velocity_feedforward = non_negative(node, "velocity_feedforward");
  if (gains.velocity_feedforward > 1.0) {
    node.child("velocity_feedforward").fail("expected a fraction between 0 and 1");
  }
  gains.torque_limit_nm = positive(node, "torque_limit_nm");
  return gains;
}

void read_joint(const ConfigNode& node, int index, KinematicModel& kinematics,
                JointDescription& joint) {
  node.require_only_keys({"name", "a_m", "alpha_deg", "d_m", "offset_deg", "limit_deg",
                          "max_velocity_deg_s", "link", "drive", "controller"});
  joint.name = non_empty_string(node, "name");
  DhParameters& dh = kinematics.dh[index];
  dh.a_m = node.child("a_m").as_double();
  dh.alpha_rad = node.child("alpha_deg").as_double() * kRadPerDeg;
  dh.d_m = node.child("d_m").as_double();
  dh.offset_rad = node.child("offset_deg").as_double() * kRadPerDeg;

  const ConfigNode limit_node = node.child("limit_deg");
  const std::vector<double> limit = limit_node.as_doubles();
  if (limit.size() != 2) limit_node.fail("expected [lower, upper] in degrees");
  if (!(limit[0] < limit[1])) limit_node.fail("expected lower < upper");
  kinematics.lower_limit_rad(index) = limit[0] * kRadPerDeg;
  kinematics.upper_limit_rad(index) = limit[1] * kRadPerDeg;
  joint.max_velocity_rad_s = positive(node, "max_velocity_deg_s") * kRadPerDeg;

  const ConfigNode link = node.child("link");
  link.require_only_keys({"mass_kg", "com_m", "inertia_kg_m2"});
  joint.link = read_body(link);
  // Drive and controller only the simulator's plant needs (sim::load_plant_robot checks them):
  // a nominal robot for kinematics, calibration and the model torque may leave them out.
  if (const auto drive = node.optional_child("drive")) joint.drive = read_drive(*drive);
  if (const auto controller = node.optional_child("controller")) {
    joint.controller = read_controller(*controller);
  }
}

}  // namespace

Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, const Eigen::Vector3d& rpy_rad) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = xyz_m;
  return pose;
}

RobotDescription parse_robot_description(const ConfigNode& root) {
  root.require_only_keys({"name", "nominal_payload_kg", "reach_m", "controller_cycle_s",
                          "convention", "base", "joints", "flange", "tool"});
  RobotDescription robot;
  robot.source = root.file();
  robot.name = non_empty_string(root, "name");
  robot.nominal_payload_kg = non_negative(root, "nominal_payload_kg");
  robot.reach_m = positive(root, "reach_m");
  robot.controller_cycle_s = positive(root, "controller_cycle_s");

  const ConfigNode convention = root.child("convention");
  const std::string convention_name = convention.as_string();
  if (convention_name == "standard_dh") {
    robot.kinematics.convention = DhConvention::kStandard;
  } else if (convention_name == "modified_dh") {
    robot.kinematics.convention = DhConvention::kModified;
  } else {
    convention.fail(
        fmt::format("expected 'standard_dh' or 'modified_dh', got '{}'", convention_name));
  }

  const ConfigNode base = root.child("base");
  base.require_only_keys({"xyz_m", "rpy_deg"});
  robot.kinematics.T_R_0 = read_pose(base);

  const ConfigNode joints_node = root.child("joints");
  const std::vector<ConfigNode> joints = joints_node.as_sequence();
  if (joints.size() != kJointCount) {
    joints_node.fail(fmt::format("expected {} joints, got {}", kJointCount, joints.size()));
  }
  for (int i = 0; i < kJointCount; ++i) {
    read_joint(joints[i], i, robot.kinematics, robot.joints[i]);
  }

  const ConfigNode flange = root.child("flange");
  flange.require_only_keys({"xyz_m", "rpy_deg"});
  robot.kinematics.T_6_H = read_pose(flange);

  const ConfigNode tool = root.child("tool");
  tool.require_only_keys({"name", "xyz_m", "rpy_deg", "mass_kg", "com_m", "inertia_kg_m2"});
  robot.tool.name = non_empty_string(tool, "name");
  robot.tool.T_H_T = read_pose(tool);
  robot.tool.body = read_body(tool);
  return robot;
}

RobotDescription load_robot_description(const std::filesystem::path& file) {
  if (file.extension() == ".urdf") return load_urdf_robot(file);
  return parse_robot_description(ConfigNode::load_file(file));
}

DriveParameters read_drive_parameters(const ConfigNode& node) {
  return read_drive(node);
}
JointControllerGains read_controller_gains(const ConfigNode& node) {
  return read_controller(node);
}
RigidBodyParameters read_rigid_body(const ConfigNode& node) {
  return read_body(node);
}
Eigen::Isometry3d read_pose_xyz_rpy_deg(const ConfigNode& node) {
  return read_pose(node);
}

}  // namespace imscal::calib
