#pragma once
// Closed-form robot-world / hand-eye calibration: the initial values of T_R_W and T_S_H for the
// frame calibration, without user guesses.
//
// At every rest pose i the forward kinematics of the internal joint readings and the IMS pose
// from the navigation solution are tied by
//   T_R_H_i = T_R_W * T_W_S_i * T_S_H          (A_i = Z B_i X)
// with Z = T_R_W (maps W-coordinates into R) and X = T_S_H.
//
// Method (steps 1-3 closed form or linear, step 4 a short iteration from their result):
//  1. Relative motions of every pose pair (i < j): A_ij = A_i^-1 A_j = X^-1 B_ij X. Pairs whose
//     rotation is below `min_relative_rotation_rad` carry too little axis information and are
//     dropped (and listed). The rotation R_H_S = R_X^T follows from the kept pairs as the unit
//     quaternion q with q_A_ij q = q q_B_ij in the least-squares sense (smallest eigenvector of
//     a 4x4 normal matrix; Chou & Kamel 1991 style).
//  2. R_Z is the chordal mean of R_A_i R_X^T R_B_i^T; then R_Z and R_X are refined by alternating
//     chordal means, which descends sum_i |R_A_i - R_Z R_B_i R_X|_F^2 on the absolute poses.
//  3. With the rotations fixed, t_Z and t_X solve the linear least-squares problem
//     t_A_i - R_Z t_B_i = t_Z + R_Z R_B_i t_X.
//  4. Optionally (on by default) a few Gauss-Newton steps on all 12 unknowns with the rotation
//     and position residuals of every pose weighted by the expected IMS noise: the positions
//     also carry information on the rotation of Z (lever arms of ~1 m), which steps 2-3 ignore.
//     On noise-free poses the residuals are zero and the step changes nothing.
//  5. Residuals per pose (rotation angle and translation distance) are reported.
// A pose set that cannot determine the unknowns (fewer than 3 poses, no rotation, rotations about
// one axis only) is refused with HandEyeUnobservable, naming the missing directions.
//
// References (docs/references.md): [ChouKamel1991] (hand-eye rotation by quaternions).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "core/input_error.hpp"

namespace imscal::calib {

struct HandEyeOptions {
  // Relative motions rotating less than this (in either A or B) are dropped [rad]. The axis of a
  // pair rotating by theta is known to ~sigma_attitude / theta: nearly equal poses add more noise
  // than information to the axis fit (and none at all when they are identical).
  double min_relative_rotation_rad = 5.0 * M_PI / 180.0;
  // The kept rotation axes must spread at least this far from a single axis [rad] (measured as
  // asin(sqrt(second eigenvalue / largest eigenvalue)) of the axis scatter matrix).
  double min_axis_spread_rad = 2.0 * M_PI / 180.0;
  // Alternating refinement of R_Z, R_X on the absolute poses: iteration limit and the change
  // [rad] below which it stops.
  int max_refinement_iterations = 200;
  double refinement_tolerance_rad = 1e-15;
  // Joint weighted refinement (step 4) with the IMS pose noise used as weights: attitude per axis
  // [rad] and position per axis [m] (navigation-grade IMS after ZUPT smoothing).
  bool joint_refinement = true;
  double attitude_sigma_rad = 0.001 * M_PI / 180.0;
  double position_sigma_m = 0.02e-3;
  int max_gauss_newton_iterations = 10;
  // Smallest accepted singular value of the translation system (scaled, see HandEyeResult).
  double min_translation_singular_value = 1e-3;
  // Name of the pose set for error messages (file name, or what the caller calls it).
  std::string source = "hand-eye pose set";
};

// A relative motion left out of the rotation fit.
struct DroppedMotion {
  std::size_t from_pose = 0;
  std::size_t to_pose = 0;
  double robot_rotation_rad = 0.0;  // angle of A_i^-1 A_j
  double ims_rotation_rad = 0.0;    // angle of B_i^-1 B_j
};

struct HandEyePoseResidual {
  double rotation_rad = 0.0;   // angle of A_i^-1 Z B_i X
  double translation_m = 0.0;  // |t(A_i) - t(Z B_i X)|
};

struct HandEyeResult {
  Eigen::Isometry3d T_R_W = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  std::size_t used_motion_count = 0;
  std::vector<DroppedMotion> dropped_motions;
  std::vector<HandEyePoseResidual> residuals;  // one per pose
  double rms_rotation_residual_rad = 0.0;
  double rms_translation_residual_m = 0.0;
  // Observability figures: eigenvalues (ascending) of the mean outer product of the kept unit
  // rotation axes (in S), and singular values (ascending) of the translation system (6 columns
  // [t_Z; t_X], scaled by 1/sqrt(pose count): 1 is ideal, 0 means undetermined).
  Eigen::Vector3d axis_scatter_eigenvalues = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 1> translation_singular_values = Eigen::Matrix<double, 6, 1>::Zero();
  int refinement_iterations = 0;
  int gauss_newton_iterations = 0;
};

// The pose set cannot determine Z and X. missing_directions() names each direction in words
// (with its frame), e.g. "rotation of S_T_H about the S axis (0.000, 0.000, 1.000)".
class HandEyeUnobservable : public InputError {
 public:
  HandEyeUnobservable(const std::string& source, const std::string& problem,
                      std::vector<std::string> missing_directions);
  const std::vector<std::string>& missing_directions() const { return missing_directions_; }

 private:
  std::vector<std::string> missing_directions_;
};

// T_R_H: forward kinematics at the rest poses; T_W_S: the IMS poses at the same instants.
// Throws InputError for unusable input (different counts, non-orthonormal rotations) and
// HandEyeUnobservable when the poses cannot determine the unknowns.
HandEyeResult solve_robot_world_hand_eye(const std::vector<Eigen::Isometry3d>& T_R_H,
                                         const std::vector<Eigen::Isometry3d>& T_W_S,
                                         const HandEyeOptions& options = {});

// Projection onto SO(3) (nearest rotation in the Frobenius norm) of a 3x3 matrix, e.g. a sum of
// rotations (chordal mean).
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& m);

}  // namespace imscal::calib
