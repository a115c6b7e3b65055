// The sim-to-real gap of real IMU signals: the MEMS IMU (MPU9150) carried by an ABB
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

calib::ToolImuRecord record(const std::string& sequence) {
  return calib::read_tool_imu_record(fs::path(IMSCAL_TEST_DATA_DIR) / "real/abb-mems" / sequence /
                                     "MPU9150.csv");
}

TEST(GapRealImu, TimeOffsetAndMisalignmentAreFoundAndTheHeldOutGapShrinks) {
  const ImuGapDiagnosis d =
      diagnose_imu_gap(record("V_500_Sequencia1"), record("V_500_Sequencia3"));
  fmt::print("{}\n", d.verdict);
  for (const auto& s : d.steps)
    fmt::print("  + {:<18} held-out RMS {:.2f} deg/s ({:.0f} % smaller): {}\n", to_string(s.effect),
               s.heldout_rms_rad_s * 180.0 / M_PI, s.heldout_shrinkage_percent, s.size);
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
}

}  // namespace
}  // namespace imscal::eval
