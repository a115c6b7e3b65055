// `imscal mechanize` writes its two outputs (trajectory.csv, trajectory.tum) all or nothing: a
// rerun whose writes fail leaves the earlier run's pair exactly as it was and says which output
// and why. A full disk is stood in for by a file-size limit (RLIMIT_FSIZE with SIGXFSZ ignored:
// a write beyond it fails with EFBIG, as ENOSPC would); an output that cannot be replaced by a
// folder of its name.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace {

namespace fs = std::filesystem;
using imscal::test_support::read_text;
using MechanizeCli = imscal::test_support::ScratchDirTest;

std::map<std::string, std::string> files_below(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder))
    if (e.is_regular_file()) files[fs::relative(e.path(), folder).string()] = read_text(e.path());
  return files;
}

TEST_F(MechanizeCli, AFailingWriteLeavesTheEarlierPairAsItWas) {
  const fs::path out = dir_ / "out", log = dir_ / "log.txt";
  // The fuzz target's seed: 26 increments of a resting IMS (fuzz/corpus/imu_csv/).
  const std::string arguments =
      "mechanize --input " + std::string(IMSCAL_SOURCE_DIR) +
      "/fuzz/corpus/imu_csv/increments.csv --initial-attitude 0,0,0 --site 48.7,9.1,380 --out " +
      out.string();
  ASSERT_EQ(imscal::test_support::run_imscal(arguments, log), 0) << read_text(log);
  const auto before = files_below(out);
  ASSERT_EQ(before.size(), 2u);
  ASSERT_GT(before.at("trajectory.csv").size(), 4096u);  // beyond the limit below

  // 4 KiB (ulimit counts 512-byte blocks in sh).
  const std::string limited = "sh -c 'trap \"\" XFSZ; ulimit -f 8; " + std::string(IMSCAL_BINARY) +
                              " " + arguments + " --force; echo exit=$?' 2>&1 | cat > " +
                              log.string();
  ASSERT_EQ(std::system(limited.c_str()), 0);
  const std::string message = read_text(log);
  EXPECT_NE(message.find("exit=3"), std::string::npos) << message;
  EXPECT_NE(message.find("File too large"), std::string::npos) << message;
  EXPECT_NE(message.find((out / "trajectory.csv").string()), std::string::npos) << message;
  EXPECT_EQ(message.find(".imscal-staging-"), std::string::npos) << message;
  EXPECT_EQ(files_below(out), before);  // no staging copy left either

  // trajectory.tum's name taken by a folder: refused before trajectory.csv is replaced.
  fs::remove(out / "trajectory.tum");
  fs::create_directories(out / "trajectory.tum" / "kept");
  EXPECT_EQ(imscal::test_support::run_imscal(arguments + " --force", log), 2) << read_text(log);
  EXPECT_NE(read_text(log).find("trajectory.tum: is a folder"), std::string::npos)
      << read_text(log);
  auto expected = before;
  expected.erase("trajectory.tum");
  EXPECT_EQ(files_below(out), expected);
}

}  // namespace
