#pragma once
// IMU preintegration between two instants (typically two rest poses) for the frame calibration:
// the IMS increments are integrated once, in the sensor frame at the start S_i and at a bias
// linearisation point; the state at the end in W then follows in closed form from the state at
// the start, for any biases near that point (first order, through the bias Jacobians).
//
// Model (as ims/strapdown.hpp, W rotating with the Earth at Omega = omega_ie_W, gravity
// g_W(p) = g0 + G p from ims::EarthModel):
//   dR_W_S/dt = R_W_S [omega_is - b_g]x - [Omega]x R_W_S
//   dv_W/dt   = R_W_S (f - b_a) - 2 Omega x v_W + g_W(p_W),     dp_W/dt = v_W.
// With tau = t - t_i and DR(tau) the body rotation integrated from the gyros alone,
//   R_W_S(tau) = exp(-[Omega]x tau) R_i DR(tau)       (exact: Omega is constant in W).
// The specific-force moments M_m = int_0^T tau^m DR(tau) (f - b_a) dtau, m = 0..4 (vectors in
// S_i), carry everything the end state needs: the Earth rotation enters through
// exp(-[Omega]x tau) expanded to second order ((Omega T)^3 / 6 < 1e-10 for T < 10 s); Coriolis
// and the gravity gradient act on the path p(tau) taken to first order in Omega (R_i DR f rotated
// by -[Omega]x tau, Coriolis displacement) and zeroth order in G, whose integrals are again
// combinations of the M_m. Neglected: (Omega T)^3 g T^2, G Omega v T^4, G^2 T^4 terms, below
// 1e-6 m for T <= 10 s and robot speeds.
//
// Discretisation: increments (dtheta_k, dv_k) over h_k; rotation products with the classical
// coning term; the specific force rotated at the interval's middle (DR_k exp(dtheta / 2)) plus
// the second-order terms of rate and force changing within the interval (from the previous
// increments); tau^m taken at the middle. Second order in h: on a 10 s robot-like motion at
// 1 kHz the end state errs by ~1e-13 rad, 3e-7 m/s and 4e-6 m (tests). The bias Jacobians leave
// out the small within-interval terms (relative effect ~ |dtheta| ~ 1e-3).
//
// Sensitivity errors (scale factors and misalignments, the model of ims/sensor_error_model.hpp:
// raw = (I + E) true + b dt, E = diag(scale) + misalignment, |E| ~ 1e-4): corrected increments
// are (I + E)^-1 (raw - b dt) = (I - E)(raw - b dt) + O(E^2) (E^2 ~ 1e-8 relative: 1e-8 of a
// 180 deg turn is 3e-8 rad, below the gyro noise). The rotation and moments are linearised in
// the 9 entries of E_g and E_a at E = 0 (the raw increments are integrated as if exact): each
// interval's increment moves by -E dtheta_k, a bias-like perturbation with a per-interval
// direction, propagated by the same recursions as the bias Jacobians. The Jacobians are 3x9 in
// vec(E), column-major (entry (r, c) of E at index 3 c + r, as Eigen::Map<Matrix3d> reads it).
// Which of the 18 entries the data can separate from the frames is the bundle's business
// (calib/frame_calibration.hpp: the gyro triad defines S, its antisymmetric part is R_S_H's).
//
// References (docs/references.md): [LuptonSukkarieh2012], [Forster2017] (preintegration, bias
// Jacobians), [Savage1998] (coning term).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/nav_state.hpp"

namespace imscal::calib {

struct ImuBiases {
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_m_s2 = Eigen::Vector3d::Zero();
};

// Sensitivity errors E of both triads (raw = (I + E) true + bias dt) [1, rad].
struct ImuSensitivityErrors {
  Eigen::Matrix3d gyro = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d acc = Eigen::Matrix3d::Zero();
};

class ImuPreintegration {
 public:
  static constexpr int kMomentCount = 5;  // M_0 .. M_4

  // Integrates the increment samples of `imu` whose intervals lie in (t_begin_s, t_end_s] (their
  // stamps in that range; the first interval must start at t_begin_s to ~1e-9 s) at the biases
  // `linearisation`. Throws InputError for rates, gaps or fewer than 1 sample.
  ImuPreintegration(const ims::ImuSeries& imu, double t_begin_s, double t_end_s,
                    const ImuBiases& linearisation = {});

  double duration_s() const { return duration_s_; }
  const ImuBiases& linearisation() const { return linearisation_; }

  // Body rotation DR (S_j in S_i) and the moments M_m at biases b (first-order correction from
  // the linearisation point).
  Eigen::Matrix3d delta_rotation(const ImuBiases& b) const;
  Eigen::Vector3d moment(int m, const ImuBiases& b) const;

  // Jacobians at the linearisation point: DR(b) = DR0 exp(J_rot_gyro (b_g - b_g0)),
  // M_m(b) = M_m0 + J_m_gyro (b_g - b_g0) + J_m_acc (b_a - b_a0).
  const Eigen::Matrix3d& rotation_gyro_jacobian() const { return rotation_gyro_jacobian_; }
  const Eigen::Matrix3d& moment_gyro_jacobian(int m) const { return moment_gyro_jacobian_[m]; }
  const Eigen::Matrix3d& moment_acc_jacobian(int m) const { return moment_acc_jacobian_[m]; }

  // Jacobians in vec(E) at E = 0 (see above): DR(b, E) = DR(b) exp(J_rot_Eg vec(E_g)),
  // M_m(b, E) = M_m(b) + J_m_Eg vec(E_g) + J_m_Ea vec(E_a).
  using Matrix39 = Eigen::Matrix<double, 3, 9>;
  const Matrix39& rotation_gyro_sensitivity_jacobian() const { return rotation_gyro_sensitivity_; }
  const Matrix39& moment_gyro_sensitivity_jacobian(int m) const {
    return moment_gyro_sensitivity_[m];
  }
  const Matrix39& moment_acc_sensitivity_jacobian(int m) const {
    return moment_acc_sensitivity_[m];
  }
  // The rotation and moments with biases b and sensitivity errors e (first order in both).
  Eigen::Matrix3d delta_rotation(const ImuBiases& b, const ImuSensitivityErrors& e) const;
  Eigen::Vector3d moment(int m, const ImuBiases& b, const ImuSensitivityErrors& e) const;

  // The state at t_end_s from `start` (at t_begin_s) with biases b.
  ims::NavState predict(const ims::NavState& start, const ims::EarthModel& earth,
                        const ImuBiases& b) const;

 private:
  double duration_s_ = 0.0;
  ImuBiases linearisation_;
  Eigen::Matrix3d delta_rotation_ = Eigen::Matrix3d::Identity();
  std::array<Eigen::Vector3d, kMomentCount> moments_{};
  Eigen::Matrix3d rotation_gyro_jacobian_ = Eigen::Matrix3d::Zero();
  std::array<Eigen::Matrix3d, kMomentCount> moment_gyro_jacobian_{};
  std::array<Eigen::Matrix3d, kMomentCount> moment_acc_jacobian_{};
  Matrix39 rotation_gyro_sensitivity_ = Matrix39::Zero();
  std::array<Matrix39, kMomentCount> moment_gyro_sensitivity_{};
  std::array<Matrix39, kMomentCount> moment_acc_sensitivity_{};
};

}  // namespace imscal::calib
