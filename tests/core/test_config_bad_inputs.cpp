// The bad-config catalogue: every file in tests/data/bad_inputs/configs/ is a YAML config
// that a user could write by mistake (typo in a key, unit in the wrong key, text for a number,
// NaN, a short vector, inverted bounds, a missing referenced file, tabs, an empty file, ...).
// Each names, in its first line, what the refusal must say:
//   # expect: line N, field F, "words"
// and the loader of its kind (the file name's prefix) must refuse it with an InputError that
// names that file, that line and that field (the words: a substring of the message). A file
// without an expectation line (the empty file) must be refused naming the file. URDF robots
// (`robot-*.urdf`) carry the same line inside an XML comment: <!-- # expect: ... -->.
// The run config of `imscal run` is checked through the binary: exit code 2, the message with
// file and line, and no run folder left behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "calib/calibration_config.hpp"
#include "calib/robot_description.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "ident/identification_config.hpp"
#include "sim/scenario.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/tools/run_campaign.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;

const fs::path kCases = fs::path(IMSCAL_TEST_DATA_DIR) / "bad_inputs" / "configs";

struct Expectation {
  bool given = false;
  std::size_t line = 0;
  std::string field, words;
};

// Parses "# expect: line N, field F, "words"" by hand (std::regex trips GCC 12's
// -Wmaybe-uninitialized in the sanitizer build).
Expectation expectation_of(const fs::path& file) {
  std::ifstream in(file);
  std::string first;
  std::getline(in, first);
  const std::string xml_open = "<!-- ";
  const std::string xml_close = " -->";
  if (first.rfind(xml_open, 0) == 0 && first.size() > xml_open.size() + xml_close.size() &&
      first.compare(first.size() - xml_close.size(), xml_close.size(), xml_close) == 0) {
    first = first.substr(xml_open.size(), first.size() - xml_open.size() - xml_close.size());
  }
  Expectation e;
  const std::string head = "# expect: line ";
  if (first.rfind(head, 0) != 0) return e;
  const auto comma = first.find(", field ");
  const auto words = first.find(", \"", comma == std::string::npos ? 0 : comma + 1);
  if (comma == std::string::npos || words == std::string::npos || first.back() != '"') return e;
  e.given = true;
  e.line = std::stoul(first.substr(head.size(), comma - head.size()));
  e.field = first.substr(comma + 8, words - comma - 8);
  e.words = first.substr(words + 3, first.size() - words - 4);
  return e;
}

void load_by_kind(const fs::path& file) {
  const std::string name = file.filename().string();
  if (name.rfind("calibration-", 0) == 0) {
    calib::load_calibration_config(file);
  } else if (name.rfind("identification-", 0) == 0) {
    ident::load_identification_config(ConfigNode::load_file(file));
  } else if (name.rfind("scenario-", 0) == 0) {
    sim::load_scenario(file);
  } else if (name.rfind("robot-", 0) == 0) {
    calib::load_robot_description(file);
  } else {
    FAIL() << "no loader for " << name
           << " (prefix calibration-, identification-, scenario- or robot-)";
  }
}

TEST(ConfigBadInputs, EveryCaseIsRefusedNamingFileLineAndField) {
  std::vector<fs::path> cases;
  for (const auto& entry : fs::directory_iterator(kCases))
    if (entry.path().extension() == ".yaml" || entry.path().extension() == ".urdf") {
      cases.push_back(entry.path());
    }
  std::sort(cases.begin(), cases.end());
  ASSERT_GE(cases.size(), 20u);
  for (const fs::path& file : cases) {
    SCOPED_TRACE(file.filename().string());
    const Expectation expected = expectation_of(file);
    try {
      load_by_kind(file);
      ADD_FAILURE() << "accepted: " << file;
    } catch (const InputError& e) {
      std::printf("%-45s %s\n", file.filename().c_str(), e.what());
      EXPECT_EQ(fs::path(e.file()).filename(), file.filename()) << e.what();
      if (expected.given) {
        EXPECT_EQ(e.line(), expected.line) << e.what();
        EXPECT_EQ(e.field(), expected.field) << e.what();
        EXPECT_NE(std::string(e.what()).find(expected.words), std::string::npos) << e.what();
      }
    }
  }
}

// `imscal run` with a bad run config: exit 2, file:line and key in the message, no run folder.
using RunConfigBadInputs = test_support::ScratchDirTest;
using test_support::read_file_text;
using test_support::run_imscal;

TEST_F(RunConfigBadInputs, RefusedWithExitTwoFileLineAndKeyAndNoRunFolder) {
  std::ofstream(dir_ / "joint_errors.csv") << "placeholder\n";
  struct Case {
    std::string name, yaml, where, words;
  };
  const std::vector<Case> cases = {
      {"unknown-key",
       "imscal-run-config: 1\ninputs: {joint_errors: joint_errors.csv}\nreprot: {}\n", ":3",
       "reprot"},
      {"wrong-version", "imscal-run-config: 2\ninputs: {joint_errors: joint_errors.csv}\n", ":1",
       "version"},
      {"missing-input-file", "imscal-run-config: 1\ninputs: {imu: nowhere.imsb}\n", ":2",
       "is not a file"},
      {"no-inputs", "imscal-run-config: 1\ninputs: {}\n", ":2", "names no input"},
      {"joint-errors-without-identify",
       "imscal-run-config: 1\ninputs: {joint_errors: joint_errors.csv}\n", ":2", "identify"},
      {"negative-overlap",
       "imscal-run-config: 1\ninputs: {imu: joint_errors.csv}\nvalidate: {min_overlap_s: -1}\n",
       ":3", "must be > 0"},
      {"text-for-points",
       "imscal-run-config: 1\ninputs: {imu: joint_errors.csv}\nreport: {max_points_per_curve: "
       "lots}\n",
       ":3", "max_points_per_curve"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path config = dir_ / (c.name + ".yaml");
    std::ofstream(config) << c.yaml;
    const fs::path out = dir_ / ("out-" + c.name), log = dir_ / (c.name + ".log");
    EXPECT_EQ(run_imscal("run " + config.string() + " --out " + out.string(), log), 2);
    const std::string message = read_file_text(log);
    std::printf("%-32s %s", c.name.c_str(), message.c_str());
    EXPECT_NE(message.find(config.filename().string() + c.where), std::string::npos) << message;
    EXPECT_NE(message.find(c.words), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(out)) << "a run folder was left behind";
  }
}

}  // namespace
}  // namespace imscal
