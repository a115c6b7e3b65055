// `imscal calibrate-kinematics` run as a user runs it, on the real UR10 poses
// (tests/data/real/ipa-ur10/SOURCE.md): exit code, the JSON report's figures, and the codes of a
// bad input and of an existing output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace {

namespace fs = std::filesystem;
using imscal::test_support::read_text;
using imscal::test_support::run_imscal;

const fs::path kPoses =
    fs::path(IMSCAL_TEST_DATA_DIR) / "real/ipa-ur10/measurements_random_poses_head400.csv";
const fs::path kRobot = fs::path(IMSCAL_SOURCE_DIR) / "datasets/robots/ur10.urdf";

using CalibrateKinematicsCli = imscal::test_support::ScratchDirTest;

// Figures as in tests/calib/test_kinematic_calibration.cpp (the same poses and split): held-out
// RMS 0.962 mm nominal, 0.494 mm calibrated; bounds 0.8 mm and 0.6 mm. 10 of the 33 parameters
// are held at nominal (decision 0026), each with its reason.
TEST_F(CalibrateKinematicsCli, WritesTheReportWithBothModelsOnHeldOutPoses) {
  const fs::path out = dir_ / "kinematics.json";
  const std::string args = "calibrate-kinematics --robot " + kRobot.string() + " --poses " +
                           kPoses.string() + " --out " + out.string();
  const int code = run_imscal(args, dir_ / "run.log");
  ASSERT_EQ(code, 0) << read_text(dir_ / "run.log");
  const auto report = nlohmann::json::parse(read_text(out));
  EXPECT_EQ(report.at("fitted_poses").get<int>(), 200);
  EXPECT_EQ(report.at("held_out_poses").get<int>(), 200);
  EXPECT_GT(report.at("nominal").at("held_out_errors").at("rms_mm").get<double>(), 0.8);
  EXPECT_LT(report.at("calibrated").at("held_out_errors").at("rms_mm").get<double>(), 0.6);
  EXPECT_TRUE(report.at("calibrated_beats_nominal_on_held_out").get<bool>());
  int held = 0;
  for (const auto& p : report.at("calibrated").at("parameters")) {
    if (!p.at("estimated").get<bool>()) {
      ++held;
      EXPECT_FALSE(p.at("reason").get<std::string>().empty());
    }
  }
  EXPECT_EQ(held, 10);
  // The output exists now: refused without --force (exit 2), the file kept.
  EXPECT_EQ(run_imscal(args, dir_ / "again.log"), 2);
  EXPECT_NE(read_text(dir_ / "again.log").find("--force"), std::string::npos);
}

TEST_F(CalibrateKinematicsCli, AJointInDegreesIsBadInput) {
  const fs::path poses = dir_ / "poses.csv";
  std::ofstream(poses)
      << "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,meas_x_mm,meas_y_mm,meas_z_mm\n"
      << "0,-90,0,0,0,0,1,2,3\n";
  const int code = run_imscal("calibrate-kinematics --robot " + kRobot.string() + " --poses " +
                                  poses.string() + " --out " + (dir_ / "k.json").string(),
                              dir_ / "bad.log");
  EXPECT_EQ(code, 2);
  const std::string log = read_text(dir_ / "bad.log");
  EXPECT_NE(log.find("q2_rad"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir_ / "k.json"));
}

// One pose measured 30 times cannot place the tracker frame: bad input (exit 2), no report.
TEST_F(CalibrateKinematicsCli, OnePoseRepeatedIsBadInput) {
  std::ifstream in(kPoses);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  const fs::path poses = dir_ / "same.csv";
  std::ofstream file(poses);
  file << header << '\n';
  for (int k = 0; k < 30; ++k) file << row << '\n';
  file.close();
  const int code = run_imscal("calibrate-kinematics --robot " + kRobot.string() + " --poses " +
                                  poses.string() + " --out " + (dir_ / "k.json").string(),
                              dir_ / "same.log");
  EXPECT_EQ(code, 2);
  EXPECT_NE(read_text(dir_ / "same.log").find("too little motion"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "k.json"));
}

}  // namespace
