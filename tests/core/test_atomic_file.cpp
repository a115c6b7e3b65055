// AtomicFile: the target appears only on commit, an abandoned write leaves nothing behind, and an
// existing output is refused unless overwriting is allowed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/atomic_file.hpp"
#include "tests/support/text_file.hpp"

namespace fs = std::filesystem;
using imscal::AtomicFile;
using imscal::Overwrite;
using imscal::test_support::read_text;

namespace {
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("imscal_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
}  // namespace

TEST(AtomicFile, TargetAppearsOnlyOnCommit) {
  const fs::path dir = fresh_dir("atomic_commit");
  const fs::path target = dir / "out.csv";
  {
    AtomicFile file(target);
    file.stream() << "a,b\n1,2\n";
    EXPECT_FALSE(fs::exists(target));
    file.commit();
  }
  EXPECT_EQ(read_text(target), "a,b\n1,2\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);
}

TEST(AtomicFile, AbandonedWriteLeavesNothing) {
  const fs::path dir = fresh_dir("atomic_abandon");
  {
    AtomicFile file(dir / "out.csv");
    file.stream() << "partial";
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 0);
}

TEST(AtomicFile, RefusesToOverwriteWithoutPermission) {
  const fs::path dir = fresh_dir("atomic_refuse");
  imscal::write_file_atomically(dir / "out.txt", "first");
  EXPECT_THROW(AtomicFile(dir / "out.txt", Overwrite::kRefuse), std::runtime_error);
  imscal::write_file_atomically(dir / "out.txt", "second", Overwrite::kAllow);
  EXPECT_EQ(read_text(dir / "out.txt"), "second");
}

// An output that cannot be written names the target a user will look for (never the hidden
// staging copy) and the system's reason.
TEST(AtomicFile, FailureNamesTheTargetAndTheReason) {
  const fs::path dir = fresh_dir("atomic_reason");
  std::ofstream(dir / "plain") << "a file, not a folder";
  const fs::path staged = dir / "plain" / ".imscal-staging-42" / "report.json";
  EXPECT_EQ(imscal::published_path(staged), dir / "plain" / "report.json");
  try {
    imscal::write_file_atomically(staged, "{}");
    ADD_FAILURE() << "written below a plain file";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find(".imscal-staging-"), std::string::npos) << message;
    EXPECT_NE(message.find((dir / "plain" / "report.json").string()), std::string::npos) << message;
    EXPECT_NE(message.find("Not a directory"), std::string::npos) << message;
  }
}
