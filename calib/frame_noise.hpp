#pragma once
// The noise of the frame calibration's measurements, from the sensor's white-noise densities.
//
// Rest mean over T seconds: rate sigma = ARW / sqrt(T) (+) LSB_g / (sqrt(6) T) (quantisation with
// the residual carried: the sum of T's increments errs by the difference of two ~uniform
// +-LSB/2 residuals), likewise for the specific force with VRW and LSB_a.
//
// Motion over T seconds (preintegration from one rest to the next), errors in the axes of S at
// the start: the angle error is the gyro's Brownian motion W_g (density ARW), which tilts the
// specific force f0 (gravity, the dominant part; f0 = the rest's mean specific force in S) and
// so feeds the velocity and position: with A = -[f0]x,
//   dtheta = W_g(T),  dv = A int W_g + W_a(T),  dp = A int int W_g + int W_a.
// The moments of integrated Brownian motion (E[W^2] = s^2 T, E[(int W)^2] = s^2 T^3/3,
// E[(int int W)^2] = s^2 T^5/20, E[W int W] = s^2 T^2/2, E[W int int W] = s^2 T^3/6,
// E[int W int int W] = s^2 T^4/8) give the 9x9 covariance in closed form (cross terms
// included). The robot's own accelerations (short, averaging out) are left out of A. The floors
// (ImuNoiseModel) are added in quadrature on the diagonal.
#include <Eigen/Core>

#include "calib/frame_calibration.hpp"

namespace imscal::calib {

struct RestSigmas {
  double rate_rad_s = 0.0;
  double force_m_s2 = 0.0;
};

RestSigmas rest_sigmas(const ImuNoiseModel& noise, double duration_s);

// Covariance of (rotation [rad], velocity [m/s], position [m]) at the end of a motion of
// duration_s starting at rest with specific force f0_S [m/s^2].
Eigen::Matrix<double, 9, 9> motion_covariance(const ImuNoiseModel& noise, double duration_s,
                                              const Eigen::Vector3d& f0_S);

// Inverse of the lower Cholesky factor: whitening * residual has unit covariance.
Eigen::Matrix<double, 9, 9> whitening_matrix(const Eigen::Matrix<double, 9, 9>& covariance);

}  // namespace imscal::calib
