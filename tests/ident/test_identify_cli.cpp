// `imscal identify` end to end on a generated joint_errors.csv: two simulated joints with known
// backlash, a time gap (two runs); the outputs must load, hold the backlash within 10 % and fit
// the held-out data; existing outputs are refused without --force; a bad config is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "core/progress_channel.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "tests/ident/joint_simulation.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace {
namespace ident = imscal::ident;
using imscal::test_support::read_text;
using imscal::test_support::SimulatedJoint;

constexpr double kDt = 0.002;
const double kTrueL[] = {0.8e-3, 1.5e-3};

class IdentifyCli : public imscal::test_support::ScratchDirTest {
 protected:
  void SetUp() override {
    ScratchDirTest::SetUp();
    // Lighter under the sanitizers (IMSCAL_SANITIZED): fewer samples, still > 40 reversals.
    const std::size_t samples = std::getenv("IMSCAL_SANITIZED") ? 30000 : 50000;
    ident::JointErrorLog log;
    log.robot = "kr16";
    log.cycle_s = kDt;
    log.source = "test_identify_cli simulation";
    log.joint_names = {"A1", "A2"};
    log.q_desired_rad.resize(2);
    log.q_measured_rad.resize(2);
    log.q_internal_rad.resize(2);
    for (std::size_t j = 0; j < 2; ++j) {
      SimulatedJoint joint;
      joint.backlash_l_rad = kTrueL[j];
      joint.pole_modulus = j == 0 ? 0.92 : 0.9;
      joint.dead_time = j == 0 ? 2 : 1;
      joint.measurement_noise_rad = 1e-5;
      joint.offset_rad = j == 0 ? 0.3 : -0.6;
      // Two runs of the same motion, 1 s apart (a gap in the time stamps).
      for (int run = 0; run < 2; ++run) {
        const auto r = imscal::test_support::simulate_joint(joint, samples / 2, kDt, 10 * j + run,
                                                            run * (samples / 2 * kDt + 1.0));
        if (j == 0) {
          log.time_s.insert(log.time_s.end(), r.t_s.begin(), r.t_s.end());
          log.payload_kg.insert(log.payload_kg.end(), r.t_s.size(), 5.0);
        }
        log.q_desired_rad[j].insert(log.q_desired_rad[j].end(), r.q_desired.begin(),
                                    r.q_desired.end());
        log.q_measured_rad[j].insert(log.q_measured_rad[j].end(), r.q_measured.begin(),
                                     r.q_measured.end());
        log.q_internal_rad[j].insert(log.q_internal_rad[j].end(), r.q_linear.begin(),
                                     r.q_linear.end());
      }
    }
    ident::write_joint_errors_csv(dir_ / "joint_errors.csv", log);
    // The shipped config of the paper's method (operating-point cells, eq. 3's backlash) with a
    // smaller sweep (the test's joints are of order 2). The default's inverse form with the
    // model torque needs a robot's motion: tests/eval/test_verification.cpp.
    std::string config =
        read_text(std::string(IMSCAL_SOURCE_DIR) + "/datasets/identification/ident-paper.yaml");
    const auto replace = [&](const std::string& from, const std::string& to) {
      const auto at = config.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      config.replace(at, from.size(), to);
    };
    replace("max_speed_deg_s: [156, 156, 156, 330, 330, 615]", "max_speed_deg_s: [60, 60]");
    replace("na: [1, 32]", "na: [1, 4]");
    replace("nb: [1, 32]", "nb: [1, 4]");
    replace("settle_s: 0.05", "settle_s: 0.08");
    std::ofstream(dir_ / "ident.yaml") << config;
  }

  int identify(const std::string& extra = "", const std::string& config = "ident.yaml") {
    return imscal::test_support::run_imscal(
        "identify --joint-errors " + (dir_ / "joint_errors.csv").string() + " --config " +
            (dir_ / config).string() + " --out " + (dir_ / "out").string() + " " + extra,
        dir_ / "log.txt");
  }
  std::string log_text() { return read_text(dir_ / "log.txt"); }
};

