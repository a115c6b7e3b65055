// All-or-nothing output folders: nothing appears before commit, an exception leaves the folder as
// it was, existing outputs are refused without overwrite.
#include "core/output_folder.hpp"

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using OutputFolderTest = test_support::ScratchDirTest;

using test_support::read_text;
using test_support::write_text;

TEST_F(OutputFolderTest, FilesAppearOnlyAtCommit) {
  OutputFolder out(dir_ / "run", {"a.txt", "truth/b.txt"}, Overwrite::kRefuse);
  write_text(out.staged("a.txt"), "A");
  write_text(out.staged("truth/b.txt"), "B");
  EXPECT_FALSE(fs::exists(dir_ / "run" / "a.txt"));
  out.commit();
  EXPECT_EQ(read_text(dir_ / "run" / "a.txt"), "A");
  EXPECT_EQ(read_text(dir_ / "run" / "truth" / "b.txt"), "B");
}

TEST_F(OutputFolderTest, AnErrorBeforeCommitLeavesTheFolderAsItWas) {
  write_text(dir_ / "a.txt", "old");
  try {
    OutputFolder out(dir_, {"a.txt", "b.txt"}, Overwrite::kAllow);
    write_text(out.staged("a.txt"), "new");
    throw std::runtime_error("stage failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read_text(dir_ / "a.txt"), "old");
  EXPECT_FALSE(fs::exists(dir_ / "b.txt"));
  // No staging folder is left behind.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_FALSE(entry.path().filename().string().starts_with(".imscal-staging"));
  }
}

TEST_F(OutputFolderTest, ExistingOutputsAreRefusedUnlessAllowed) {
  write_text(dir_ / "a.txt", "old");
  try {
    OutputFolder out(dir_, {"b.txt", "a.txt"}, Overwrite::kRefuse);
    ADD_FAILURE() << "accepted an existing output";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (dir_ / "a.txt").string());
  }
  OutputFolder out(dir_, {"a.txt"}, Overwrite::kAllow);
  write_text(out.staged("a.txt"), "new");
  out.commit();
  EXPECT_EQ(read_text(dir_ / "a.txt"), "new");
}

TEST_F(OutputFolderTest, CommitRefusesAMissingOutputAndUndeclaredFiles) {
  OutputFolder out(dir_, {"a.txt", "b.txt"}, Overwrite::kRefuse);
  write_text(out.staged("a.txt"), "A");
  EXPECT_THROW(out.staged("c.txt"), std::logic_error);
  EXPECT_THROW(out.commit(), std::logic_error);
  EXPECT_FALSE(fs::exists(dir_ / "a.txt"));  // nothing moved: the set was incomplete
}

// A folder in the place of the second output (with --force): refused before the first rename, so
// the command leaves neither output, not one new and one old.
TEST_F(OutputFolderTest, AFolderInPlaceOfAnOutputStopsTheCommitBeforeAnyRename) {
  write_text(dir_ / "a.txt", "old A");
  fs::create_directories(dir_ / "b.txt" / "inside");
  OutputFolder out(dir_, {"a.txt", "b.txt"}, Overwrite::kAllow);
  write_text(out.staged("a.txt"), "new A");
  write_text(out.staged("b.txt"), "new B");
  EXPECT_THROW(out.commit(), InputError);
  EXPECT_EQ(read_text(dir_ / "a.txt"), "old A");
}

// --out naming a file is a mistake on the command line (exit 2 in every command).
TEST_F(OutputFolderTest, AFileAsTheFolderIsBadInput) {
  write_text(dir_ / "plain", "a file");
  EXPECT_THROW(OutputFolder(dir_ / "plain", {"a.txt"}, Overwrite::kAllow), InputError);
  EXPECT_THROW(create_output_folder(dir_ / "plain"), InputError);
}

}  // namespace
}  // namespace imscal
