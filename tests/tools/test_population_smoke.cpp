// `imscal population` on 3 plants (seeds 1000-1002), shortened to 1 cycle per verification
// (the full run, 10 cycles, is bench/population.sh): every plant runs the lab's chain to its
// figures, the table and the summary are written, no half-built plant folder is left, a rerun
// skips the finished plants, and the chain's commands were handed the nominal robot file only
// (the plant exists only in the scenarios `simulate` and `verify` run).
// Measured (Release, seeds 1000-1002, 1 cycle): seed-line median 84.3 %, worst 82.7 %; ISO
// 100 % median 87.4 %, worst 79.4 %; 111 s for the 3 plants on a shared 2-core machine
// (a full plant, 10 cycles, takes ~100 s). The figures are printed, not asserted: the smoke run
// checks the machinery; the distribution is bench/population.sh's.
// Release only: under the sanitizers the plants take 5-10x longer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using PopulationSmoke = test_support::ScratchDirTest;
constexpr auto* run = &test_support::run_imscal;
using test_support::read_text;

TEST_F(PopulationSmoke, ThreePlantsThroughTheChain) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "3 plants through the chain: Release only";
  const fs::path nominal = fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "robots" / "kr16.yaml";
  const fs::path out = dir_ / "population";
  const std::string arguments = "population --nominal " + nominal.string() +
                                " --seeds 1000-1002 --cycles 1 --out " + out.string();
  ASSERT_EQ(run(arguments, dir_ / "first.log"), 0) << read_text(dir_ / "first.log");
  const std::string summary = read_text(out / "summary.txt");
  std::printf("%s", summary.c_str());
  EXPECT_NE(summary.find("3 plants finished, 0 failed"), std::string::npos) << summary;
  EXPECT_NE(summary.find("seed_line_reduction_percent: 3 plants, median"), std::string::npos);
  EXPECT_NE(summary.find("iso100_reduction_percent: 3 plants, median"), std::string::npos);
  // A header and a row per plant.
  std::ifstream csv(out / "population.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 4);
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_NE(entry.path().filename().string().front(), '.') << "left behind: " << entry.path();
  // The chain's commands (calibrate, identify) got the nominal robot file, never a plant file;
  // the plant's scenarios name it as `robot:` with the drawn deviations.
  for (int seed : {1000, 1001, 1002}) {
    const fs::path plant = out / ("plant-" + std::to_string(seed));
    EXPECT_TRUE(fs::exists(plant / "verify-iso9283" / "iso9283" / "verification.json"));
    EXPECT_NE(read_text(plant / "plant" / "identification.yaml").find("plant_deviations:"),
              std::string::npos);
    for (const char* step : {"calibrate.log", "calibrate-frames.log", "identify.log"}) {
      const std::string log = read_text(plant / step);
      const std::string command = log.substr(0, log.find('\n'));
      EXPECT_NE(command.find("--robot " + nominal.string()), std::string::npos) << command;
      EXPECT_EQ(command.find("plant/"), std::string::npos) << command;
    }
  }
  // A rerun skips the finished plants and writes the same summary.
  ASSERT_EQ(run(arguments, dir_ / "second.log"), 0) << read_text(dir_ / "second.log");
  EXPECT_NE(read_text(dir_ / "second.log").find("plant 1002 (3/3) finished before, skipped"),
            std::string::npos);
  EXPECT_EQ(read_text(out / "summary.txt"), summary);
}

}  // namespace
}  // namespace imscal