TEST_F(IdentifyCli, WritesALoadableTableThatFitsHeldOutData) {
  ASSERT_EQ(identify(), 0) << log_text();
  const ident::ParameterTable table = ident::read_parameters_json(dir_ / "out" / "parameters.json");
  EXPECT_EQ(table.robot, "kr16");
  EXPECT_EQ(table.sample_time_s, kDt);
  EXPECT_EQ(table.source.sha256, ident::file_sha256_hex(dir_ / "joint_errors.csv"));
  ASSERT_EQ(table.joints.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    const auto& joint = table.joints[j];
    EXPECT_TRUE(joint.backlash_identified);
    // The brief's goal for backlash: within 10 %.
    EXPECT_NEAR(joint.backlash_l_rad, kTrueL[j], 0.1 * kTrueL[j]) << joint.name;
    ASSERT_EQ(joint.cells.size(), 6u);  // 3 speed bands x 2 payload bands
    int identified = 0;
    for (const auto& cell : joint.cells) {
      if (cell.status != ident::CellStatus::kIdentified) {
        EXPECT_FALSE(cell.reason.empty());
        continue;
      }
      ++identified;
      // The goal for held-out simulation fit of a joint: >= 90 %.
      EXPECT_GE(cell.figures.simulation_fit_percent, 90.0) << joint.name << " cell";
      EXPECT_LT(cell.figures.spectral_radius, 1.0);
    }
    // Payload 5 kg of 16: payload band 1 is empty; the motion (60 deg/s max) reaches speed bands
    // 0 and 1 at least.
    EXPECT_GE(identified, 2);
    EXPECT_EQ(joint.cells[1].status, ident::CellStatus::kFilled);
  }
  // The report: chosen structures with criterion curves, validation tests, backlash.
  std::ifstream in(dir_ / "out" / "identification_report.json");
  const auto report = nlohmann::json::parse(in);
  ASSERT_EQ(report["joints"].size(), 2u);
  const auto& cell0 = report["joints"][0]["cells"][0];
  EXPECT_TRUE(cell0.contains("criterion_curves"));
  EXPECT_EQ(cell0["criterion_curves"]["over_na"].size(), 4u);
  EXPECT_TRUE(cell0["validation"]["residual_whiteness"].contains("band"));
  EXPECT_TRUE(report["joints"][1]["cells"][1].contains("reason"));
  EXPECT_EQ(report["segments"], 2);
  // CSV: header + 2 joints x 6 cells.
  std::ifstream csv(dir_ / "out" / "parameters.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 13);

  // Outputs exist: refused without --force (exit 2, files untouched), accepted with it.
  const auto before = std::filesystem::last_write_time(dir_ / "out" / "parameters.json");
  EXPECT_EQ(identify(), 2) << log_text();
  EXPECT_NE(log_text().find("--force"), std::string::npos);
  EXPECT_EQ(std::filesystem::last_write_time(dir_ / "out" / "parameters.json"), before);
  EXPECT_EQ(identify("--force"), 0) << log_text();
}

// A joint that never moved cannot be identified; the run still succeeds, that joint gets the
// neutral model (pass-through: zero correction) with the reason, the others their models.
TEST_F(IdentifyCli, JointThatCannotBeIdentifiedGetsTheNeutralModel) {
  ident::JointErrorLog log = ident::read_joint_errors_csv(dir_ / "joint_errors.csv");
  log.joint_names.push_back("A3");
  log.q_desired_rad.emplace_back(log.sample_count(), 0.25);  // standing still
  log.q_measured_rad.emplace_back(log.sample_count(), 0.2501);
  log.q_internal_rad.emplace_back(log.sample_count(), 0.25);
  std::filesystem::remove(dir_ / "joint_errors.csv");
  ident::write_joint_errors_csv(dir_ / "joint_errors.csv", log);
  std::string config = read_text(dir_ / "ident.yaml");
  const auto at = config.find("max_speed_deg_s: [60, 60]");
  ASSERT_NE(at, std::string::npos);
  config.replace(at, 25, "max_speed_deg_s: [60, 60, 60]");
  std::ofstream(dir_ / "three-joints.yaml") << config;

  ASSERT_EQ(identify("", "three-joints.yaml"), 0) << log_text();
  EXPECT_NE(log_text().find("A3: not identified"), std::string::npos) << log_text();
  const ident::ParameterTable table = ident::read_parameters_json(dir_ / "out" / "parameters.json");
  ASSERT_EQ(table.joints.size(), 3u);
  EXPECT_TRUE(table.joints[0].backlash_identified);  // A1 keeps its model
  const auto& neutral = table.joints[2];
  EXPECT_EQ(neutral.name, "A3");
  EXPECT_FALSE(neutral.backlash_identified);
  ASSERT_EQ(neutral.cells.size(), 1u);
  EXPECT_EQ(neutral.cells[0].status, ident::CellStatus::kNeutral);
  EXPECT_FALSE(neutral.cells[0].reason.empty());
}

// The progress channel (core/progress_channel.hpp): with the variable set, as `imscal run` sets
// it for its stages, each finished joint is one progress line, the last at 1; without it, none.
TEST_F(IdentifyCli, ReportsEachJointThroughTheProgressChannelWhenAsked) {
  ASSERT_EQ(identify(), 0) << log_text();
  EXPECT_EQ(log_text().find("imscal-progress"), std::string::npos) << log_text();
  ::setenv(imscal::kProgressChannelVariable, "1", 1);
  const int code = identify("--force");
  ::unsetenv(imscal::kProgressChannelVariable);
  ASSERT_EQ(code, 0) << log_text();
  std::vector<double> fractions;
  std::istringstream lines(log_text());
  for (std::string line; std::getline(lines, line);)
    if (const auto report = imscal::parse_progress_line(line)) {
      EXPECT_EQ(report->stage, "joints");
      fractions.push_back(report->fraction);
    }
  // The start (0) and one line per joint: 0, 1/2, 1.
  ASSERT_EQ(fractions.size(), 3u) << log_text();
  EXPECT_EQ(fractions.front(), 0.0);
  EXPECT_DOUBLE_EQ(fractions[1], 0.5);
  EXPECT_EQ(fractions.back(), 1.0);
}

// A log in which no joint moved: a table of neutral models corrects nothing, so identify fails
// the check (exit 1), names the reason per joint and writes none of its outputs.
TEST_F(IdentifyCli, NoJointIdentifiedIsAFailedCheckWithoutOutput) {
  ident::JointErrorLog log = ident::read_joint_errors_csv(dir_ / "joint_errors.csv");
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    std::fill(log.q_desired_rad[j].begin(), log.q_desired_rad[j].end(), 0.25);
    std::fill(log.q_internal_rad[j].begin(), log.q_internal_rad[j].end(), 0.25);
    std::fill(log.q_measured_rad[j].begin(), log.q_measured_rad[j].end(), 0.2501);
  }
  std::filesystem::remove(dir_ / "joint_errors.csv");
  ident::write_joint_errors_csv(dir_ / "joint_errors.csv", log);
  EXPECT_EQ(identify(), 1) << log_text();
  EXPECT_NE(log_text().find("no joint could be identified"), std::string::npos) << log_text();
  EXPECT_NE(log_text().find("joint A2:"), std::string::npos) << log_text();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out" / "parameters.json"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out" / "identification_report.json"));
}

