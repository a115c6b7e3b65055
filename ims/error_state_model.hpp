#pragma once
// Linear error model of the strapdown navigation in the Earth-fixed frame W (ims/frames.hpp), the
// one the zero-velocity smoother (ims/zupt_smoother.hpp) propagates its covariance with.
//
// Error state (15): x = [phi, dv, dp, dbg, dba]
//   phi  [rad]   attitude error in W:       R_W_S(true) = Exp(phi) * R_W_S(estimate)
//   dv   [m/s]   velocity error in W:       v_W(true) = v_W(estimate) + dv
//   dp   [m]     position error in W:       p_W(true) = p_W(estimate) + dp
//   dbg  [rad/s] gyro bias error in S:      b_g(true) = b_g(estimate) + dbg
//   dba  [m/s^2] accelerometer bias error:  b_a(true) = b_a(estimate) + dba
//
// Mechanization in W (Earth-fixed, rotating with the Earth at omega_ie):
//   dR/dt = R [w_is]x - [omega_ie]x R,   dv/dt = R f + g(p) - 2 omega_ie x v,   dp/dt = v
// with w_is = gyro - b_g - n_g and f = acc - b_a - n_a. To first order in the errors:
//   dphi/dt = -[omega_ie]x phi - R dbg - R n_g
//   ddv/dt  = -[f_W]x phi - 2 [omega_ie]x dv + G_W dp - R dba - R n_a      (f_W = R f)
//   ddp/dt  = dv
//   ddb/dt  = -db / tau + w_b       (first-order Gauss-Markov; tau = infinity: random walk)
// G_W is the gravity gradient (ims/earth_model.hpp); n_g, n_a, w_b are white noises with the
// power spectral densities in ErrorProcessNoise.
//
// References (docs/references.md): [Groves2013] (Earth-fixed-frame error model).
#include <Eigen/Core>

namespace imscal::ims {

namespace error_state {
inline constexpr int kAttitude = 0;
inline constexpr int kVelocity = 3;
inline constexpr int kPosition = 6;
inline constexpr int kGyroBias = 9;
inline constexpr int kAccBias = 12;
inline constexpr int kSize = 15;
}  // namespace error_state

using ErrorVector = Eigen::Matrix<double, error_state::kSize, 1>;
using ErrorMatrix = Eigen::Matrix<double, error_state::kSize, error_state::kSize>;

// Power spectral densities of the white noises, per sensor axis.
struct ErrorProcessNoise {
  Eigen::Vector3d gyro_white_psd = Eigen::Vector3d::Zero();       // ARW^2 [rad^2/s]
  Eigen::Vector3d acc_white_psd = Eigen::Vector3d::Zero();        // VRW^2 [m^2/s^3]
  Eigen::Vector3d gyro_bias_drive_psd = Eigen::Vector3d::Zero();  // [(rad/s)^2/s]
  Eigen::Vector3d acc_bias_drive_psd = Eigen::Vector3d::Zero();   // [(m/s^2)^2/s]
  // Correlation times of the bias processes [s]; infinity means random walk.
  double gyro_bias_correlation_time_s = 0.0;
  double acc_bias_correlation_time_s = 0.0;
};

// The linearisation point of one propagation interval: the interval means of R_W_S(estimate)
// and of the specific force in W (computed from the bias-corrected increments).
struct ErrorLinearisation {
  Eigen::Matrix3d mean_R_W_S = Eigen::Matrix3d::Identity();
  Eigen::Vector3d mean_specific_force_W = Eigen::Vector3d::Zero();  // [m/s^2]
  Eigen::Vector3d earth_rate_W = Eigen::Vector3d::Zero();           // [rad/s]
  Eigen::Matrix3d gravity_gradient_W = Eigen::Matrix3d::Zero();     // [1/s^2]
};

// Continuous-time system matrix F (dx/dt = F x + noise).
ErrorMatrix continuous_error_dynamics(const ErrorLinearisation& point,
                                      const ErrorProcessNoise& noise);

// Continuous-time noise covariance G Qc G^T (the noise of phi and dv rotated into W).
ErrorMatrix continuous_error_noise(const ErrorLinearisation& point, const ErrorProcessNoise& noise);

struct DiscreteErrorModel {
  ErrorMatrix transition;        // Phi = exp(F dt)
  ErrorMatrix noise_covariance;  // Qd = int_0^dt exp(F s) Qc exp(F s)^T ds
};

// Phi and Qd over dt [s] by their Taylor series to third order in F dt. The chain
// dbg -> phi -> dv -> dp is three steps long, so the third order keeps the leading term of every
// block; the neglected fourth-order terms are below (|F| dt)^4 / 24, i.e. below 1e-6 relative
// for dt = 10 ms (|F| dt ~ g dt ~ 0.1).
DiscreteErrorModel discretize_error_model(const ErrorMatrix& F, const ErrorMatrix& Qc, double dt);

}  // namespace imscal::ims
