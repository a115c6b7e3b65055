// Two sessions on real files: the lab calibrates the IMS mount in one session and records the
// identification runs in another with the same robot, base, mount and unit
// (tests/data/scenarios/two-sessions-*.yaml: same seed, so the simulator draws the same base
// heading, mount and unit; see there). The chain, each step the `imscal` command:
//   simulate both sessions -> unit calibration from the drawn scale factors and misalignments
//   (as datasets/campaign/regenerate.sh) -> `calibrate` the mounting session -> `calibrate
//   --frames` the identification session (1 usable rest: plain `calibrate` refuses it) ->
//   `identify` its joint_errors.csv with the shipped config and the model torque (--robot,
//   --gravity-m-s2 the site's normal gravity).
// Printed: (a) the chain's joint errors against the simulator's truth (q_desired - q_link of
// truth/joints.csv at the same robot samples), RMS per joint of the truth and of the
// measurement error: measured A1 0.036, A2 0.080, A3 0.176 mrad (signal ~3.5-3.7 mrad); (b) the
// held-out joint-error fit per joint that identify reports (cells weighted by their validation
// rows, as eval::summarize_fit): A1 96.2, A2 95.1, A3 94.0 %; (c) the same identification
// in-process (eval::identify_table, checked equal to identify's figures) with its models judged
// against the TRUE joint errors of the held-out rows (eval::replay_held_out_fits, as
// tests/eval/test_verification.cpp's IdentifiedFromTheImsChain): A1 96.1, A2 95.2, A3 93.1 %
// (the shipped config's 60 input taps; 95.2/94.1/93.4 and 95.1/94.7/93.0 % with 32), asserted
// 3 %-points below; the goal (>= 90 % per primary joint) is met both ways and asserted
// (Release).
// The clock offset: 0.033 ms off (asserted below), with session 1's link share of the drives'
// friction as the prior (0.098 ms off without; it costs A1 0.02 mrad). The biases --frames finds
// from the 1 usable rest (acc ~30 ug off the truth, within their 18-27 ug sigma) do not matter:
// the smoother estimates them anew.
// Before the correction at the revisited poses (calib/revisited_poses.hpp) the chain erred by
// 0.171/0.513/0.856 mrad here (fits 94.3/86.5/82.0 % measured, 94.7/91.6/78.6 % against the
// truth): the smoother's attitude stayed within 0.02 mrad, but its position, which no
// zero-velocity or creep update observes, walked off by 0.3-0.7 mm over the record (0.4 mm after
// the pause that follows A4 +90 deg alone, where A5's axis stands vertical and its unloaded link
// slides in its play while the creep updates take the motor's motion for the link's). With the
// true frames, biases and clock the in-process chain erred as much (0.16/0.48/0.76 mrad; with the
// nominal mount and base heading the same): not the frames nor the bias and clock offset that
// --frames estimates (a 30 ug error of the initial acc bias changes it < 0.001 mrad: the smoother
// estimates the biases anew; 0.1 ms of clock offset by 0.01-0.02), but the position's random walk,
// which varies with the unit's noise draw (A3 0.20-1.19 mrad over 8 draws on this plant run with
// the true frames, biases and clock; with the correction 0.05-0.12 over 6 of them). With the
// first rest's pose alone the correction gave 0.051/0.102/0.194 mrad here; every revisited pose
// (the mixed moves' poses too) 0.036/0.080/0.176.
// Release only: two plant runs (~10 s), two calibrations and two identifications (~5 s); under
// the sanitizers (5-10x slower) it is skipped, and the known-frames bundle is covered there by
// tests/calib/test_frame_calibration_known_frames.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/config_node.hpp"
#include "core/sha256.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"
#include "ims/earth_model.hpp"
#include "ims/sensor_error_model.hpp"
#include "robot/robot_description.hpp"
#include "sim/scenario.hpp"
#include "tests/support/frames_json.hpp"
#include "tests/support/record_figure.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using CalibrateTwoSessions = test_support::ScratchDirTest;
constexpr auto* run = &imscal::test_support::run_imscal;
using imscal::test_support::read_text;