// A '# source:' line in Latin-1 (not UTF-8): the outputs are written, the invalid byte as U+FFFD,
// with a warning naming the output, instead of a JSON library error after all the work.
TEST_F(IdentifyCli, LatinOneSourceLineIsWrittenAsReplacementCharacter) {
  ident::JointErrorLog log = ident::read_joint_errors_csv(dir_ / "joint_errors.csv");
  log.source =
      "Messung in der Halle S\xfc"
      "d";
  std::filesystem::remove(dir_ / "joint_errors.csv");
  ident::write_joint_errors_csv(dir_ / "joint_errors.csv", log);
  ASSERT_EQ(identify(), 0) << log_text();
  EXPECT_NE(log_text().find("not valid UTF-8"), std::string::npos) << log_text();
  EXPECT_TRUE(std::filesystem::exists(dir_ / "out" / "identification_report.json"));
  const ident::ParameterTable table = ident::read_parameters_json(dir_ / "out" / "parameters.json");
  EXPECT_EQ(table.source.description,
            "Messung in der Halle S\xef\xbf\xbd"
            "d");  // U+FFFD
}

// A file name that is not UTF-8 (a legacy encoding): the outputs are written, the name recorded
// with U+FFFD and a warning, instead of a JSON library error after all the work. The console
// gives each joint's fit as the table is applied beside the cells' own, labelled as such.
TEST_F(IdentifyCli, NonUtf8FileNameIsWrittenAndTheTablesFitIsPrinted) {
  const std::filesystem::path latin = dir_ / "joint_errors_\xe9t\xe9.csv";
  std::filesystem::copy_file(dir_ / "joint_errors.csv", latin);
  ASSERT_EQ(imscal::test_support::run_imscal("identify --joint-errors '" + latin.string() +
                                                 "' --config " + (dir_ / "ident.yaml").string() +
                                                 " --out " + (dir_ / "out").string(),
                                             dir_ / "log.txt"),
            0)
      << log_text();
  EXPECT_NE(log_text().find("is not valid UTF-8; its invalid bytes are written as U+FFFD"),
            std::string::npos)
      << log_text();
  const std::string report = read_text(dir_ / "out" / "identification_report.json");
  EXPECT_NE(report.find("joint_errors_\xef\xbf\xbdt\xef\xbf\xbd.csv"), std::string::npos);
  EXPECT_NE(log_text().find("A1 table: held-out joint-error fit"), std::string::npos) << log_text();
  EXPECT_NE(log_text().find("cell's own held-out fit"), std::string::npos) << log_text();
}

