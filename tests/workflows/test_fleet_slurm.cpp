// workflows/fleet.smk through a single-node Slurm cluster that the test brings up
// (tests/workflows/slurm-single-node.sh: munged, slurmctld, slurmd) with the Slurm profile
// (workflows/profiles/slurm): the same workflow as on one machine, every job submitted with
// sbatch. Three campaigns; each job leaves Slurm's own log (.snakemake/slurm-JOBID.log); the
// summary agrees with the run folders (tests/workflows/fleet_checks.hpp).
// Needs root and Debian's slurm-wlm and munge (scripts/install-deps.sh); Release only (CI's
// Release stage runs it as root).
#include <gtest/gtest.h>
#include <unistd.h>

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
using FleetOnSlurm = test_support::ScratchDirTest;
using test_support::read_text;

const fs::path kSource = IMSCAL_SOURCE_DIR;
const fs::path kCluster = kSource / "tests" / "workflows" / "slurm-single-node.sh";

// Stops the cluster however the test ends.
struct Cluster {
  fs::path dir;
  ~Cluster() { test_support::run_shell(kCluster.string() + " stop " + dir.string(), "/dev/null"); }
};

TEST_F(FleetOnSlurm, ThreeCampaignsAsSlurmJobs) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "three campaigns: Release only";
  ASSERT_EQ(::geteuid(), 0u) << "the test starts Slurm's daemons: run it as root";
  for (const char* program : {"snakemake", "slurmctld", "slurmd", "munged", "sbatch"})
    ASSERT_TRUE(test_support::on_path(program)) << program << ": scripts/install-deps.sh";
  const Cluster cluster{dir_ / "cluster"};
  ASSERT_EQ(test_support::run_shell(kCluster.string() + " start " + cluster.dir.string(),
                                    dir_ / "cluster-start.log"),
            0)
      << read_text(dir_ / "cluster-start.log");
  const fs::path campaign = kSource / "datasets" / "campaign" / "run.yaml";
  std::ofstream(dir_ / "fleet.yaml")
      << "imscal: " << IMSCAL_BINARY << "\nout: " << (dir_ / "results").string()
      << "\ncampaigns:\n  robot-a: " << campaign.string() << "\n  robot-b: " << campaign.string()
      << "\n  robot-c: " << campaign.string() << "\n";
  const std::string command = "SLURM_CONF=" + (cluster.dir / "slurm.conf").string() +
                              " snakemake -s " + (kSource / "workflows" / "fleet.smk").string() +
                              " --configfile " + (dir_ / "fleet.yaml").string() + " --profile " +
                              (kSource / "workflows" / "profiles" / "slurm").string() +
                              " --directory " + dir_.string();
  ASSERT_EQ(test_support::run_shell(command, dir_ / "fleet.log"), 0)
      << read_text(dir_ / "fleet.log") << read_text(cluster.dir / "slurmctld.log");

  int slurm_logs = 0;
  for (const auto& entry : fs::directory_iterator(dir_ / ".snakemake"))
    if (entry.path().filename().string().rfind("slurm-", 0) == 0) ++slurm_logs;
  EXPECT_EQ(slurm_logs, 4) << "three campaigns and the summary, each a Slurm job";
  EXPECT_NE(read_text(dir_ / "fleet.log").find("Submitted job"), std::string::npos);
  const auto rows = test_support::read_fleet_csv(dir_ / "results" / "fleet.csv");
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& row : rows)
    test_support::expect_row_matches_run(row, dir_ / "results" / "runs" / row.at("robot"));
}

}  // namespace
}  // namespace imscal
