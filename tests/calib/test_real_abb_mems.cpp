// The rotation part of a tool-IMU calibration on real data: two MEMS IMUs (MPU9150, LSM9DS0)
// carried by an ABB robot (tests/data/real/abb-mems/SOURCE.md). R_T_S, gyro bias and scale and
// the time offset are calibrated on one sequence; the calibrated gyro then carries the tool's
// orientation through the other sequence (attitude filter started from the robot's pose), and
// its error against the robot's reported pose is set beside the error of a commercial AHRS, an
// XSENS MTi-30, on its own record of the same path (XSENS.csv).
//
// Fairness, stated: the XSENS's constant alignment to the tool and to the robot base is fitted
// by least squares on the very sequence it is evaluated on, and its clock offset by
// cross-correlation on it (generous to the XSENS: the fit absorbs every constant error). imscal
// gets R_T_S and the scale from the OTHER sequence; on the evaluated sequence it uses only what a
// user has at run time: the time offset by cross-correlation of |omega| and the gyro bias from
// the initial standstill. The robot columns differ between the files of one sequence (each
// sensor's file is its own run of the same program), so each estimate is compared with the
// robot poses of its own file.
//
// Truth: the robot controller's reported tool orientation (an industrial robot repeats to
// ~0.01 deg; the poses carry ms timing jitter, which is why the comparison uses interpolation at
// t - offset and why sub-degree agreement during 450 deg/s turns is not expected).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "calib/attitude_filter.hpp"
#include "calib/orientation_error.hpp"
#include "calib/orientation_losses.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

const std::string kDir = std::string(IMSCAL_TEST_DATA_DIR) + "/real/abb-mems/";
const char* kSeq1 = "V_500_Sequencia1";
const char* kSeq3 = "V_500_Sequencia3";

std::string v3(const Eigen::Vector3d& v, double scale = 1.0) {
  return fmt::format("({:.4g}, {:.4g}, {:.4g})", v.x() * scale, v.y() * scale, v.z() * scale);
}

struct Calibrated {
  ToolImuRecord record;
  ToolImuAnalysis analysis;
  RotationCalibration calibration;
};

Calibrated calibrate(const std::string& sequence, const std::string& sensor) {
  Calibrated out;
  out.record = read_tool_imu_record(kDir + sequence + "/" + sensor + ".csv");
  out.analysis = check_tool_imu_record(out.record);
  out.calibration = calibrate_rotation(out.record, out.analysis);
  const auto& c = out.calibration;
  fmt::print(
      "{} calibrated on {}: {} windows ({} skipped), residual RMS {:.3f} -> {:.3f} deg, {} "
      "windows above 3 Cauchy scales\n  R_T_S angle {:.2f} deg, 1 sigma {} deg ({} motion "
      "segments resampled); time offset {:.4f} +- {:.4f} s; bias {} +- {} deg/s (as labelled); "
      "scale {} +- {}; cross-coupling {} +- {}\n",
      sensor, sequence, c.window_count, c.skipped_window_count,
      c.initial_rms_residual_rad * kDegPerRad, c.rms_residual_rad * kDegPerRad,
      c.outlier_window_count, Eigen::AngleAxisd(c.q_T_S).angle() * kDegPerRad,
      v3(c.sigma_rotation_rad, kDegPerRad), c.bootstrap_unit_count, c.time_offset_s,
      c.sigma_time_offset_s, v3(c.gyro_bias_rad_s, kDegPerRad), v3(c.sigma_bias_rad_s, kDegPerRad),
      v3(c.gyro_scale), v3(c.sigma_scale), v3(c.gyro_cross_coupling), v3(c.sigma_cross_coupling));
  return out;
}

struct SplitResult {
  OrientationErrorStats imscal_from_start;
  OrientationErrorStats imscal_after_missed;  // restarted after each lost span
  std::size_t restart_count = 0;
  std::size_t loss_count = 0;  // segments losing 5 deg or more
  OrientationErrorStats xsens;
};

