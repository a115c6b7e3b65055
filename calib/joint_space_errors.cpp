#include "calib/joint_space_errors.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <utility>

#include "core/input_error.hpp"
#include "ims/earth_model.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/ik_solver.hpp"
#include "robot/jacobian.hpp"

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

namespace {

// The rows of joint_errors_along, one robot sample at a time (in the log's order).
class JointErrorRows {
 public:
  // With `sink`, the rows go to it and the columns stay empty.
  JointErrorRows(const RobotLog& log, const KinematicModel& kinematics,
                 const CalibratedFrames& frames, double min_wrist_sin,
                 std::function<void(const JointErrorRow&)> sink = {})
      : kinematics_(kinematics),
        frames_(frames),
        min_wrist_sin_(min_wrist_sin),
        solver_(make_inverse_kinematics(kinematics)),
        sink_(std::move(sink)) {
    out.robot = log.robot_name;
    out.cycle_s = log.cycle_s;
    if (sink_) return;
    // At most one row per sample: reserved, the rows take no more than they hold.
    const std::size_t n = log.samples.size();
    for (auto* column :
         {&out.q_desired_rad, &out.q_measured_rad, &out.q_internal_rad, &out.q_measured_sigma_rad})
      column->reserve(n);
    out.t_s.reserve(n);
    out.payload_kg.reserve(n);
  }

  // The row of `sample` from the trajectory around its IMS time (counted as outside the record
  // when the trajectory does not span it).
  void add(const std::vector<ims::SmoothedState>& trajectory, const RobotLogSample& sample) {
    Eigen::Isometry3d T_W_S;
    const double t_ims = sample.t_s + frames_.time_offset_s;
    if (!interpolate_sensor_pose(trajectory, t_ims, T_W_S)) {
      ++out.outside_record;
      return;
    }
    const Eigen::Isometry3d T_R_H = frames_.T_R_W * T_W_S * frames_.T_S_H;
    // The solution nearest the robot's own reading (either wrist branch): near A5 = 0 the
    // measured pose may lie across the singularity from the encoders' configuration.
    const IkResult solution = solver_->solve_nearest(T_R_H, sample.q_internal_rad);
    if (!solution.ok()) {
      if (out.ik_failures == 0)
        out.first_ik_failure = fmt::format("t = {:.3f} s: {}", sample.t_s, solution.reason);
      ++out.ik_failures;
      return;
    }
    if (solver_->singularity_measures(solution.q).wrist < min_wrist_sin_) {
      ++out.near_wrist_singularity;
      return;
    }
    // The smoother's sigmas at the nearest state.
    auto nearest =
        std::lower_bound(trajectory.begin(), trajectory.end(), t_ims,
                         [](const ims::SmoothedState& s, double t) { return s.state.t_s < t; });
    if (nearest == trajectory.end()) --nearest;
    const Eigen::Vector3d r_S_H_W = T_W_S.linear() * frames_.T_S_H.translation();  // S to H in W
    JointErrorRow row{
        sample.t_s,
        sample.payload_kg,
        sample.q_desired_rad,
        solution.q,
        sample.q_internal_rad,
        joint_sigma(kinematics_, solution.q, nearest->sigma, frames_.T_R_W.linear(), r_S_H_W)};
    out.sums.add(row);
    if (sink_) return sink_(row);
    out.t_s.push_back(row.t_s);
    out.payload_kg.push_back(row.payload_kg);
    out.q_desired_rad.push_back(row.q_desired_rad);
    out.q_measured_rad.push_back(row.q_measured_rad);
    out.q_internal_rad.push_back(row.q_internal_rad);
    out.q_measured_sigma_rad.push_back(row.q_measured_sigma_rad);
  }

  JointSpaceErrors out;

