#include "ims/spline_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "ims/so3.hpp"

namespace imscal::ims {
namespace {
constexpr int kStencil = 7;
constexpr double kMaxStepAngle = 0.2;  // [rad] between consecutive samples (series below)

// Finite-difference weights for derivatives 0..2 at z from values at x[0..n-1] (Fornberg 1988,
// "Generation of finite difference formulas on arbitrarily spaced grids").
void fornberg_weights(double z, const double* x, double (&c)[kStencil][3]) {
  constexpr int m = 2;
  for (auto& row : c)
    for (double& v : row) v = 0.0;
  double c1 = 1.0;
  double c4 = x[0] - z;
  c[0][0] = 1.0;
  for (int i = 1; i < kStencil; ++i) {
    const int mn = std::min(i, m);
    double c2 = 1.0;
    const double c5 = c4;
    c4 = x[i] - z;
    for (int j = 0; j < i; ++j) {
      const double c3 = x[i] - x[j];
      c2 *= c3;
      if (j == i - 1) {
        for (int k = mn; k >= 1; --k) c[i][k] = c1 * (k * c[i - 1][k - 1] - c5 * c[i - 1][k]) / c2;
        c[i][0] = -c1 * c5 * c[i - 1][0] / c2;
      }
      for (int k = mn; k >= 1; --k) c[j][k] = (c4 * c[j][k] - k * c[j][k - 1]) / c3;
      c[j][0] = c4 * c[j][0] / c3;
    }
    c1 = c2;
  }
}

// Quintic in u in [0, 1] with value, first and second derivative (per unit time, interval h)
// given at both ends.
std::array<Eigen::Vector3d, 6> hermite_quintic(const Eigen::Vector3d& y0, const Eigen::Vector3d& d0,
                                               const Eigen::Vector3d& dd0,
                                               const Eigen::Vector3d& y1, const Eigen::Vector3d& d1,
                                               const Eigen::Vector3d& dd1, double h) {
  std::array<Eigen::Vector3d, 6> c;
  c[0] = y0;
  c[1] = h * d0;
  c[2] = 0.5 * h * h * dd0;
  const Eigen::Vector3d value_gap = y1 - c[0] - c[1] - c[2];
  const Eigen::Vector3d slope_gap = h * d1 - c[1] - 2.0 * c[2];
  const Eigen::Vector3d curvature_gap = h * h * dd1 - 2.0 * c[2];
  c[3] = 10.0 * value_gap - 4.0 * slope_gap + 0.5 * curvature_gap;
  c[4] = -15.0 * value_gap + 7.0 * slope_gap - curvature_gap;
  c[5] = 6.0 * value_gap - 3.0 * slope_gap + 0.5 * curvature_gap;
  return c;
}

struct QuinticValue {
  Eigen::Vector3d y, dy_dt, d2y_dt2;
};
QuinticValue evaluate(const std::array<Eigen::Vector3d, 6>& c, double u, double h) {
  QuinticValue out;
  out.y = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
  out.dy_dt = (c[1] + u * (2.0 * c[2] + u * (3.0 * c[3] + u * (4.0 * c[4] + u * 5.0 * c[5])))) / h;
  out.d2y_dt2 = (2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]))) / (h * h);
  return out;
}

// Right Jacobian of SO(3): omega = J_r(phi) dphi/dt for q = q0 exp(phi).
Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi) {
  const double t2 = phi.squaredNorm();
  double a, b;      // (1 - cos t) / t^2, (t - sin t) / t^3
  if (t2 < 1e-2) {  // t < 0.1: series, next terms < 3e-15 relative
    a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0 - t2 * t2 * t2 / 40320.0;
    b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0 - t2 * t2 * t2 / 362880.0;
  } else {
    const double t = std::sqrt(t2);
    a = (1.0 - std::cos(t)) / t2;
    b = (t - std::sin(t)) / (t2 * t);
  }
  const Eigen::Matrix3d k = skew(phi);
  return Eigen::Matrix3d::Identity() - a * k + b * k * k;
}

// J_r^-1(phi) = I + K/2 + c(t) K^2 (K = [phi]x) and its time derivative for dphi/dt. The
// series of c(t) = 1/t^2 - (1 + cos t) / (2 t sin t) to t^6 is exact to ~1e-15 for t <= 0.25.
void inverse_right_jacobian(const Eigen::Vector3d& phi, const Eigen::Vector3d& phi_dot,
                            Eigen::Matrix3d& jinv, Eigen::Matrix3d& jinv_dot) {
  const double t2 = phi.squaredNorm();
  const double c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2 * t2 * t2 / 1209600.0;
  const double dc_dt_over_t = 1.0 / 360.0 + t2 / 7560.0 + t2 * t2 / 201600.0;  // c'(t) / t
  const double c_dot = dc_dt_over_t * phi.dot(phi_dot);
  const Eigen::Matrix3d k = skew(phi);
  const Eigen::Matrix3d k_dot = skew(phi_dot);
  jinv = Eigen::Matrix3d::Identity() + 0.5 * k + c * k * k;
  jinv_dot = 0.5 * k_dot + c * (k_dot * k + k * k_dot) + c_dot * k * k;
}
}  // namespace

