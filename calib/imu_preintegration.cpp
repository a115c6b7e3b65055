#include "calib/imu_preintegration.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

Eigen::Matrix3d exp_rotation(const Eigen::Vector3d& phi) {
  return ims::quat_exp(phi).toRotationMatrix();
}

// Right Jacobian of SO(3): exp(phi + d) ~ exp(phi) exp(Jr(phi) d).
Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi) {
  const double angle_sq = phi.squaredNorm();
  const Eigen::Matrix3d k = ims::skew(phi);
  if (angle_sq < 1e-10) {
    // Series to second order; the next term is ~angle^3 / 24 < 1e-15.
    return Eigen::Matrix3d::Identity() - 0.5 * k + k * k / 6.0;
  }
  const double angle = std::sqrt(angle_sq);
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(angle)) / angle_sq * k +
         (angle - std::sin(angle)) / (angle_sq * angle) * k * k;
}

// d(-E v)/d vec(E): column 3 c + r holds -v_c e_r.
ImuPreintegration::Matrix39 sensitivity_derivative(const Eigen::Vector3d& v) {
  ImuPreintegration::Matrix39 d = ImuPreintegration::Matrix39::Zero();
  for (int c = 0; c < 3; ++c) d.block<3, 3>(0, 3 * c) = -v[c] * Eigen::Matrix3d::Identity();
  return d;
}

Eigen::Matrix<double, 9, 1> vec(const Eigen::Matrix3d& e) {
  return Eigen::Map<const Eigen::Matrix<double, 9, 1>>(e.data());
}

}  // namespace