// Plausibility against the record: orders a short record cannot fit (every cell would fit from
// no rows and correct nothing) and a payload far above the robot's rating are refused (exit 2),
// naming the field, before any output.
TEST_F(IdentifyCli, OrdersBeyondTheRecordAndAbsurdPayloadRefused) {
  ident::JointErrorLog log = ident::read_joint_errors_csv(dir_ / "joint_errors.csv");
  const std::size_t keep = 150;  // one segment of 150 samples
  log.time_s.resize(keep);
  log.payload_kg.resize(keep);
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    log.q_desired_rad[j].resize(keep);
    log.q_measured_rad[j].resize(keep);
    log.q_internal_rad[j].resize(keep);
  }
  std::filesystem::remove(dir_ / "joint_errors.csv");
  ident::write_joint_errors_csv(dir_ / "joint_errors.csv", log);
  std::ofstream(dir_ / "long.yaml")
      << "imscal-identification-config: 1\n"
         "joints: {max_speed_deg_s: [60, 60], nominal_payload_kg: 16}\n"
         "order: {na: [1, 64], nb: [1, 64], dead_time: [0, 8]}\n";
  EXPECT_EQ(identify("", "long.yaml"), 2) << log_text();
  EXPECT_NE(log_text().find("long.yaml:3: field 'order'"), std::string::npos) << log_text();
  EXPECT_NE(log_text().find("has 150"), std::string::npos) << log_text();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out"));

  log.payload_kg.assign(keep, 5000.0);
  std::filesystem::remove(dir_ / "joint_errors.csv");
  ident::write_joint_errors_csv(dir_ / "joint_errors.csv", log);
  EXPECT_EQ(identify(), 2) << log_text();
  EXPECT_NE(log_text().find("field 'payload_kg': payload 5000 kg"), std::string::npos)
      << log_text();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out"));
}

// Every regular file below `folder` (relative path -> content).
std::map<std::string, std::string> files_below(const std::filesystem::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(folder))
    if (e.is_regular_file())
      files[std::filesystem::relative(e.path(), folder).string()] = read_text(e.path());
  return files;
}

// All or nothing: a rerun whose writes fail leaves the earlier run's outputs exactly as they
// were, and says which output and why. A full disk is stood in for by a file-size limit
// (RLIMIT_FSIZE, SIGXFSZ ignored: a write beyond it fails with EFBIG, as ENOSPC would); a commit
// that cannot replace an output by a folder of that name.
TEST_F(IdentifyCli, AFailingWriteLeavesTheEarlierOutputsAsTheyWere) {
  ASSERT_EQ(identify(), 0) << log_text();
  const auto out = dir_ / "out";
  const auto before = files_below(out);
  ASSERT_EQ(before.size(), 3u);  // identification_report.json, parameters.csv, parameters.json
  // 16 KiB (ulimit counts 512-byte blocks in sh): smaller than the report, the first file written.
  const std::string limited = "sh -c 'trap \"\" XFSZ; ulimit -f 32; " + std::string(IMSCAL_BINARY) +
                              " identify --joint-errors " + (dir_ / "joint_errors.csv").string() +
                              " --config " + (dir_ / "ident.yaml").string() + " --out " +
                              out.string() + " --force; echo exit=$?' 2>&1 | cat > " +
                              (dir_ / "log.txt").string();
  ASSERT_EQ(std::system(limited.c_str()), 0);
  EXPECT_NE(log_text().find("exit=3"), std::string::npos) << log_text();
  EXPECT_NE(log_text().find("File too large"), std::string::npos) << log_text();
  EXPECT_NE(log_text().find((out / "identification_report.json").string()), std::string::npos)
      << log_text();
  EXPECT_EQ(log_text().find(".imscal-staging-"), std::string::npos) << log_text();
  EXPECT_EQ(files_below(out), before);  // no staging copy left either

  // parameters.json's name taken by a folder: refused before any output is replaced.
  std::filesystem::remove(out / "parameters.json");
  std::filesystem::create_directories(out / "parameters.json" / "kept");
  EXPECT_EQ(identify("--force"), 2) << log_text();
  EXPECT_NE(log_text().find("parameters.json: is a folder"), std::string::npos) << log_text();
  auto expected = before;
  expected.erase("parameters.json");
  EXPECT_EQ(files_below(out), expected);
}

TEST_F(IdentifyCli, BadConfigRefusedWithoutOutput) {
  std::ofstream(dir_ / "bad.yaml")
      << "imscal-identification-config: 1\n"
         "joints: {max_speed_deg_s: [60, 60], nominal_payload_kg: 16}\n"
         "order: {na: [1, 4], nb: [1, 4], dead_tme: [0, 2]}\n";
  EXPECT_EQ(identify("", "bad.yaml"), 2);
  EXPECT_NE(log_text().find("dead_tme"), std::string::npos) << log_text();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out" / "parameters.json"));
  // A config for the wrong number of joints.
  std::ofstream(dir_ / "three.yaml")
      << "imscal-identification-config: 1\n"
         "joints: {max_speed_deg_s: [60, 60, 60], nominal_payload_kg: 16}\n";
  EXPECT_EQ(identify("", "three.yaml"), 2);
  EXPECT_NE(log_text().find("3 maximum speeds"), std::string::npos) << log_text();
}

}  // namespace
