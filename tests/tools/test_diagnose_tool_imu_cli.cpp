// `imscal diagnose-tool-imu` on the real LSM9DS0 records (tests/data/real/abb-mems/SOURCE.md),
// run as a user runs it: the gap measured after the unit check finds the 1/64 unit as a scale
// error, the axes turned about 94 deg and the clock offset (figures and their independent checks
// in tests/eval/test_gap_real_imu.cpp); an AHRS record without raw gyro columns is bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace {

namespace fs = std::filesystem;
using imscal::test_support::read_text;
using imscal::test_support::run_imscal;

const fs::path kDir = fs::path(IMSCAL_TEST_DATA_DIR) / "real" / "abb-mems";

using DiagnoseToolImuCli = imscal::test_support::ScratchDirTest;

TEST_F(DiagnoseToolImuCli, Lsm9ds0UnitAxesAndClock) {
  const fs::path out = dir_ / "gap.json";
  const int code =
      run_imscal("diagnose-tool-imu --imu " + (kDir / "V_500_Sequencia1" / "LSM9DS0.csv").string() +
                     " --held-out " + (kDir / "V_500_Sequencia3" / "LSM9DS0.csv").string() +
                     " --out " + out.string(),
                 dir_ / "run.log");
  const std::string log = read_text(dir_ / "run.log");
  ASSERT_EQ(code, 0) << log;
  EXPECT_NE(log.find("1/63.9"), std::string::npos) << log;
  const auto report = nlohmann::json::parse(read_text(out));
  // Bounds as in tests/eval/test_gap_real_imu.cpp: 1/64 within 5 %, axes 94 deg within 1.5 deg
  // of the record check's 94.7, clock within 0.03 s of its 0.089 s.
  EXPECT_NEAR(report.at("unit_scale").get<double>() * 64.0, 1.0, 0.05);
  const auto& steps = report.at("steps");
  ASSERT_GE(steps.size(), 3u);
  EXPECT_EQ(steps[0].at("effect"), "scale_factors");
  EXPECT_TRUE(steps[0].at("from_unit_check").get<bool>());
  EXPECT_NEAR(report.at("model").at("axis_angle_deg").get<double>(), 94.7, 1.5);
  EXPECT_NEAR(report.at("model").at("time_offset_s").get<double>(), 0.089, 0.03);
  EXPECT_LT(report.at("held_out_rms_modelled_deg_s").get<double>(),
            0.5 * report.at("held_out_rms_deg_s").get<double>());
}

TEST_F(DiagnoseToolImuCli, AnAhrsRecordIsBadInput) {
  const int code =
      run_imscal("diagnose-tool-imu --imu " + (kDir / "V_500_Sequencia1" / "XSENS.csv").string() +
                     " --held-out " + (kDir / "V_500_Sequencia3" / "LSM9DS0.csv").string(),
                 dir_ / "bad.log");
  EXPECT_EQ(code, 2);
  EXPECT_NE(read_text(dir_ / "bad.log").find("no raw gyro"), std::string::npos);
}

}  // namespace