ImuPreintegration::ImuPreintegration(const ims::ImuSeries& imu, double t_begin_s, double t_end_s,
                                     const ImuBiases& linearisation)
    : linearisation_(linearisation) {
  const std::string source = imu.source.empty() ? std::string("IMS increments") : imu.source;
  if (imu.quantity != ims::ImuQuantity::kIncrements) {
    throw InputError(source, 0, "quantity", "preintegration needs increments, not rates");
  }
  for (auto& m : moments_) m.setZero();
  for (auto& j : moment_gyro_jacobian_) j.setZero();
  for (auto& j : moment_acc_jacobian_) j.setZero();
  for (auto& j : moment_gyro_sensitivity_) j.setZero();
  for (auto& j : moment_acc_sensitivity_) j.setZero();
  Eigen::Vector3d previous_rotation_vector = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_dv = Eigen::Vector3d::Zero();
  bool first = true;
  double t_previous = 0.0;
  // The stamps increase strictly (ims/imu_validation.cpp): the samples in (t_begin_s, t_end_s]
  // start at the first stamp after t_begin_s, so a motion costs its own samples, not the record's.
  const auto after_begin =
      std::upper_bound(imu.samples.begin(), imu.samples.end(), t_begin_s,
                       [](double t, const ims::ImuSample& sample) { return t < sample.t_s; });
  for (auto k = static_cast<std::size_t>(after_begin - imu.samples.begin()); k < imu.samples.size();
       ++k) {
    const ims::ImuSample& s = imu.samples[k];
    if (s.t_s > t_end_s) break;
    const double interval_start = k == 0 ? s.t_s - imu.nominal_dt_s : imu.samples[k - 1].t_s;
    if (first && std::abs(interval_start - t_begin_s) > 1e-9) {
      throw InputError(source, 0, "t_s",
                       fmt::format("no increment interval starts at {} s (nearest {} s)", t_begin_s,
                                   interval_start));
    }
    const double h = s.t_s - interval_start;
    if (!(h > 0.0)) throw InputError(source, 0, "t_s", "time does not increase");
    // Body rotation of the interval, with the classical coning term (dtheta_{k-1} x dtheta_k
    // / 12) for the rotation of the axis within it; biases removed.
    const Eigen::Vector3d dtheta = s.gyro - linearisation.gyro_rad_s * h;
    const Eigen::Vector3d rotation_vector =
        dtheta + (first ? Eigen::Vector3d::Zero()
                        : Eigen::Vector3d(previous_rotation_vector.cross(dtheta) / 12.0));
    const Eigen::Vector3d dv = s.acc - linearisation.acc_m_s2 * h;
    // Midpoint rotation and time.
    const Eigen::Matrix3d half_step = exp_rotation(0.5 * rotation_vector);
    const Eigen::Matrix3d rotation_mid = delta_rotation_ * half_step;
    const Eigen::Matrix3d jacobian_mid = half_step.transpose() * rotation_gyro_jacobian_ -
                                         right_jacobian(0.5 * rotation_vector) * (0.5 * h);
    const double tau_mid = 0.5 * (interval_start + s.t_s) - t_begin_s;
    // Second-order terms of int DR f over the interval about its middle, for rate and specific
    // force linear in time (their changes from the previous increments): the rotation within
    // the interval acting on the changing force, the changing rate on the force, and the
    // second-order rotation.
    Eigen::Vector3d within = dtheta.cross(dtheta.cross(dv)) / 24.0;
    if (!first) {
      within += dtheta.cross(dv - previous_dv) / 12.0 +
                (dtheta - previous_rotation_vector).cross(dv) / 24.0;
    }
    const Eigen::Vector3d rotated_dv = rotation_mid * (dv + within);
    const Eigen::Matrix3d dv_gyro = -rotation_mid * ims::skew(dv) * jacobian_mid;
    // Sensitivity errors: the interval's increments move by -E_g dtheta, -E_a dv.
    const Matrix39 dtheta_sensitivity = sensitivity_derivative(dtheta);
    const Matrix39 sensitivity_mid =
        half_step.transpose() * rotation_gyro_sensitivity_ +
        right_jacobian(0.5 * rotation_vector) * (0.5 * dtheta_sensitivity);
    const Matrix39 dv_gyro_sensitivity = -rotation_mid * ims::skew(dv) * sensitivity_mid;
    const Matrix39 dv_acc_sensitivity = rotation_mid * sensitivity_derivative(dv);
    double weight = 1.0;  // tau_mid^m
    for (int m = 0; m < kMomentCount; ++m) {
      moments_[m] += weight * rotated_dv;
      moment_gyro_jacobian_[m] += weight * dv_gyro;
      moment_acc_jacobian_[m] += -weight * h * rotation_mid;
      moment_gyro_sensitivity_[m] += weight * dv_gyro_sensitivity;
      moment_acc_sensitivity_[m] += weight * dv_acc_sensitivity;
      weight *= tau_mid;
    }
    // Advance the rotation and its gyro-bias Jacobian over the whole interval.
    const Eigen::Matrix3d step = exp_rotation(rotation_vector);
    const Eigen::Matrix3d step_jacobian = right_jacobian(rotation_vector);
    rotation_gyro_jacobian_ = step.transpose() * rotation_gyro_jacobian_ - step_jacobian * h;
    rotation_gyro_sensitivity_ =
        step.transpose() * rotation_gyro_sensitivity_ + step_jacobian * dtheta_sensitivity;
    delta_rotation_ = delta_rotation_ * step;
    previous_rotation_vector = dtheta;
    previous_dv = dv;
    t_previous = s.t_s;
    first = false;
  }
  if (first) {
    throw InputError(source, 0, "t_s",
                     fmt::format("no increment in ({} s, {} s]", t_begin_s, t_end_s));
  }
  duration_s_ = t_previous - t_begin_s;
}

Eigen::Matrix3d ImuPreintegration::delta_rotation(const ImuBiases& b) const {
  return delta_rotation_ *
         exp_rotation(rotation_gyro_jacobian_ * (b.gyro_rad_s - linearisation_.gyro_rad_s));
}