SplitResult evaluate(const Calibrated& cal, const std::string& test_sequence,
                     const std::string& sensor) {
  SplitResult result;
  const auto record = read_tool_imu_record(kDir + test_sequence + "/" + sensor + ".csv");
  const auto analysis = check_tool_imu_record(record);
  RotationCalibration applied = cal.calibration;
  applied.time_offset_s = analysis.time_offset_s;  // the run's own clock offset
  // The run's own gyro bias from its initial standstill (first 3 s at most).
  gyro_bias_at_rest(record, applied.time_offset_s, 0.01, applied.gyro_bias_rad_s, 3.0);
  // Restarted from the robot's pose after every span the sensor lost: the check's missed
  // motion and every segment whose rotation the gyro lost by 5 deg or more.
  const OrientationLossCheck losses = find_orientation_losses(record, applied);
  const auto restarted =
      orientation_error_with_restarts(record, applied, lost_spans(analysis, losses));
  result.imscal_from_start = restarted.from_start;
  result.imscal_after_missed = restarted.with_restarts;
  result.restart_count = restarted.restart_times_s.size();
  result.loss_count = losses.losses.size();
  const auto xsens_record = read_tool_imu_record(kDir + test_sequence + "/XSENS.csv");
  const auto alignment = align_ahrs_to_robot(xsens_record);
  result.xsens =
      orientation_error(xsens_record, alignment.time_offset_s, alignment.t_s, alignment.q_B_T);
  fmt::print(
      "  applied to {}: imscal orientation error RMS {:.2f} deg, max {:.2f} deg (from the start, "
      "{} samples)",
      test_sequence, result.imscal_from_start.rms_rad * kDegPerRad,
      result.imscal_from_start.max_rad * kDegPerRad, result.imscal_from_start.sample_count);
  if (result.restart_count > 0) {
    fmt::print(
        "; {} segments losing 5 deg or more; re-initialised after each of the {} lost spans, "
        "those spans left out: RMS {:.2f}, max {:.2f} deg",
        result.loss_count, result.restart_count, result.imscal_after_missed.rms_rad * kDegPerRad,
        result.imscal_after_missed.max_rad * kDegPerRad);
  }
  fmt::print(
      "\n  XSENS MTi-30 on {} (alignment fitted on it, offset {:.3f} s): RMS {:.2f} deg, max "
      "{:.2f} deg ({} samples)\n",
      test_sequence, alignment.time_offset_s, result.xsens.rms_rad * kDegPerRad,
      result.xsens.max_rad * kDegPerRad, result.xsens.sample_count);
  return result;
}

class RealAbbMems : public ::testing::TestWithParam<const char*> {};

