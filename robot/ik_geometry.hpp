#pragma once
// Small geometric helpers of the closed-form inverse kinematics (robot/inverse_kinematics.cpp,
// robot/ur_inverse_kinematics.cpp). Angles in rad.
//
// References (docs/references.md): [Paden1985] for subproblem 1.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <vector>

namespace imscal::calib::ik_geometry {

// How far a model may depart from a solver's ideal structure for its closed form to be a good
// start for Newton (a few mrad / mm converge in a handful of steps).
inline constexpr double kStructureAngleTolerance = 1e-2;     // rad
inline constexpr double kStructureDistanceTolerance = 5e-3;  // m

inline Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

// Paden-Kahan subproblem 1: the angle that turns u into v about the unit axis w.
inline double angle_about(const Eigen::Vector3d& w, const Eigen::Vector3d& u,
                          const Eigen::Vector3d& v) {
  const Eigen::Vector3d u_perp = u - w.dot(u) * w;
  const Eigen::Vector3d v_perp = v - w.dot(v) * w;
  return std::atan2(w.dot(u_perp.cross(v_perp)), u_perp.dot(v_perp));
}

inline double wrap_to_pi(double angle) {
  return std::remainder(angle, 2.0 * M_PI);
}

// Point nearest (least squares) to the lines {p_i + t w_i}.
inline Eigen::Vector3d nearest_point_to_lines(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<Eigen::Vector3d>& directions) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Matrix3d projector =
        Eigen::Matrix3d::Identity() - directions[i] * directions[i].transpose();
    a += projector;
    b += projector * points[i];
  }
  return a.ldlt().solve(b);
}

inline double distance_to_line(const Eigen::Vector3d& x, const Eigen::Vector3d& p,
                               const Eigen::Vector3d& w) {
  return (x - p - w.dot(x - p) * w).norm();
}

inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

inline Eigen::Vector2d rotate2(const Eigen::Vector2d& v, double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

}  // namespace imscal::calib::ik_geometry
