#include "robot/ur_inverse_kinematics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "robot/forward_kinematics.hpp"
#include "robot/ik_geometry.hpp"
#include "robot/ik_refinement.hpp"

namespace imscal::calib {
namespace {

using ik_geometry::angle_about;
using ik_geometry::cross2;
using ik_geometry::distance_to_line;
using ik_geometry::nearest_point_to_lines;
using ik_geometry::rotate2;
using ik_geometry::rotation_about;
using ik_geometry::wrap_to_pi;

using ik_geometry::kStructureAngleTolerance;
using ik_geometry::kStructureDistanceTolerance;

void require(bool condition, const std::string& what) {
  if (!condition) {
    throw std::invalid_argument("UrInverseKinematics: the arm is not of the UR class: " + what);
  }
}

}  // namespace

UrInverseKinematics::UrInverseKinematics(const KinematicModel& model) : IkSolver(model) {
  const ChainPoses<double> zero = chain_poses<double>(model_, JointVector::Zero().eval());
  for (int i = 0; i < kJointCount; ++i) {
    axis_[i] = zero.T_R_axis[i].linear().col(2);
    point_[i] = zero.T_R_axis[i].translation();
  }
  T_R_H_zero_ = zero.T_R_H;
  check_structure();
  normal_ = axis_[1];
  shoulder_y_ = axis_[0].cross(normal_).normalized();
  lateral_offset_m_ = normal_.dot(wrist_point_R_ - point_[0]);
  const double wrist_ahead = shoulder_y_.dot(wrist_point_R_ - point_[0]);
  const double elbow_ahead = shoulder_y_.dot(point_[2] - point_[0]);
  front_sign_ = std::abs(wrist_ahead) > 1e-9 ? (wrist_ahead > 0 ? 1.0 : -1.0)
                                             : (elbow_ahead >= 0 ? 1.0 : -1.0);
  joint3_sign_ = axis_[2].dot(normal_) > 0 ? 1.0 : -1.0;
  joint4_sign_ = axis_[3].dot(normal_) > 0 ? 1.0 : -1.0;
  // n . R5(q5) w6 = A cos q5 + B sin q5 = rho cos(q5 - q5_0).
  const double a = normal_.dot(axis_[5]);
  const double b = normal_.dot(axis_[4].cross(axis_[5]));
  wrist_zero_angle_ = std::atan2(b, a);
  wrist_cos_scale_ = std::hypot(a, b);

  plane_a_ = shoulder_y_;
  plane_b_ = normal_.cross(plane_a_);
  shoulder_2d_ = in_plane(point_[1]);
  elbow_2d_ = in_plane(point_[2]);
  wrist_2d_ = in_plane(point_[3]);
  const Eigen::Vector2d upper_arm = elbow_2d_ - shoulder_2d_;
  const Eigen::Vector2d forearm = wrist_2d_ - elbow_2d_;
  upper_arm_m_ = upper_arm.norm();
  forearm_m_ = forearm.norm();
  require(upper_arm_m_ > kStructureDistanceTolerance, "axes 2 and 3 coincide");
  require(forearm_m_ > kStructureDistanceTolerance, "axes 3 and 4 coincide");
  stretched_angle_ =
      std::atan2(upper_arm.y(), upper_arm.x()) - std::atan2(forearm.y(), forearm.x());
  const Eigen::Vector3d forward = front_sign_ * shoulder_y_;
  elbow_up_sign_ = forward.cross(normal_).z() >= 0 ? 1.0 : -1.0;
}

void UrInverseKinematics::check_structure() {
  const double angle_errors[] = {std::abs(axis_[0].dot(axis_[1])), axis_[1].cross(axis_[2]).norm(),
                                 axis_[1].cross(axis_[3]).norm(), std::abs(axis_[3].dot(axis_[4])),
                                 std::abs(axis_[4].dot(axis_[5]))};
  const char* angle_problems[] = {
      "axis 2 is not perpendicular to axis 1", "axis 3 is not parallel to axis 2",
      "axis 4 is not parallel to axis 2", "axis 5 is not perpendicular to axis 4",
      "axis 6 is not perpendicular to axis 5"};
  double worst_angle = 0.0;
  for (int k = 0; k < 5; ++k) {
    require(angle_errors[k] < kStructureAngleTolerance, angle_problems[k]);
    worst_angle = std::max(worst_angle, angle_errors[k]);
  }
  wrist_point_R_ = nearest_point_to_lines({point_[4], point_[5]}, {axis_[4], axis_[5]});
  double worst_distance = 0.0;
  for (int i = 4; i < kJointCount; ++i) {
    const double miss = distance_to_line(wrist_point_R_, point_[i], axis_[i]);
    require(miss < kStructureDistanceTolerance,
            fmt::format("axes 5 and 6 do not meet (axis {} misses by {:.6f} m)", i + 1, miss));
    worst_distance = std::max(worst_distance, miss);
  }
  wrist_point_H_ = T_R_H_zero_.inverse() * wrist_point_R_;
  // Angle errors act over the arm's whole length (base to flange at q = 0).
  double length_m = 0.0;
  for (int i = 1; i < kJointCount; ++i) length_m += (point_[i] - point_[i - 1]).norm();
  length_m += (T_R_H_zero_.translation() - point_[5]).norm();
  structure_slack_m_ = 4.0 * (worst_angle * length_m + worst_distance);
  // Below 0.1 um the closed form's reach and singularity tests are exact to far below the
  // default singularity tolerance (1e-6): the UR URDFs state pi/2 to 9 digits (2e-10 rad).
  ideal_ = structure_slack_m_ < 1e-7;
}

Eigen::Vector2d UrInverseKinematics::in_plane(const Eigen::Vector3d& point_R) const {
  return {plane_a_.dot(point_R), plane_b_.dot(point_R)};
}

Eigen::Vector3d UrInverseKinematics::undo_joint_1(const Eigen::Vector3d& point_R, double q1) const {
  return turn(0, -q1, point_R);
}

Eigen::Vector3d UrInverseKinematics::turn(int joint, double angle, const Eigen::Vector3d& x) const {
  return rotation_about(axis_[joint], angle) * (x - point_[joint]) + point_[joint];
}

double UrInverseKinematics::signed_shoulder_measure(const Eigen::Vector3d& wrist_point_R,
                                                    double q1) const {
  return front_sign_ * shoulder_y_.dot(undo_joint_1(wrist_point_R, q1) - point_[0]);
}

double UrInverseKinematics::elbow_bend(double q3) const {
  return joint3_sign_ * q3 - stretched_angle_;
}

ArmConfiguration UrInverseKinematics::configuration_of(const JointVector& q) const {
  const Eigen::Vector3d wrist = forward_kinematics<double>(model_, q) * wrist_point_H_;
  ArmConfiguration c;
  c.shoulder_front = signed_shoulder_measure(wrist, q(0)) >= 0;
  c.elbow_up = elbow_up_sign_ * std::sin(elbow_bend(q(2))) >= 0;
  c.wrist_flip = std::sin(q(4) - wrist_zero_angle_) < 0;
  return c;
}

SingularityMeasures UrInverseKinematics::singularity_measures(const JointVector& q) const {
  const Eigen::Vector3d wrist = forward_kinematics<double>(model_, q) * wrist_point_H_;
  SingularityMeasures m;
  m.shoulder_m = std::abs(signed_shoulder_measure(wrist, q(0)));
  m.elbow = std::abs(std::sin(elbow_bend(q(2))));
  m.wrist = std::abs(std::sin(q(4) - wrist_zero_angle_));
  return m;
}

IkResult UrInverseKinematics::solve(const Eigen::Isometry3d& T_R_H,
                                    const ArmConfiguration& configuration,
                                    const IkOptions& options) const {
  IkResult result;
  result.configuration = configuration;
  const double tolerance = options.singularity_tolerance;
  JointVector q = JointVector::Zero();
  if (!solve_joint_1(T_R_H, configuration, tolerance, q, result) ||
      !solve_joints_5_6(T_R_H, configuration, tolerance, q, result) ||
      !solve_joints_2_3_4(T_R_H, configuration, tolerance, q, result)) {
    return result;
  }
  for (int i = 0; i < kJointCount; ++i) q(i) = wrap_to_pi(q(i));
  result.q = q;
  refine_ik(model_, T_R_H, options, result);
  finish_refined(ideal_, configuration, options, result);
  return result;
}

bool UrInverseKinematics::solve_joint_1(const Eigen::Isometry3d& T_R_H,
                                        const ArmConfiguration& configuration, double tolerance,
                                        JointVector& q, IkResult& result) const {
  // W keeps the offset c along the turned axis 2 from axis 1 (axis 5 is normal to axis 2 and
  // joints 2..4 move in planes normal to it): turn W to that offset.
  const Eigen::Vector3d from_axis1 = T_R_H * wrist_point_H_ - point_[0];
  const double x = normal_.dot(from_axis1);
  const double y = shoulder_y_.dot(from_axis1);
  const double radius = std::hypot(x, y);
  const double offset = std::abs(lateral_offset_m_);
  if (radius < offset - tolerance - structure_slack_m_) {
    result.status = IkStatus::kUnreachable;
    result.reason = fmt::format(
        "wrist point {:.6f} m from axis 1, inside the {:.6f} m offset of axis 5", radius, offset);
    return false;
  }
  const double lateral = std::sqrt(std::max(radius * radius - offset * offset, 0.0));
  if (ideal_ && lateral < tolerance) {
    result.status = IkStatus::kShoulderSingular;
    result.reason = fmt::format(
        "wrist point {:.3g} m from the shoulder singularity (the {:.6f} m cylinder about axis 1)",
        lateral, offset);
    return false;
  }
  const double branch1 = configuration.shoulder_front ? front_sign_ : -front_sign_;
  q(0) = std::atan2(y, x) - branch1 * std::acos(std::clamp(lateral_offset_m_ / radius, -1.0, 1.0));
  return true;
}

bool UrInverseKinematics::solve_joints_5_6(const Eigen::Isometry3d& T_R_H,
                                           const ArmConfiguration& configuration, double tolerance,
                                           JointVector& q, IkResult& result) const {
  // R_G = R1 R_n(q2 + q3 + q4) R5 R6: the rotation of the whole arm from q = 0.
  const Eigen::Matrix3d R_G = T_R_H.linear() * T_R_H_zero_.linear().transpose();
  const Eigen::Vector3d n1 = rotation_about(axis_[0], q(0)) * normal_;
  const double cos_bend = n1.dot(R_G * axis_[5]) / wrist_cos_scale_;
  const double sin_bend_abs = std::sqrt(std::max(0.0, 1.0 - cos_bend * cos_bend));
  if (ideal_ && sin_bend_abs < tolerance) {
    result.status = IkStatus::kWristSingular;
    result.reason = fmt::format("axis 6 parallel to axes 2, 3, 4 (|sin| of the wrist bend {:.3g})",
                                sin_bend_abs);
    return false;
  }
  constexpr double kMinimumStartBend = 1e-2;  // rad: a non-ideal start inside the branch
  double bend_abs = std::acos(std::clamp(cos_bend, -1.0, 1.0));
  if (!ideal_) bend_abs = std::clamp(bend_abs, kMinimumStartBend, M_PI - kMinimumStartBend);
  q(4) = wrist_zero_angle_ + (configuration.wrist_flip ? -bend_abs : bend_abs);
  // R6^T R5^T n = R_G^T R1 n (R_n leaves n alone): subproblem 1 about axis 6.
  const Eigen::Matrix3d R5 = rotation_about(axis_[4], q(4));
  q(5) = angle_about(axis_[5], R_G.transpose() * n1, R5.transpose() * normal_);
  return true;
}

bool UrInverseKinematics::solve_joints_2_3_4(const Eigen::Isometry3d& T_R_H,
                                             const ArmConfiguration& configuration,
                                             double tolerance, JointVector& q,
                                             IkResult& result) const {
  const Eigen::Matrix3d R_G = T_R_H.linear() * T_R_H_zero_.linear().transpose();
  const Eigen::Matrix3d R_sum = rotation_about(axis_[0], q(0)).transpose() * R_G *
                                rotation_about(axis_[5], q(5)).transpose() *
                                rotation_about(axis_[4], q(4)).transpose();
  const Eigen::Vector3d u = normal_.unitOrthogonal();
  const double theta_sum = angle_about(normal_, u, R_sum * u);
  // Axis 4 (any point on it) after joints 1..3: T_G e6^-1 e5^-1 p4, T_G = T_R_H T_R_H(0)^-1.
  const Eigen::Vector3d p4 =
      T_R_H * (T_R_H_zero_.inverse() * turn(5, -q(5), turn(4, -q(4), point_[3])));
  const Eigen::Vector2d target = in_plane(undo_joint_1(p4, q(0)));
  const Eigen::Vector2d shoulder_to_target = target - shoulder_2d_;
  const double distance = shoulder_to_target.norm();
  const double reach_min = std::abs(upper_arm_m_ - forearm_m_);
  const double reach_max = upper_arm_m_ + forearm_m_;
  const double slack = structure_slack_m_;
  if (distance > reach_max + tolerance + slack || distance < reach_min - tolerance - slack) {
    result.status = IkStatus::kUnreachable;
    result.reason =
        fmt::format("axis 4 {:.6f} m from axis 2, outside the arm's reach [{:.6f}, {:.6f}] m",
                    distance, reach_min, reach_max);
    return false;
  }
  const double cos_bend =
      (distance * distance - upper_arm_m_ * upper_arm_m_ - forearm_m_ * forearm_m_) /
      (2.0 * upper_arm_m_ * forearm_m_);
  const double sin_bend_abs = std::sqrt(std::max(0.0, 1.0 - cos_bend * cos_bend));
  if (ideal_ && sin_bend_abs < tolerance) {
    result.status = IkStatus::kElbowSingular;
    result.reason = fmt::format("arm {} (|sin| of the elbow bend {:.3g})",
                                cos_bend > 0 ? "stretched" : "folded", sin_bend_abs);
    return false;
  }
  constexpr double kMinimumStartBend = 1e-2;  // rad
  double bend_abs = std::acos(std::clamp(cos_bend, -1.0, 1.0));
  if (!ideal_) bend_abs = std::clamp(bend_abs, kMinimumStartBend, M_PI - kMinimumStartBend);
  const double branch3 = configuration.elbow_up ? elbow_up_sign_ : -elbow_up_sign_;
  const double theta3 = stretched_angle_ + branch3 * bend_abs;
  const Eigen::Vector2d wrist_moved = elbow_2d_ + rotate2(wrist_2d_ - elbow_2d_, theta3);
  const Eigen::Vector2d shoulder_to_wrist = wrist_moved - shoulder_2d_;
  const double theta2 = std::atan2(cross2(shoulder_to_wrist, shoulder_to_target),
                                   shoulder_to_wrist.dot(shoulder_to_target));
  q(1) = theta2;
  q(2) = joint3_sign_ * theta3;
  q(3) = joint4_sign_ * (theta_sum - theta2 - theta3);
  return true;
}

}  // namespace imscal::calib
