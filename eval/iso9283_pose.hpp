#pragma once
// ISO 9283:1998 pose characteristics (clause 7.2: pose accuracy AP, clause 7.3: pose
// repeatability RP) of one commanded pose from n attained poses x_j (j = 1..n), all in the base
// frame:
//   barycentre  x̄ = (1/n) Σ_j x_j                      (likewise ȳ, z̄)
//   AP_x = x̄ − x_c, AP_y, AP_z;  AP_p = sqrt(AP_x² + AP_y² + AP_z²)         position accuracy
//   l_j = |x_j − x̄|,  l̄ = mean_j l_j,  S_l = sqrt(Σ_j (l_j − l̄)² / (n − 1))
//   RP_l = l̄ + 3 S_l                                                        position repeatability
// Orientation: the attained attitude's deviation from the commanded one as a rotation vector
// (a, b, c) about the base axes X, Y, Z (small angles: ISO's a, b, c differences, as in
// eval/iso9283_path.hpp):
//   AP_a = ā − 0 (likewise b, c);  S_a = sqrt(Σ_j (a_j − ā)² / (n − 1));  RP_a = ±3 S_a.
// With one attained pose (n = 1) the repeatabilities are not defined and are reported as NaN.
//
// References (docs/references.md): [ISO9283] (clause 7).
#include <Eigen/Geometry>
#include <vector>

namespace imscal::eval {

struct Iso9283PoseResult {
  int cycles = 0;  // n
  Eigen::Vector3d barycentre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d AP_xyz_m = Eigen::Vector3d::Zero();  // x̄ − x_c, ȳ − y_c, z̄ − z_c
  double AP_p_m = 0.0;
  double RP_l_m = 0.0;
  Eigen::Vector3d AP_abc_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d RP_abc_rad = Eigen::Vector3d::Zero();  // 3 S_a, 3 S_b, 3 S_c (the ± is implied)
};

// attained: >= 1 pose. Throws std::invalid_argument when it is empty.
Iso9283PoseResult iso9283_pose(const Eigen::Isometry3d& commanded,
                               const std::vector<Eigen::Isometry3d>& attained);

// The attained poses grouped by commanded pose: poses whose commanded positions lie within
// position_tolerance_m and whose commanded attitudes differ by at most angle_tolerance_rad
// belong to one group (the first pose of the group is its commanded pose). Indices into
// `commanded`, in order of first appearance.
std::vector<std::vector<std::size_t>> group_repeated_poses(
    const std::vector<Eigen::Isometry3d>& commanded, double position_tolerance_m,
    double angle_tolerance_rad);

// Measured poses (an external system's frame, its own target attitude) brought into the base
// frame: the measuring frame registered by a rigid best fit (Umeyama, no scale) of the measured
// positions onto the commanded ones over all poses given, and the target's attitude offset by the
// chordal mean of (R_base_measuring R_measured)ᵀ R_commanded. AP is then the accuracy left after
// that best fit (its mean over the poses is zero by construction); RP does not depend on it.
std::vector<Eigen::Isometry3d> register_to_commanded(
    const std::vector<Eigen::Isometry3d>& commanded,
    const std::vector<Eigen::Isometry3d>& measured);

}  // namespace imscal::eval
