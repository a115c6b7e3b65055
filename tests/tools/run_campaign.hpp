#pragma once
// A small campaign for `imscal run` tests, written into a scratch folder: the shipped default
// IMS record (datasets/default/imu.imsb, 60 s), a 6-joint robot log over the same clock span,
// a joint_errors.csv of two simulated joints with known dynamics and backlash (the generator of
// the ident tests), an identification config with a small order sweep, and run.yaml naming them.
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "ident/joint_error_io.hpp"
#include "robot/robot_log.hpp"
#include "tests/ident/joint_simulation.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::test_support {

// Writes the campaign into `dir`; returns the path of run.yaml. `extra` is appended to run.yaml.
inline std::filesystem::path write_campaign(const std::filesystem::path& dir,
                                            const std::string& extra = "") {
  namespace fs = std::filesystem;
  constexpr double kDt = 0.002;
  // Lighter under the sanitizers (IMSCAL_SANITIZED): fewer samples, still many reversals.
  const std::size_t samples = std::getenv("IMSCAL_SANITIZED") ? 12000 : 30000;
  ident::JointErrorLog log;
  log.robot = "kr16";
  log.cycle_s = kDt;
  log.source = "imscal run test campaign";
  log.joint_names = {"A1", "A2"};
  log.q_desired_rad.resize(2);
  log.q_measured_rad.resize(2);
  log.q_internal_rad.resize(2);
  for (std::size_t j = 0; j < 2; ++j) {
    SimulatedJoint joint;
    joint.backlash_l_rad = j == 0 ? 0.8e-3 : 1.5e-3;
    joint.dead_time = j == 0 ? 2 : 1;
    joint.measurement_noise_rad = 1e-5;
    joint.offset_rad = j == 0 ? 0.3 : -0.6;
    const auto r = simulate_joint(joint, samples, kDt, 10 * unsigned(j));
    if (j == 0) {
      log.time_s = r.t_s;
      log.payload_kg.assign(r.t_s.size(), 5.0);
    }
    log.q_desired_rad[j] = r.q_desired;
    log.q_measured_rad[j] = r.q_measured;
    // The internal sensors see the drive's dynamics but not the backlash (paper, section 2).
    log.q_internal_rad[j] = r.q_linear;
  }
  ident::write_joint_errors_csv(dir / "joint_errors.csv", log);

  std::string config =
      read_text(fs::path(IMSCAL_SOURCE_DIR) / "datasets/identification/ident-paper.yaml");
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = config.find(from);
    if (at == std::string::npos) throw std::runtime_error("ident-paper.yaml lacks " + from);
    config.replace(at, from.size(), to);
  };
  replace("max_speed_deg_s: [156, 156, 156, 330, 330, 615]", "max_speed_deg_s: [60, 60]");
  replace("na: [1, 32]", "na: [1, 4]");
  replace("nb: [1, 32]", "nb: [1, 4]");
  replace("settle_s: 0.05", "settle_s: 0.08");
  std::ofstream(dir / "ident.yaml") << config;

  // Robot log over 0..20 s of the robot clock (the IMS record spans about 0..60 s).
  calib::RobotLog robot;
  robot.robot_name = "kr16";
  robot.cycle_s = kDt;
  for (int k = 0; k <= 10000; ++k) {
    calib::RobotLogSample s;
    s.t_s = k * kDt;
    s.payload_kg = 5.0;
    for (int j = 0; j < 6; ++j) {
      s.q_desired_rad[j] = 0.1 * j + 0.2 * std::sin(0.5 * s.t_s + j);
      s.q_internal_rad[j] = s.q_desired_rad[j] - 1e-4;
    }
    robot.samples.push_back(s);
  }
  calib::write_robot_log_csv(dir / "robot.csv", robot, Overwrite::kAllow);

  const fs::path run_yaml = dir / "run.yaml";
  std::ofstream(run_yaml) << "imscal-run-config: 1\n"
                             "title: Test campaign\n"
                             "inputs:\n"
                             "  imu: " IMSCAL_SOURCE_DIR
                             "/datasets/default/imu.imsb\n"
                             "  robot_log: robot.csv\n"
                             "  joint_errors: joint_errors.csv\n"
                             "identify:\n"
                             "  config: ident.yaml\n"
                          << extra;
  return run_yaml;
}

}  // namespace imscal::test_support
