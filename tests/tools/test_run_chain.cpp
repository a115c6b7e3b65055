// `imscal run` through the later stages of the paper's chain on the simulated KR 16: joint
// errors of the `identification` scenario (the simulator's link-side truth, written by
// `imscal verify --identify-scenario`) -> identify -> verify (closed loop on seed-line, ISO 9283
// before/after, Fig. 5/6) -> diagnose (gap between the joint errors and the identified model)
// -> report. Checked: every stage ran and ended ok, each left its files, the report carries the
// ISO table, the two redrawn figures (non-empty SVG) and the diagnosis, and a second run with
// nothing changed skips every stage. Release only: one closed-loop simulation per case and the
// diagnosis' bootstrap take ~30 s here and 5-10x that under the sanitizers (IMSCAL_SANITIZED),
// where the stage machinery is covered by test_run_cli.
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "core/run_stage.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/run_campaign.hpp"

namespace {
namespace fs = std::filesystem;
using imscal::test_support::count_of;
using imscal::test_support::read_text;
using imscal::test_support::run_imscal;

using RunChain = imscal::test_support::ScratchDirTest;

TEST_F(RunChain, IdentifyVerifyDiagnoseAndReport) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only (see the file's comment)";
  const fs::path truth = dir_ / "truth";
  ASSERT_EQ(run_imscal("verify --identify-scenario identification --scenario seed-line "
                       "--cycles 1 --no-ablation --out " +
                           truth.string(),
                       dir_ / "truth.log"),
            0)
      << read_text(dir_ / "truth.log");
  ASSERT_TRUE(fs::exists(truth / "joint_errors_truth.csv"));
  const fs::path config = dir_ / "run.yaml";
  std::ofstream(config) << "imscal-run-config: 1\n"
                           "title: chain test\n"
                           "inputs:\n"
                           "  joint_errors: truth/joint_errors_truth.csv\n"
                           "identify:\n"
                           "  config: " IMSCAL_SOURCE_DIR
                           "/datasets/identification/ident-default.yaml\n"
                           "  robot: " IMSCAL_SOURCE_DIR
                           "/datasets/robots/kr16.yaml\n"
                           "verify:\n"
                           "  scenarios: [seed-line]\n"
                           "  cycles: 2\n"
                           "diagnose:\n"
                           "  robot: " IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml\n";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run_imscal("run " + config.string() + " --out " + out.string(), dir_ / "run.log"), 0)
      << read_text(dir_ / "run.log");
  for (const char* file : {"identify/parameters.json", "verify/seed-line/verification.json",
                           "verify/seed-line/fig5_paths.csv", "verify/seed-line/fig6_deviation.csv",
                           "diagnose/report.json", "diagnose/report.txt", "report/report.html"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  for (const char* stage : {"identify", "verify", "diagnose", "report"}) {
    const auto record = nlohmann::json::parse(read_text(out / stage / imscal::kStageRecordName));
    EXPECT_EQ(record.value("status", ""), "ok") << stage;
  }
  const std::string html = read_text(out / "report" / "report.html");
  // The ISO 9283 table of verify, the two figures of the verified scenario and the diagnosis.
  EXPECT_NE(html.find("AT_p"), std::string::npos);
  EXPECT_NE(html.find("Fig. 5 (seed-line)"), std::string::npos);
  EXPECT_NE(html.find("Fig. 6 (seed-line)"), std::string::npos);
  EXPECT_NE(html.find("gap diagnosis"), std::string::npos);
  EXPECT_EQ(count_of(html, "Not run:"), 2u) << "only raw inputs and calibrate are not run";
  // Every <svg> element holds drawn paths (gnuplot draws curves as <path>).
  EXPECT_GE(count_of(html, "<svg"), 4u);
  EXPECT_GE(count_of(html, "<path"), count_of(html, "<svg"));

  // Nothing changed: every stage is skipped.
  ASSERT_EQ(run_imscal("run " + config.string() + " --out " + out.string(), dir_ / "again.log"), 0);
  const std::string again = read_text(dir_ / "again.log");
  EXPECT_EQ(count_of(again, "skipped (inputs unchanged)"), 4u) << again;
}

}  // namespace
