#include "robot/inverse_kinematics.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

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

}  // namespace

InverseKinematics::InverseKinematics(const KinematicModel& model) : IkSolver(model) {
  const ChainPoses<double> zero = chain_poses<double>(model_, JointVector::Zero().eval());
  for (int i = 0; i < kJointCount; ++i) {
    axis_[i] = zero.T_R_axis[i].linear().col(2);
    point_[i] = zero.T_R_axis[i].translation();
  }
  R_R_H_zero_ = zero.T_R_H.linear();

  auto require = [](bool condition, const std::string& what) {
    if (!condition) {
      throw std::invalid_argument(
          "InverseKinematics: the arm is not a 6R arm with a spherical "
          "wrist of the usual class: " +
          what);
    }
  };
  const double angle_errors[] = {std::abs(axis_[0].dot(axis_[1])), axis_[1].cross(axis_[2]).norm(),
                                 std::abs(axis_[3].dot(axis_[4])),
                                 std::abs(axis_[4].dot(axis_[5]))};
  const char* angle_problems[] = {
      "axis 2 is not perpendicular to axis 1", "axis 3 is not parallel to axis 2",
      "axis 5 is not perpendicular to axis 4", "axis 6 is not perpendicular to axis 5"};
  double worst_angle = 0.0;
  for (int k = 0; k < 4; ++k) {
    require(angle_errors[k] < kStructureAngleTolerance, angle_problems[k]);
    worst_angle = std::max(worst_angle, angle_errors[k]);
  }
  wrist_centre_R_ =
      nearest_point_to_lines({point_[3], point_[4], point_[5]}, {axis_[3], axis_[4], axis_[5]});
  double worst_distance = 0.0;
  for (int i = 3; i < kJointCount; ++i) {
    const double miss = distance_to_line(wrist_centre_R_, point_[i], axis_[i]);
    require(miss < kStructureDistanceTolerance,
            fmt::format("axis {} misses the wrist centre by {:.6f} m", i + 1, miss));
    worst_distance = std::max(worst_distance, miss);
  }
  wrist_centre_H_ = zero.T_R_H.inverse() * wrist_centre_R_;

  shoulder_x_ = axis_[1];
  shoulder_y_ = axis_[0].cross(axis_[1]).normalized();
  lateral_offset_m_ = shoulder_x_.dot(wrist_centre_R_ - point_[0]);
  // "Front" is where the wrist centre (else the elbow) lies at q = 0.
  const double wrist_ahead = shoulder_y_.dot(wrist_centre_R_ - point_[0]);
  const double elbow_ahead = shoulder_y_.dot(point_[2] - point_[0]);
  front_sign_ = std::abs(wrist_ahead) > 1e-9 ? (wrist_ahead > 0 ? 1.0 : -1.0)
                                             : (elbow_ahead >= 0 ? 1.0 : -1.0);

  plane_a_ = shoulder_y_;
  plane_b_ = axis_[1].cross(plane_a_);
  shoulder_2d_ = in_plane(point_[1]);
  elbow_2d_ = in_plane(point_[2]);
  wrist_2d_ = in_plane(wrist_centre_R_);
  const Eigen::Vector2d upper_arm = elbow_2d_ - shoulder_2d_;
  const Eigen::Vector2d forearm = wrist_2d_ - elbow_2d_;
  upper_arm_m_ = upper_arm.norm();
  forearm_m_ = forearm.norm();
  require(upper_arm_m_ > kStructureDistanceTolerance, "axes 2 and 3 coincide");
  require(forearm_m_ > kStructureDistanceTolerance, "the wrist centre lies on axis 3");
  // How far the closed form may be off on a non-ideal arm: angle errors act over the arm's
  // length. Below 1e-9 m the arm counts as ideal and the closed form as exact.
  structure_slack_m_ = 4.0 * (worst_angle * (upper_arm_m_ + forearm_m_) + worst_distance);
  ideal_ = structure_slack_m_ < 1e-9;
  stretched_angle_ =
      std::atan2(upper_arm.y(), upper_arm.x()) - std::atan2(forearm.y(), forearm.x());
  joint3_sign_ = axis_[2].dot(axis_[1]) > 0 ? 1.0 : -1.0;
  // A positive bend (about axis 2) puts the elbow on the (line x axis2) side of the
  // shoulder-wrist line; with the arm reaching forward that side is "up" if it has +z in R.
  const Eigen::Vector3d forward = front_sign_ * shoulder_y_;
  elbow_up_sign_ = forward.cross(axis_[1]).z() >= 0 ? 1.0 : -1.0;
}

