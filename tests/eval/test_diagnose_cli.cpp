// `imscal diagnose` end to end: real and sim joint_errors.csv from the simulator (one withheld
// effect, tests/eval/gap_cases.hpp), the report names it; outputs all or nothing, refusals.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/eval/gap_cases.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using DiagnoseCli = test_support::ScratchDirTest;

constexpr auto* run = &imscal::test_support::run_imscal;

using imscal::test_support::read_text;

TEST_F(DiagnoseCli, NamesTheWithheldEffectAndWritesAllOrNothing) {
  const eval::test::GapWorld world;
  // Joint zero offset injected on A3 (the harness's most clear-cut case class).
  const auto c = world.make_case({{"zero_offset", 2}}, 14);
  ident::write_joint_errors_csv(dir_ / "real.csv", c.real);
  ident::JointErrorLog sim = c.real;
  for (std::size_t j = 0; j < 6; ++j)
    for (std::size_t k = 0; k < sim.sample_count(); ++k)
      sim.q_measured_rad[j][k] = sim.q_desired_rad[j][k] - c.sim_joint_error_rad[j][k];
  ident::write_joint_errors_csv(dir_ / "sim.csv", sim);
  const std::string robot = std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/kr16.yaml";
  const fs::path out = dir_ / "out";
  const std::string args = "diagnose --joint-errors " + (dir_ / "real.csv").string() +
                           " --sim-joint-errors " + (dir_ / "sim.csv").string() + " --robot " +
                           robot + " --out " + out.string();
  ASSERT_EQ(run(args, dir_ / "a.log"), 0) << read_text(dir_ / "a.log");
  const auto report = nlohmann::json::parse(read_text(out / "report.json"));
  EXPECT_EQ(report["schema_version"], 2);
  EXPECT_TRUE(report["significant_gap"].get<bool>());
  EXPECT_EQ(report["candidates"][0]["effect"], "zero_offset");
  EXPECT_EQ(report["candidates"][0]["joint"], "A3");
  EXPECT_NE(read_text(out / "report.txt").find("Most likely cause: zero_offset on joint A3"),
            std::string::npos);
  // A3 carries the forearm against gravity: its gear torque along the program never changes
  // sign (checked here on the rigid-body torque of the drive's motion), so a backlash of A3 would
  // hold its link on one flank, a constant offset of half the play: on these data exactly the
  // zero offset. The report must say so, with the measurement that separates them.
  const eval::GapSignals signals =
      eval::make_gap_signals(c.real, c.sim_joint_error_rad, world.robot);
  const auto& tau = signals.torque_internal_nm[2];
  ASSERT_TRUE(std::all_of(tau.begin(), tau.end(), [](double v) { return v > 0.0; }) ||
              std::all_of(tau.begin(), tau.end(), [](double v) { return v < 0.0; }));
  EXPECT_EQ(report["leading_group"], nlohmann::json::array({"A3 zero_offset", "A3 backlash"}));
  ASSERT_FALSE(report["ambiguity_groups"].empty());
  const auto& group = report["ambiguity_groups"][0];
  EXPECT_EQ(group["members"], report["leading_group"]);
  // The same column (a constant) fitted to the same rows: the same model up to rounding.
  EXPECT_LE(group["difference_rms_rad"].get<double>(),
            1e-9 * group["residual_rms_rad"].get<double>());
  EXPECT_NE(group["separate_by"].get<std::string>().find("changes sign"), std::string::npos);
  EXPECT_EQ(report["candidates"][1]["shape"], eval::kOneFlankShape);
  EXPECT_NE(read_text(out / "report.txt").find("indistinguishable from it on these data"),
            std::string::npos);
  // Existing outputs are refused without --force (exit 2, files unchanged), kept with it.
  const std::string before = read_text(out / "report.json");
  EXPECT_EQ(run(args, dir_ / "b.log"), 2) << read_text(dir_ / "b.log");
  EXPECT_EQ(read_text(out / "report.json"), before);
  EXPECT_EQ(run(args + " --force", dir_ / "c.log"), 0) << read_text(dir_ / "c.log");
  // Neither --table nor --sim-joint-errors: refused, nothing written.
  const fs::path none = dir_ / "none";
  EXPECT_NE(run("diagnose --joint-errors " + (dir_ / "real.csv").string() + " --robot " + robot +
                    " --out " + none.string(),
                dir_ / "d.log"),
            0);
  EXPECT_FALSE(fs::exists(none / "report.json"));
}

TEST_F(DiagnoseCli, WritesTheModelErrorModelAndFigures) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "gnuplot is not installed";
  const eval::test::GapWorld world;
  // Elastic gear withheld on A3: a linear dynamic gap the model-error model sees.
  const auto c = world.make_case({{"elastic", 2}}, 8);
  ident::write_joint_errors_csv(dir_ / "real.csv", c.real);
  ident::JointErrorLog sim = c.real;
  for (std::size_t j = 0; j < 6; ++j)
    for (std::size_t k = 0; k < sim.sample_count(); ++k)
      sim.q_measured_rad[j][k] = sim.q_desired_rad[j][k] - c.sim_joint_error_rad[j][k];
  ident::write_joint_errors_csv(dir_ / "sim.csv", sim);
  const std::string robot = std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/kr16.yaml";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("diagnose --figures --joint-errors " + (dir_ / "real.csv").string() +
                    " --sim-joint-errors " + (dir_ / "sim.csv").string() + " --robot " + robot +
                    " --out " + out.string(),
                dir_ / "a.log"),
            0)
      << read_text(dir_ / "a.log");
  for (const char* f : {"gap-spectrum.svg", "gap-where.svg", "gap-model-error.svg"}) {
    const std::string svg = read_text(out / f);
    EXPECT_NE(svg.find("<svg"), std::string::npos) << f;
    EXPECT_NE(svg.find("<path"), std::string::npos) << f;  // something was drawn
  }
  const auto report = nlohmann::json::parse(read_text(out / "report.json"));
  ASSERT_EQ(report["model_error"].size(), 6u);
  const auto& a3 = report["model_error"][2];
  EXPECT_EQ(a3["joint"], "A3");
  EXPECT_FALSE(a3["frequency_response"].empty());
  for (const auto& p : a3["frequency_response"])
    EXPECT_LE(p["band_lower"].get<double>(), p["magnitude_rad_per_rad"].get<double>());
  EXPECT_NE(read_text(out / "report.txt").find("Model-error model"), std::string::npos);
}

}  // namespace
}  // namespace imscal
