#pragma once
// Ceres cost functors of the frame-and-bias bundle (calib/frame_calibration.hpp), templated on
// the scalar for automatic differentiation. Parameter blocks (SI):
//   q_W_R, q_S_H : Eigen quaternions (x, y, z, w), EigenQuaternionManifold (left perturbation,
//                  Ceres' tangent delta turns by 2 |delta|);
//   p_S_H [m], b_g [rad/s], b_a [m/s^2], dt [s] (t_ims = t_robot + dt), s_g, s_a [1] (scale
//   factors), dq_i [rad] (joint deviation of rest i), m_w, m_p [1] (per joint: the fraction of
//   the modelled wind-up / play that is not there, 1 - k of estimate_deflection_scale).
// Every residual is whitened (multiplied by the inverse square root of its covariance), so that
// Huber scales and chi-square tests are in units of sigma.
#include <ceres/cubic_interpolation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "calib/forward_kinematics.hpp"
#include "calib/imu_preintegration.hpp"
#include "calib/robot_description.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {

template <typename T>
using Vector3T = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Matrix3T = Eigen::Matrix<T, 3, 3>;

// The joint deviation of a rest: dq + m_w * windup + m_p * play (per joint).
template <typename T>
Eigen::Matrix<T, 6, 1> rest_deviation(const T* dq, const T* m_w, const T* m_p,
                                      const JointVector& windup, const JointVector& play) {
  Eigen::Matrix<T, 6, 1> out;
  for (int k = 0; k < kJointCount; ++k) out[k] = dq[k] + m_w[k] * windup[k] + m_p[k] * play[k];
  return out;
}

// R_W_S of a rest from the frames and the joint angles q + dq.
template <typename T>
Matrix3T<T> rest_attitude(const KinematicModel& model, const JointVector& q, const T* q_W_R,
                          const T* q_S_H, const T* dq, Vector3T<T>* p_R_S = nullptr,
                          const T* p_S_H = nullptr) {
  const Eigen::Matrix<T, 6, 1> joints = q.cast<T>() + Eigen::Map<const Eigen::Matrix<T, 6, 1>>(dq);
  const Isometry3<T> T_R_H = forward_kinematics<T>(model, joints);
  const Matrix3T<T> R_W_R = Eigen::Map<const Eigen::Quaternion<T>>(q_W_R).toRotationMatrix();
  const Matrix3T<T> R_S_H = Eigen::Map<const Eigen::Quaternion<T>>(q_S_H).toRotationMatrix();
  if (p_R_S != nullptr) {
    // p_H_S = -R_H_S p_S_H, then into R.
    const Vector3T<T> p_H_S = -(R_S_H.transpose() * Eigen::Map<const Vector3T<T>>(p_S_H));
    *p_R_S = T_R_H.translation() + T_R_H.linear() * p_H_S;
  }
  return R_W_R * T_R_H.linear() * R_S_H.transpose();
}

// Rest pose: mean rate and specific force over the rest against
//   rate = (I + diag(s_g)) R_S_W Omega_W + b_g,   force = (I + diag(s_a)) (-R_S_W g_W) + b_a.
// Residual (6): whitened (measured - model); sigmas per component.
struct RestResidual {
  const KinematicModel* model = nullptr;
  JointVector q = JointVector::Zero();
  JointVector windup = JointVector::Zero();  // RestObservation::q_windup_rad
  JointVector play = JointVector::Zero();    // RestObservation::q_play_rad
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d earth_rate_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_W = Eigen::Vector3d::Zero();
  double rate_sigma = 1.0;   // [rad/s]
  double force_sigma = 1.0;  // [m/s^2]

  template <typename T>
  bool operator()(const T* q_W_R, const T* q_S_H, const T* dq, const T* b_g, const T* b_a,
                  const T* s_g, const T* s_a, const T* m_w, const T* m_p, T* residual) const {
    const Eigen::Matrix<T, 6, 1> deviation = rest_deviation<T>(dq, m_w, m_p, windup, play);
    const Matrix3T<T> R_S_W =
        rest_attitude<T>(*model, q, q_W_R, q_S_H, deviation.data()).transpose();
    const Vector3T<T> rate_true = R_S_W * earth_rate_W.cast<T>();
    const Vector3T<T> force_true = -(R_S_W * gravity_W.cast<T>());
    for (int k = 0; k < 3; ++k) {
      const T rate_model = (T(1) + s_g[k]) * rate_true[k] + b_g[k];
      const T force_model = (T(1) + s_a[k]) * force_true[k] + b_a[k];
      residual[k] = (T(mean_rate[k]) - rate_model) / T(rate_sigma);
      residual[3 + k] = (T(mean_force[k]) - force_model) / T(force_sigma);
    }
    return true;
  }
};