Eigen::Vector2d InverseKinematics::in_plane(const Eigen::Vector3d& point_R) const {
  return {plane_a_.dot(point_R), plane_b_.dot(point_R)};
}

Eigen::Vector3d InverseKinematics::undo_joint_1(const Eigen::Vector3d& point_R, double q1) const {
  return rotation_about(axis_[0], -q1) * (point_R - point_[0]) + point_[0];
}

double InverseKinematics::signed_shoulder_measure(const Eigen::Vector3d& wrist_centre_R,
                                                  double q1) const {
  return front_sign_ * shoulder_y_.dot(undo_joint_1(wrist_centre_R, q1) - point_[0]);
}

double InverseKinematics::elbow_bend(double q3) const {
  return joint3_sign_ * q3 - stretched_angle_;
}

double InverseKinematics::signed_wrist_measure(double q5) const {
  const Eigen::Vector3d axis6 = rotation_about(axis_[4], q5) * axis_[5];
  return axis_[4].dot(axis_[3].cross(axis6));
}

ArmConfiguration InverseKinematics::configuration_of(const JointVector& q) const {
  const Eigen::Vector3d wrist = forward_kinematics<double>(model_, q) * wrist_centre_H_;
  ArmConfiguration c;
  c.shoulder_front = signed_shoulder_measure(wrist, q(0)) >= 0;
  c.elbow_up = elbow_up_sign_ * std::sin(elbow_bend(q(2))) >= 0;
  c.wrist_flip = signed_wrist_measure(q(4)) < 0;
  return c;
}

SingularityMeasures InverseKinematics::singularity_measures(const JointVector& q) const {
  const Eigen::Vector3d wrist = forward_kinematics<double>(model_, q) * wrist_centre_H_;
  SingularityMeasures m;
  m.shoulder_m = std::abs(signed_shoulder_measure(wrist, q(0)));
  m.elbow = std::abs(std::sin(elbow_bend(q(2))));
  m.wrist = std::abs(signed_wrist_measure(q(4)));
  return m;
}

