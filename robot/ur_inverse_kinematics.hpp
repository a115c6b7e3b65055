#pragma once
// Inverse kinematics of the UR class of 6R arms: axis 2 perpendicular to axis 1, axes 2, 3 and
// 4 parallel, axis 5 perpendicular to them, axis 6 perpendicular to axis 5 and meeting it in the
// wrist point W; lateral offsets (along axis 2) and offsets along axes 5 and 6 are allowed, so
// no three wrist axes meet. Universal Robots UR3/5/10/16 and their e-Series are of this class
// (DH d4, d5, d6 are the wrist offsets).
//
// Method: closed form from the joint screws at q = 0 (convention-free, no robot's numbers built
// in), the analytic solution of Hawkins (2013) in screw form: the axis-5 line keeps a fixed
// offset c along axis 2 from axis 1, so joint 1 follows from W (the flange pose moved back
// along axis 6); joint 5 from the component of axis 6 along the turned axis 2
// (n . R5(q5) w6 = cos(q5 - q5_0)); joint 6 by Paden-Kahan subproblem 1 from
// R6^T R5^T n = R_G^T R1 n; the sum of joints 2..4 from the remaining rotation about n; joints 2
// and 3 from the planar two-link problem that places axis 4; joint 4 from the sum. Then the
// Newton steps of robot/ik_refinement.hpp on the full model (absorbs calibrated DH deviations).
//
// Configuration flags (constant on each branch, they change only at a singularity):
// - shoulder_front: W lies, seen from axis 1 along the arm plane's normal, on the side where it
//   lies at q = 0 ("shoulder left/right" of the UR literature; for the UR URDFs, whose zero pose
//   reaches out along base -x with W on the -y side, front is the q = 0 side).
// - elbow_up: as for the spherical wrist (robot/inverse_kinematics.hpp): the elbow above the
//   shoulder-to-axis-4 line when the arm reaches forward, in a base frame R with z up; defined on
//   joint 3 alone.
// - wrist_flip: sin(q5 - q5_0) < 0, q5_0 the wrist-2 angle at which axis 6 is parallel to axes
//   2..4 (for the UR URDFs q5_0 = 0: flip is q5 < 0, "wrist down").
//
// Failures (IkResult::status, reason with the numbers; never thrown):
// - kUnreachable: W inside the cylinder of radius |c| about axis 1, or axis 4 out of the arm's
//   reach (too far or too close).
// - kShoulderSingular: W on that cylinder (the two joint-1 solutions merge).
// - kElbowSingular: arm stretched or folded (axes 2, 3, 4 in one plane).
// - kWristSingular: axis 6 parallel to axes 2..4 (q5 = q5_0 or + pi): joints 6 and 2..4 turn
//   about parallel axes, only their sum is defined.
// - kOutsideJointLimits, kNotConverged: as for the spherical wrist.
// The constructor throws std::invalid_argument naming the first structural condition that fails.
//
// References (docs/references.md): [Hawkins2013], [Paden1985].
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "robot/ik_solver.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

class UrInverseKinematics : public IkSolver {
 public:
  explicit UrInverseKinematics(const KinematicModel& model);

  IkResult solve(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                 const IkOptions& options = {}) const override;
  ArmConfiguration configuration_of(const JointVector& q) const override;
  SingularityMeasures singularity_measures(const JointVector& q) const override;
  const char* structure() const override { return "UR class"; }

  // The wrist point W (axes 5 and 6 meet) in the flange frame H [m].
  const Eigen::Vector3d& wrist_point_H() const { return wrist_point_H_; }
  // q5_0: the wrist-2 angle of the wrist singularity [rad].
  double wrist_singular_q5_rad() const { return wrist_zero_angle_; }

 private:
  void check_structure();
  Eigen::Vector3d undo_joint_1(const Eigen::Vector3d& point_R, double q1) const;
  // Screw motion of joint i by angle (x -> R (x - p_i) + p_i).
  Eigen::Vector3d turn(int joint, double angle, const Eigen::Vector3d& x) const;
  double signed_shoulder_measure(const Eigen::Vector3d& wrist_point_R, double q1) const;
  double elbow_bend(double q3) const;
  Eigen::Vector2d in_plane(const Eigen::Vector3d& point_R) const;
  // Closed-form steps; false with result.status/reason set on failure.
  bool solve_joint_1(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                     double tolerance, JointVector& q, IkResult& result) const;
  bool solve_joints_5_6(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                        double tolerance, JointVector& q, IkResult& result) const;
  bool solve_joints_2_3_4(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                          double tolerance, JointVector& q, IkResult& result) const;

  std::array<Eigen::Vector3d, kJointCount> axis_;   // joint axes at q = 0, in R
  std::array<Eigen::Vector3d, kJointCount> point_;  // a point on each axis at q = 0, in R
  Eigen::Isometry3d T_R_H_zero_;                    // flange at q = 0
  Eigen::Vector3d wrist_point_R_, wrist_point_H_;   // W at q = 0
  Eigen::Vector3d normal_;                          // n = axis 2 at q = 0
  Eigen::Vector3d shoulder_y_;                      // axis 1 x n
  double lateral_offset_m_ = 0.0;                   // c: offset of axis 5 from axis 1 along n
  double front_sign_ = 1.0;
  double joint3_sign_ = 1.0, joint4_sign_ = 1.0;  // axis i = sign * n
  double wrist_zero_angle_ = 0.0;                 // q5_0 [rad]
  double wrist_cos_scale_ = 1.0;                  // |n projected off axis 5| (1 when ideal)
  // Arm plane (normal n) basis and the planar two-link geometry at q = 0 (axis 4 as "wrist").
  Eigen::Vector3d plane_a_, plane_b_;
  Eigen::Vector2d shoulder_2d_, elbow_2d_, wrist_2d_;
  double upper_arm_m_ = 0.0, forearm_m_ = 0.0;
  double stretched_angle_ = 0.0;
  double elbow_up_sign_ = 1.0;
  double structure_slack_m_ = 0.0;  // closed-form error bound on a non-ideal arm [m]
  bool ideal_ = true;
};

}  // namespace imscal::calib
