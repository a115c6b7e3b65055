// The residual groups of the frame-and-bias bundle (calib/frame_bundle.hpp): frames and biases,
// joint deviations at the rests with their priors, the rest means and the motions between them.
#include <cmath>

#include "calib/frame_bundle.hpp"
#include "calib/frame_noise.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"

namespace imscal::calib {
namespace {

// The sensor's velocity in R at joint angles q and rates q_dot, for the sensor at p_H_S [m/s].
Eigen::Vector3d sensor_velocity_R(const KinematicModel& model, const JointVector& q,
                                  const JointVector& q_dot, const Eigen::Vector3d& p_H_S) {
  const Jacobian J = geometric_jacobian(model, q);
  const Eigen::Vector3d omega_R = J.bottomRows<3>() * q_dot;
  const Eigen::Matrix3d R_R_H = forward_kinematics<double>(model, q).linear();
  return J.topRows<3>() * q_dot + omega_R.cross(R_R_H * p_H_S);
}

RestCreep rest_creep(const KinematicModel& model, const RestObservation& rest, double duration_s,
                     const Eigen::Vector3d& p_H_S) {
  RestCreep c;
  const JointVector q_begin = rest.q_link_rad + rest.q_creep_begin_rad;
  const JointVector q_end = rest.q_link_rad + rest.q_creep_end_rad;
  const Eigen::Matrix3d R_begin = forward_kinematics<double>(model, q_begin).linear();
  const Eigen::Matrix3d R_end = forward_kinematics<double>(model, q_end).linear();
  c.mean_rate_H =
      ims::quat_log<double>(Eigen::Quaterniond(R_begin.transpose() * R_end)) / duration_s;
  c.velocity_begin_R = sensor_velocity_R(model, q_begin, rest.q_rate_begin_rad_s, p_H_S);
  c.velocity_end_R = sensor_velocity_R(model, q_end, rest.q_rate_end_rad_s, p_H_S);
  c.mean_acceleration_R = (c.velocity_end_R - c.velocity_begin_R) / duration_s;
  return c;
}

// The motion residual of motion i -> i+1 with its covariance (creep at the ends included).
MotionResidual motion_functor(const FrameBundle& b, const FrameStage& stage, std::size_t i,
                              const std::vector<Eigen::Vector3d>& p_W,
                              const std::vector<RestCreep>& creep,
                              Eigen::Matrix<double, 9, 9>* covariance) {
  const FrameCalibrationInput& input = b.input;
  const FrameCalibrationOptions& options = b.options;
  MotionResidual f;
  f.model = &input.kinematics;
  f.preintegration = &stage.motions[i];
  f.q_i = input.rests[i].q_link_rad;
  f.q_j = input.rests[i + 1].q_link_rad;
  f.creep_i = input.rests[i].q_creep_end_rad;
  f.creep_j = input.rests[i + 1].q_creep_begin_rad;
  f.velocity_start_R = creep[i].velocity_end_R;
  f.velocity_end_R = creep[i + 1].velocity_begin_R;
  f.windup_i = input.rests[i].q_windup_rad;
  f.play_i = input.rests[i].q_play_rad;
  f.windup_j = input.rests[i + 1].q_windup_rad;
  f.play_j = input.rests[i + 1].q_play_rad;
  f.earth_rate_W = b.earth.earth_rate_W();
  f.gravity_start_W = b.earth.gravity_W(p_W[i]);
  f.gravity_gradient_W = b.earth.gravity_gradient_W();
  Eigen::Matrix<double, 9, 9> cov = motion_covariance(input.noise, stage.motions[i].duration_s(),
                                                      b.rests[i].mean_specific_force_m_s2);
  // The creep velocities at the ends are good to the same fraction.
  const double creep_velocity =
      options.creep_model_fraction *
      std::hypot(creep[i].velocity_end_R.norm(), creep[i + 1].velocity_begin_R.norm());
  const double creep_position =
      options.creep_model_fraction * creep[i].velocity_end_R.norm() * stage.motions[i].duration_s();
  for (int k = 0; k < 3; ++k) {
    cov(3 + k, 3 + k) += creep_velocity * creep_velocity;
    cov(6 + k, 6 + k) += creep_position * creep_position;
  }
  f.whitening = whitening_matrix(cov);
  *covariance = cov;
  return f;
}

}  // namespace

void add_frame_and_bias_blocks(FrameBundle& b, ceres::Problem& problem) {
  FrameUnknowns& x = b.x;
  problem.AddParameterBlock(x.q_W_R, 4, new ceres::EigenQuaternionManifold);
  problem.AddParameterBlock(x.q_S_H, 4, new ceres::EigenQuaternionManifold);
  problem.AddParameterBlock(x.p_S_H, 3);
  problem.AddParameterBlock(x.b_g, 3);
  for (double* block : x.b_a) problem.AddParameterBlock(block, 3);
}

void add_joint_deviations(FrameBundle& b, ceres::Problem& problem) {
  for (std::size_t i = 0; i < b.rests.size(); ++i) {
    double* dq = b.x.dq[i];
    const JointVector& sigma = b.input.rests[i].q_link_sigma_rad;
    problem.AddParameterBlock(dq, 6);
    std::vector<int> fixed;
    for (int k = 0; k < kJointCount; ++k) {
      if (!(sigma[k] > 0.0)) fixed.push_back(k);
    }
    if (fixed.size() == static_cast<std::size_t>(kJointCount)) {
      problem.SetParameterBlockConstant(dq);
      continue;
    }
    if (!fixed.empty()) problem.SetManifold(dq, new ceres::SubsetManifold(6, fixed));
    JointPriorResidual prior;
    for (int k = 0; k < kJointCount; ++k) {
      const double s = sigma[k];
      prior.inverse_sigma[k] = s > 0.0 ? 1.0 / s : 0.0;
    }
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<JointPriorResidual, 6, 6>(new JointPriorResidual(prior)),
        nullptr, dq);
  }
}

