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

#include "calib/imu_preintegration.hpp"
#include "ims/so3.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"

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
//   rate = (I + diag(s_g)) (R_S_W Omega_W + R_S_H w_creep) + b_g,
//   force = (I + diag(s_a)) R_S_W (R_W_R a_creep - g_W) + b_a,
// with the creeping arm's mean flange rate w_creep (in H) and mean acceleration a_creep (in R)
// over the rest (zero when the arm is still).
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
  // The arm's creep over the rest (RestObservation::q_creep_*): mean flange rate in H [rad/s]
  // and mean acceleration of the sensor in R [m/s^2]; zero when still.
  Eigen::Vector3d creep_rate_H = Eigen::Vector3d::Zero();
  Eigen::Vector3d creep_acceleration_R = Eigen::Vector3d::Zero();
  double rate_sigma = 1.0;   // [rad/s]
  double force_sigma = 1.0;  // [m/s^2]

  template <typename T>
  bool operator()(const T* q_W_R, const T* q_S_H, const T* dq, const T* b_g, const T* b_a,
                  const T* s_g, const T* s_a, const T* m_w, const T* m_p, T* residual) const {
    const Eigen::Matrix<T, 6, 1> deviation = rest_deviation<T>(dq, m_w, m_p, windup, play);
    const Matrix3T<T> R_S_W =
        rest_attitude<T>(*model, q, q_W_R, q_S_H, deviation.data()).transpose();
    const Matrix3T<T> R_W_R = Eigen::Map<const Eigen::Quaternion<T>>(q_W_R).toRotationMatrix();
    const Matrix3T<T> R_S_H = Eigen::Map<const Eigen::Quaternion<T>>(q_S_H).toRotationMatrix();
    const Vector3T<T> rate_true = R_S_W * earth_rate_W.cast<T>() + R_S_H * creep_rate_H.cast<T>();
    const Vector3T<T> force_true =
        R_S_W * (R_W_R * creep_acceleration_R.cast<T>() - gravity_W.cast<T>());
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
  // Where the creeping arm is at the motion's ends (rest i's end, rest j's begin) relative to
  // the rests' mean readings [rad], and the sensor's velocity there in R [m/s] (zero: still).
  JointVector creep_i = JointVector::Zero(), creep_j = JointVector::Zero();
  Eigen::Vector3d velocity_start_R = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_end_R = Eigen::Vector3d::Zero();
  JointVector windup_i = JointVector::Zero(), play_i = JointVector::Zero();
  JointVector windup_j = JointVector::Zero(), play_j = JointVector::Zero();
  Eigen::Vector3d earth_rate_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_start_W = Eigen::Vector3d::Zero();  // g at rest i's position
  Eigen::Matrix3d gravity_gradient_W = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> whitening = Eigen::Matrix<double, 9, 9>::Identity();

  // b_a_i, b_a_j: the accelerometer biases of rests i and j (the same block without drift); the
  // motion uses their mean.
  template <typename T>
  bool operator()(const T* q_W_R, const T* q_S_H, const T* p_S_H, const T* dq_i, const T* dq_j,
                  const T* b_g, const T* b_a_i, const T* b_a_j, const T* m_w, const T* m_p,
                  T* residual) const {
    const ImuPreintegration& pre = *preintegration;
    const Eigen::Matrix<T, 6, 1> deviation_i = rest_deviation<T>(dq_i, m_w, m_p, windup_i, play_i);
    const Eigen::Matrix<T, 6, 1> deviation_j = rest_deviation<T>(dq_j, m_w, m_p, windup_j, play_j);
    Vector3T<T> p_R_S_i, p_R_S_j;
    const JointVector q_start = q_i + creep_i, q_end = q_j + creep_j;
    const Matrix3T<T> R_i =
        rest_attitude<T>(*model, q_start, q_W_R, q_S_H, deviation_i.data(), &p_R_S_i, p_S_H);
    const Matrix3T<T> R_j =
        rest_attitude<T>(*model, q_end, q_W_R, q_S_H, deviation_j.data(), &p_R_S_j, p_S_H);
    const Matrix3T<T> R_W_R = Eigen::Map<const Eigen::Quaternion<T>>(q_W_R).toRotationMatrix();
    const Vector3T<T> dp_model = R_W_R * (p_R_S_j - p_R_S_i);
    // Start and end velocities of a creeping arm (the Coriolis term of v_start, 2 Omega x v T^2
    // / 2 ~ 1e-7 m for 1e-4 m/s over 3 s, is left out).
    const Vector3T<T> v_start = R_W_R * velocity_start_R.cast<T>();
    const Vector3T<T> v_end = R_W_R * velocity_end_R.cast<T>();

    const Vector3T<T> dbg =
        Eigen::Map<const Vector3T<T>>(b_g) - pre.linearisation().gyro_rad_s.cast<T>();
    const Vector3T<T> b_a =
        T(0.5) * (Eigen::Map<const Vector3T<T>>(b_a_i) + Eigen::Map<const Vector3T<T>>(b_a_j));
    const Vector3T<T> dba = b_a - pre.linearisation().acc_m_s2.cast<T>();
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
    raw.template segment<3>(3) = R_i.transpose() * (v + v_start - v_end);
    raw.template segment<3>(6) = R_i.transpose() * (dp + v_start * duration - dp_model);
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
  // Per grid node: omega_H (3) from the joint readings and lag_H (3) = sum_j lag_j z_j qdd_j in H,
  // the rate the link falls behind per unit of the link share of friction (see
  // RobotJointSeries::link_lag_per_share_s).
  using Interpolator = ceres::CubicInterpolator<ceres::Grid1D<double, 6>>;
  const Interpolator* omega_H = nullptr;
  double grid_t0_s = 0.0;  // robot time of node 0
  double grid_step_s = 1.0;
  std::vector<double> mid_times_ims_s;
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_S_H = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset_S = Eigen::Vector3d::Zero();  // b_g + Earth rate in S [rad/s]
  double sigma = 1.0;

  // dt [s]; share [1]: the link share of the drives' viscous friction (link rate =
  // omega_H - share lag_H).
  template <typename T>
  bool operator()(const T* dt, const T* share, T* residual) const {
    Vector3T<T> sum = Vector3T<T>::Zero();
    for (const double t : mid_times_ims_s) {
      const T x = (T(t) - dt[0] - T(grid_t0_s)) / T(grid_step_s);
      T value[6];
      omega_H->Evaluate(x, value);
      for (int k = 0; k < 3; ++k) sum[k] += value[k] - share[0] * value[3 + k];
    }
    const Vector3T<T> mean_H = sum / T(static_cast<double>(mid_times_ims_s.size()));
    const Vector3T<T> model = R_S_H.cast<T>() * mean_H + offset_S.cast<T>();
    for (int k = 0; k < 3; ++k) residual[k] = (T(mean_rate[k]) - model[k]) / T(sigma);
    return true;
  }
};

// MotionResidual with one constant accelerometer bias (Ceres refuses a block passed twice).
struct MotionResidualConstantBias {
  MotionResidual motion;
  template <typename T>
  bool operator()(const T* q_W_R, const T* q_S_H, const T* p_S_H, const T* dq_i, const T* dq_j,
                  const T* b_g, const T* b_a, const T* m_w, const T* m_p, T* residual) const {
    return motion(q_W_R, q_S_H, p_S_H, dq_i, dq_j, b_g, b_a, b_a, m_w, m_p, residual);
  }
};

// Random walk of the accelerometer bias from one rest to the next: (b_j - b_i) / sigma.
struct BiasDriftResidual {
  double inverse_sigma = 1.0;  // 1 / sqrt(psd dt) [s^2/m]
  template <typename T>
  bool operator()(const T* b_i, const T* b_j, T* residual) const {
    for (int k = 0; k < 3; ++k) residual[k] = (b_j[k] - b_i[k]) * T(inverse_sigma);
    return true;
  }
};

// Prior N(mean, sigma) of the link share of the drives' viscous friction.
struct LinkSharePriorResidual {
  double mean = 0.5;
  double inverse_sigma = 2.0;
  template <typename T>
  bool operator()(const T* share, T* residual) const {
    residual[0] = (share[0] - T(mean)) * T(inverse_sigma);
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
