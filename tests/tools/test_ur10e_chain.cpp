// The lab's chain on the second robot family, the UR10e (no spherical wrist: the UR-class
// inverse kinematics in calibrate and in the IMS chain that measures the verified paths), from
// raw simulated records, with only the nominal robot (datasets/robots/ur10e.urdf and its side
// file) handed to the chain; the plants deviate from it (datasets/scenarios/ur10e-*.yaml).
//  - Campaign: `imscal simulate --scenario ur10e-campaign`, then `imscal run` with the shipped
//    datasets/campaign-ur10e configs: validate -> calibrate -> identify -> verify on the
//    seed-line-like line at the workspace edge.
//  - Two sessions: simulate ur10e-mounting and ur10e-identification -> calibrate ->
//    calibrate --frames -> identify -> verify on ur10e-seed-line and the ISO 9283 set at 100 %.
// The reductions of the maximum path deviation are checked on the plant's true path (the
// simulator's truth) and as the IMS chain measures it. Measured (Release): campaign line
// 1.94 -> 0.22 mm as measured (-88.6 %), 1.91 -> 0.175 mm true (-90.8 %); two sessions, 1 cycle:
// line 11.30 -> 0.57 mm (-94.9 % measured, -95.0 % true), ISO 100 % 8.35 -> 0.66 mm (-92.1 %
// measured, -92.7 % true). Release only (~20 s and ~80 s here; 5-10x under the sanitizers).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
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

using Ur10eChain = imscal::test_support::ScratchDirTest;

const fs::path kDatasets = fs::path(IMSCAL_SOURCE_DIR) / "datasets";

struct Reduction {
  double before_mm = 0, after_mm = 0, measured_percent = 0, true_percent = 0;
};

Reduction reduction_of(const fs::path& verification_json) {
  const nlohmann::json v = nlohmann::json::parse(read_text(verification_json));
  const nlohmann::json& before = v.at("cases").at(0);
  const nlohmann::json& after = v.at("cases").at(1);
  EXPECT_EQ(before.at("case"), "uncompensated");
  EXPECT_EQ(after.at("case"), "compensated");
  EXPECT_TRUE(after.at("precontrol_events").empty()) << after.at("precontrol_events").dump();
  return {before.at("max_path_deviation_mm"), after.at("max_path_deviation_mm"),
          after.at("reduction_of_max_path_deviation_percent"),
          after.at("true_path").at("reduction_of_max_path_deviation_percent")};
}

void print(const char* what, const Reduction& r) {
  std::printf("%s: %.3f -> %.3f mm, %.1f %% as measured, %.1f %% on the true path\n", what,
              r.before_mm, r.after_mm, r.measured_percent, r.true_percent);
}

void simulate(const std::string& scenario, const fs::path& out, const fs::path& log) {
  ASSERT_EQ(run_imscal("simulate --scenario " + scenario + " --out " + out.string(), log), 0)
      << read_text(log);
}

TEST_F(Ur10eChain, CampaignThroughImscalRun) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only (see the file's comment)";
  ASSERT_NO_FATAL_FAILURE(simulate("ur10e-campaign", dir_ / "sim", dir_ / "sim.log"));
  const fs::path campaign = kDatasets / "campaign-ur10e";
  const fs::path config = dir_ / "run.yaml";
  std::ofstream(config) << "imscal-run-config: 1\n"
                        << "inputs: {imu: sim/imu.csv, robot_log: sim/robot.csv}\n"
                        << "validate: {robot: ur10e, min_overlap_s: 30}\n"
                        << "calibrate: {config: " << (campaign / "calibrate.yaml").string() << "}\n"
                        << "identify: {config: " << (campaign / "identify.yaml").string()
                        << ", robot: " << (kDatasets / "robots" / "ur10e.urdf").string() << "}\n"
                        << "verify: {scenarios: [" << (campaign / "verify-line.yaml").string()
                        << "], cycles: 3}\n";
  const fs::path out = dir_ / "out";
  // Exit 0: every stage ok, the mounting verdict included (a `warn` or `fail` would be 1).
  ASSERT_EQ(run_imscal("run " + config.string() + " --out " + out.string(), dir_ / "run.log"), 0)
      << read_text(dir_ / "run.log");
  EXPECT_NE(read_text(out / "calibrate" / "summary.txt").find("VERDICT: pass"), std::string::npos);
  const Reduction line = reduction_of(out / "verify" / "ur10e-campaign-line" / "verification.json");
  print("UR10e campaign, seed-line-like line", line);
  // Measured 90.8 % true, 88.6 % through the IMS chain; 5 pp of margin for a changed draw. The
  // stiff campaign plant's line deviates by only ~1.9 mm, so the IMS chain's own scatter (~0.1 mm,
  // the report's "about the mean") is ~5 % of it: measured and true agree within 5 pp.
  EXPECT_GT(line.true_percent, 85.0);
  EXPECT_GT(line.measured_percent, 83.0);
  EXPECT_NEAR(line.measured_percent, line.true_percent, 5.0);
}