std::vector<Eigen::Vector3d> rest_positions_W(const FrameBundle& b) {
  const FrameUnknowns& x = b.x;
  std::vector<Eigen::Vector3d> p_abs(b.rests.size());
  const Eigen::Matrix3d R_W_R = x.R_W_R();
  const Eigen::Matrix3d R_H_S = x.R_S_H().transpose();
  const Eigen::Vector3d p_H_S = -R_H_S * Eigen::Map<const Eigen::Vector3d>(x.p_S_H);
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < b.rests.size(); ++i) {
    const Eigen::Isometry3d T_R_H = forward_kinematics<double>(
        b.input.kinematics, JointVector(b.input.rests[i].q_link_rad + x.joint_deviation(i)));
    const Eigen::Vector3d p = R_W_R * (T_R_H.translation() + T_R_H.linear() * p_H_S);
    if (i == 0) first = p;
    p_abs[i] = p - first + b.input.first_rest_position_W_m;
  }
  return p_abs;
}

std::vector<RestCreep> rest_creeps(const FrameBundle& b) {
  std::vector<RestCreep> creep(b.rests.size());
  const Eigen::Vector3d p_H_S =
      -(b.x.R_S_H().transpose() * Eigen::Map<const Eigen::Vector3d>(b.x.p_S_H));
  for (std::size_t i = 0; i < b.rests.size(); ++i)
    creep[i] = rest_creep(b.input.kinematics, b.input.rests[i], b.rests[i].duration_s(), p_H_S);
  return creep;
}

void add_rest_residuals(FrameBundle& b, FrameStage& stage, const std::vector<Eigen::Vector3d>& p_W,
                        const std::vector<RestCreep>& creep) {
  const FrameCalibrationInput& input = b.input;
  const FrameCalibrationOptions& options = b.options;
  FrameUnknowns& x = b.x;
  stage.rest_functors.clear();
  for (std::size_t i = 0; i < b.rests.size(); ++i) {
    RestResidual f;
    f.model = &input.kinematics;
    f.q = input.rests[i].q_link_rad;
    f.windup = input.rests[i].q_windup_rad;
    f.play = input.rests[i].q_play_rad;
    f.mean_rate = b.rests[i].mean_rate_rad_s;
    f.mean_force = b.rests[i].mean_specific_force_m_s2;
    f.earth_rate_W = b.earth.earth_rate_W();
    f.gravity_W = b.earth.gravity_W(p_W[i]);
    f.creep_rate_H = creep[i].mean_rate_H;
    f.creep_acceleration_R = creep[i].mean_acceleration_R;
    const RestSigmas sig = rest_sigmas(input.noise, b.rests[i].duration_s());
    // The creep as the joint readings see it is good to a fraction (transmission error, the
    // friction's share at the gear output).
    f.rate_sigma =
        std::hypot(sig.rate_rad_s, options.creep_model_fraction * creep[i].mean_rate_H.norm());
    f.force_sigma = std::hypot(sig.force_m_s2,
                               options.creep_model_fraction * creep[i].mean_acceleration_R.norm());
    stage.rest_functors.push_back(f);
    stage.problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<RestResidual, 6, 4, 4, 6, 3, 3, 3, 3, 6, 6>(
            new RestResidual(f)),
        new ceres::HuberLoss(options.huber_scale_sigma * std::sqrt(6.0)), x.q_W_R, x.q_S_H, x.dq[i],
        x.b_g, x.b_a_blocks[i], x.s_g, x.s_a, x.m_w, x.m_p);
  }
}

// With a drifting accelerometer bias the motion takes the mean of its two ends' biases.
void add_motion_residuals(FrameBundle& b, FrameStage& stage,
                          const std::vector<Eigen::Vector3d>& p_W,
                          const std::vector<RestCreep>& creep) {
  FrameUnknowns& x = b.x;
  ceres::Problem& problem = *stage.problem;
  const double huber = b.options.huber_scale_sigma * 3.0;
  stage.motion_functors.clear();
  stage.motion_covariance_factor.clear();
  for (std::size_t i = 0; i + 1 < b.rests.size(); ++i) {
    Eigen::Matrix<double, 9, 9> cov;
    const MotionResidual f = motion_functor(b, stage, i, p_W, creep, &cov);
    stage.motion_covariance_factor.push_back(
        Eigen::LLT<Eigen::Matrix<double, 9, 9>>(cov).matrixL());
    stage.motion_functors.push_back(f);
    if (b.acc_bias_drifts) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<MotionResidual, 9, 4, 4, 3, 6, 6, 3, 3, 3, 6, 6>(
              new MotionResidual(f)),
          new ceres::HuberLoss(huber), x.q_W_R, x.q_S_H, x.p_S_H, x.dq[i], x.dq[i + 1], x.b_g,
          x.b_a_blocks[i], x.b_a_blocks[i + 1], x.m_w, x.m_p);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<MotionResidualConstantBias, 9, 4, 4, 3, 6, 6, 3, 3, 6, 6>(
              new MotionResidualConstantBias{f}),
          new ceres::HuberLoss(huber), x.q_W_R, x.q_S_H, x.p_S_H, x.dq[i], x.dq[i + 1], x.b_g,
          x.b_a_blocks[i], x.m_w, x.m_p);
    }
  }
}

}  // namespace imscal::calib
