// workflows/fleet.smk run by Snakemake on this machine (the local profile): three campaigns (the
// shipped default campaign under three robot names) and one whose run.yaml names a missing file.
// The failed campaign is retried, then reported, and leaves no folder; the three others finish;
// the summary waits for every campaign. A rerun without the failed one runs only the summary,
// whose rows agree with the run folders read here (tests/workflows/fleet_checks.hpp).
// Release only (CI's Release stage): three `imscal run`s take ~30 s there, 5-10x that under the
// sanitizers.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/support/run_shell.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"
#include "tests/workflows/fleet_checks.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using FleetWorkflow = test_support::ScratchDirTest;
using test_support::read_text;

const fs::path kSource = IMSCAL_SOURCE_DIR;

// The workflow's config: the campaigns by robot name, results in DIR/results.
fs::path write_config(const fs::path& dir, const std::string& name, bool with_broken) {
  const fs::path campaign = kSource / "datasets" / "campaign" / "run.yaml";
  std::ofstream config(dir / name);
  config << "imscal: " << IMSCAL_BINARY << "\nout: " << (dir / "results").string()
         << "\ncampaigns:\n";
  for (const char* robot : {"robot-a", "robot-b", "robot-c"})
    config << "  " << robot << ": " << campaign.string() << "\n";
  if (with_broken) config << "  robot-broken: " << (dir / "broken" / "run.yaml").string() << "\n";
  return dir / name;
}

// A campaign whose IMS record does not exist: `imscal run` refuses it (exit 2).
void write_broken_campaign(const fs::path& dir) {
  fs::create_directories(dir / "broken");
  std::string run = read_text(kSource / "datasets" / "campaign" / "run.yaml");
  run.replace(run.find("imu: imu.csv"), 12, "imu: missing.csv");
  std::ofstream(dir / "broken" / "run.yaml") << run;
}

std::string snakemake(const fs::path& config, const fs::path& dir) {
  return "snakemake -s " + (kSource / "workflows" / "fleet.smk").string() + " --configfile " +
         config.string() + " --profile " + (kSource / "workflows" / "profiles" / "local").string() +
         " --cores 2 --directory " + dir.string();
}

TEST_F(FleetWorkflow, ThreeCampaignsAFailureReportedAndARerunOfWhatIsMissing) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "three campaigns: Release only";
  ASSERT_TRUE(test_support::on_path("snakemake")) << "scripts/install-deps.sh installs snakemake";
  write_broken_campaign(dir_);
  const fs::path first = write_config(dir_, "with-broken.yaml", true);
  EXPECT_NE(test_support::run_shell(snakemake(first, dir_), dir_ / "first.log"), 0);
  const std::string log = read_text(dir_ / "first.log");
  EXPECT_NE(log.find("Error in rule run_campaign"), std::string::npos) << log;
  EXPECT_NE(log.find("robot-broken"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir_ / "results" / "runs" / "robot-broken")) << "half-written run";
  EXPECT_FALSE(fs::exists(dir_ / "results" / "fleet.csv")) << "a summary without every robot";
  for (const char* robot : {"robot-a", "robot-b", "robot-c"})
    EXPECT_TRUE(fs::exists(dir_ / "results" / "runs" / robot / "report" / "report.html")) << robot;

  const fs::path second = write_config(dir_, "fleet.yaml", false);
  ASSERT_EQ(test_support::run_shell(snakemake(second, dir_), dir_ / "second.log"), 0)
      << read_text(dir_ / "second.log");
  const std::string rerun = read_text(dir_ / "second.log");
  EXPECT_EQ(rerun.find("rule run_campaign"), std::string::npos) << "reran a finished campaign";
  EXPECT_NE(rerun.find("rule fleet_summary"), std::string::npos) << rerun;

  const auto rows = test_support::read_fleet_csv(dir_ / "results" / "fleet.csv");
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& row : rows)
    test_support::expect_row_matches_run(row, dir_ / "results" / "runs" / row.at("robot"));
  EXPECT_TRUE(fs::exists(dir_ / "results" / "fleet.md"));
}

}  // namespace
}  // namespace imscal
