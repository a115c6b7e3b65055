// `imscal check-tool-imu` on real records (tests/data/real/abb-mems/SOURCE.md), run as a user
// runs it: the exit code, the printed words and report.json.
//   - V_1500_Sequencia1/LSM9DS0.csv, the record on which the rotation calibration's solve once
//     failed and the process died (a signal): it is calibrated now (exit 0, main.cpp's codes).
//   - V_800_Sequencia3/MPU6050RM3100.csv, whose gyro stream loses about 30 deg in one turn: the
//     loss is listed, and the error restarted after it is far below the error from the start.
//   - An AHRS record whose orientation does not follow the robot (its quaternions replaced by a
//     random walk): refused as a reference with the reason, the IMU's results still written.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace {

namespace fs = std::filesystem;
using imscal::test_support::read_text;
using imscal::test_support::run_imscal;

const fs::path kDir = fs::path(IMSCAL_TEST_DATA_DIR) / "real" / "abb-mems";

using CheckToolImuCli = imscal::test_support::ScratchDirTest;

TEST_F(CheckToolImuCli, FastRecordWithSignFlippingPosesIsCalibrated) {
  const fs::path out = dir_ / "fast.json";
  const int code =
      run_imscal("check-tool-imu --imu " + (kDir / "V_1500_Sequencia1" / "LSM9DS0.csv").string() +
                     " --out " + out.string(),
                 dir_ / "fast.log");
  const std::string log = read_text(dir_ / "fast.log");
  // The solve used to fail on windows without a robot pose at the initial clock offset (the
  // robot's quaternions flip sign around 180 deg about z, leaving 0.2 s without valid poses)
  // and the covariance of the failed solve killed the process. Now it calibrates: exit 0.
  ASSERT_EQ(code, 0) << log;
  const auto report = nlohmann::json::parse(read_text(out));
  const auto& calibration = report.at("calibration");
  EXPECT_GE(calibration.at("window_count").get<int>(), 10);
  // The LSM9DS0's gyro counts 1/64 of the labelled deg/s (SOURCE.md): scale 1/64 +- 5 %, the
  // bound of tests/calib/test_real_abb_mems.cpp (measured 0.0150-0.0161 per axis).
  for (const auto& k : calibration.at("gyro_scale")) EXPECT_NEAR(k.get<double>() * 64.0, 1.0, 0.05);
  EXPECT_TRUE(report.at("orientation").contains("from_start"));
}

// XSENS.csv of V_800_Sequencia3 with sens_q0..3 replaced by a random walk of 1 deg steps.
fs::path ahrs_not_following_the_robot(const fs::path& dir) {
  std::ifstream in(kDir / "V_800_Sequencia3" / "XSENS.csv");
  const fs::path path = dir / "XSENS_random.csv";
  std::ofstream out(path);
  std::string line;
  std::getline(in, line);
  out << line << '\n';  // header: t_s, sens_q0..3, robot columns
  std::mt19937 random(7);
  std::normal_distribution<double> step(0.0, 1.0 * M_PI / 180.0);
  double w = 1.0, x = 0.0, y = 0.0, z = 0.0;
  while (std::getline(in, line)) {
    // q <- q * exp(step / 2), first order, renormalised.
    const double a = step(random) / 2, b = step(random) / 2, c = step(random) / 2;
    const double nw = w - x * a - y * b - z * c, nx = x + w * a + y * c - z * b,
                 ny = y + w * b + z * a - x * c, nz = z + w * c + x * b - y * a;
    const double n = std::sqrt(nw * nw + nx * nx + ny * ny + nz * nz);
    w = nw / n, x = nx / n, y = ny / n, z = nz / n;
    std::stringstream fields(line);
    std::string t, rest;
    std::getline(fields, t, ',');
    for (int i = 0; i < 4; ++i) std::getline(fields, rest, ',');
    std::getline(fields, rest);
    out << t << ',' << w << ',' << x << ',' << y << ',' << z << ',' << rest << '\n';
  }
  return path;
}

TEST_F(CheckToolImuCli, PartialLossIsListedAndARefusedReferenceIsReported) {
  const fs::path out = dir_ / "loss.json";
  const fs::path xsens = ahrs_not_following_the_robot(dir_);
  const int code = run_imscal("check-tool-imu --imu " +
                                  (kDir / "V_800_Sequencia3" / "MPU6050RM3100.csv").string() +
                                  " --xsens " + xsens.string() + " --out " + out.string(),
                              dir_ / "loss.log");
  const std::string log = read_text(dir_ / "loss.log");
  ASSERT_EQ(code, 0) << log;
  EXPECT_NE(log.find("[orientation_loss]"), std::string::npos) << log;
  EXPECT_NE(log.find("REFUSED"), std::string::npos) << log;
  const auto report = nlohmann::json::parse(read_text(out));
  const auto& orientation = report.at("orientation");
  // The one partial loss of the record (SOURCE.md: about 30 deg in one turn): 15-40 deg.
  ASSERT_GE(orientation.at("losses").size(), 1u);
  double largest = 0.0;
  for (const auto& loss : orientation.at("losses")) {
    largest = std::max(largest, loss.at("loss_deg").get<double>());
  }
  EXPECT_GT(largest, 15.0);
  EXPECT_LT(largest, 40.0);
  const double from_start = orientation.at("from_start").at("rms_deg").get<double>();
  const double restarted = orientation.at("with_restarts").at("rms_deg").get<double>();
  EXPECT_LT(restarted, 0.5 * from_start);
  // The refused reference, with its reason, beside the IMU's own results.
  const auto& ahrs = report.at("ahrs_orientation_error");
  EXPECT_TRUE(ahrs.at("refused").get<bool>());
  EXPECT_FALSE(ahrs.at("reason").get<std::string>().empty());
  EXPECT_TRUE(report.contains("calibration"));

  // An AHRS file that cannot be read is bad input, not a refused reference: exit 2 naming it,
  // nothing written.
  const fs::path missing_out = dir_ / "missing.json";
  EXPECT_EQ(
      run_imscal("check-tool-imu --imu " +
                     (kDir / "V_800_Sequencia3" / "MPU6050RM3100.csv").string() + " --xsens " +
                     (dir_ / "no_such_xsens.csv").string() + " --out " + missing_out.string(),
                 dir_ / "missing.log"),
      2);
  EXPECT_NE(read_text(dir_ / "missing.log").find("no_such_xsens.csv"), std::string::npos);
  EXPECT_FALSE(fs::exists(missing_out));

  // --no-restart: the error from the start only.
  const fs::path plain = dir_ / "plain.json";
  ASSERT_EQ(run_imscal("check-tool-imu --no-restart --imu " +
                           (kDir / "V_800_Sequencia3" / "MPU6050RM3100.csv").string() + " --out " +
                           plain.string(),
                       dir_ / "plain.log"),
            0);
  const auto plain_report = nlohmann::json::parse(read_text(plain));
  EXPECT_FALSE(plain_report.at("orientation").contains("with_restarts"));
  EXPECT_DOUBLE_EQ(plain_report.at("orientation").at("from_start").at("rms_deg").get<double>(),
                   from_start);
}

}  // namespace
