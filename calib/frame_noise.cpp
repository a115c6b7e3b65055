#include "calib/frame_noise.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "ims/so3.hpp"

namespace imscal::calib {

RestSigmas rest_sigmas(const ImuNoiseModel& noise, double duration_s) {
  const double T = duration_s;
  auto combine = [T](double density, double lsb) {
    const double white = density / std::sqrt(T);
    const double quantisation = lsb / (std::sqrt(6.0) * T);
    return std::sqrt(white * white + quantisation * quantisation);
  };
  RestSigmas s;
  s.rate_rad_s = combine(noise.gyro_noise_density_rad_per_sqrt_s, noise.gyro_quantization_rad);
  s.force_m_s2 = combine(noise.acc_noise_density_m_s_per_sqrt_s, noise.acc_quantization_m_s);
  return s;
}

Eigen::Matrix<double, 9, 9> motion_covariance(const ImuNoiseModel& noise, double duration_s,
                                              const Eigen::Vector3d& f0_S) {
  const double T = duration_s;
  const double T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  const double sg2 =
      noise.gyro_noise_density_rad_per_sqrt_s * noise.gyro_noise_density_rad_per_sqrt_s;
  const double sa2 =
      noise.acc_noise_density_m_s_per_sqrt_s * noise.acc_noise_density_m_s_per_sqrt_s;
  const Eigen::Matrix3d A = -ims::skew<double>(f0_S);
  const Eigen::Matrix3d AAt = A * A.transpose();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 9, 9> c = Eigen::Matrix<double, 9, 9>::Zero();
  c.block<3, 3>(0, 0) = sg2 * T * I;
  c.block<3, 3>(0, 3) = sg2 * T2 / 2.0 * A.transpose();
  c.block<3, 3>(0, 6) = sg2 * T3 / 6.0 * A.transpose();
  c.block<3, 3>(3, 3) = sg2 * T3 / 3.0 * AAt + sa2 * T * I;
  c.block<3, 3>(3, 6) = sg2 * T4 / 8.0 * AAt + sa2 * T2 / 2.0 * I;
  c.block<3, 3>(6, 6) = sg2 * T5 / 20.0 * AAt + sa2 * T3 / 3.0 * I;
  c.block<3, 3>(3, 0) = c.block<3, 3>(0, 3).transpose();
  c.block<3, 3>(6, 0) = c.block<3, 3>(0, 6).transpose();
  c.block<3, 3>(6, 3) = c.block<3, 3>(3, 6).transpose();
  for (int k = 0; k < 3; ++k) {
    c(k, k) += noise.rotation_floor_rad * noise.rotation_floor_rad;
    c(3 + k, 3 + k) += noise.velocity_floor_m_s * noise.velocity_floor_m_s;
    c(6 + k, 6 + k) += noise.position_floor_m * noise.position_floor_m;
  }
  return c;
}

Eigen::Matrix<double, 9, 9> whitening_matrix(const Eigen::Matrix<double, 9, 9>& covariance) {
  const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(covariance);
  const Eigen::Matrix<double, 9, 9> L = llt.matrixL();
  return L.triangularView<Eigen::Lower>().solve(Eigen::Matrix<double, 9, 9>::Identity());
}

}  // namespace imscal::calib
