// workflows/population.smk run by Snakemake on this machine (the local profile, 2 cores): three
// plants (seeds 1000-1002, 1 cycle per verification), one job per plant and step. Truth: the same
// plants run by `imscal population` in one process (eval/population_study.hpp runs the same steps
// in a loop); every figure of every row must agree. A rerun has nothing to do.
// Release only (CI's Release stage): ~2 min for the two runs there, 5-10x under the sanitizers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "tests/support/run_imscal.hpp"
#include "tests/support/run_shell.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using PopulationWorkflow = test_support::ScratchDirTest;
using test_support::read_text;

const fs::path kSource = IMSCAL_SOURCE_DIR;
const fs::path kNominal = kSource / "datasets" / "robots" / "kr16.yaml";

std::vector<std::vector<double>> rows_of(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::vector<double>& row = rows.emplace_back();
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
  }
  return rows;
}

std::string snakemake(const fs::path& dir) {
  std::ofstream(dir / "population.yaml")
      << "imscal: " << IMSCAL_BINARY << "\nnominal: " << kNominal.string()
      << "\nfirst_seed: 1000\nlast_seed: 1002\ncycles: 1\nout: " << (dir / "engine").string()
      << "\n";
  return "snakemake -s " + (kSource / "workflows" / "population.smk").string() + " --configfile " +
         (dir / "population.yaml").string() + " --profile " +
         (kSource / "workflows" / "profiles" / "local").string() + " --cores 2 --directory " +
         dir.string();
}

TEST_F(PopulationWorkflow, StepsOnTheEngineGiveTheLoopsRows) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "3 plants twice: Release only";
  ASSERT_TRUE(test_support::on_path("snakemake")) << "scripts/install-deps.sh installs snakemake";
  ASSERT_EQ(test_support::run_shell(snakemake(dir_), dir_ / "engine.log"), 0)
      << read_text(dir_ / "engine.log");
  const std::string summary = read_text(dir_ / "engine" / "summary.txt");
  EXPECT_NE(summary.find("3 plants finished, 0 failed"), std::string::npos) << summary;
  // One job per plant and step (9 x 3), the summary and the target rule `all`.
  EXPECT_NE(read_text(dir_ / "engine.log").find("29 of 29 steps (100%) done"), std::string::npos);

  ASSERT_EQ(test_support::run_shell(snakemake(dir_), dir_ / "rerun.log"), 0);
  EXPECT_NE(read_text(dir_ / "rerun.log").find("Nothing to be done"), std::string::npos)
      << read_text(dir_ / "rerun.log");

  const std::string loop = "population --nominal " + kNominal.string() +
                           " --seeds 1000-1002 --cycles 1 --out " + (dir_ / "loop").string();
  ASSERT_EQ(test_support::run_imscal(loop, dir_ / "loop.log"), 0) << read_text(dir_ / "loop.log");
  const auto engine = rows_of(dir_ / "engine" / "population.csv");
  const auto in_process = rows_of(dir_ / "loop" / "population.csv");
  ASSERT_EQ(engine.size(), 3u);
  ASSERT_EQ(in_process.size(), 3u);
  for (std::size_t r = 0; r < engine.size(); ++r) {
    ASSERT_EQ(engine[r].size(), in_process[r].size());
    // The same commands on the same files: equal up to the rows' 6 printed digits.
    for (std::size_t c = 0; c < engine[r].size(); ++c)
      EXPECT_NEAR(engine[r][c], in_process[r][c], 1e-5 * (1.0 + std::abs(in_process[r][c])))
          << "row " << r << " column " << c;
  }
}

}  // namespace
}  // namespace imscal
