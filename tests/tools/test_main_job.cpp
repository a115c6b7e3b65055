// The main job as a new user meets it (README, "The main job"): `imscal run` on the shipped
// default campaign datasets/campaign/run.yaml, end to end (validate -> calibrate -> identify ->
// verify -> diagnose -> report), and the campaign itself regenerated from its scenario.
// Checked against the simulator's truth (regenerated here): the shipped raw files are exactly
// what `imscal simulate --scenario campaign` writes; the calibrated frames and the measured joint
// angles agree with the truth; the parameter table covers every joint; the ISO 9283 figures of
// the verification exist for both cases and the precontrol reduces the path deviation; the
// report carries every section and every figure is drawn in headless Chromium; a second run
// recomputes nothing.
// Runs under the sanitizers too (CI): ~2 min there, ~10 s in Release.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "core/numeric_table.hpp"
#include "core/run_stage.hpp"
#include "core/sha256.hpp"
#include "core/units.hpp"
#include "ident/parameter_table_io.hpp"
#include "tests/support/frames_json.hpp"
#include "tests/support/record_figure.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/browser_check.hpp"
#include "tests/tools/run_campaign.hpp"

using imscal::kRadPerDeg;

namespace {
namespace fs = std::filesystem;
using imscal::test_support::count_of;
using imscal::test_support::quaternion_of;
using imscal::test_support::read_text;
using imscal::test_support::run_imscal;
using nlohmann::json;

const fs::path kCampaign = fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "campaign";

using MainJob = imscal::test_support::ScratchDirTest;

// RMS per joint [rad] of the measured joint angles (calibrate's joint_errors.csv, robot clock)
// against the simulator's link angles (truth/joints.csv), on the samples both have.
std::vector<double> measured_joint_rms_error(const fs::path& joint_errors, const fs::path& truth) {
  const imscal::NumericTable measured = imscal::read_numeric_table(joint_errors);
  const imscal::NumericTable links = imscal::read_numeric_table(truth);
  std::map<long, std::size_t> truth_row;  // time in ms -> row
  for (std::size_t r = 0; r < links.rows(); ++r) truth_row[std::lround(links.at(r, 0) * 1e3)] = r;
  std::vector<std::size_t> measured_column, link_column;
  for (const char* joint : {"A1", "A2", "A3", "A4", "A5", "A6"}) {
    measured_column.push_back(measured.column(fmt::format("q_measured_{}_rad", joint)));
    link_column.push_back(links.column(fmt::format("q_link_{}_rad", joint)));
  }
  std::vector<double> sum(6, 0.0);
  std::size_t n = 0;
  for (std::size_t r = 0; r < measured.rows(); ++r) {
    const auto it = truth_row.find(std::lround(measured.at(r, 0) * 1e3));
    if (it == truth_row.end()) continue;
    ++n;
    for (std::size_t j = 0; j < 6; ++j) {
      const double e = measured.at(r, measured_column[j]) - links.at(it->second, link_column[j]);
      sum[j] += e * e;
    }
  }
  EXPECT_GT(n, 30000u) << "the robot log spans 70 s at 2 ms";
  for (double& s : sum) s = std::sqrt(s / double(std::max<std::size_t>(n, 1)));
  return sum;
}

TEST_F(MainJob, ShippedCampaignRunsEndToEndAgainstItsRegeneratedTruth) {
  // 1. The shipped raw files are what the scenario regenerates, bit for bit (also across
  // compilers: GCC Release and clang with the sanitizers write the same bytes).
  const fs::path sim = dir_ / "sim";
  ASSERT_EQ(run_imscal("simulate --scenario campaign --out " + sim.string(), dir_ / "sim.log"), 0)
      << read_text(dir_ / "sim.log");
  for (const char* file : {"imu.csv", "robot.csv"})
    EXPECT_EQ(imscal::sha256_hex_of_file(sim / file), imscal::sha256_hex_of_file(kCampaign / file))
        << file << " differs from what datasets/campaign/regenerate.sh writes";

  // 2. The main command.
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run_imscal("run " + (kCampaign / "run.yaml").string() + " --out " + out.string(),
                       dir_ / "run.log"),
            0)
      << read_text(dir_ / "run.log");
  for (const char* stage : {"validate", "calibrate", "identify", "verify", "diagnose", "report"}) {
    const json record = json::parse(read_text(out / stage / imscal::kStageRecordName));
    EXPECT_EQ(record.value("status", ""), "ok") << stage;
  }

