#pragma once
// Rotation helpers shared by mechanization, synthesis and smoothing. Scalar-templated so that
// Ceres cost functors can use them. Rotation vectors in [rad].
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace imscal::ims {

template <typename T>
Eigen::Matrix<T, 3, 3> skew(const Eigen::Matrix<T, 3, 1>& v) {
  Eigen::Matrix<T, 3, 3> m;
  m << T(0), -v.z(), v.y(), v.z(), T(0), -v.x(), -v.y(), v.x(), T(0);
  return m;
}

// Quaternion of the rotation vector phi (exp map). Uses a Taylor series below 1e-4 rad so that
// the result is exact to double precision without a division by a tiny angle.
template <typename T>
Eigen::Quaternion<T> quat_exp(const Eigen::Matrix<T, 3, 1>& phi) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T angle_sq = phi.squaredNorm();
  T real_part, imag_scale;
  if (angle_sq < T(1e-8)) {
    // cos(a/2) and sin(a/2)/a to O(a^6): the neglected terms are below 1e-25.
    real_part = T(1) - angle_sq / T(8) + angle_sq * angle_sq / T(384);
    imag_scale = T(0.5) - angle_sq / T(48) + angle_sq * angle_sq / T(3840);
  } else {
    const T angle = sqrt(angle_sq);
    real_part = cos(angle / T(2));
    imag_scale = sin(angle / T(2)) / angle;
  }
  return Eigen::Quaternion<T>(real_part, imag_scale * phi.x(), imag_scale * phi.y(),
                              imag_scale * phi.z());
}

// Rotation vector of a unit quaternion (log map), angle in [0, pi].
template <typename T>
Eigen::Matrix<T, 3, 1> quat_log(const Eigen::Quaternion<T>& q_in) {
  using std::atan2;
  Eigen::Quaternion<T> q = q_in;
  if (q.w() < T(0)) q.coeffs() = -q.coeffs();
  const Eigen::Matrix<T, 3, 1> v = q.vec();
  const T sin_half_sq = v.squaredNorm();
  if (sin_half_sq < T(1e-16)) {
    // 2*atan2(s, w)/s = 2/w * (1 - s^2/(3 w^2)) to the order needed here.
    return v * (T(2) / q.w()) * (T(1) - sin_half_sq / (T(3) * q.w() * q.w()));
  }
  const T sin_half = sqrt(sin_half_sq);
  return v * (T(2) * atan2(sin_half, q.w()) / sin_half);
}

// Angle [rad] of the rotation that takes a to b.
inline double rotation_angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return quat_log(Eigen::Quaterniond(a.conjugate() * b)).norm();
}

}  // namespace imscal::ims
