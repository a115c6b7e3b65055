#include "calib/joint_space_errors.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "calib/forward_kinematics.hpp"
#include "calib/ik_solver.hpp"
#include "calib/jacobian.hpp"
#include "core/input_error.hpp"
#include "ims/earth_model.hpp"

namespace imscal::calib {

namespace {

// 1-sigma of the joint angles from the sensor pose's sigmas (attitude phi in W, position in W;
// taken as independent) through the flange twist in R and the inverse Jacobian.
JointVector joint_sigma(const KinematicModel& kinematics, const JointVector& q,
                        const Eigen::Matrix<double, 9, 1>& sigma_W, const Eigen::Matrix3d& R_R_W,
                        const Eigen::Vector3d& r_S_H_W) {
  if (sigma_W.isZero(0.0)) return JointVector::Zero();
  // (phi_W, dp_W) -> (dp_H in R, phi in R): dp_H = R_R_W (dp + phi x r), phi_R = R_R_W phi.
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix3d minus_skew_r;
  minus_skew_r << 0, r_S_H_W.z(), -r_S_H_W.y(), -r_S_H_W.z(), 0, r_S_H_W.x(), r_S_H_W.y(),
      -r_S_H_W.x(), 0;
  A.block<3, 3>(0, 0) = R_R_W * minus_skew_r;
  A.block<3, 3>(0, 3) = R_R_W;
  A.block<3, 3>(3, 0) = R_R_W;
  Eigen::Matrix<double, 6, 1> variance;
  variance << sigma_W.head<3>().cwiseAbs2(), sigma_W.tail<3>().cwiseAbs2();
  const Eigen::Matrix<double, 6, 6> twist = A * variance.asDiagonal() * A.transpose();
  const Jacobian J = geometric_jacobian(kinematics, q);
  const Eigen::FullPivLU<Jacobian> lu(J);
  if (!lu.isInvertible()) return JointVector::Constant(std::numeric_limits<double>::infinity());
  const Jacobian J_inverse = lu.inverse();
  return (J_inverse * twist * J_inverse.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
}

}  // namespace

bool interpolate_sensor_pose(const std::vector<ims::SmoothedState>& states, double t_ims_s,
                             Eigen::Isometry3d& T_W_S) {
  if (states.empty() || t_ims_s < states.front().state.t_s || t_ims_s > states.back().state.t_s) {
    return false;
  }
  const auto after =
      std::lower_bound(states.begin(), states.end(), t_ims_s,
                       [](const ims::SmoothedState& s, double t) { return s.state.t_s < t; });
  const ims::NavState& b = after->state;
  if (after == states.begin() || b.t_s == t_ims_s) {
    T_W_S = Eigen::Isometry3d::Identity();
    T_W_S.linear() = b.q_W_S.toRotationMatrix();
    T_W_S.translation() = b.p_W;
    return true;
  }
  const ims::NavState& a = std::prev(after)->state;
  const double f = (t_ims_s - a.t_s) / (b.t_s - a.t_s);
  T_W_S = Eigen::Isometry3d::Identity();
  T_W_S.linear() = a.q_W_S.slerp(f, b.q_W_S).toRotationMatrix();
  T_W_S.translation() = (1.0 - f) * a.p_W + f * b.p_W;
  return true;
}

JointSpaceErrors joint_errors_along(const std::vector<ims::SmoothedState>& trajectory,
                                    const RobotLog& log, const KinematicModel& kinematics,
                                    const CalibratedFrames& frames, double min_wrist_sin) {
  JointSpaceErrors out;
  out.robot = log.robot_name;
  out.cycle_s = log.cycle_s;
  const std::unique_ptr<IkSolver> solver = make_inverse_kinematics(kinematics);
  const IkSolver& ik = *solver;
  for (const RobotLogSample& sample : log.samples) {
    Eigen::Isometry3d T_W_S;
    if (!interpolate_sensor_pose(trajectory, sample.t_s + frames.time_offset_s, T_W_S)) {
      ++out.outside_record;
      continue;
    }
    const Eigen::Isometry3d T_R_H = frames.T_R_W * T_W_S * frames.T_S_H;
    // The solution nearest the robot's own reading (either wrist branch): near A5 = 0 the
    // measured pose may lie across the singularity from the encoders' configuration.
    const IkResult solution = ik.solve_nearest(T_R_H, sample.q_internal_rad);
    if (!solution.ok()) {
      if (out.ik_failures == 0) {
        out.first_ik_failure = fmt::format("t = {:.3f} s: {}", sample.t_s, solution.reason);
      }
      ++out.ik_failures;
      continue;
    }
    if (ik.singularity_measures(solution.q).wrist < min_wrist_sin) {
      ++out.near_wrist_singularity;
      continue;
    }
    out.t_s.push_back(sample.t_s);
    out.payload_kg.push_back(sample.payload_kg);
    out.q_desired_rad.push_back(sample.q_desired_rad);
    out.q_measured_rad.push_back(solution.q);
    out.q_internal_rad.push_back(sample.q_internal_rad);
    // The smoother's sigmas at the nearest state.
    const double t_ims = sample.t_s + frames.time_offset_s;
    auto nearest =
        std::lower_bound(trajectory.begin(), trajectory.end(), t_ims,
                         [](const ims::SmoothedState& s, double t) { return s.state.t_s < t; });
    if (nearest == trajectory.end()) --nearest;
    const Eigen::Vector3d r_S_H_W = T_W_S.linear() * frames.T_S_H.translation();  // S to H in W
    out.q_measured_sigma_rad.push_back(
        joint_sigma(kinematics, solution.q, nearest->sigma, frames.T_R_W.linear(), r_S_H_W));
  }
  return out;
}

JointSpaceErrors joint_space_errors(const JointSpaceInput& input,
                                    const JointSpaceOptions& options) {
  const std::string source = input.source.empty() ? "joint-space errors" : input.source;
  if (input.imu == nullptr || input.log == nullptr) {
    throw InputError(source, 0, "", "the IMS record and the robot log are required");
  }
  const ims::ImuSeries& imu = *input.imu;
  if (imu.quantity != ims::ImuQuantity::kIncrements) {
    throw InputError(imu.source, 0, "", "the joint-space errors need increments, not rates");
  }
  if (imu.samples.size() < 2) throw InputError(imu.source, 0, "", "fewer than 2 IMS samples");
  const double start = input.first_rest.begin_ims_s;
  if (start < imu.samples.front().t_s - imu.nominal_dt_s || start >= imu.samples.back().t_s) {
    throw InputError(imu.source, 0, "",
                     fmt::format("the first rest ({:.3f} s) lies outside the IMS record", start));
  }
  // Cut the record at the first rest: the smoothing starts at the end stamp of the last
  // increment not after its begin.
  const auto first_kept =
      std::upper_bound(imu.samples.begin(), imu.samples.end(), start,
                       [](double t, const ims::ImuSample& s) { return t < s.t_s; });
  ims::ImuSeries cut;
  cut.quantity = imu.quantity;
  cut.nominal_dt_s = imu.nominal_dt_s;
  cut.source = imu.source;
  cut.site = imu.site;
  cut.samples.assign(first_kept, imu.samples.end());
  const double t0 = first_kept == imu.samples.begin() ? start : std::prev(first_kept)->t_s;

  // Initial state from the frames and the forward kinematics of the first rest.
  const Eigen::Isometry3d T_W_R = input.frames.T_R_W.inverse();
  const Eigen::Isometry3d T_R_H0 =
      forward_kinematics<double>(input.kinematics, input.first_rest.q_link_rad);
  const Eigen::Isometry3d T_W_S0 = T_W_R * T_R_H0 * input.frames.T_S_H.inverse();
  ims::NavState initial;
  initial.t_s = t0;
  initial.q_W_S = Eigen::Quaterniond(T_W_S0.linear()).normalized();
  initial.p_W = T_W_S0.translation();
  Eigen::Matrix<double, 9, 1> sigma0;
  sigma0 << Eigen::Vector3d::Constant(options.initial_attitude_sigma_rad),
      Eigen::Vector3d::Constant(options.initial_velocity_sigma_m_s),
      Eigen::Vector3d::Constant(options.initial_position_sigma_m);
  ims::ZuptOptions zupt = input.zupt;
  zupt.initial_gyro_bias_rad_s = input.frames.biases.gyro_rad_s;
  zupt.initial_acc_bias_m_s2 = input.frames.biases.acc_m_s2;
  const ims::EarthModel earth(input.site);
  ims::SmootherAids aids;
  if (options.encoder_stillness || options.creep_velocity_updates) {
    const EncoderMotion motion = encoder_motion(*input.log, input.kinematics, T_W_R,
                                                input.frames.T_S_H.inverse().translation(),
                                                input.frames.time_offset_s, options.encoder);
    if (options.encoder_stillness) aids.still = motion.still;
    if (options.creep_velocity_updates) aids.velocity = motion.creep_velocity;
  }
  ims::ZuptSmootherResult smoothed = ims::smooth_with_zupt(cut, earth, initial, sigma0, zupt, aids);
  std::vector<ims::ImuSample>().swap(cut.samples);  // released: the record's copy is done with

  // The initial state belongs to the trajectory too (the start of the first increment): the
  // smoother leaves room for it, so the insertion moves the states instead of copying them.
  ims::SmoothedState first;
  first.state = initial;
  smoothed.states.insert(smoothed.states.begin(), first);
  std::vector<PositionErrorSample> errors;
  if (options.revisited_pose_correction) {
    errors =
        position_errors_at_revisited_poses(smoothed.states, *input.log, input.kinematics, T_W_R,
                                           input.frames.T_S_H.inverse().translation(),
                                           input.frames.time_offset_s, options.revisited_poses);
    remove_position_errors(smoothed.states, errors);
  }
  JointSpaceErrors out = joint_errors_along(smoothed.states, *input.log, input.kinematics,
                                            input.frames, options.min_wrist_sin);
  out.smoother = smoothed.summary;
  out.revisited_pose_errors = std::move(errors);
  out.trajectory = std::move(smoothed.states);
  return out;
}

}  // namespace imscal::calib