// Motion i -> j (= i + 1) by the preintegration from rest i (zero velocity, attitude and position
// of the model) to rest j: the end state (imu_preintegration.cpp's predict(), templated here with
// the bias Jacobians) against the model's attitude, zero velocity and position at rest j.
// Residual (9): rotation log(R_pred R_model_j^T), velocity, position difference, all expressed
// in the axes of S at rest i (where the covariance is computed), whitened by `whitening` (the
// inverse of the lower Cholesky factor of the 9x9 covariance).
struct MotionResidual {
  const KinematicModel* model = nullptr;
  const ImuPreintegration* preintegration = nullptr;
  JointVector q_i = JointVector::Zero();
  JointVector q_j = JointVector::Zero();
  JointVector windup_i = JointVector::Zero(), play_i = JointVector::Zero();
  JointVector windup_j = JointVector::Zero(), play_j = JointVector::Zero();
  Eigen::Vector3d earth_rate_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_start_W = Eigen::Vector3d::Zero();  // g at rest i's position
  Eigen::Matrix3d gravity_gradient_W = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> whitening = Eigen::Matrix<double, 9, 9>::Identity();

  template <typename T>
  bool operator()(const T* q_W_R, const T* q_S_H, const T* p_S_H, const T* dq_i, const T* dq_j,
                  const T* b_g, const T* b_a, const T* m_w, const T* m_p, T* residual) const {
    const ImuPreintegration& pre = *preintegration;
    const Eigen::Matrix<T, 6, 1> deviation_i = rest_deviation<T>(dq_i, m_w, m_p, windup_i, play_i);
    const Eigen::Matrix<T, 6, 1> deviation_j = rest_deviation<T>(dq_j, m_w, m_p, windup_j, play_j);
    Vector3T<T> p_R_S_i, p_R_S_j;
    const Matrix3T<T> R_i =
        rest_attitude<T>(*model, q_i, q_W_R, q_S_H, deviation_i.data(), &p_R_S_i, p_S_H);
    const Matrix3T<T> R_j =
        rest_attitude<T>(*model, q_j, q_W_R, q_S_H, deviation_j.data(), &p_R_S_j, p_S_H);
    const Matrix3T<T> R_W_R = Eigen::Map<const Eigen::Quaternion<T>>(q_W_R).toRotationMatrix();
    const Vector3T<T> dp_model = R_W_R * (p_R_S_j - p_R_S_i);

    const Vector3T<T> dbg =
        Eigen::Map<const Vector3T<T>>(b_g) - pre.linearisation().gyro_rad_s.cast<T>();
    const Vector3T<T> dba =
        Eigen::Map<const Vector3T<T>>(b_a) - pre.linearisation().acc_m_s2.cast<T>();
    const ImuBiases zero_offset = pre.linearisation();
    std::array<Vector3T<T>, ImuPreintegration::kMomentCount> w;
    for (int m = 0; m < ImuPreintegration::kMomentCount; ++m) {
      const Vector3T<T> moment = pre.moment(m, zero_offset).template cast<T>() +
                                 pre.moment_gyro_jacobian(m).template cast<T>() * dbg +
                                 pre.moment_acc_jacobian(m).template cast<T>() * dba;
      w[m] = R_i * moment;
    }
    const T duration(pre.duration_s());
    const T T2 = duration * duration, T3 = T2 * duration, T4 = T3 * duration;
    const Vector3T<T> omega = earth_rate_W.cast<T>();
    const Matrix3T<T> O = ims::skew<T>(omega);
    const Matrix3T<T> O2 = O * O;
    const Matrix3T<T> G = gravity_gradient_W.cast<T>();
    const Vector3T<T> g = gravity_start_W.cast<T>();
    const Vector3T<T> single = w[0] - O * w[1] + T(0.5) * O2 * w[2];
    const Vector3T<T> double_integral = (duration * w[0] - w[1]) - O * (duration * w[1] - w[2]) +
                                        T(0.5) * O2 * (duration * w[2] - w[3]);
    const Vector3T<T> path_2 =
        g * T4 / T(24) + (T3 * w[0] - T(3) * T2 * w[1] + T(3) * duration * w[2] - w[3]) / T(6) -
        O * (T3 * w[1] - T(3) * T2 * w[2] + T(3) * duration * w[3] - w[4]) / T(6);
    const Vector3T<T> path_1 = g * T3 / T(6) + (T2 * w[0] - T(2) * duration * w[1] + w[2]) / T(2) -
                               O * (T2 * w[1] - T(2) * duration * w[2] + w[3]) / T(2) -
                               T(2) * omega.cross(path_2);
    const Vector3T<T> dp =
        g * T2 / T(2) + G * path_2 - T(2) * omega.cross(path_1) + double_integral;
    const Vector3T<T> v = g * duration + G * path_1 - T(2) * omega.cross(dp) + single;
    // DR(b) = DR0 exp(J (b_g - b_g0)); R_end = exp(-Omega T) R_i DR(b).
    const Matrix3T<T> DR =
        pre.delta_rotation(zero_offset).template cast<T>() *
        ims::quat_exp<T>(Vector3T<T>(pre.rotation_gyro_jacobian().template cast<T>() * dbg))
            .toRotationMatrix();
    const Matrix3T<T> earth_turn =
        ims::quat_exp<T>(Vector3T<T>(-omega * duration)).toRotationMatrix();
    const Matrix3T<T> R_end = earth_turn * R_i * DR;
    const Matrix3T<T> R_error = R_end * R_j.transpose();
    const Vector3T<T> rotation_W = ims::quat_log<T>(Eigen::Quaternion<T>(R_error));
    Eigen::Matrix<T, 9, 1> raw;
    raw.template segment<3>(0) = R_i.transpose() * rotation_W;
    raw.template segment<3>(3) = R_i.transpose() * v;
    raw.template segment<3>(6) = R_i.transpose() * (dp - dp_model);
    Eigen::Map<Eigen::Matrix<T, 9, 1>> out(residual);
    out = whitening.cast<T>() * raw;
    return true;
  }
};