const fs::path kSource(IMSCAL_SOURCE_DIR);
const fs::path kScenarios = fs::path(IMSCAL_TEST_DATA_DIR) / "scenarios";
const fs::path kRobot = kSource / "datasets" / "robots" / "kr16.yaml";
const fs::path kSensor = kSource / "datasets" / "sensors" / "navigation-grade.yaml";
const fs::path kConfig = kSource / "datasets" / "calibration" / "calibrate-default.yaml";
const fs::path kIdentConfig = kSource / "datasets" / "identification" / "ident-default.yaml";

std::string calibrate_arguments(const fs::path& sim, const fs::path& unit, const fs::path& out) {
  return "calibrate --imu " + (sim / "imu.csv").string() + " --robot-log " +
         (sim / "robot.csv").string() + " --robot " + kRobot.string() + " --sensor " +
         kSensor.string() + " --config " + kConfig.string() + " --unit-calibration " +
         unit.string() + " --out " + out.string();
}

// truth/joints.csv: t_s and the link-side angles q_link_A1..A6 [s, rad], keyed by time in us.
std::map<long long, std::array<double, 6>> read_truth_link_angles(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::map<long long, std::array<double, 6>> out;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      EXPECT_EQ(line.rfind("t_s,q_link_A1_rad,q_link_A2_rad", 0), 0u) << line;
      header = true;
      continue;
    }
    std::istringstream fields(line);
    std::string field;
    std::getline(fields, field, ',');
    const long long t_us = std::llround(std::stod(field) * 1e6);
    std::array<double, 6> q{};
    for (double& v : q) {
      std::getline(fields, field, ',');
      v = std::stod(field);
    }
    out.emplace(t_us, q);
  }
  return out;
}

