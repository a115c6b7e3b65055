#include "calib/orientation_losses.hpp"

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

// The calibrated gyro's rotation of T over samples [first, last]: trapezoidal rate per
// interval, the last rate held across a step longer than max_step_s (as run_attitude_filter).
Eigen::Quaterniond gyro_rotation_T(const ToolImuRecord& record,
                                   const RotationCalibration& calibration, std::size_t first,
                                   std::size_t last, double max_step_s) {
  const Eigen::Matrix3d R_T_S = calibration.q_T_S.toRotationMatrix();
  auto rate_T = [&](std::size_t k) -> Eigen::Vector3d {
    return R_T_S * calibrated_rate_S(calibration, record.gyro_rad_s[k]);
  };
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (std::size_t k = first; k < last; ++k) {
    const double dt = record.t_s[k + 1] - record.t_s[k];
    const Eigen::Vector3d omega_T =
        dt > max_step_s ? rate_T(k) : Eigen::Vector3d(0.5 * (rate_T(k) + rate_T(k + 1)));
    q = (q * ims::quat_exp<double>(omega_T * dt)).normalized();
  }
  return q;
}

// Sensor samples [first, last] inside [begin_s, end_s]; false when fewer than two.
bool samples_inside(const std::vector<double>& t, double begin_s, double end_s, std::size_t& first,
                    std::size_t& last) {
  first = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), begin_s) - t.begin());
  const auto after = std::upper_bound(t.begin(), t.end(), end_s);
  if (after == t.begin()) return false;
  last = static_cast<std::size_t>(after - t.begin()) - 1;
  return first < last && last < t.size();
}

// Keeps the samples of `track` in [from_s, until_s) outside every lost span.
void append_outside_spans(const AttitudeTrack& track, double from_s, double until_s,
                          const std::vector<std::pair<double, double>>& lost,
                          std::vector<double>& t_s, std::vector<Eigen::Quaterniond>& q_B_T) {
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const double t = track.t_s[k];
    if (t < from_s || t >= until_s) continue;
    const bool inside = std::any_of(lost.begin(), lost.end(), [t](const auto& span) {
      return t >= span.first && t <= span.second;
    });
    if (inside) continue;
    t_s.push_back(t);
    q_B_T.push_back(track.q_B_T[k]);
  }
}

}  // namespace

OrientationLossCheck find_orientation_losses(const ToolImuRecord& record,
                                             const RotationCalibration& calibration,
                                             const OrientationLossOptions& options) {
  if (!record.has_raw_imu) {
    throw InputError(record.file, 0, "gyro_x_dps", "the loss check needs raw gyro columns");
  }
  const AttitudeFilterOptions filter_defaults;
  OrientationLossCheck check;
  const RobotRateSeries robot = robot_tool_rate(record);
  for (const MotionSegment& motion :
       motion_segments(record, robot, calibration.time_offset_s, options.segment_rate_rad_s,
                       options.min_segment_angle_rad)) {
    std::size_t first = 0, last = 0;
    if (!samples_inside(record.t_s, motion.begin_s, motion.end_s, first, last)) continue;
    // A segment cut by the record's ends (the robot already moving at the first sample) is
    // judged from the first to the last sample with a robot pose.
    Eigen::Quaterniond q_a, q_b;
    const double offset = calibration.time_offset_s;
    while (first < last && !robot_orientation_at(record, record.t_s[first] - offset, q_a)) ++first;
    while (last > first && !robot_orientation_at(record, record.t_s[last] - offset, q_b)) --last;
    if (first == last) continue;  // no robot pose in it: the segment cannot be judged
    const Eigen::Quaterniond robot_T = q_a.conjugate() * q_b;
    const Eigen::Quaterniond gyro_T =
        gyro_rotation_T(record, calibration, first, last, filter_defaults.max_step_s);
    SegmentRotation segment;
    segment.begin_s = record.t_s[first];
    segment.end_s = record.t_s[last];
    segment.first_line = record.lines[first];
    segment.last_line = record.lines[last];
    segment.robot_angle_rad = ims::quat_log(robot_T).norm();
    segment.gyro_angle_rad = ims::quat_log(gyro_T).norm();
    // The difference split along the robot's turn axis (rotation lost or added) and across it
    // (the turn's axis tilted: a gyro misalignment, which a turn of 180 deg doubles and the
    // return turn undoes).
    const Eigen::Vector3d difference =
        ims::quat_log(Eigen::Quaterniond(robot_T.conjugate() * gyro_T));
    // A segment that turns out and back has almost no net rotation and no axis to split about;
    // there an axis error tilts little (2 sin(angle / 2) x the error) and all of the difference
    // counts as lost.
    const Eigen::Vector3d robot_rotation = ims::quat_log(robot_T);
    const bool has_axis = robot_rotation.norm() >= options.min_axis_angle_rad;
    const Eigen::Vector3d robot_axis =
        has_axis ? Eigen::Vector3d(robot_rotation.normalized()) : Eigen::Vector3d::Zero();
    const double along = has_axis ? difference.dot(robot_axis) : difference.norm();
    segment.difference_rad = difference.norm();
    segment.loss_rad = std::abs(along);
    segment.axis_tilt_rad = has_axis ? (difference - along * robot_axis).norm() : 0.0;
    check.segments.push_back(segment);
    if (segment.loss_rad >= options.min_loss_rad) check.losses.push_back(segment);
  }
  return check;
}

std::vector<std::pair<double, double>> lost_spans(const ToolImuAnalysis& analysis,
                                                  const OrientationLossCheck& losses) {
  std::vector<std::pair<double, double>> spans = analysis.missed_motion_spans_s;
  for (const auto& loss : losses.losses) spans.emplace_back(loss.begin_s, loss.end_s);
  std::sort(spans.begin(), spans.end());
  std::vector<std::pair<double, double>> merged;
  for (const auto& span : spans) {
    if (!merged.empty() && span.first <= merged.back().second) {
      merged.back().second = std::max(merged.back().second, span.second);
    } else {
      merged.push_back(span);
    }
  }
  return merged;
}

RestartedOrientationError orientation_error_with_restarts(
    const ToolImuRecord& record, const RotationCalibration& calibration,
    const std::vector<std::pair<double, double>>& lost,
    const AttitudeFilterOptions& filter_options) {
  RestartedOrientationError result;
  const AttitudeTrack track = run_attitude_filter(record, calibration, filter_options);
  const double offset = calibration.time_offset_s;
  result.from_start = orientation_error(record, offset, track.t_s, track.q_B_T);
  if (lost.empty()) {
    result.with_restarts = result.from_start;
    return result;
  }
  std::vector<double> t_s;
  std::vector<Eigen::Quaterniond> q_B_T;
  append_outside_spans(track, -1e300, lost.front().second, lost, t_s, q_B_T);
  for (std::size_t i = 0; i < lost.size(); ++i) {
    const double restart_s = lost[i].second;
    const double until_s = i + 1 < lost.size() ? lost[i + 1].second : 1e300;
    AttitudeFilterOptions options = filter_options;
    options.start_time_s = restart_s;
    AttitudeTrack piece;
    try {
      piece = run_attitude_filter(record, calibration, options);
    } catch (const InputError&) {
      break;  // no robot pose after the span (it ends the record): nothing left to restart
    }
    append_outside_spans(piece, restart_s, until_s, lost, t_s, q_B_T);
    result.restart_times_s.push_back(piece.t_s.front());
  }
  result.with_restarts = orientation_error(record, offset, t_s, q_B_T);
  return result;
}

}  // namespace imscal::calib