TEST_F(Ur10eChain, TwoSessionsCalibrateFramesIdentifyVerify) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only (see the file's comment)";
  for (const char* session : {"mounting", "identification"}) {
    ASSERT_NO_FATAL_FAILURE(simulate(std::string("ur10e-") + session,
                                     dir_ / ("sim-" + std::string(session)),
                                     dir_ / ("sim-" + std::string(session) + ".log")));
  }
  // The unit's lab calibration: the simulated unit's scale factors and misalignments (the
  // sessions share the scenario seed, hence the unit), biases left to the bundle.
  std::string unit = read_text(dir_ / "sim-mounting" / "truth" / "sensor_errors.yaml");
  for (const char* bias : {"  bias_deg_per_h: ", "  bias_ug: "}) {
    const auto at = unit.find(bias);
    ASSERT_NE(at, std::string::npos) << bias;
    const auto end = unit.find('\n', at);
    unit.replace(at, end - at, std::string(bias) + "[0, 0, 0]");
  }
  std::ofstream(dir_ / "unit.yaml") << unit;
  const std::string robot = (kDatasets / "robots" / "ur10e.urdf").string();
  const auto calibrate = [&](const std::string& session, const std::string& extra) {
    const fs::path sim = dir_ / ("sim-" + session);
    return "calibrate --imu " + (sim / "imu.csv").string() + " --robot-log " +
           (sim / "robot.csv").string() + " --robot " + robot + " --sensor " +
           (kDatasets / "sensors" / "navigation-grade.yaml").string() + " --config " +
           (kDatasets / "calibration" / "calibrate-default.yaml").string() +
           " --unit-calibration " + (dir_ / "unit.yaml").string() + extra;
  };
  ASSERT_EQ(
      run_imscal(calibrate("mounting", " --out " + (dir_ / "cal").string()), dir_ / "cal.log"), 0)
      << read_text(dir_ / "cal.log");
  ASSERT_EQ(run_imscal(
                calibrate("identification", " --frames " + (dir_ / "cal" / "frames.json").string() +
                                                " --out " + (dir_ / "calf").string()),
                dir_ / "calf.log"),
            0)
      << read_text(dir_ / "calf.log");
  ASSERT_EQ(
      run_imscal("identify --joint-errors " + (dir_ / "calf" / "joint_errors.csv").string() +
                     " --config " + (kDatasets / "identification" / "ident-ur10e.yaml").string() +
                     " --robot " + robot + " --search-transmission-error-order --out " +
                     (dir_ / "ident").string(),
                 dir_ / "ident.log"),
      0)
      << read_text(dir_ / "ident.log");
  const auto verify = [&](const std::string& scenario, const std::string& segments) {
    const fs::path out = dir_ / ("v-" + scenario);
    EXPECT_EQ(run_imscal("verify --table " + (dir_ / "ident" / "parameters.json").string() +
                             " --scenario " + scenario + segments +
                             " --cycles 1 --no-ablation --out " + out.string(),
                         dir_ / (scenario + ".log")),
              0)
        << read_text(dir_ / (scenario + ".log"));
    return reduction_of(out / scenario / "verification.json");
  };
  const Reduction line = verify("ur10e-seed-line", "");
  const Reduction iso = verify("ur10e-iso9283", " --segments 100%");
  print("UR10e two sessions, seed-line-like line", line);
  print("UR10e two sessions, ISO 9283 at 100 %", iso);
  // Measured 94.9 / 95.0 % (line) and 92.1 / 92.7 % (ISO, measured / true); the KR 16's shipped
  // chain gives 95.2 and 91.8 %. 5 pp of margin.
  EXPECT_GT(line.true_percent, 90.0);
  EXPECT_GT(line.measured_percent, 90.0);
  EXPECT_GT(iso.true_percent, 87.0);
  EXPECT_GT(iso.measured_percent, 87.0);
}

}  // namespace
