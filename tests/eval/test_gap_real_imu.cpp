// The sim-to-real gap of real IMU signals: the MEMS IMUs (MPU9150, LSM9DS0) carried by an ABB
// robot (tests/data/real/abb-mems/SOURCE.md), "sim" = the angular rate of the robot's reported
// tool poses, "real" = the gyro as read. Trained on sequence 1, judged on sequence 3 (held out).
// Independent truth: the dataset's own description (a time offset of roughly 0.1 s between the
// streams, sensor axes not aligned with the tool, a gyro saturating near 500 deg/s) and
// calib::check_tool_imu_record's findings on the same record (tests/calib/test_real_abb_mems.cpp:
// offset 0.09 +- 0.03 s).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "eval/gap_imu_signals.hpp"

namespace imscal::eval {
namespace {

namespace fs = std::filesystem;

calib::ToolImuRecord record(const std::string& sequence,
                            const std::string& sensor = "MPU9150.csv") {
  return calib::read_tool_imu_record(fs::path(IMSCAL_TEST_DATA_DIR) / "real/abb-mems" / sequence /
                                     sensor);
}

void print(const ImuGapDiagnosis& d) {
  fmt::print("{}\n", d.verdict);
  for (const auto& s : d.steps)
    fmt::print("  + {:<18} held-out RMS {:.2f} deg/s ({:.0f} % smaller): {}\n", to_string(s.effect),
               s.heldout_rms_rad_s * 180.0 / M_PI, s.heldout_shrinkage_percent, s.size);
}

TEST(GapRealImu, TimeOffsetAndMisalignmentAreFoundAndTheHeldOutGapShrinks) {
  const ImuGapDiagnosis d =
      diagnose_imu_gap(record("V_500_Sequencia1"), record("V_500_Sequencia3"));
  print(d);
  const auto found = [&](ImuGapEffect e) {
    return std::any_of(d.steps.begin(), d.steps.end(),
                       [&](const ImuGapStep& s) { return s.effect == e; });
  };
  EXPECT_TRUE(found(ImuGapEffect::kTimeOffset));
  EXPECT_TRUE(found(ImuGapEffect::kAxisMisalignment));
  // ~0.1 s (the dataset's description), 0.09 +- 0.03 s by the record check's cross-correlation.
  EXPECT_NEAR(d.model.time_offset_s, 0.09, 0.03);
  // The axes: the record check's rate-vector fit on the held-out sequence itself (4.2 deg; 4.0
  // on sequence 1) is the independent value; within 1.5 deg (the fits scatter by ~0.5 deg with
  // the poses' timing jitter).
  const calib::ToolImuAnalysis check = calib::check_tool_imu_record(record("V_500_Sequencia3"));
  const double between = Eigen::AngleAxisd(d.model.R_T_S.transpose() * check.R_T_S).angle();
  fmt::print("misalignment {:.2f} deg, the held-out check's {:.2f} deg, {:.2f} deg apart\n",
             Eigen::AngleAxisd(d.model.R_T_S).angle() * 180.0 / M_PI,
             check.misalignment_rad * 180.0 / M_PI, between * 180.0 / M_PI);
  EXPECT_LT(between * 180.0 / M_PI, 1.5);
  // The held-out gap shrinks by more than half (measured 58 %: 29.9 -> 12.4 deg/s).
  EXPECT_LT(d.heldout_rms_modelled_rad_s, 0.5 * d.heldout_rms_rad_s);
  EXPECT_EQ(d.unit_scale, 1.0);  // the MPU9150's labelled deg/s is right
}

// The LSM9DS0 of the same runs reads 1/64 of the labelled deg/s (SOURCE.md) and its axes are
// turned about 94 deg from the tool's. The gap is measured after the unit check, so the scale is
// found as a scale error and the axes and the clock as what they are (measured: 1/63.9, 94.3 deg,
// 0.080 s; the held-out gap 79.3 -> 14.3 deg/s, 82 %). Independent values: the unit ratio within
// 5 % of 1/64 (the bound of tests/calib/test_real_abb_mems.cpp), the record check's rate-vector
// fit and cross-correlation offset on the held-out record itself, within 1.5 deg (as for the
// MPU9150 above) and 0.03 s (the cross-correlation's resolution on 15 Hz poses).
TEST(GapRealImu, Lsm9ds0ScaleAxesAndClockAreFoundAfterTheUnitCheck) {
  const calib::ToolImuRecord training = record("V_500_Sequencia1", "LSM9DS0.csv");
  const calib::ToolImuRecord heldout = record("V_500_Sequencia3", "LSM9DS0.csv");
  const ImuGapDiagnosis d = diagnose_imu_gap(training, heldout);
  print(d);
  EXPECT_NEAR(d.unit_scale * 64.0, 1.0, 0.05);
  ASSERT_GE(d.steps.size(), 3u);
  EXPECT_TRUE(d.steps.front().from_unit_check);
  EXPECT_EQ(d.steps.front().effect, ImuGapEffect::kScaleFactors);
  const auto found = [&](ImuGapEffect e) {
    return std::any_of(d.steps.begin(), d.steps.end(),
                       [&](const ImuGapStep& s) { return s.effect == e && !s.from_unit_check; });
  };
  EXPECT_TRUE(found(ImuGapEffect::kAxisMisalignment));
  EXPECT_TRUE(found(ImuGapEffect::kTimeOffset));
  const calib::ToolImuAnalysis check = calib::check_tool_imu_record(heldout);
  const double between = Eigen::AngleAxisd(d.model.R_T_S.transpose() * check.R_T_S).angle();
  fmt::print(
      "axes turned {:.2f} deg, the held-out check's {:.2f} deg, {:.2f} deg apart; clock "
      "{:.3f} s, the check's {:.3f} s\n",
      Eigen::AngleAxisd(d.model.R_T_S).angle() * 180.0 / M_PI,
      check.misalignment_rad * 180.0 / M_PI, between * 180.0 / M_PI, d.model.time_offset_s,
      check.time_offset_s);
  EXPECT_LT(between * 180.0 / M_PI, 1.5);
  EXPECT_NEAR(d.model.time_offset_s, check.time_offset_s, 0.03);
  // The model is for the gyro as labelled: its scale carries the unit (K ~ 1/64 per axis).
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(d.model.scale[i] * 64.0, 1.0, 0.15) << i;
  // Measured 82 %; the gap after the unit check is at least halved.
  EXPECT_LT(d.heldout_rms_modelled_rad_s, 0.5 * d.heldout_rms_rad_s);
}

}  // namespace
}  // namespace imscal::eval
