#pragma once
// ISO 9283:1998 path characteristics (clause 8: path accuracy and repeatability, cornering
// deviations, path velocity characteristics) from a commanded path and n attained cycles of it.
//
// Calculation points: m points equally spaced along the commanded path's arc length. At each, the
// plane normal to the commanded path; every attained cycle's path is intersected with it (linear
// interpolation between attained samples, attitude by slerp), giving x_ij, j = 1..n.
//   barycentre  x̄_i = (1/n) Σ_j x_ij
//   AT_p = max_i |x̄_i − x_ci|                                  path (position) accuracy
//   l_ij = |x_ij − x̄_i|,  l̄_i = mean_j l_ij,  S_li = sqrt(Σ_j (l_ij − l̄_i)² / (n − 1))
//   RT_p = max_i (l̄_i + 3 S_li)                                path repeatability
// Orientation: the attained attitude's deviation from the commanded one at the same point, as a
// rotation vector (a, b, c) about the base axes X, Y, Z (small angles: ISO's a, b, c differences):
//   AT_a = max_i |ā_i − 0|, likewise b, c;  RT_a = max_i 3 sqrt(Σ_j (a_ij − ā_i)² / (n − 1)).
// Path velocity over the constant-velocity part (attained speed |dp/dt| at the calculation points
// whose arc length lies in [velocity_from_m, velocity_to_m]), commanded speed v_c:
//   v̄_j = mean_i v_ij,  v̄ = mean_j v̄_j,  AV = (v̄ − v_c) / v_c · 100 %,
//   RV = 3 sqrt(Σ_j (v̄_j − v̄)² / (n − 1)) / v_c · 100 %  (reported as ±RV),
//   FV = max_j (max_i v_ij − min_i v_ij)                       velocity fluctuation [m/s].
// Cornering (a commanded corner between two straight legs, run without stopping):
//   CR_j = min over the attained path j of the distance to the corner point      round-off
//   CO_j = max over the attained points beyond the corner of their distance from the second leg,
//          counted on the outside of the corner (the side the first leg's motion carries on to)
//   CR = max_j CR_j, CO = max_j CO_j.
// With one cycle (n = 1) the repeatabilities are not defined and are reported as NaN.
//
// References (docs/references.md): [ISO9283] (clause 8).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace imscal::eval {

struct PathPose {
  double t_s = 0.0;  // each attained cycle on the commanded path's clock (see time_window_s)
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // attitude in the base frame
};
using PoseSeries = std::vector<PathPose>;

struct Iso9283Options {
  int calculation_points = 200;  // m, equally spaced along the commanded arc length
  // An attained crossing of a normal plane counts only within ±time_window_s of the commanded
  // time of its calculation point, so paths that come back along themselves are not mixed up.
  double time_window_s = 1.0;
  double velocity_from_m = 0.0;  // arc-length range of the path-velocity evaluation
  double velocity_to_m = -1.0;   // < 0: up to the end of the path
};

struct Iso9283PathResult {
  int cycles = 0;
  double length_m = 0.0;  // commanded arc length
  double AT_p_m = 0.0, RT_p_m = 0.0;
  Eigen::Vector3d AT_abc_rad = Eigen::Vector3d::Zero(), RT_abc_rad = Eigen::Vector3d::Zero();
  double AV_percent = 0.0, RV_percent = 0.0, FV_m_s = 0.0;
  // Per calculation point: arc length, commanded position, |x̄_i − x_ci| (for plots).
  std::vector<double> arc_length_m;
  std::vector<Eigen::Vector3d> commanded_m;
  std::vector<double> accuracy_m;
  int missed_crossings = 0;  // point/cycle pairs without a crossing in the window (skipped)
};

// commanded: >= 2 poses, strictly increasing time, non-zero length. attained: >= 1 cycle.
// v_c_m_s: commanded path speed for AV/RV (<= 0: velocity characteristics not computed).
// Throws std::invalid_argument when the input cannot give the characteristics.
Iso9283PathResult iso9283_path(const PoseSeries& commanded, const std::vector<PoseSeries>& attained,
                               double v_c_m_s, const Iso9283Options& options = {});

struct Iso9283CornerResult {
  double CR_m = 0.0;
  double CO_m = 0.0;
};

// Commanded corner: first leg from `start` to `corner`, second leg from `corner` to `end`.
Iso9283CornerResult iso9283_corner(const Eigen::Vector3d& start, const Eigen::Vector3d& corner,
                                   const Eigen::Vector3d& end,
                                   const std::vector<PoseSeries>& attained);

}  // namespace imscal::eval
