#pragma once
// Kinematic calibration of a 6-axis arm from laser-tracker positions of a target on its tool:
// the deviations of the DH parameters (joint offsets Δθ, link offsets Δd, lengths Δa, twists Δα)
// together with the tracker <- base transform and the target's position on the flange, by least
// squares (Ceres) on the position residuals
//   r_k = T_tracker_base · T_R_H(q_k; DH + Δ) · p_H_target − p_tracker_k.
// Orientation is not used: the target's attitude on the flange then needs no parameters.
//
// Identifiability: the columns of the residuals' Jacobian at the initial values, each scaled to
// unit length, are taken in a fixed order (base, target, then Δθ, Δd, Δa, Δα of joints 1..6); a
// parameter whose column keeps less than `min_independence` of its length after projection on
// the columns already kept is not estimated (it stays at its nominal value) and is reported as
// dropped with that fraction. This drops what the base and target transforms absorb (joint 1's
// Δθ and Δd, joint 6's), for parallel axes all but one of their Δd and, with the target close to
// the flange axis, joint 5's Δa and Δα (seen only through the target's small offset from that
// axis). The default limit, 1 %, drops a parameter whose σ the others would inflate over 100-fold
// (the real UR10's weakest kept parameter keeps 8 %, the dropped ones 0.1 % or less). 1σ comes from
// the covariance scaled by the residual variance (Ceres; the poses are treated as independent).
//
// References (docs/references.md): [Hollerbach2008] (identifiability by the scaled Jacobian),
// [Spong2006] (DH).
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/tracker_poses.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

// Layout of the parameter vector (see kinematic_parameter_names()).
inline constexpr int kBaseRotationIndex = 0;  // 3: rotation vector applied to the initial R [rad]
inline constexpr int kBaseTranslationIndex = 3;  // 3: tracker <- base translation [m]
inline constexpr int kTargetIndex = 6;           // 3: target on the flange, frame H [m]
inline constexpr int kDhIndex = 9;  // 4 per joint: Δθ [rad], Δd [m], Δa [m], Δα [rad]
inline constexpr int kKinematicParameterCount = kDhIndex + 4 * kJointCount;

struct KinematicCalibrationOptions {
  bool estimate_geometry = true;  // false: base and target only (the nominal model's best fit)
  double min_independence = 1e-2;
  int max_iterations = 100;
};

struct KinematicParameter {
  std::string name;    // e.g. "base_rx", "target_z", "dtheta3", "dd2", "da4", "dalpha5"
  std::string unit;    // "rad" or "m"
  double value = 0.0;  // the estimate (for DH entries the deviation from nominal)
  double sigma = 0.0;  // 1σ; 0 when not estimated
  bool estimated = false;
  double independence = 0.0;  // the unit column's part not explained by the earlier ones
  std::string reason;         // why it was not estimated (empty when it was)
};

struct KinematicCalibration {
  KinematicModel model;  // nominal + estimated deviations
  Eigen::Isometry3d T_tracker_base = Eigen::Isometry3d::Identity();
  Eigen::Vector3d p_H_target_m = Eigen::Vector3d::Zero();
  std::vector<KinematicParameter> parameters;  // kKinematicParameterCount, in layout order
  int pose_count = 0;
  int estimated_count = 0;
  double rms_fit_m = 0.0;         // RMS of |r_k| on the fitted poses
  double residual_sigma_m = 0.0;  // per component, sqrt(Σ r² / (3N − p))
  std::string solver_summary;
};

std::vector<std::string> kinematic_parameter_names();

// Throws std::invalid_argument with fewer than 10 poses, fewer residuals than 2 × the parameters
// estimated, or poses that leave a base or target parameter without an effect of its own, and
// std::runtime_error when the solver fails (no covariance is then computed).
KinematicCalibration calibrate_kinematics(const KinematicModel& nominal,
                                          const std::vector<TrackerPose>& poses,
                                          const KinematicCalibrationOptions& options = {});

// The target's predicted tracker position at q.
Eigen::Vector3d predicted_target_m(const KinematicCalibration& calibration, const JointVector& q);

// |predicted − measured| per pose [m].
std::vector<double> position_errors_m(const KinematicCalibration& calibration,
                                      const std::vector<TrackerPose>& poses);

}  // namespace imscal::calib
