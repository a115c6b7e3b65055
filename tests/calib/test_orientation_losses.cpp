// Rotation lost per motion segment, and the orientation error restarted after each loss
// (calib/orientation_losses.hpp).
//
// Truth, synthetic: a tool turning 90 deg about one axis per motion, with rests between, and a
// gyro that reads the exact body rate; dropping the readings over part of one turn loses exactly
// the rotation the robot made meanwhile (rate x duration, closed form).
// Truth, real: the ABB MEMS record V_800_Sequencia3/MPU6050RM3100.csv, whose gyro stream loses
// about 30 deg in one turn and keeps that error (tests/data/real/abb-mems/SOURCE.md).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "calib/orientation_losses.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/units.hpp"

namespace imscal::calib {
namespace {

const std::string kDir = std::string(IMSCAL_TEST_DATA_DIR) + "/real/abb-mems/";
// The losses use the estimate, not its sigma: no bootstrap (saves 40 solves per record).
const RotationCalibrationOptions kNoBootstrap = [] {
  RotationCalibrationOptions options;
  options.bootstrap_replicates = 0;
  return options;
}();

// 100 Hz record: rest 1 s, then three 1 s turns of 90 deg about T's z, x and y axes with 1 s rests
// between and after; the gyro (S = T) reads the body rate exactly.
ToolImuRecord turning_record() {
  ToolImuRecord record;
  record.file = "synthetic.csv";
  record.has_raw_imu = true;
  const double step = 0.01;
  const double rate = 0.5 * M_PI;  // rad/s: 90 deg in 1 s
  const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY()};
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (int k = 0; k <= 700; ++k) {
    const double t = k * step;
    // Turn i runs over [1 + 2i, 2 + 2i) s.
    Eigen::Vector3d omega = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (t >= 1.0 + 2 * i && t < 2.0 + 2 * i) omega = rate * axes[i];
    }
    record.lines.push_back(static_cast<std::size_t>(k) + 2);
    record.t_s.push_back(t);
    record.gyro_rad_s.push_back(omega);
    record.acc_m_s2.push_back(q.conjugate() * Eigen::Vector3d(0.0, 0.0, 9.80665));
    record.robot_position_m.push_back(Eigen::Vector3d::Zero());
    record.q_B_T.push_back(q);
    record.robot_quaternion_norm.push_back(1.0);
    record.robot_pose_valid.push_back(true);
    q = (q * Eigen::Quaterniond(Eigen::AngleAxisd(
                 omega.norm() * step,
                 omega.norm() > 0 ? omega.normalized() : Eigen::Vector3d::UnitZ())))
            .normalized();
  }
  return record;
}

TEST(OrientationLosses, ExactGyroLosesNothing) {
  const ToolImuRecord record = turning_record();
  const OrientationLossCheck check = find_orientation_losses(record, RotationCalibration{});
  ASSERT_EQ(check.segments.size(), 3u);
  for (const auto& s : check.segments) {
    // Each segment is one 90 deg turn; rest margins add nothing. The gyro and the robot poses
    // come from the same rates; what differs is the trapezoid at the turn's two rate steps
    // (half a sample at 90 deg/s: 0.45 deg each side). Bounds: 2 deg and 1 deg.
    EXPECT_NEAR(s.robot_angle_rad * kDegPerRad, 90.0, 2.0);
    EXPECT_LT(s.loss_rad * kDegPerRad, 1.0);
  }
  EXPECT_TRUE(check.losses.empty());
}

TEST(OrientationLosses, DroppedReadingsInOneTurnAreListedWithTheirSize) {
  ToolImuRecord record = turning_record();
  // 0.2 s of the second turn (about x) read zero: 18 deg lost.
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    if (record.t_s[k] >= 3.4 && record.t_s[k] < 3.6) record.gyro_rad_s[k].setZero();
  }
  const OrientationLossCheck check = find_orientation_losses(record, RotationCalibration{});
  ASSERT_EQ(check.losses.size(), 1u);
  const SegmentRotation& loss = check.losses.front();
  EXPECT_LE(loss.begin_s, 3.4);
  EXPECT_GE(loss.end_s, 3.6);
  // 18 deg +- the trapezoid's half samples at the two added rate steps (0.9 deg each).
  EXPECT_NEAR(loss.loss_rad * kDegPerRad, 18.0, 2.0);

  // Restarted after the loss, the track carries no error of it; from the start it keeps 18 deg
  // through the third turn. Gravity aiding off: the synthetic accelerometer is exact, but the
  // claim here is about the gyro track.
  AttitudeFilterOptions filter;
  filter.use_gravity = false;
  RotationCalibration calibration;
  const auto error =
      orientation_error_with_restarts(record, calibration, lost_spans({}, check), filter);
  ASSERT_EQ(error.restart_times_s.size(), 1u);
  EXPECT_GT(error.from_start.final_rad * kDegPerRad, 15.0);
  EXPECT_LT(error.with_restarts.max_rad * kDegPerRad, 2.0);
}

