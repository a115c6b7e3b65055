// `imscal simulate` end to end on a short scenario (tests/data/scenarios/short.yaml): the files
// exist and read back with our readers, they agree with each other and with the truth, the same
// seed gives the same bytes and another seed other draws, existing outputs are refused, and a bad
// scenario is refused with file, line and key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/numeric_table.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_file.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"
#include "tests/support/frames_json.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using SimulateCli = test_support::ScratchDirTest;

const fs::path kScenario = fs::path(IMSCAL_TEST_DATA_DIR) / "scenarios" / "short.yaml";

constexpr auto* run = &imscal::test_support::run_imscal;

using imscal::test_support::read_text;

TEST_F(SimulateCli, WritesConsistentFilesAndTheSameBytesForTheSameSeed) {
  const fs::path a = dir_ / "a", b = dir_ / "b", c = dir_ / "c";
  ASSERT_EQ(
      run("simulate --scenario " + kScenario.string() + " --out " + a.string(), dir_ / "a.log"), 0)
      << read_text(dir_ / "a.log");
  ASSERT_EQ(
      run("simulate --scenario " + kScenario.string() + " --out " + b.string(), dir_ / "b.log"), 0);
  ASSERT_EQ(run("simulate --scenario " + kScenario.string() + " --seed 4 --out " + c.string(),
                dir_ / "c.log"),
            0);
  for (const char* file : {"imu.csv", "robot.csv", "truth/joints.csv", "truth/flange_poses.csv",
                           "truth/trajectory.csv", "truth/frames.json", "truth/sensor_errors.yaml",
                           "truth/imu_bias.csv", "truth/segments.csv", "truth/scenario.yaml"}) {
    SCOPED_TRACE(file);
    ASSERT_TRUE(fs::is_regular_file(a / file));
    EXPECT_EQ(read_text(a / file), read_text(b / file));  // same seed, same bytes
  }
  // Another seed: other noise and errors, another mount and base.
  EXPECT_NE(read_text(a / "imu.csv"), read_text(c / "imu.csv"));
  EXPECT_NE(read_text(a / "truth/frames.json"), read_text(c / "truth/frames.json"));

  // robot.csv: 2 ms rows; its internal angles are the truth's motor angles at the same instants.
  const calib::RobotLog log = calib::read_robot_log_csv(a / "robot.csv", "kr16");
  const NumericTable joints = read_numeric_table(a / "truth/joints.csv");
  ASSERT_GT(log.samples.size(), 1000u);  // > 2 s of 2 ms cycles
  for (std::size_t k = 0; k < log.samples.size(); k += 97) {
    const std::size_t row = 2 * k;  // truth every 1 ms
    ASSERT_LT(row, joints.rows());
    EXPECT_EQ(joints.at(row, 0), log.samples[k].t_s);
    for (int j = 0; j < 6; ++j) {
      EXPECT_EQ(joints.at(row, joints.column("q_motor_A" + std::to_string(j + 1) + "_rad")),
                log.samples[k].q_internal_rad[j]);
    }
    EXPECT_EQ(log.samples[k].payload_kg, 5.0);
  }

  // The IMS record: on the IMS clock (12.3 ms ahead), 1 kHz, covering the run.
  const ims::ImuSeries imu = ims::read_imu_file(a / "imu.csv");
  EXPECT_NEAR(imu.samples.front().t_s, 0.001 + 0.0123, 1e-12);
  EXPECT_NEAR(imu.nominal_dt_s, 0.001, 0);
  EXPECT_NEAR(imu.samples.back().t_s, log.samples.back().t_s + 0.0123, 0.0011);
  // At rest at the start the accelerometers feel the site's gravity: |mean dv| / dt within
  // 1e-3 m/s^2 of normal gravity (navigation-grade biases are ~25 ug = 2.5e-4 m/s^2; the plant
  // is settled at the start by construction).
  Eigen::Vector3d dv = Eigen::Vector3d::Zero();
  for (int k = 0; k < 500; ++k) dv += imu.samples[k].acc;
  const ims::EarthModel earth({48.78232, 9.18162, 245.4});
  EXPECT_NEAR(dv.norm() / 0.5, earth.normal_gravity_magnitude(), 1e-3);
  // The biases the record carries: every 0.1 s of the IMS clock from its first sample on; the
  // navigation-grade accelerometer's in-run part (10 ug over 600 s) keeps them within a few
  // tens of ug of the turn-on bias (25 ug sigma) over a few seconds.
  const NumericTable bias = read_numeric_table(a / "truth/imu_bias.csv");
  ASSERT_GT(bias.rows(), 10u);
  EXPECT_NEAR(bias.at(0, 0), imu.samples.front().t_s, 1e-12);
  EXPECT_NEAR(bias.at(1, 0) - bias.at(0, 0), 0.1, 1e-9);
  EXPECT_NEAR(bias.at(bias.rows() - 1, 0), imu.samples.back().t_s, 0.1);
  for (std::size_t r = 0; r < bias.rows(); r += bias.rows() / 10)
    EXPECT_LT(std::abs(bias.at(r, bias.column("acc_bias_z_ug"))), 200.0);

  // The truth trajectory of S in W is the flange truth through the frames: check 20 instants.
  const nlohmann::json frames = nlohmann::json::parse(read_text(a / "truth/frames.json"));
  auto pose = [](const nlohmann::json& j) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = imscal::test_support::quaternion_of(j).toRotationMatrix();
    T.translation() = Eigen::Vector3d(j["xyz_m"][0], j["xyz_m"][1], j["xyz_m"][2]);
    return T;
  };
  const Eigen::Isometry3d T_W_R = pose(frames["T_W_R"]), T_H_S = pose(frames["T_H_S"]);
  EXPECT_TRUE((T_W_R * pose(frames["T_R_W"])).matrix().isIdentity(1e-12));
  EXPECT_DOUBLE_EQ(frames["imu_clock_offset_s"].get<double>(), 0.0123);
  const ims::NavTrajectory truth = ims::read_trajectory_csv(a / "truth/trajectory.csv");
  const NumericTable flange = read_numeric_table(a / "truth/flange_poses.csv");
  for (std::size_t i = 1; i < truth.states.size(); i += truth.states.size() / 20) {
    const double t_robot = truth.states[i].t_s - 0.0123;
    const auto row = static_cast<std::size_t>(std::llround(t_robot / 0.001));
    if (std::abs(row * 0.001 - t_robot) > 1e-9 || row >= flange.rows()) continue;
    Eigen::Isometry3d T_R_H = Eigen::Isometry3d::Identity();
    T_R_H.translation() = Eigen::Vector3d(flange.at(row, 1), flange.at(row, 2), flange.at(row, 3));
    T_R_H.linear() = Eigen::Quaterniond(flange.at(row, 4), flange.at(row, 5), flange.at(row, 6),
                                        flange.at(row, 7))
                         .toRotationMatrix();
    const Eigen::Isometry3d T_W_S = T_W_R * T_R_H * T_H_S;
    // The spline passes through its knots; the files round-trip doubles exactly, the json
    // frames to 1e-15: agreement to 1e-9 m.
    EXPECT_LT((T_W_S.translation() - truth.states[i].p_W).norm(), 1e-9);
  }
}