// Flange rate during motion (time offset): the mean gyro rate over a short window against
//   b_g + R_S_H mean(omega_H(t_ims - dt)) + earth_rate_S,
// omega_H from the joint readings (a cubic interpolator on a uniform robot-time grid, 3 values
// per node), averaged at the window's increment mid-times. Only dt is a parameter here: R_S_H,
// b_g and the Earth rate in S come from the previous solution, so that the model error of the
// joint-reading rates (systematic with the motion) cannot pull the frames or the biases, which
// the rests and motions determine far better.
// Residual (3): whitened by `sigma` [rad/s].
struct RateResidual {
  using Interpolator = ceres::CubicInterpolator<ceres::Grid1D<double, 3>>;
  const Interpolator* omega_H = nullptr;
  double grid_t0_s = 0.0;  // robot time of node 0
  double grid_step_s = 1.0;
  std::vector<double> mid_times_ims_s;
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_S_H = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset_S = Eigen::Vector3d::Zero();  // b_g + Earth rate in S [rad/s]
  double sigma = 1.0;

  template <typename T>
  bool operator()(const T* dt, T* residual) const {
    Vector3T<T> sum = Vector3T<T>::Zero();
    for (const double t : mid_times_ims_s) {
      const T x = (T(t) - dt[0] - T(grid_t0_s)) / T(grid_step_s);
      T value[3];
      omega_H->Evaluate(x, value);
      sum += Vector3T<T>(value[0], value[1], value[2]);
    }
    const Vector3T<T> mean_H = sum / T(static_cast<double>(mid_times_ims_s.size()));
    const Vector3T<T> model = R_S_H.cast<T>() * mean_H + offset_S.cast<T>();
    for (int k = 0; k < 3; ++k) residual[k] = (T(mean_rate[k]) - model[k]) / T(sigma);
    return true;
  }
};

// Prior N(0, sigma) of the deflection-scale deviations m_w, m_p (6 + 6; 1/sigma 0: none).
struct DeflectionScalePriorResidual {
  JointVector inverse_sigma_windup = JointVector::Zero();
  JointVector inverse_sigma_play = JointVector::Zero();
  template <typename T>
  bool operator()(const T* m_w, const T* m_p, T* residual) const {
    for (int k = 0; k < kJointCount; ++k) {
      residual[k] = m_w[k] * T(inverse_sigma_windup[k]);
      residual[kJointCount + k] = m_p[k] * T(inverse_sigma_play[k]);
    }
    return true;
  }
};

// Prior N(0, sigma) of a rest's joint deviations; joints with sigma 0 give a zero residual (and
// are held constant by a SubsetManifold).
struct JointPriorResidual {
  JointVector inverse_sigma = JointVector::Zero();  // 1/sigma, 0 for fixed joints
  template <typename T>
  bool operator()(const T* dq, T* residual) const {
    for (int k = 0; k < kJointCount; ++k) residual[k] = dq[k] * T(inverse_sigma[k]);
    return true;
  }
};

}  // namespace imscal::calib