 private:
  const KinematicModel& kinematics_;
  const CalibratedFrames& frames_;
  double min_wrist_sin_;
  std::unique_ptr<IkSolver> solver_;
  std::function<void(const JointErrorRow&)> sink_;
};

// Calls use(block) on consecutive blocks of the trajectory: `first`, then the stream's states
// (from its start), each block starting with the last state of the one before, so that every
// time up to a block's last state lies between two of its states as in the whole trajectory.
// With `errors`, the positions are corrected by them (remove_position_errors), each state once.
template <typename Use>
void for_each_block(ims::SmoothedStateStream& stream, std::size_t states_per_block,
                    const ims::SmoothedState& first, const std::vector<PositionErrorSample>* errors,
                    Use use) {
  states_per_block = std::max<std::size_t>(1, states_per_block);
  stream.rewind();
  std::vector<ims::SmoothedState> block;
  block.reserve(states_per_block + 1);
  block.push_back(first);
  std::size_t fresh = 0;  // the block's states not corrected yet
  do {
    stream.next(block, states_per_block);
    if (errors) remove_position_errors(std::span(block).subspan(fresh), *errors);
    use(block);
    const ims::SmoothedState carried = block.back();
    block.clear();
    block.push_back(carried);
    fresh = 1;
  } while (!stream.done());
}

// The states at and before each of `times_ims_s` (sorted): the two interpolate_sensor_pose takes
// there, so that it gives on them what it gives on the whole trajectory.
std::vector<ims::SmoothedState> states_around(ims::SmoothedStateStream& stream,
                                              std::size_t states_per_block,
                                              const ims::SmoothedState& first,
                                              const std::vector<double>& times_ims_s) {
  std::vector<ims::SmoothedState> kept;
  const auto keep = [&](const ims::SmoothedState& s) {
    if (kept.empty() || kept.back().state.t_s < s.state.t_s) kept.push_back(s);
  };
  std::size_t next = 0;
  for_each_block(
      stream, states_per_block, first, nullptr, [&](const std::vector<ims::SmoothedState>& block) {
        for (; next < times_ims_s.size() && times_ims_s[next] <= block.back().state.t_s; ++next) {
          if (times_ims_s[next] < block.front().state.t_s) continue;  // before the trajectory
          const auto at = std::lower_bound(
              block.begin(), block.end(), times_ims_s[next],
              [](const ims::SmoothedState& s, double t) { return s.state.t_s < t; });
          if (at != block.begin()) keep(*std::prev(at));
          keep(*at);
        }
      });
  return kept;
}

// The IMS times at which position_errors_at_revisited_poses looks at the trajectory.
std::vector<double> revisited_pose_times(const RobotLog& log, double time_offset_s,
                                         const RevisitedPoseOptions& options) {
  std::vector<double> times;
  for (const StandstillWindow& w : settled_standstill_windows(log, options))
    for (std::size_t k = w.first_averaged; k <= w.last; ++k)
      times.push_back(log.samples[k].t_s + time_offset_s);
  std::sort(times.begin(), times.end());
  return times;
}

// The joint errors along the smoothed trajectory, corrected by `errors`, block by block (the
// same rows as joint_errors_along on the whole corrected trajectory); with `keep_trajectory`
// the corrected trajectory too.
JointSpaceErrors joint_errors_in_blocks(ims::SmoothedStateStream& stream,
                                        const ims::SmoothedState& first,
                                        const std::vector<PositionErrorSample>& errors,
                                        const JointSpaceInput& input,
                                        const JointSpaceOptions& options) {
  JointErrorRows rows(*input.log, input.kinematics, input.frames, options.min_wrist_sin,
                      options.row_sink);
  const auto& samples = input.log->samples;
  const double offset_s = input.frames.time_offset_s;
  std::vector<ims::SmoothedState> trajectory;
  std::size_t next = 0;
  std::vector<ims::SmoothedState> last(1);
  for_each_block(
      stream, options.states_per_block, first, &errors,
      [&](const std::vector<ims::SmoothedState>& block) {
        for (; next < samples.size() && samples[next].t_s + offset_s <= block.back().state.t_s;
             ++next)
          rows.add(block, samples[next]);
        if (options.keep_trajectory)
          trajectory.insert(trajectory.end(), block.begin() + (trajectory.empty() ? 0 : 1),
                            block.end());
        last.front() = block.back();
      });
  for (; next < samples.size(); ++next) rows.add(last, samples[next]);  // after the record
  rows.out.trajectory = std::move(trajectory);
  return std::move(rows.out);
}

}  // namespace

JointSpaceErrors joint_errors_along(const std::vector<ims::SmoothedState>& trajectory,
                                    const RobotLog& log, const KinematicModel& kinematics,
                                    const CalibratedFrames& frames, double min_wrist_sin) {
  JointErrorRows rows(log, kinematics, frames, min_wrist_sin);
  for (const RobotLogSample& sample : log.samples) rows.add(trajectory, sample);
  return std::move(rows.out);
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
  // The record from there on, without a copy.
  const ims::ImuSamples cut(imu, std::size_t(first_kept - imu.samples.begin()));
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
  ims::ZuptSmoothing smoothed =
      ims::smooth_with_zupt_streamed(cut, earth, initial, sigma0, zupt, aids);

  // The trajectory: the initial state (the start of the first increment), then the smoothed
  // states, used block by block (twice with the revisited poses: once where they are looked
  // at, once for the joint errors) instead of whole.
  ims::SmoothedState first;
  first.state = initial;
  std::vector<PositionErrorSample> errors;
  if (options.revisited_pose_correction) {
    const std::vector<ims::SmoothedState> looked_at = states_around(
        smoothed.states, options.states_per_block, first,
        revisited_pose_times(*input.log, input.frames.time_offset_s, options.revisited_poses));
    errors = position_errors_at_revisited_poses(
        looked_at, *input.log, input.kinematics, T_W_R, input.frames.T_S_H.inverse().translation(),
        input.frames.time_offset_s, options.revisited_poses);
  }
  JointSpaceErrors out = joint_errors_in_blocks(smoothed.states, first, errors, input, options);
  out.smoother = smoothed.summary;
  out.revisited_pose_errors = std::move(errors);
  return out;
}

void JointErrorSums::add(const JointErrorRow& row) {
  ++rows;
  for (int j = 0; j < kJointCount; ++j) {
    const double e = row.q_desired_rad[j] - row.q_measured_rad[j];
    error_squared_rad2[j] += e * e;
    error_max_abs_rad[j] = std::max(error_max_abs_rad[j], std::abs(e));
  }
  sigma_squared_rad2 += row.q_measured_sigma_rad.cwiseAbs2();
}

JointVector q_measured_sigma_rms_rad(const JointSpaceErrors& errors) {
  JointVector sum = JointVector::Zero();
  if (errors.q_measured_sigma_rad.empty()) {
    if (errors.sums.rows == 0) return sum;
    return (errors.sums.sigma_squared_rad2 / double(errors.sums.rows)).cwiseSqrt();
  }
  for (const JointVector& sigma : errors.q_measured_sigma_rad) sum += sigma.cwiseAbs2();
  return (sum / double(errors.q_measured_sigma_rad.size())).cwiseSqrt();
}

}  // namespace imscal::calib
