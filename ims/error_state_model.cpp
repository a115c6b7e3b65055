#include "ims/error_state_model.hpp"

#include <cmath>

#include "ims/so3.hpp"

namespace imscal::ims {
using namespace error_state;

namespace {
// -1/tau, or 0 for a random walk (tau infinite or not positive: no decay).
double decay_rate(double correlation_time_s) {
  return (std::isfinite(correlation_time_s) && correlation_time_s > 0.0) ? -1.0 / correlation_time_s
                                                                         : 0.0;
}
}  // namespace

ErrorMatrix continuous_error_dynamics(const ErrorLinearisation& point,
                                      const ErrorProcessNoise& noise) {
  ErrorMatrix F = ErrorMatrix::Zero();
  const Eigen::Matrix3d earth_rate_skew = skew(point.earth_rate_W);
  F.block<3, 3>(kAttitude, kAttitude) = -earth_rate_skew;
  F.block<3, 3>(kAttitude, kGyroBias) = -point.mean_R_W_S;
  F.block<3, 3>(kVelocity, kAttitude) = -skew(point.mean_specific_force_W);
  F.block<3, 3>(kVelocity, kVelocity) = -2.0 * earth_rate_skew;
  F.block<3, 3>(kVelocity, kPosition) = point.gravity_gradient_W;
  F.block<3, 3>(kVelocity, kAccBias) = -point.mean_R_W_S;
  F.block<3, 3>(kPosition, kVelocity) = Eigen::Matrix3d::Identity();
  F.block<3, 3>(kGyroBias, kGyroBias) =
      decay_rate(noise.gyro_bias_correlation_time_s) * Eigen::Matrix3d::Identity();
  F.block<3, 3>(kAccBias, kAccBias) =
      decay_rate(noise.acc_bias_correlation_time_s) * Eigen::Matrix3d::Identity();
  return F;
}

ErrorMatrix continuous_error_noise(const ErrorLinearisation& point,
                                   const ErrorProcessNoise& noise) {
  ErrorMatrix Qc = ErrorMatrix::Zero();
  const Eigen::Matrix3d& R = point.mean_R_W_S;
  Qc.block<3, 3>(kAttitude, kAttitude) = R * noise.gyro_white_psd.asDiagonal() * R.transpose();
  Qc.block<3, 3>(kVelocity, kVelocity) = R * noise.acc_white_psd.asDiagonal() * R.transpose();
  Qc.block<3, 3>(kGyroBias, kGyroBias) = noise.gyro_bias_drive_psd.asDiagonal();
  Qc.block<3, 3>(kAccBias, kAccBias) = noise.acc_bias_drive_psd.asDiagonal();
  return Qc;
}

DiscreteErrorModel discretize_error_model(const ErrorMatrix& F, const ErrorMatrix& Qc, double dt) {
  const ErrorMatrix Fdt = F * dt;
  const ErrorMatrix Fdt2 = Fdt * Fdt;
  DiscreteErrorModel model;
  model.transition = ErrorMatrix::Identity() + Fdt + Fdt2 / 2.0 + Fdt2 * Fdt / 6.0;
  // Qd = Qc dt + (F Qc + Qc F^T) dt^2/2 + (F^2 Qc + 2 F Qc F^T + Qc F^T^2) dt^3/6.
  const ErrorMatrix FQ = Fdt * Qc;  // F Qc dt
  const ErrorMatrix first = FQ + FQ.transpose();
  const ErrorMatrix second = Fdt2 * Qc + 2.0 * FQ * Fdt.transpose() + Qc * Fdt2.transpose();
  model.noise_covariance = (Qc + first / 2.0 + second / 6.0) * dt;
  model.noise_covariance = 0.5 * (model.noise_covariance + model.noise_covariance.transpose());
  return model;
}

}  // namespace imscal::ims
