#pragma once
// Rotation a tool-IMU stream lost, and the orientation error of the calibrated gyro with the
// track restarted after each loss.
//
// Loss per motion segment: a segment is a span of robot motion between two stops
// (motion_segments in calib/tool_imu_record.hpp, robot |omega| above segment_rate_rad_s, with
// 0.15 s of rest on both sides). Over it, the rotation the calibrated gyro integrates,
//   dR_T_gyro = R_T_S * prod exp(((gyro_S - b) ./ k) * dt) * R_T_S^T  (trapezoidal rate, as the
//   attitude filter integrates it),
// is set against the rotation the robot reports between the segment's first and last sensor
// sample (robot poses at t - offset). Their difference d = log(dR_T_robot^T * dR_T_gyro) is
// split along the robot's turn axis a = log(dR_T_robot)/|.|: loss = |d . a|, the rotation the
// gyro lost (or added) about the axis it turned about, and across it, the axis tilt
// |d - (d . a) a|. The tilt comes from a misaligned or cross-coupled gyro; a turn of 180 deg
// doubles it (rot(a, pi)^T rot(b, pi) turns by twice the angle between a and b) and the return
// turn undoes it: it is reported, not counted as a loss (measured 0.0-3.7 deg on the six shipped
// ABB records with the gyro's cross-coupling calibrated). The segment
// ends lie at rest, so the poses' ms timing jitter does not enter.
// Every segment whose loss reaches min_loss_rad is listed. Unlike the check's segment-ratio test
// (ToolImuCheckOptions::missed_motion_fraction), this compares rotations, not |rate| integrals,
// so a partial loss of 15-40 deg in a 180 deg turn is found.
//
// Restarts: the attitude filter (calib/attitude_filter.hpp) is run from the start, and again
// from the robot's pose at the end of every lost span (what a lab does after a dropout: no gyro
// carries the orientation across lost motion). The error with restarts leaves the lost spans
// themselves out.
#include <cstddef>
#include <utility>
#include <vector>

#include "calib/attitude_filter.hpp"
#include "calib/orientation_error.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"

namespace imscal::calib {

struct OrientationLossOptions {
  double min_loss_rad = 5.0 * M_PI / 180.0;           // a segment losing this much is listed
  double segment_rate_rad_s = 0.05;                   // robot |omega| above which the tool moves
  double min_segment_angle_rad = 5.0 * M_PI / 180.0;  // smaller motions are not judged
  // Net rotations below this are not split about their axis (all of the difference is loss).
  double min_axis_angle_rad = 20.0 * M_PI / 180.0;
};

struct SegmentRotation {
  double begin_s = 0.0;  // sensor clock: first and last sensor sample of the segment
  double end_s = 0.0;
  std::size_t first_line = 0;  // their file lines
  std::size_t last_line = 0;
  double robot_angle_rad = 0.0;  // angle of the robot's rotation over the segment
  double gyro_angle_rad = 0.0;   // angle of the calibrated gyro's rotation over it
  double difference_rad = 0.0;   // angle between the two rotations
  double loss_rad = 0.0;         // |part of the difference about the robot's turn axis|
  double axis_tilt_rad = 0.0;    // part of the difference across that axis
};

struct OrientationLossCheck {
  std::vector<SegmentRotation> segments;  // every judged segment, in time order
  std::vector<SegmentRotation> losses;    // those with loss_rad >= min_loss_rad
};

// Needs record.has_raw_imu; `calibration` as applied to this record (its time offset and bias).
OrientationLossCheck find_orientation_losses(const ToolImuRecord& record,
                                             const RotationCalibration& calibration,
                                             const OrientationLossOptions& options = {});

// The spans [begin, end] of the sensor clock after which the orientation is restarted: the
// check's missed-motion spans and the listed losses, merged where they overlap, in time order.
std::vector<std::pair<double, double>> lost_spans(const ToolImuAnalysis& analysis,
                                                  const OrientationLossCheck& losses);

struct RestartedOrientationError {
  OrientationErrorStats from_start;     // one track from the first sample
  OrientationErrorStats with_restarts;  // restarted after each lost span, the spans left out
  std::vector<double> restart_times_s;  // sensor clock
};

// The attitude filter's error against the robot's poses, from the start and restarted after
// every span in `lost` (sensor clock). With no spans, with_restarts equals from_start.
RestartedOrientationError orientation_error_with_restarts(
    const ToolImuRecord& record, const RotationCalibration& calibration,
    const std::vector<std::pair<double, double>>& lost,
    const AttitudeFilterOptions& filter_options = {});

}  // namespace imscal::calib
