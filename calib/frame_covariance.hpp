#pragma once
// Uncertainty of the frame calibration: the tangent-space covariance of the estimated blocks by
// ceres::Covariance, and the directions the data determine poorly, in words.
//
// Covariance: first the sparse algorithm (full rank expected); when Ceres finds the Jacobian
// rank deficient it is redone with DENSE_SVD and null_space_rank = -1 (pseudo-inverse dropping
// the directions whose eigenvalue ratio is below min_reciprocal_condition_number), and the result
// says so. Quaternion blocks (EigenQuaternionManifold: the tangent delta turns by 2 |delta|) are
// scaled to small angles in rad.
//
// Weak directions:
//  - the heading of R in W (rotation of T_R_W about the vertical), always: only gyrocompassing
//    sees it (sigma ~ ARW / (Omega cos(lat) sqrt(T))); named with its sigma and what helps;
//  - flange rotation axes the motions between the rests do not excite (from the relative
//    rotations of the forward kinematics): T_S_H's rotation about that axis and the lever arm
//    along it are then poorly determined;
//  - eigen-directions of the T_S_H rotation / translation covariance whose sigma exceeds the
//    limits below; a time offset without motion to see it; null-space directions.
#include <ceres/problem.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/frame_calibration.hpp"

namespace imscal::calib {

struct CovarianceBlock {
  std::string name;  // e.g. "R_W_R"
  double* parameters = nullptr;
  int tangent_size = 3;
  double tangent_to_si = 1.0;  // 2 for quaternion tangents (rad per tangent unit)
  std::vector<std::string> components;
};

struct FrameCovariance {
  bool computed = false;
  bool rank_deficient = false;
  std::vector<std::string> parameter_names;  // "<block>.<component>"
  Eigen::MatrixXd covariance;                // SI, rotations as small angles [rad]
  Eigen::MatrixXd correlation;
  std::string message;  // why it failed, if it did
};

FrameCovariance compute_frame_covariance(ceres::Problem& problem,
                                         const std::vector<CovarianceBlock>& blocks);

struct WeakDirectionLimits {
  double rotation_sigma_rad = 0.005 * M_PI / 180.0;  // the accuracy goal for the frames
  double translation_sigma_m = 0.05e-3;
  double axis_spread_ratio = 0.05;  // smallest / largest eigenvalue of the axis scatter
};

// covariance: as computed above, blocks in the order R_W_R, R_S_H, p_S_H, ... (offsets given);
// R_W_R's tangent is in W (ENU) axes, R_S_H's in S axes. flange_rotations: R_H_i^T R_H_j of the
// consecutive rests (from forward kinematics).
std::vector<WeakDirection> describe_weak_directions(
    const FrameCovariance& covariance, int offset_R_W_R, int offset_R_S_H, int offset_p_S_H,
    int offset_dt, bool time_offset_observed, const Eigen::Matrix3d& R_S_H,
    const std::vector<Eigen::Matrix3d>& flange_rotations, const WeakDirectionLimits& limits = {});

}  // namespace imscal::calib