Eigen::Vector3d ImuPreintegration::moment(int m, const ImuBiases& b) const {
  return moments_[m] + moment_gyro_jacobian_[m] * (b.gyro_rad_s - linearisation_.gyro_rad_s) +
         moment_acc_jacobian_[m] * (b.acc_m_s2 - linearisation_.acc_m_s2);
}

Eigen::Matrix3d ImuPreintegration::delta_rotation(const ImuBiases& b,
                                                  const ImuSensitivityErrors& e) const {
  return delta_rotation_ *
         exp_rotation(rotation_gyro_jacobian_ * (b.gyro_rad_s - linearisation_.gyro_rad_s) +
                      rotation_gyro_sensitivity_ * vec(e.gyro));
}

Eigen::Vector3d ImuPreintegration::moment(int m, const ImuBiases& b,
                                          const ImuSensitivityErrors& e) const {
  return moment(m, b) + moment_gyro_sensitivity_[m] * vec(e.gyro) +
         moment_acc_sensitivity_[m] * vec(e.acc);
}

ims::NavState ImuPreintegration::predict(const ims::NavState& start, const ims::EarthModel& earth,
                                         const ImuBiases& b) const {
  const double T = duration_s_;
  const Eigen::Matrix3d R_i = start.q_W_S.toRotationMatrix();
  const Eigen::Vector3d& omega = earth.earth_rate_W();
  const Eigen::Matrix3d O = ims::skew(omega);
  const Eigen::Matrix3d O2 = O * O;
  std::array<Eigen::Vector3d, kMomentCount> w;  // the moments in W axes at the start
  for (int m = 0; m < kMomentCount; ++m) w[m] = R_i * moment(m, b);
  // int R f dtau and int int R f, Earth rotation to second order.
  const Eigen::Vector3d single = w[0] - O * w[1] + 0.5 * O2 * w[2];
  const Eigen::Vector3d double_integral =
      (T * w[0] - w[1]) - O * (T * w[1] - w[2]) + 0.5 * O2 * (T * w[2] - w[3]);
  const Eigen::Vector3d g_i = earth.gravity_W(start.p_W);
  const Eigen::Matrix3d& G = earth.gravity_gradient_W();
  // Integrals of the path p(tau) - p_i, int over [0, T] (path_1) and int (T - tau) (...) dtau
  // (path_2), to first order in Omega: R_W_S f = (I - [Omega]x tau) R_i x and, in path_1, the
  // Coriolis displacement -2 Omega x int (p - p_i). Without these first-order terms the
  // Coriolis term of the position would miss 2 Omega x (Omega x g) T^4 / 24 (~4e-5 m at 10 s).
  const double T2 = T * T, T3 = T2 * T, T4 = T3 * T;
  const Eigen::Vector3d path_2 = start.v_W * T3 / 6.0 + g_i * T4 / 24.0 +
                                 (T3 * w[0] - 3.0 * T2 * w[1] + 3.0 * T * w[2] - w[3]) / 6.0 -
                                 O * (T3 * w[1] - 3.0 * T2 * w[2] + 3.0 * T * w[3] - w[4]) / 6.0;
  const Eigen::Vector3d path_1 =
      start.v_W * T2 / 2.0 + g_i * T3 / 6.0 + (T2 * w[0] - 2.0 * T * w[1] + w[2]) / 2.0 -
      O * (T2 * w[1] - 2.0 * T * w[2] + w[3]) / 2.0 - 2.0 * omega.cross(path_2);
  ims::NavState end;
  end.t_s = start.t_s + T;
  end.p_W = start.p_W + start.v_W * T + g_i * T2 / 2.0 + G * path_2 - 2.0 * omega.cross(path_1) +
            double_integral;
  end.v_W = start.v_W + g_i * T + G * path_1 - 2.0 * omega.cross(end.p_W - start.p_W) + single;
  end.q_W_S = Eigen::Quaterniond(exp_rotation(-omega * T) * R_i * delta_rotation(b)).normalized();
  return end;
}

}  // namespace imscal::calib