TEST_F(CalibrateTwoSessions, IdentificationSessionWithTheMountingSessionsFrames) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "two plant runs and identify: Release only";
  const fs::path cal_sim = dir_ / "cal-sim", id_sim = dir_ / "id-sim";
  for (const auto& [scenario, out] : {std::pair{"two-sessions-mounting.yaml", cal_sim},
                                      std::pair{"two-sessions-identification.yaml", id_sim}}) {
    const fs::path log = dir_ / (out.filename().string() + ".log");
    ASSERT_EQ(
        run("simulate --scenario " + (kScenarios / scenario).string() + " --out " + out.string(),
            log),
        0)
        << read_text(log);
  }
  // Same robot, base, mount and unit: the premise of --frames (the scenarios' seed).
  const json cal_truth = json::parse(read_text(cal_sim / "truth" / "frames.json"));
  const json id_truth = json::parse(read_text(id_sim / "truth" / "frames.json"));
  ASSERT_EQ(cal_truth.at("T_S_H"), id_truth.at("T_S_H"));
  ASSERT_EQ(cal_truth.at("T_R_W"), id_truth.at("T_R_W"));
  ASSERT_EQ(read_text(cal_sim / "truth" / "sensor_errors.yaml"),
            read_text(id_sim / "truth" / "sensor_errors.yaml"));

  // The unit's lab calibration: scale factors and misalignments; biases left to the bundle.
  ims::SensorErrorModel lab =
      ims::load_sensor_error_model(cal_sim / "truth" / "sensor_errors.yaml");
  lab.gyro.bias.setZero();
  lab.acc.bias.setZero();
  const fs::path unit = dir_ / "unit-calibration.yaml";
  std::ofstream(unit) << ims::to_yaml(lab);

  // Session 1: the frames. 0 = pass/warn, 1 = verdict fail with the outputs written.
  const fs::path cal = dir_ / "cal";
  int status = run(calibrate_arguments(cal_sim, unit, cal), dir_ / "cal.log");
  ASSERT_TRUE(status == 0 || status == 1) << read_text(dir_ / "cal.log");
  // Session 2 alone has too few rests for the frames: refused (exit 2).
  EXPECT_EQ(run(calibrate_arguments(id_sim, unit, dir_ / "refused"), dir_ / "refused.log"), 2);
  EXPECT_NE(read_text(dir_ / "refused.log").find("at least 3"), std::string::npos)
      << read_text(dir_ / "refused.log");
  // With the frames of session 1.
  const fs::path id = dir_ / "id";
  status =
      run(calibrate_arguments(id_sim, unit, id) + " --frames " + (cal / "frames.json").string(),
          dir_ / "id.log");
  ASSERT_TRUE(status == 0 || status == 1) << read_text(dir_ / "id.log");
  std::printf("%s", read_text(id / "summary.txt").c_str());
  // The identification program returns home after every single-joint move and every fourth mixed
  // move: the summary says where the positions were corrected (calib/revisited_poses.hpp).
  EXPECT_NE(read_text(id / "summary.txt").find("returns to a pose stood at before"),
            std::string::npos);
  const json cal_frames = json::parse(read_text(cal / "frames.json"));
  const json id_frames = json::parse(read_text(id / "frames.json"));
  const json report = json::parse(read_text(id / "mounting_report.json"));
  // Where the frames came from, and the frames themselves with their sigma, unchanged.
  EXPECT_EQ(id_frames.at("frames_from").at("path"), (cal / "frames.json").string());
  EXPECT_EQ(id_frames.at("frames_from").at("sha256"), sha256_hex_of_file(cal / "frames.json"));
  EXPECT_EQ(id_frames.at("inputs").at("frames").at("sha256"),
            sha256_hex_of_file(cal / "frames.json"));
  // T_S_H held: equal to rounding (the mm/SI conversions on the way in and out: 1e-9 mm, 1e-12).
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(id_frames.at("T_S_H").at("xyz_mm")[k].get<double>(),
                cal_frames.at("T_S_H").at("xyz_mm")[k].get<double>(), 1e-9);
  EXPECT_LT(test_support::quaternion_of(id_frames.at("T_S_H"))
                .angularDistance(test_support::quaternion_of(cal_frames.at("T_S_H"))),
            1e-12);
  // T_R_W's rotation goes through R_W_R and back: equal to rounding (1e-12).
  EXPECT_LT(test_support::quaternion_of(id_frames.at("T_R_W"))
                .angularDistance(test_support::quaternion_of(cal_frames.at("T_R_W"))),
            1e-12);
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 9; ++c)
      EXPECT_EQ(id_frames.at("covariance_si").at(r).at(c),
                cal_frames.at("covariance_si").at(r).at(c));
  EXPECT_TRUE(id_frames.at("solver").at("converged").get<bool>());
  bool previous_frames_check = false;
  for (const auto& check : report.at("checks"))
    previous_frames_check |= check.at("name") == "previous_frames";
  EXPECT_TRUE(previous_frames_check) << report.at("checks").dump(1);
  // The clock offset of session 2 (37.1 ms in the scenario, session 1 has 12.3 ms).
  const double dt_true_ms = id_truth.at("imu_clock_offset_s").get<double>() * 1e3;
  std::printf("time offset: %.4f ms (truth %.4f ms)\n",
              id_frames.at("time_offset_ms").get<double>(), dt_true_ms);
  // With session 1's link share of the drives' friction as its prior (it trades against the
  // clock offset; tools/cmd_calibrate.cpp): measured 0.033 ms off (0.098 ms with the default
  // prior 0.5 +- 0.5, the share then found at 0.32 against session 1's 0.06). Bound 0.06 ms: 2
  // of the estimate's own sigma (0.029 ms).
  EXPECT_LT(std::abs(id_frames.at("time_offset_ms").get<double>() - dt_true_ms), 0.06);

  // (a) The chain's joint errors against the truth at the same robot samples.
  const ident::JointErrorLog measured = ident::read_joint_errors_csv(id / "joint_errors.csv");
  const auto truth = read_truth_link_angles(id_sim / "truth" / "joints.csv");
  std::array<double, 6> sq_true{}, sq_error{};
  std::size_t matched = 0;
  // The measured log with the true link angles in place of the chain's (same rows and runs).
  ident::JointErrorLog truth_on_measured_rows = measured;
  for (std::size_t k = 0; k < measured.sample_count(); ++k) {
    const auto it = truth.find(std::llround(measured.time_s[k] * 1e6));
    if (it == truth.end()) continue;
    ++matched;
    for (std::size_t j = 0; j < 6; ++j) {
      truth_on_measured_rows.q_measured_rad[j][k] = it->second[j];
      const double e_true = measured.q_desired_rad[j][k] - it->second[j];
      const double e_ims = measured.q_desired_rad[j][k] - measured.q_measured_rad[j][k];
      sq_true[j] += e_true * e_true;
      sq_error[j] += (e_ims - e_true) * (e_ims - e_true);
    }
  }
  ASSERT_EQ(matched, measured.sample_count()) << "robot samples without a truth sample";
  std::printf(
      "joint errors of the identification session by the two-session chain, %zu samples; "
      "RMS (true | measurement error) [mrad]:",
      matched);
  for (std::size_t j = 0; j < 6; ++j)
    std::printf(" A%zu %.3f | %.3f", j + 1, std::sqrt(sq_true[j] / double(matched)) * 1e3,
                std::sqrt(sq_error[j] / double(matched)) * 1e3);
  std::printf("\n");
  // The measurement must resolve the signal it is taken for: on the primary joints A1..A3 (issue
  // 5's goal) the error below the true joint errors' RMS (a chain whose error is as large as the
  // signal identifies noise). A4..A6 are printed only: their joint errors are small (A4, A6
  // without play) and the chain's error is of their size (measured: A6 0.22 mrad against 0.49; 0.75
  // before the correction at the revisited poses).
  for (std::size_t j = 0; j < 3; ++j) EXPECT_LT(sq_error[j], sq_true[j]) << "A" << j + 1;

  // (b) identify on the chain's joint errors.
  const ims::EarthModel earth(
      sim::load_scenario(kScenarios / "two-sessions-identification.yaml").site);
  const double g = earth.gravity_W(Eigen::Vector3d::Zero()).norm();
  const fs::path ident_out = dir_ / "ident";
  // Gravity to 17 digits: the in-process identification below takes the same number.
  std::ostringstream gravity;
  gravity.precision(17);
  gravity << -g;
  ASSERT_EQ(run("identify --joint-errors " + (id / "joint_errors.csv").string() + " --config " +
                    kIdentConfig.string() + " --robot " + kRobot.string() + " --gravity-m-s2 0 0 " +
                    gravity.str() + " --out " + ident_out.string(),
                dir_ / "ident.log"),
            0)
      << read_text(dir_ / "ident.log");
  const json ident_report = json::parse(read_text(ident_out / "identification_report.json"));
  std::map<std::string, double> fit, table_fits;
  for (const auto& joint : ident_report.at("joints")) {
    double sum = 0.0, rows = 0.0;
    std::string chosen;  // the chosen order and dead time are reported
    for (const auto& cell : joint.at("cells")) {
      if (cell.at("status") != "identified") continue;
      EXPECT_TRUE(cell.contains("chosen")) << joint.at("joint");
      if (cell.contains("chosen"))
        chosen += " na " + cell.at("chosen").at("na").dump() + " nb " +
                  cell.at("chosen").at("nb").dump() + " d " +
                  cell.at("chosen").at("dead_time").dump();
      if (!cell.contains("validation")) continue;
      const auto& v = cell.at("validation").at("joint_error_fit_percent");
      const double n = cell.at("validation_rows").get<double>();
      if (v.is_null() || n == 0.0) continue;
      sum += v.get<double>() * n;
      rows += n;
    }
    const std::string name = joint.at("joint");
    fit[name] = rows > 0.0 ? sum / rows : std::nan("");
    // The whole table's figure (cells blended as the precontrol applies them), recorded beside
    // the cells' weighted one for the results page; not asserted here.
    const json& table_fit = joint.at("table_joint_error_fit_percent");
    table_fits[name] = table_fit.is_number() ? table_fit.get<double>() : std::nan("");
    std::printf(
        "%s (two-session chain): held-out joint-error fit %.1f %% (cells weighted), %.1f %% "
        "(table), chosen%s\n",
        name.c_str(), fit[name], table_fits[name], chosen.c_str());
  }
  for (const char* joint : {"A1", "A2", "A3"}) {
    ASSERT_TRUE(fit.count(joint)) << joint;
    EXPECT_TRUE(std::isfinite(fit[joint])) << joint;
  }

  // (c) The same identification in-process (eval::identify_table: the config and the model
  // torque identify was given), which must give identify's figures, and its models judged
  // against the TRUE joint errors of the same held-out rows (eval::replay_held_out_fits): the
  // models' own error, without the measurement's in the held-out target.
  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(kIdentConfig));
  eval::ModelTorqueSource torque_model;
  torque_model.robot = calib::load_robot_description(kRobot);
  torque_model.gravity_in_base_m_s2 = Eigen::Vector3d(0.0, 0.0, -g);
  const eval::IdentifiedTable table =
      eval::identify_table(measured, config, (id / "joint_errors.csv").string(), &torque_model);
  for (const std::string& failed : table.failed_joints) {
    std::printf("not identified: %s\n", failed.c_str());
    // A6's measurement error is of its signal's size (above): it may fail; A1..A3 must not.
    for (const char* primary : {"A1:", "A2:", "A3:"})
      EXPECT_NE(failed.rfind(primary, 0), 0u) << failed;
  }
  const std::vector<double> against_truth =
      eval::replay_held_out_fits(table, truth_on_measured_rows, config, &torque_model);
  ASSERT_EQ(against_truth.size(), table.joints.size());
  for (std::size_t j = 0; j < table.joints.size(); ++j) {
    const std::string& name = table.joints[j].parameters.name;
    const double in_process = eval::summarize_fit(table.joints[j]).joint_error_fit_percent;
    std::printf(
        "%s (two-session chain): held-out joint-error fit %.1f %% against the IMS-measured "
        "error, %.1f %% against the true error\n",
        name.c_str(), in_process, against_truth[j]);
    // The same data, config, gravity and code as identify, whose JSON numbers round-trip:
    // equal but for the order of the sums (1e-9 %-points).
    ASSERT_TRUE(fit.count(name)) << name;
    EXPECT_EQ(std::isfinite(in_process), std::isfinite(fit[name])) << name;
    if (std::isfinite(fit[name])) {
      EXPECT_NEAR(in_process, fit[name], 1e-9) << name;
    }
  }
  // Measured against the truth: A1 96.1, A2 95.2, A3 93.1 % (against the IMS-measured errors
  // 96.2, 95.1, 94.0 %). Asserted 3 %-points below, as IdentifiedFromTheImsChain (the chain is
  // deterministic; the margin covers other platforms' rounding through the order selection).
  // The goal, >= 90 % per primary joint both ways, asserted at the goal itself: met by
  // 3.1 %-points or more.
  const std::array<double, 3> measured_against_truth = {96.1, 95.2, 93.1};
  for (std::size_t j = 0; j < 3; ++j) {
    const std::string& joint = table.joints[j].parameters.name;
    test_support::record_figure(joint + "_fit_against_truth_percent", against_truth[j]);
    test_support::record_figure(joint + "_fit_against_measured_percent", fit[joint]);
    test_support::record_figure(joint + "_table_fit_against_measured_percent", table_fits[joint]);
    EXPECT_GE(against_truth[j], measured_against_truth[j] - 3.0) << table.joints[j].parameters.name;
    EXPECT_GE(against_truth[j], 90.0) << table.joints[j].parameters.name;
    EXPECT_GE(fit[table.joints[j].parameters.name], 90.0) << table.joints[j].parameters.name;
  }
}

