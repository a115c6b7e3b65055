// ConfigNode::as_existing_file, the one resolver of file names in every config (run config,
// calibration config, scenario): a relative name is relative to the config file's folder, never
// to the working directory; the result is absolute and normalised; an empty name, a folder, a
// missing file and a name the file system refuses are InputErrors naming file, line and key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal {
namespace {
namespace fs = std::filesystem;

using ConfigPaths = test_support::ScratchDirTest;

TEST_F(ConfigPaths, RelativeToTheConfigsFolderAbsoluteAndNormalised) {
  fs::create_directories(dir_ / "configs" / "sub");
  fs::create_directories(dir_ / "data");
  std::ofstream(dir_ / "data" / "robot.yaml") << "x: 1\n";
  std::ofstream(dir_ / "configs" / "sub" / "run.yaml")
      << "robot: ../../data/robot.yaml\nsame: " << (dir_ / "data" / "robot.yaml").string()
      << "\nfolder: ../../data\nmissing: nowhere.yaml\nempty: ''\ntoo_long: "
      << std::string(300, 'x') << "\n";
  // The working directory is elsewhere: it must not matter.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_ / "data");
  const ConfigNode root = ConfigNode::load_file(dir_ / "configs" / "sub" / "run.yaml");
  const fs::path expected = fs::weakly_canonical(dir_ / "data" / "robot.yaml");
  EXPECT_EQ(root.child("robot").as_existing_file(), expected);
  EXPECT_EQ(root.child("same").as_existing_file(), expected);
  struct Bad {
    const char* key;
    int line;
    const char* words;
  };
  for (const Bad& bad : {Bad{"folder", 3, "is not a file"}, Bad{"missing", 4, "is not a file"},
                         Bad{"empty", 5, "an empty path"}, Bad{"too_long", 6, "is not a file"}}) {
    SCOPED_TRACE(bad.key);
    try {
      root.child(bad.key).as_existing_file();
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("run.yaml:" + std::to_string(bad.line)), std::string::npos) << what;
      EXPECT_NE(what.find(bad.key), std::string::npos) << what;
      EXPECT_NE(what.find(bad.words), std::string::npos) << what;
    }
  }
  fs::current_path(cwd);
}

}  // namespace
}  // namespace imscal