SplineTrajectory::SplineTrajectory(const std::vector<PoseSample>& samples) {
  const std::size_t n = samples.size();
  if (n < kStencil) throw std::invalid_argument("SplineTrajectory: need at least 7 pose samples");
  for (std::size_t i = 0; i < n; ++i) {
    const PoseSample& s = samples[i];
    if (!std::isfinite(s.t_s) || !s.p_W.allFinite() || !s.q_W_S.coeffs().allFinite() ||
        !(s.q_W_S.norm() > 0.5)) {
      throw std::invalid_argument("SplineTrajectory: sample " + std::to_string(i) +
                                  " is not finite or has no unit quaternion");
    }
    if (i > 0 && !(s.t_s > samples[i - 1].t_s)) {
      throw std::invalid_argument("SplineTrajectory: times must increase (sample " +
                                  std::to_string(i) + ")");
    }
    times_.push_back(s.t_s);
    attitudes_.push_back(s.q_W_S.normalized());
    if (i > 0 && rotation_angle_between(attitudes_[i - 1], attitudes_[i]) > kMaxStepAngle) {
      throw std::invalid_argument(
          "SplineTrajectory: attitude changes by more than 0.2 rad "
          "between samples " +
          std::to_string(i - 1) + " and " + std::to_string(i) + "; sample faster");
    }
  }
  // Derivatives at the samples, in the sample's own chart for the attitude.
  std::vector<Eigen::Vector3d> v(n), a(n), omega(n), omega_dot(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t first = std::min(i >= 3 ? i - 3 : 0, n - kStencil);
    double x[kStencil];
    for (int j = 0; j < kStencil; ++j) x[j] = times_[first + j] - times_[i];
    double w[kStencil][3];
    fornberg_weights(0.0, x, w);
    v[i] = a[i] = omega[i] = omega_dot[i] = Eigen::Vector3d::Zero();
    const Eigen::Quaterniond q_inv = attitudes_[i].conjugate();
    for (int j = 0; j < kStencil; ++j) {
      // Differences of positions relative to sample i: fewer rounding digits lost.
      const Eigen::Vector3d dp = samples[first + j].p_W - samples[i].p_W;
      const Eigen::Vector3d phi = quat_log(Eigen::Quaterniond(q_inv * attitudes_[first + j]));
      v[i] += w[j][1] * dp;
      a[i] += w[j][2] * dp;
      omega[i] += w[j][1] * phi;
      omega_dot[i] += w[j][2] * phi;
    }
  }
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double h = times_[i + 1] - times_[i];
    position_.push_back(
        hermite_quintic(samples[i].p_W, v[i], a[i], samples[i + 1].p_W, v[i + 1], a[i + 1], h));
    const Eigen::Vector3d phi1 =
        quat_log(Eigen::Quaterniond(attitudes_[i].conjugate() * attitudes_[i + 1]));
    Eigen::Matrix3d jinv, jinv_dot;
    inverse_right_jacobian(phi1, Eigen::Vector3d::Zero(), jinv, jinv_dot);
    const Eigen::Vector3d phi1_dot = jinv * omega[i + 1];
    inverse_right_jacobian(phi1, phi1_dot, jinv, jinv_dot);
    const Eigen::Vector3d phi1_ddot = jinv_dot * omega[i + 1] + jinv * omega_dot[i + 1];
    rotation_.push_back(hermite_quintic(Eigen::Vector3d::Zero(), omega[i], omega_dot[i], phi1,
                                        phi1_dot, phi1_ddot, h));
  }
}

KinematicState SplineTrajectory::at(double t_s) const {
  // Interval i with times_[i] <= t < times_[i+1], clamped to the first and last.
  const auto it = std::upper_bound(times_.begin(), times_.end(), t_s);
  const std::size_t i = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - times_.begin() - 1, 0)), 0,
      position_.size() - 1);
  const double h = times_[i + 1] - times_[i];
  const double u = (t_s - times_[i]) / h;
  const QuinticValue p = evaluate(position_[i], u, h);
  const QuinticValue phi = evaluate(rotation_[i], u, h);
  KinematicState state;
  state.p_W = p.y;
  state.v_W = p.dy_dt;
  state.a_W = p.d2y_dt2;
  state.q_W_S = (attitudes_[i] * quat_exp(phi.y)).normalized();
  state.omega_WS_S = right_jacobian(phi.y) * phi.dy_dt;
  return state;
}

}  // namespace imscal::ims