  // Frames against the truth. Tolerances: the accuracy goals for T_S_H (0.005 deg, 0.05 mm;
  // measured 0.0026 deg, 0.021 mm) and the tilt of R in W (0.005 deg; measured 0.003 deg).
  // The heading of R in W is gyrocompass-limited (1-sigma 0.16 deg; measured 0.22 deg off): 3
  // sigma of the run's own estimate.
  const json frames = json::parse(read_text(out / "calibrate" / "frames.json"));
  const json truth = json::parse(read_text(sim / "truth" / "frames.json"));
  const json mounting = json::parse(read_text(out / "calibrate" / "mounting_report.json"));
  EXPECT_NE(mounting.at("verdict"), "fail") << mounting.at("reasons").dump(1);
  EXPECT_LT(quaternion_of(frames.at("T_S_H")).angularDistance(quaternion_of(truth.at("T_S_H"))),
            0.005 * kRadPerDeg);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(frames.at("T_S_H").at("xyz_mm").at(i).get<double>(),
                truth.at("T_S_H").at("xyz_m").at(i).get<double>() * 1e3, 0.05);
  const Eigen::Quaterniond q_R_W = quaternion_of(frames.at("T_R_W"));
  const Eigen::Quaterniond q_R_W_true = quaternion_of(truth.at("T_R_W"));
  const Eigen::Vector3d up_R = q_R_W * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up_R.dot(q_R_W_true * Eigen::Vector3d::UnitZ()))),
            0.005 * kRadPerDeg);
  EXPECT_LT(q_R_W.angularDistance(q_R_W_true), 0.5 * kRadPerDeg);

  // Measured joint angles (IMS trajectory + inverse kinematics) against the link truth, printed
  // (RMS 0.030 / 0.045 / 0.059 / 0.040 / 0.038 / 0.035 mrad, A1..A6; 0.13 / 0.31 / 0.28 on A1..A3
  // in an earlier version of the chain); the true joint errors are 0.1-2 mrad. Tolerance 0.5 mrad:
  // a regression of the chain (frames, clock, inverse kinematics) shows as whole milliradians.
  const auto rms = measured_joint_rms_error(out / "calibrate" / "joint_errors.csv",
                                            sim / "truth" / "joints.csv");
  std::printf("main job: measured joint angles against the link truth, RMS [mrad]:");
  for (int j = 0; j < 6; ++j) std::printf(" A%d %.3f", j + 1, rms[j] * 1e3);
  std::printf("\n");
  for (int j = 0; j < 6; ++j) EXPECT_LT(rms[j], 0.5e-3) << "A" << j + 1;
  for (int j = 0; j < 6; ++j)
    imscal::test_support::record_figure(fmt::format("A{}_joint_angle_rms_mrad", j + 1),
                                        rms[j] * 1e3);

  // The parameter table: every joint, from calibrate's joint errors, every cell with a model.
  const auto table = imscal::ident::read_parameters_json(out / "identify" / "parameters.json");
  ASSERT_EQ(table.joints.size(), 6u);
  EXPECT_EQ(table.source.sha256,
            imscal::sha256_hex_of_file(out / "calibrate" / "joint_errors.csv"));
  for (const auto& joint : table.joints) EXPECT_FALSE(joint.cells.empty()) << joint.name;
  EXPECT_TRUE(fs::exists(out / "identify" / "parameters.csv"));

  // ISO 9283 figures with and without the precontrol on the paper's line, printed (10.42 ->
  // 0.93 mm, -91.1 %; 10.31 -> 5.51 mm, -46.5 % with the paper's forward form). A precontrol that
  // no longer helps (< 20 % reduction) is a regression of identify or verify.
  const json verification =
      json::parse(read_text(out / "verify" / "campaign-line" / "verification.json"));
  ASSERT_EQ(verification.at("cases").size(), 2u);
  for (const auto& c : verification.at("cases")) {
    for (const char* figure : {"AT_p_mm", "RT_p_mm", "AV_percent", "max_path_deviation_mm"})
      EXPECT_TRUE(std::isfinite(c.at(figure).get<double>())) << c.at("case") << " " << figure;
  }
  EXPECT_EQ(verification.at("cases")[1].at("case"), "compensated");
  std::printf(
      "main job: campaign line, max path deviation %.3f -> %.3f mm (%.1f %% less)\n",
      verification.at("cases")[0].at("max_path_deviation_mm").get<double>(),
      verification.at("cases")[1].at("max_path_deviation_mm").get<double>(),
      verification.at("cases")[1].at("reduction_of_max_path_deviation_percent").get<double>());
  EXPECT_GT(verification.at("cases")[1].at("reduction_of_max_path_deviation_percent").get<double>(),
            20.0);
  imscal::test_support::record_figure(
      "campaign_line_reduction_percent",
      verification.at("cases")[1].at("reduction_of_max_path_deviation_percent").get<double>());

  // The report: every section, every figure drawn (gnuplot's SVG curves are <path> elements).
  const std::string html = read_text(out / "report" / "report.html");
  for (const char* part :
       {"Default campaign", "mounting verdict", "(paper Fig. 2)", "Identified error models",
        "Operating-point table coverage", "AT_p", "Fig. 5 (campaign-line)",
        "Fig. 6 (campaign-line)", "Sim-to-real gap diagnosis"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  EXPECT_EQ(count_of(html, "Not run:"), 0u);
  EXPECT_GE(count_of(html, "<svg"), 12u);  // Fig. 2, 6 responses, Fig. 5, 6, gap
  EXPECT_GE(count_of(html, "<path"), count_of(html, "<svg"));
  // ... and in a real browser: loads without errors, every figure laid out and drawn.
  const std::string chromium = imscal::test_support::find_chromium();
  if (chromium.empty()) {
    imscal::test_support::warn_chromium_missing();
    ADD_FAILURE() << "chromium not installed (scripts/install-deps.sh installs it)";
  } else {
    const auto drawn = imscal::test_support::figures_in_chromium(
        chromium, out / "report" / "report.html", dir_ / "profile");
    EXPECT_EQ(drawn.size(), count_of(html, "<svg"));
    imscal::test_support::expect_every_figure_drawn(drawn);
    fs::remove(out / "report" / "probe.html");  // not an output of the run
  }

  // 3. Nothing changed: every stage is skipped.
  ASSERT_EQ(run_imscal("run " + (kCampaign / "run.yaml").string() + " --out " + out.string(),
                       dir_ / "again.log"),
            0);
  EXPECT_EQ(count_of(read_text(dir_ / "again.log"), "skipped (inputs unchanged)"), 6u);
}

}  // namespace
