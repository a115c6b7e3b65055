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
// Failures are reported, never thrown: IkResult::status says what went wrong and
// IkResult::reason says it in words with the numbers (distances in m, angles in rad).
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
#include <optional>
#include <string>
#include <vector>

#include "calib/robot_description.hpp"

namespace imscal::calib {

struct ArmConfiguration {
  bool shoulder_front = true;
  bool elbow_up = true;
  bool wrist_flip = false;
  bool operator==(const ArmConfiguration&) const = default;
};
std::string to_string(const ArmConfiguration& configuration);  // "front/up/noflip"

enum class IkStatus {
  kOk,
  kUnreachable,
  kShoulderSingular,
  kElbowSingular,
  kWristSingular,
  kOutsideJointLimits,
  kNotConverged,
};
const char* to_string(IkStatus status);

struct IkOptions {
  // Distance to a singularity below which solve() refuses: shoulder [m] (wrist centre from the
  // singular cylinder about axis 1), elbow and wrist [sine of the bend angle].
  double singularity_tolerance = 1e-6;
  int max_newton_iterations = 20;
  double position_tolerance_m = 1e-12;       // flange position error after refinement
  double orientation_tolerance_rad = 1e-12;  // flange rotation error after refinement
  bool enforce_joint_limits = true;
  // Among the 2*pi-equivalents of each angle within the limits, take the one nearest to this
  // (default: nearest to 0).
  std::optional<JointVector> q_near;
};

struct IkResult {
  IkStatus status = IkStatus::kNotConverged;
  std::string reason;  // empty when ok
  JointVector q = JointVector::Zero();
  ArmConfiguration configuration;
  double position_error_m = 0.0;       // |p_H(q) - p_target| after refinement
  double orientation_error_rad = 0.0;  // angle of R_H(q)^T R_target after refinement
  int newton_iterations = 0;
  bool ok() const { return status == IkStatus::kOk; }
};

// Distances to the three singularities at q (same units as IkOptions::singularity_tolerance).
struct SingularityMeasures {
  double shoulder_m = 0.0;
  double elbow = 0.0;  // |sin| of the elbow bend from the stretched arm
  double wrist = 0.0;  // |sin| of the wrist bend
};

class InverseKinematics {
 public:
  explicit InverseKinematics(const KinematicModel& model);

  // The solution of the given configuration for the flange pose T_R_H.
  IkResult solve(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                 const IkOptions& options = {}) const;
  // The solution nearest (largest joint difference) to a reference reading, e.g. the robot's
  // own encoders: of q_reference's arm configuration with either wrist branch. Near the wrist
  // singularity (wrist bend ~ 0) a pose error of microradians can put the pose's wrist bend on
  // the other side of zero; the reference's own branch is then A4 and A6 turned by ~pi, the
  // other branch the physical solution. options.q_near defaults to q_reference.
  IkResult solve_nearest(const Eigen::Isometry3d& T_R_H, const JointVector& q_reference,
                         IkOptions options = {}) const;
  // All 8 configurations, in the order of all_configurations(); each with its own status.
  std::vector<IkResult> solve_all(const Eigen::Isometry3d& T_R_H,
                                  const IkOptions& options = {}) const;

  ArmConfiguration configuration_of(const JointVector& q) const;
  SingularityMeasures singularity_measures(const JointVector& q) const;

  static std::vector<ArmConfiguration> all_configurations();
  const KinematicModel& model() const { return model_; }
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
  void refine(const Eigen::Isometry3d& T_R_H, const IkOptions& options, IkResult& result) const;
  bool fit_limits(const IkOptions& options, JointVector& q) const;

  KinematicModel model_;
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