TEST_P(RealAbbMems, CalibrateOnOneSequenceTrackTheOther) {
  const std::string sensor = GetParam();
  const Calibrated cal1 = calibrate(kSeq1, sensor);
  const Calibrated cal3 = calibrate(kSeq3, sensor);
  const double rotation_difference =
      ims::rotation_angle_between(cal1.calibration.q_T_S, cal3.calibration.q_T_S);
  // The difference about each T axis against the two sequences' combined 1 sigma.
  const Eigen::Vector3d difference = ims::quat_log(
      Eigen::Quaterniond(cal1.calibration.q_T_S * cal3.calibration.q_T_S.conjugate()));
  const Eigen::Vector3d combined_sigma = (cal1.calibration.sigma_rotation_rad.cwiseAbs2() +
                                          cal3.calibration.sigma_rotation_rad.cwiseAbs2())
                                             .cwiseSqrt();
  const Eigen::Vector3d covariance_sigma =
      (cal1.calibration.covariance_sigma_rotation_rad.cwiseAbs2() +
       cal3.calibration.covariance_sigma_rotation_rad.cwiseAbs2())
          .cwiseSqrt();
  fmt::print(
      "{}: R_T_S from the two sequences differ by {:.3f} deg, about T x, y, z {} deg; combined 1 "
      "sigma {} deg (motion-segment bootstrap, at least the covariance), {} deg (covariance of "
      "independent "
      "windows)\n",
      sensor, rotation_difference * kDegPerRad, v3(difference, kDegPerRad),
      v3(combined_sigma, kDegPerRad), v3(covariance_sigma, kDegPerRad));
  const SplitResult on3 = evaluate(cal1, kSeq3, sensor);
  const SplitResult on1 = evaluate(cal3, kSeq1, sensor);

  // Repeatability of the calibration between the two sequences (same mount). With the gyro's
  // cross-coupling estimated (calib/rotation_calibration.hpp) the two R_T_S differ by 0.07 deg
  // (MPU9150) and 0.73 deg (LSM9DS0); with a diagonal scale they differed by 2.0 and 3.3 deg,
  // mostly about T y, a path-dependent error that no resampling of one record could see. The
  // 1 sigma (motion segments resampled, robust spread, at least the covariance's) combined over
  // the two sequences is 0.31-0.55 deg per axis; the differences lie within 0.2 sigma (MPU9150)
  // and 1.1-1.4 sigma (LSM9DS0). Asserted: every axis within 3 sigma (the goal); the
  // whole difference below 1.5 deg (2x the larger measured); and the sigma below 1 deg per axis,
  // so that the 3-sigma test is not passed by a sigma too wide to use (the old block bootstrap
  // gave 0.27-0.85 deg, the covariance 0.20-0.33 deg).
  EXPECT_LT(rotation_difference * kDegPerRad, 1.5);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(difference[i]), 3.0 * combined_sigma[i]) << "axis " << i;
    EXPECT_LT(combined_sigma[i] * kDegPerRad, 1.0) << "axis " << i;
  }
  for (const auto* cal : {&cal1, &cal3}) {
    const auto& c = cal->calibration;
    // The calibrated fit explains the windows to about a degree (measured 0.7-1.0 deg RMS per
    // axis over 0.5 s windows of up to 200 deg).
    EXPECT_LT(c.rms_residual_rad * kDegPerRad, 2.0);
    // Clock offset near the check's cross-correlation value (measured 0.080-0.093 s).
    EXPECT_NEAR(c.time_offset_s, 0.09, 0.03);
    // Scale: MPU9150 in deg/s as labelled (measured 0.973-1.028 per axis); LSM9DS0 ~1/64 of
    // the labelled unit (measured 0.0150-0.0159, 0.957-1.020 x 1/64). Both +-5 %.
    const double expected_scale = sensor == "MPU9150" ? 1.0 : 1.0 / 64.0;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.gyro_scale[i] / expected_scale, 1.0, 0.05);
  }

  // Orientation against the robot on the OTHER sequence, imscal against the XSENS MTi-30.
  // Measured (RMS, deg): sequence 1: MPU9150 2.36, LSM9DS0 2.29, XSENS 30.1; sequence 3
  // restarted after each lost span (calib/orientation_losses.hpp; MPU9150: 4 spans, the other
  // sequence's scale errors of 2-4 % lose 8-16 deg in the long complex turns; LSM9DS0: 3 spans):
  // MPU9150 2.57, LSM9DS0 2.59, XSENS 22.3. imscal beats the
  // XSENS by a factor 4-10 in every split; asserted: at least 2x better, and absolute bounds
  // with ~60 % margin over the measured values.
  EXPECT_LT(on1.imscal_from_start.rms_rad * kDegPerRad, 5.0);
  EXPECT_LT(on1.imscal_after_missed.rms_rad, 0.5 * on1.xsens.rms_rad);
  EXPECT_LT(on3.imscal_after_missed.rms_rad * kDegPerRad, 8.0);
  EXPECT_LT(on3.imscal_after_missed.rms_rad, 0.5 * on3.xsens.rms_rad);
  // Sequence 1 loses no motion: no segment loses 5 deg, nothing to re-initialise.
  EXPECT_EQ(on1.loss_count, 0u);
  EXPECT_EQ(on1.restart_count, 0u);
  // Sequence 3 does (MPU9150: the first 180 deg turn, LSM9DS0: the start and a 0.68 s gap):
  // without re-initialisation the error from the start is large; that is the data, not the
  // calibration (reported by check_tool_imu_record as sensor_missed_motion).
  EXPECT_GE(on3.restart_count, 1u);
}

INSTANTIATE_TEST_SUITE_P(Sensors, RealAbbMems, ::testing::Values("MPU9150", "LSM9DS0"));

}  // namespace
}  // namespace imscal::calib
