#pragma once
// Inverse kinematics of the usual industrial 6R arm: axis 2 parallel to axis 3, both
// perpendicular to axis 1 (an offset between axis 1 and 2 and a lateral arm offset are allowed),
// and a spherical wrist (axes 4, 5, 6 meet in the wrist centre; 4 _|_ 5 _|_ 6). KUKA KR 16,
// ABB IRB, Fanuc M-/R-series, PUMA are of this class.
//
// Method: closed form from the joint screws at q = 0 (convention-free, so it works for standard
// and modified DH alike): joint 1 from the wrist centre's position about axis 1, joints 2 and 3
// from the planar two-link problem in the arm plane, joints 4..6 from the wrist rotation
// (Paden-Kahan subproblems 2 and 1). Then Newton steps on the full model
// (q += J^-1 e until the pose error is below the tolerances), which also absorbs small
// departures from the ideal structure (e.g. calibrated DH parameters).
//
// Configuration flags (constant on each solution branch, they change only at a singularity):
// - shoulder_front: the wrist centre lies, seen from axis 1 in the arm plane, on the side where
//   it lies at q = 0 (for the KR 16: in front of axis 1).
// - elbow_up: the elbow bends to the side that puts it above the shoulder-wrist line when the
//   arm reaches forward (shoulder front) in a base frame R with z up. Defined on joint 3 alone
//   (as industrial controllers' status bits are), so with shoulder back "elbow up" is
//   physically below the line.
// - wrist_flip: the signed wrist bend (angle from axis 4 to axis 6 about axis 5) is negative
//   (for the KR 16 description: q5 < 0).
//
// Types, failures and the common calls: robot/ik_solver.hpp. Failures are reported, never thrown:
// IkResult::status says what went wrong and IkResult::reason says it in words with the numbers
// (distances in m, angles in rad).
// - kUnreachable: the wrist centre is out of reach of the arm (too far, too close, or inside
//   the cylinder of the lateral offset about axis 1).
// - kShoulderSingular / kElbowSingular / kWristSingular: the pose lies within
//   IkOptions::singularity_tolerance of a singularity (wrist centre on axis 1; arm stretched or
//   folded; axes 4 and 6 aligned): there the solution is not unique and the flag is undefined.
// - kOutsideJointLimits: a solution exists but no 2*pi-equivalent of it is within the limits
//   (q holds it anyway).
// - kNotConverged: the Newton refinement did not reach the tolerances (q holds the best).
// The constructor throws std::invalid_argument if the model is not of the class above.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "robot/ik_solver.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

class InverseKinematics : public IkSolver {
 public:
  explicit InverseKinematics(const KinematicModel& model);

  // The solution of the given configuration for the flange pose T_R_H.
  IkResult solve(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                 const IkOptions& options = {}) const override;
  ArmConfiguration configuration_of(const JointVector& q) const override;
  SingularityMeasures singularity_measures(const JointVector& q) const override;
  const char* structure() const override { return "spherical wrist"; }

  // Wrist centre in the flange frame H [m].
  const Eigen::Vector3d& wrist_centre_H() const { return wrist_centre_H_; }

 private:
  // Wrist centre with joint 1 undone, and the signed lateral distance from the singular
  // cylinder (positive = front side).
  Eigen::Vector3d undo_joint_1(const Eigen::Vector3d& point_R, double q1) const;
  double signed_shoulder_measure(const Eigen::Vector3d& wrist_centre_R, double q1) const;
  double elbow_bend(double q3) const;
  double signed_wrist_measure(double q5) const;
  Eigen::Vector2d in_plane(const Eigen::Vector3d& point_R) const;

  std::array<Eigen::Vector3d, kJointCount> axis_;   // joint axes at q = 0, in R
  std::array<Eigen::Vector3d, kJointCount> point_;  // a point on each axis at q = 0, in R
  Eigen::Matrix3d R_R_H_zero_;                      // flange orientation at q = 0
  Eigen::Vector3d wrist_centre_R_;                  // at q = 0
  Eigen::Vector3d wrist_centre_H_;
  // Shoulder: e_x = axis 2, e_y = axis1 x axis2; lateral offset of the arm plane along e_x.
  Eigen::Vector3d shoulder_x_, shoulder_y_;
  double lateral_offset_m_ = 0.0;
  double front_sign_ = 1.0;
  // Arm plane (normal = axis 2) basis, and the planar two-link geometry at q = 0.
  Eigen::Vector3d plane_a_, plane_b_;
  Eigen::Vector2d shoulder_2d_, elbow_2d_, wrist_2d_;
  double upper_arm_m_ = 0.0, forearm_m_ = 0.0;
  double stretched_angle_ = 0.0;  // planar joint-3 angle at which the arm is stretched
  double joint3_sign_ = 1.0;      // axis 3 = joint3_sign * axis 2
  double elbow_up_sign_ = 1.0;
  double structure_slack_m_ = 0.0;  // closed-form error bound on a non-ideal arm [m]
  bool ideal_ = true;               // exact structure: the closed form is exact
};

}  // namespace imscal::calib