IkResult InverseKinematics::solve(const Eigen::Isometry3d& T_R_H,
                                  const ArmConfiguration& configuration,
                                  const IkOptions& options) const {
  IkResult result;
  result.configuration = configuration;
  const double tolerance = options.singularity_tolerance;
  // On a non-ideal arm the closed form is only a start: its reach tests get slack, and its
  // singularity tests are replaced by tests of the refined solution.
  const double slack = structure_slack_m_;
  auto fail = [&](IkStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    return result;
  };

  // Joint 1: turn the wrist centre into the arm plane, whose offset from axis 1 is fixed.
  const Eigen::Vector3d wrist_target = T_R_H * wrist_centre_H_;
  const Eigen::Vector3d from_axis1 = wrist_target - point_[0];
  const double x = shoulder_x_.dot(from_axis1);
  const double y = shoulder_y_.dot(from_axis1);
  const double radius = std::hypot(x, y);
  const double lateral_sq = radius * radius - lateral_offset_m_ * lateral_offset_m_;
  if (radius < std::abs(lateral_offset_m_) - tolerance - slack) {
    return fail(IkStatus::kUnreachable,
                fmt::format("wrist centre {:.6f} m from axis 1, inside the {:.6f} m lateral "
                            "offset of the arm",
                            radius, std::abs(lateral_offset_m_)));
  }
  const double lateral = std::sqrt(std::max(lateral_sq, 0.0));
  if (ideal_ && lateral < tolerance) {
    return fail(IkStatus::kShoulderSingular,
                fmt::format("wrist centre {:.3g} m from the shoulder singularity (on axis 1 or "
                            "its offset cylinder)",
                            lateral));
  }
  const double branch1 = configuration.shoulder_front ? front_sign_ : -front_sign_;
  const double q1 =
      std::atan2(y, x) - branch1 * std::acos(std::clamp(lateral_offset_m_ / radius, -1.0, 1.0));

  // Joints 2 and 3: the planar two-link problem shoulder -> elbow -> wrist centre.
  const Eigen::Vector2d target = in_plane(undo_joint_1(wrist_target, q1));
  const Eigen::Vector2d shoulder_to_target = target - shoulder_2d_;
  const double distance = shoulder_to_target.norm();
  const double cos_bend =
      (distance * distance - upper_arm_m_ * upper_arm_m_ - forearm_m_ * forearm_m_) /
      (2.0 * upper_arm_m_ * forearm_m_);
  const double reach_min = std::abs(upper_arm_m_ - forearm_m_);
  const double reach_max = upper_arm_m_ + forearm_m_;
  if (distance > reach_max + tolerance + slack) {
    return fail(IkStatus::kUnreachable,
                fmt::format("wrist centre {:.6f} m from the shoulder axis, beyond the arm's "
                            "reach of {:.6f} m",
                            distance, reach_max));
  }
  if (distance < reach_min - tolerance - slack) {
    return fail(IkStatus::kUnreachable,
                fmt::format("wrist centre {:.6f} m from the shoulder axis, closer than the "
                            "folded arm's {:.6f} m",
                            distance, reach_min));
  }
  const double sin_bend_abs = std::sqrt(std::max(0.0, 1.0 - cos_bend * cos_bend));
  if (ideal_ && sin_bend_abs < tolerance) {
    return fail(IkStatus::kElbowSingular,
                fmt::format("arm {} (|sin| of the elbow bend {:.3g})",
                            cos_bend > 0 ? "stretched" : "folded", sin_bend_abs));
  }
  const double branch3 = configuration.elbow_up ? elbow_up_sign_ : -elbow_up_sign_;
  // Non-ideal arm near a stretched/folded pose: start a little inside the requested branch.
  constexpr double kMinimumStartBend = 1e-2;  // rad
  double bend_abs = std::acos(std::clamp(cos_bend, -1.0, 1.0));
  if (!ideal_) bend_abs = std::clamp(bend_abs, kMinimumStartBend, M_PI - kMinimumStartBend);
  const double bend = branch3 * bend_abs;
  const double theta3 = stretched_angle_ + bend;
  const Eigen::Vector2d wrist_moved = elbow_2d_ + rotate2(wrist_2d_ - elbow_2d_, theta3);
  const Eigen::Vector2d shoulder_to_wrist = wrist_moved - shoulder_2d_;
  const double theta2 = std::atan2(cross2(shoulder_to_wrist, shoulder_to_target),
                                   shoulder_to_wrist.dot(shoulder_to_target));
  JointVector q;
  q(0) = q1;
  q(1) = theta2;
  q(2) = joint3_sign_ * theta3;

  // Joints 4..6: the wrist rotation R4 R5 R6 = R_G, all about axes through the wrist centre.
  const Eigen::Matrix3d R_arm = rotation_about(axis_[0], q(0)) * rotation_about(axis_[1], q(1)) *
                                rotation_about(axis_[2], q(2));
  const Eigen::Matrix3d R_G = R_arm.transpose() * T_R_H.linear() * R_R_H_zero_.transpose();
  const Eigen::Vector3d& w4 = axis_[3];
  const Eigen::Vector3d& w5 = axis_[4];
  const Eigen::Vector3d& w6 = axis_[5];
  const Eigen::Vector3d v = R_G * w6;
  // Subproblem 2: z = R5 w6 = R4^T v, so w4.z = w4.v and w5.z = w5.w6.
  const double c45 = w4.dot(w5);
  const double denominator = c45 * c45 - 1.0;
  const double alpha = (c45 * w5.dot(w6) - w4.dot(v)) / denominator;
  const double beta = (c45 * w4.dot(v) - w5.dot(w6)) / denominator;
  const Eigen::Vector3d w45 = w4.cross(w5);
  const double gamma_sq =
      (1.0 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c45) / w45.squaredNorm();
  const double gamma_abs = std::sqrt(std::max(gamma_sq, 0.0));
  // w5.(w4 x z) = gamma (c45^2 - 1): its sign is the wrist bend's.
  const double wrist_sin = gamma_abs * (1.0 - c45 * c45);
  if (ideal_ && wrist_sin < tolerance) {
    return fail(IkStatus::kWristSingular,
                fmt::format("axes 4 and 6 aligned (|sin| of the wrist bend {:.3g})", wrist_sin));
  }
  const double gamma = configuration.wrist_flip ? gamma_abs : -gamma_abs;
  const Eigen::Vector3d z = alpha * w4 + beta * w5 + gamma * w45;
  q(4) = angle_about(w5, w6, z);
  q(3) = angle_about(w4, z, v);
  const Eigen::Matrix3d R45 = rotation_about(w4, q(3)) * rotation_about(w5, q(4));
  const Eigen::Vector3d u = w6.unitOrthogonal();
  q(5) = angle_about(w6, u, R45.transpose() * R_G * u);

  for (int i = 0; i < kJointCount; ++i) q(i) = wrap_to_pi(q(i));
  result.q = q;
  refine_ik(model_, T_R_H, options, result);
  finish_refined(ideal_, configuration, options, result);
  return result;
}

}  // namespace imscal::calib