// Refusals of --frames, before the records are read (file and field named, exit 2, nothing
// written). The base is a minimal frames.json with the fields --frames reads (datasets/FORMAT.md
// §16.2: imscal-frames, robot, T_R_W, T_S_H, parameter_names, covariance_si; the link share in
// estimates is optional), which passes the checks (the run then fails later for other reasons or
// not at all: only the refusal's message is checked); each case changes one field. The record is
// the shipped campaign's (kr16).
TEST_F(CalibrateTwoSessions, FramesOfAnotherRobotVersionOrWithNaNAreRefused) {
  json base = {{"imscal-frames", 1},
               {"robot", "kr16"},
               {"T_R_W", {{"xyz_mm", {0, 0, 0}}, {"quaternion_wxyz", {1, 0, 0, 0}}}},
               {"T_S_H", {{"xyz_mm", {1, 2, -120}}, {"quaternion_wxyz", {1, 0, 0, 0}}}},
               {"parameter_names",
                {"R_W_R.east", "R_W_R.north", "R_W_R.up", "R_S_H.x", "R_S_H.y", "R_S_H.z",
                 "p_S_H.x", "p_S_H.y", "p_S_H.z"}}};
  json covariance = json::array();
  for (int r = 0; r < 9; ++r) {
    json row = json::array();
    for (int c = 0; c < 9; ++c) row.push_back(r == c ? 1e-10 : 0.0);
    covariance.push_back(row);
  }
  base["covariance_si"] = covariance;
  const fs::path campaign = kSource / "datasets" / "campaign";
  struct Case {
    const char* name;
    std::function<void(json&)> change;
    const char* field;
    const char* words;
  };
  const std::vector<Case> cases = {
      {"another robot", [](json& j) { j["robot"] = "kr6"; }, "robot", "'kr6'"},
      {"no robot", [](json& j) { j.erase("robot"); }, "robot", "which robot"},
      {"unknown version", [](json& j) { j["imscal-frames"] = 2; }, "imscal-frames",
       "unknown format version 2"},
      {"not a frames file", [](json& j) { j.erase("imscal-frames"); }, "imscal-frames",
       "not an imscal frames.json"},
      {"NaN in T_S_H (written as null)", [](json& j) { j["T_S_H"]["xyz_mm"][1] = nullptr; },
       "T_S_H.xyz_mm[1]", "not a finite number"},
      {"NaN in the rotation of T_R_W", [](json& j) { j["T_R_W"]["quaternion_wxyz"][2] = nullptr; },
       "T_R_W.quaternion_wxyz[2]", "not a finite number"},
      {"NaN in the covariance", [](json& j) { j["covariance_si"][4][4] = nullptr; },
       "covariance_si[4][4]", "not a finite number"},
      {"other covariance layout", [](json& j) { j["parameter_names"][0] = "gyro_bias.x"; },
       "parameter_names", "R_W_R.east"},
      {"NaN link share (optional, but then valid)",
       [](json& j) {
         j["estimates"] = {{{"name", "link_share (of the drives' viscous friction)"},
                            {"value", {nullptr}},
                            {"sigma", {0.05}}}};
       },
       "estimates[0].value[0]", "not a finite number"},
      {"link share without a positive sigma",
       [](json& j) {
         j["estimates"] = {{{"name", "link_share (of the drives' viscous friction)"},
                            {"value", {0.1}},
                            {"sigma", {0.0}}}};
       },
       "estimates[0].sigma[0]", "not a positive 1-sigma"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    json frames = base;
    c.change(frames);
    const fs::path file = dir_ / "frames.json", out = dir_ / "out";
    std::ofstream(file) << frames.dump(1);
    const fs::path log = dir_ / "refused.log";
    EXPECT_EQ(
        run("calibrate --imu " + (campaign / "imu.csv").string() + " --robot-log " +
                (campaign / "robot.csv").string() + " --robot " + kRobot.string() + " --sensor " +
                kSensor.string() + " --frames " + file.string() + " --out " + out.string(),
            log),
        2);
    const std::string text = read_text(log);
    EXPECT_NE(text.find(file.string()), std::string::npos) << text;
    EXPECT_NE(text.find(std::string("field '") + c.field + "'"), std::string::npos) << text;
    EXPECT_NE(text.find(c.words), std::string::npos) << text;
    EXPECT_FALSE(fs::exists(out / "frames.json"));
  }
}

}  // namespace
}  // namespace imscal