TEST(OrientationLosses, RealPartialLossInOneTurnIsFlagged) {
  const ToolImuRecord record = read_tool_imu_record(kDir + "V_800_Sequencia3/MPU6050RM3100.csv");
  const ToolImuAnalysis analysis = check_tool_imu_record(record);
  const RotationCalibration calibration = calibrate_rotation(record, analysis, kNoBootstrap);
  const OrientationLossCheck check = find_orientation_losses(record, calibration);
  for (const auto& s : check.segments) {
    fmt::print(
        "  segment {:.2f}-{:.2f} s: robot {:.1f} deg, gyro {:.1f} deg, difference {:.2f} deg, "
        "about the turn axis {:.2f} deg, across it {:.2f} deg\n",
        s.begin_s, s.end_s, s.robot_angle_rad * kDegPerRad, s.gyro_angle_rad * kDegPerRad,
        s.difference_rad * kDegPerRad, s.loss_rad * kDegPerRad, s.axis_tilt_rad * kDegPerRad);
  }
  const auto error =
      orientation_error_with_restarts(record, calibration, lost_spans(analysis, check));
  fmt::print("from the start RMS {:.2f} deg, with {} restarts RMS {:.2f} deg\n",
             error.from_start.rms_rad * kDegPerRad, error.restart_times_s.size(),
             error.with_restarts.rms_rad * kDegPerRad);
  // The record's one partial loss (SOURCE.md: about 30 deg in one turn) is listed, 15-40 deg.
  ASSERT_GE(check.losses.size(), 1u);
  double largest = 0.0;
  for (const auto& loss : check.losses) largest = std::max(largest, loss.loss_rad);
  EXPECT_GT(largest * kDegPerRad, 15.0);
  EXPECT_LT(largest * kDegPerRad, 40.0);
  // Restarting after it removes the error it leaves behind.
  EXPECT_LT(error.with_restarts.rms_rad, 0.5 * error.from_start.rms_rad);
}

// The check's missed-motion spans (a |rate| integral off by 25 % or more) on the shipped
// V_500_Sequencia3/LSM9DS0.csv, the stream silent while the robot turns from the start, and a
// 0.68 s gap, are both found by the rotation comparison, the first from the record's first pose
// on (the robot already moving): measured 30.7 and 12.5 deg; no other segment reaches 5 deg
// (measured at most 3.5).
TEST(OrientationLosses, EveryMissedMotionSpanIsALoss) {
  const ToolImuRecord record = read_tool_imu_record(kDir + "V_500_Sequencia3/LSM9DS0.csv");
  const ToolImuAnalysis analysis = check_tool_imu_record(record);
  const RotationCalibration calibration = calibrate_rotation(record, analysis, kNoBootstrap);
  const OrientationLossCheck check = find_orientation_losses(record, calibration);
  ASSERT_EQ(analysis.missed_motion_spans_s.size(), 2u);
  ASSERT_EQ(check.losses.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& [begin_s, end_s] = analysis.missed_motion_spans_s[i];
    EXPECT_LT(check.losses[i].begin_s, end_s);
    EXPECT_GT(check.losses[i].end_s, begin_s);
    EXPECT_GT(check.losses[i].loss_rad * kDegPerRad, 8.0);
  }
}

// A segment whose net rotation is below min_axis_angle_rad (a motion out and back) has no
// axis to split about: all of the difference counts as loss, no tilt. Forced here on the
// 90 deg turns by a threshold above them: the 18 deg dropped in the second turn is the whole
// difference (+- the trapezoid's two half samples, 0.9 deg each).
TEST(OrientationLosses, WithoutANetAxisTheWholeDifferenceIsLoss) {
  ToolImuRecord record = turning_record();
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    if (record.t_s[k] >= 3.4 && record.t_s[k] < 3.6) record.gyro_rad_s[k].setZero();
  }
  OrientationLossOptions options;
  options.min_axis_angle_rad = M_PI;
  const OrientationLossCheck check =
      find_orientation_losses(record, RotationCalibration{}, options);
  ASSERT_EQ(check.losses.size(), 1u);
  EXPECT_NEAR(check.losses.front().loss_rad * kDegPerRad, 18.0, 2.0);
  EXPECT_DOUBLE_EQ(check.losses.front().loss_rad, check.losses.front().difference_rad);
  EXPECT_EQ(check.losses.front().axis_tilt_rad, 0.0);
}

}  // namespace
}  // namespace imscal::calib