TEST_F(SimulateCli, RefusesExistingOutputsAndBadScenarios) {
  fs::create_directories(dir_ / "out");
  std::ofstream(dir_ / "out" / "robot.csv") << "precious\n";
  EXPECT_EQ(run("simulate --scenario " + kScenario.string() + " --out " + (dir_ / "out").string(),
                dir_ / "refuse.log"),
            2);
  EXPECT_EQ(read_text(dir_ / "out" / "robot.csv"), "precious\n");  // nothing lost
  EXPECT_NE(read_text(dir_ / "refuse.log").find("--force"), std::string::npos);

  // A copy with a misspelt key, its relative paths made absolute (tests write only to scratch).
  std::string text = read_text(kScenario);
  const std::string datasets = std::string(IMSCAL_SOURCE_DIR) + "/datasets";
  text.replace(text.find("../../../datasets"), 17, datasets);
  text.replace(text.find("../../../datasets"), 17, datasets);
  text.replace(text.find("short-program.yaml"), 18,
               (kScenario.parent_path() / "short-program.yaml").string());
  text.replace(text.find("seed: 3"), 7, "seed: 3\nsede: 4");
  const fs::path bad = dir_ / "bad.yaml";
  std::ofstream(bad) << text;
  const int code = run("simulate --scenario " + bad.string() + " --out " + (dir_ / "x").string(),
                       dir_ / "bad.log");
  EXPECT_EQ(code, 2);
  EXPECT_NE(read_text(dir_ / "bad.log").find("sede"), std::string::npos)
      << read_text(dir_ / "bad.log");
  EXPECT_FALSE(fs::exists(dir_ / "x" / "robot.csv"));

  EXPECT_EQ(run("simulate --scenario no-such-scenario --out " + (dir_ / "y").string(),
                dir_ / "unknown.log"),
            2);
  EXPECT_NE(read_text(dir_ / "unknown.log").find("seed-line"), std::string::npos)
      << "the message lists the shipped scenarios";
}

}  // namespace
}  // namespace imscal
