// The command-line bad-input catalogue: every command given what a user gets wrong on its command
// line. Each input option with a missing file, a folder and a named pipe (refused at once,
// exit 2, the file and what is wrong with it named; a named pipe would block a reader forever); a
// bad field in an input file (exit 2, file, line and field); an output that exists without
// --force, an output file's name taken by a folder and a folder output named by a file (exit 2,
// the earlier file left as it was); a missing folder of an output file is created. Exit codes as
// README states: 2 for every bad input, the same mistake the same code in every command.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using test_support::read_text;
using test_support::run_imscal;

const fs::path kSource(IMSCAL_SOURCE_DIR);
const std::string kKr16 = (kSource / "datasets/robots/kr16.yaml").string();
const std::string kUr10 = (kSource / "datasets/robots/ur10.urdf").string();
const std::string kTable = (kSource / "fuzz/corpus/parameter_table/table.json").string();
const std::string kJointErrors = (kSource / "fuzz/corpus/joint_errors/small.csv").string();
const std::string kPoses = (kSource / "fuzz/corpus/tracker_poses/ipa-series-c-head.csv").string();
const std::string kToolImu = (kSource / "fuzz/corpus/tool_imu_record/mpu9150-head.csv").string();

// `text` with field `column` (0-based) of line `line` (1-based) replaced by `value`.
std::string with_field(const std::string& text_in, std::size_t line, std::size_t column,
                       const std::string& value) {
  std::istringstream in(text_in);
  std::string out, text;
  for (std::size_t n = 1; std::getline(in, text); ++n) {
    if (n == line) {
      std::size_t begin = 0;
      for (std::size_t c = 0; c < column; ++c) begin = text.find(',', begin) + 1;
      const std::size_t end = text.find(',', begin);
      text = text.substr(0, begin) + value + (end == std::string::npos ? "" : text.substr(end));
    }
    out += text + "\n";
  }
  return out;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

class CommandBadInputs : public test_support::ScratchDirTest {
 protected:
  // Runs the command; returns its exit code, the message in message_.
  int run(const std::string& arguments) {
    const int status = run_imscal(arguments, dir_ / "message.log");
    message_ = read_text(dir_ / "message.log");
    return status;
  }
  std::string message_;
};

// Each command line holds INPUT where the bad input goes (and OUT for its output).
struct CommandLine {
  std::string name, arguments;
};

TEST_F(CommandBadInputs, MissingFileFolderAndNamedPipeAreRefusedAtOnceWithExitTwo) {
  const std::vector<CommandLine> commands = {
      {"serve --table", "serve --table INPUT --port 0 --idle-timeout-s 1"},
      {"serve --path", "serve --table " + kTable + " --port 0 --path INPUT --robot " + kKr16 +
                           " --idle-timeout-s 1"},
      {"calibrate-kinematics --poses",
       "calibrate-kinematics --robot " + kUr10 + " --poses INPUT --out OUT"},
      {"calibrate-kinematics --robot",
       "calibrate-kinematics --robot INPUT --poses " + kPoses + " --out OUT"},
      {"diagnose-tool-imu --imu", "diagnose-tool-imu --imu INPUT --held-out INPUT --out OUT"},
      {"check-tool-imu --imu", "check-tool-imu --imu INPUT --out OUT"},
      {"model-joint-errors --joint-errors",
       "model-joint-errors --joint-errors INPUT --robot " + kKr16 + " --out OUT"},
      {"model-joint-errors --robot",
       "model-joint-errors --joint-errors " + kJointErrors + " --robot INPUT --out OUT"},
      {"population --nominal", "population --nominal INPUT --seeds 1 --out OUT"},
      {"mechanize --input", "mechanize --input INPUT --initial-attitude 0,0,0 --out OUT"},
      {"run", "run INPUT --out OUT"},
      {"calibrate --config",
       "calibrate --imu " + (kSource / "fuzz/corpus/imu_csv/increments.csv").string() +
           " --robot-log " + (kSource / "fuzz/corpus/robot_log/valid.csv").string() + " --robot " +
           kKr16 + " --sensor " + (kSource / "datasets/sensors/navigation-grade.yaml").string() +
           " --config INPUT --out OUT"},
      {"identify --config",
       "identify --joint-errors " + kJointErrors + " --config INPUT --out OUT"},
  };
  const fs::path fifo = dir_ / "pipe.csv", folder = dir_ / "folder.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_directories(folder);
  const std::vector<std::pair<fs::path, std::string>> inputs = {
      {dir_ / "missing.csv", "No such file or directory"},
      {folder, "is a directory, not a regular file"},
      {fifo, "is a named pipe (FIFO), not a regular file"}};
  for (const CommandLine& command : commands) {
    for (const auto& [input, words] : inputs) {
      SCOPED_TRACE(command.name + " with " + input.filename().string());
      const fs::path out = dir_ / "out";
      const auto start = std::chrono::steady_clock::now();
      EXPECT_EQ(
          run(replaced(replaced(command.arguments, "INPUT", input.string()), "OUT", out.string())),
          2)
          << message_;
      // At once: a blocked open would never return; reading and refusing takes milliseconds.
      EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
      EXPECT_NE(message_.find(input.string() + ": "), std::string::npos) << message_;
      EXPECT_NE(message_.find(words), std::string::npos) << message_;
      EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << "an output was left behind";
    }
  }
}

// A joint angle beyond the robot's limit (A2 of the KR 16: 35 deg) by more than the margin of
// core/joint_limit_plausibility.hpp, in every file of joint angles a command checks against its
// robot: refused with exit 2 naming file, line and column.
std::string joint_errors_with_a2(const std::string& q_rad) {
  std::string text = read_text(kJointErrors);
  for (std::size_t column : {3, 9, 15}) text = with_field(text, 6, column, q_rad);
  return text;
}

std::string robot_log_with_a2(const std::string& q_rad) {
  std::string text = read_text(kSource / "fuzz/corpus/robot_log/valid.csv");
  for (std::size_t column : {3, 9}) text = with_field(text, 7, column, q_rad);
  return text;
}

// A bad field in an input file of each of the newer commands: exit 2 naming file, line and field.
TEST_F(CommandBadInputs, ABadFieldIsRefusedWithFileLineAndField) {
  struct Case {
    std::string name, file, content, arguments, where, field;
  };
  const std::vector<Case> cases = {
      {"serve: robot log cycle", "robot.csv",
       read_text(kSource / "tests/data/bad_inputs/robot/bad_cycle.csv"),
       "serve --table " + kTable + " --port 0 --robot " + kKr16 +
           " --idle-timeout-s 1 --path INPUT",
       "robot.csv:3", "cycle_s"},
      {"calibrate-kinematics: text for a joint angle", "poses.csv",
       with_field(read_text(kPoses), 3, 7, "abc"),
       "calibrate-kinematics --robot " + kUr10 + " --poses INPUT --out OUT", "poses.csv:3",
       "q1_shoulder_pan_rad"},
      {"check-tool-imu: text for a rate", "imu.csv", with_field(read_text(kToolImu), 3, 1, "abc"),
       "check-tool-imu --imu INPUT --out OUT", "imu.csv:3", "gyro_x_dps"},
      {"diagnose-tool-imu: text for a rate", "imu.csv",
       with_field(read_text(kToolImu), 3, 1, "abc"),
       "diagnose-tool-imu --imu INPUT --held-out " + kToolImu + " --out OUT", "imu.csv:3",
       "gyro_x_dps"},
      {"model-joint-errors: a corrupted sample", "joint_errors.csv",
       with_field(read_text(kJointErrors), 6, 2, "253"),
       "model-joint-errors --joint-errors INPUT --robot " + kKr16 + " --out OUT",
       "joint_errors.csv:6", "q_measured_A1_rad"},
      {"model-joint-errors: A2 at 57 deg", "joint_errors.csv", joint_errors_with_a2("1.0"),
       "model-joint-errors --joint-errors INPUT --robot " + kKr16 + " --out OUT",
       "joint_errors.csv:6", "q_desired_A2_rad"},
      {"verify: joint errors with A2 at 57 deg", "joint_errors.csv", joint_errors_with_a2("1.0"),
       "verify --joint-errors INPUT --scenario seed-line --cycles 1 --out OUT",
       "joint_errors.csv:6", "q_desired_A2_rad"},
      {"serve: a path with A2 at 57 deg", "robot.csv", robot_log_with_a2("1.0"),
       "serve --table " + kTable + " --port 0 --robot " + kKr16 +
           " --idle-timeout-s 1 --path INPUT",
       "robot.csv:7", "q_desired_A2_rad"},
      {"compensate: a log with A2 at 57 deg", "robot.csv", robot_log_with_a2("1.0"),
       "compensate --table " + kTable + " --robot " + kKr16 + " --robot-log INPUT --out OUT",
       "robot.csv:7", "q_desired_A2_rad"},
      {"calibrate-kinematics: q1 at 401 deg on the UR10", "poses.csv",
       with_field(read_text(kPoses), 3, 7, "7.0"),
       "calibrate-kinematics --robot " + kUr10 + " --poses INPUT --out OUT", "poses.csv:3",
       "q1_rad"},
      {"compensate: the log of another robot than the table's", "robot.csv",
       replaced(read_text(kSource / "fuzz/corpus/robot_log/valid.csv"), "# robot: kr16",
                "# robot: kr6"),
       "compensate --table " + kTable + " --robot-log INPUT --out OUT", "robot.csv:2", "robot"},
      {"population: a robot file that is no URDF", "robot.urdf",
       read_text(kSource / "tests/data/bad_inputs/configs/robot-urdf-not-xml.urdf"),
       "population --nominal INPUT --seeds 1 --out OUT", "robot.urdf", ""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path input = dir_ / c.file, out = dir_ / "out";
    std::ofstream(input) << c.content;
    EXPECT_EQ(run(replaced(replaced(c.arguments, "INPUT", input.string()), "OUT", out.string())), 2)
        << message_;
    std::printf("%-48s %s", c.name.c_str(), message_.c_str());
    EXPECT_NE(message_.find(c.where), std::string::npos) << message_;
    if (!c.field.empty()) {
      EXPECT_NE(message_.find("field '" + c.field + "'"), std::string::npos) << message_;
    }
    EXPECT_FALSE(fs::exists(out)) << "an output was left behind";
  }
  // A seed range that is no range: the option named.
  EXPECT_EQ(run("population --nominal " + kKr16 + " --seeds 5-1 --out " + (dir_ / "p").string()), 2)
      << message_;
  EXPECT_NE(message_.find("--seeds"), std::string::npos) << message_;
}

// Outputs: an existing one without --force, a folder in place of an output file and a file in
// place of an output folder are bad input (exit 2) before any work, the earlier file untouched;
// a missing folder of an output file is created.
TEST_F(CommandBadInputs, OutputsThatExistOrAreTheWrongKindAreRefusedWithExitTwo) {
  const std::vector<CommandLine> file_outputs = {
      {"calibrate-kinematics", "calibrate-kinematics --robot " + kUr10 + " --poses " + kPoses},
      {"diagnose-tool-imu", "diagnose-tool-imu --imu " + kToolImu + " --held-out " + kToolImu},
      {"check-tool-imu", "check-tool-imu --imu " + kToolImu},
      {"model-joint-errors",
       "model-joint-errors --joint-errors " + kJointErrors + " --robot " + kKr16},
      {"compensate", "compensate --table " + kTable + " --robot-log " +
                         (kSource / "fuzz/corpus/robot_log/valid.csv").string()},
  };
  const fs::path existing = dir_ / "existing.json", folder = dir_ / "folder.json";
  fs::create_directories(folder / "kept");
  for (const CommandLine& command : file_outputs) {
    SCOPED_TRACE(command.name);
    std::ofstream(existing) << "earlier output\n";
    EXPECT_EQ(run(command.arguments + " --out " + existing.string()), 2) << message_;
    EXPECT_NE(message_.find(existing.string() + ": field '--out': exists already"),
              std::string::npos)
        << message_;
    EXPECT_NE(message_.find("--force"), std::string::npos) << message_;
    EXPECT_EQ(read_text(existing), "earlier output\n");
    EXPECT_EQ(run(command.arguments + " --out " + folder.string() + " --force"), 2) << message_;
    EXPECT_NE(message_.find(folder.string() + ": field '--out': is a folder, not a file"),
              std::string::npos)
        << message_;
    EXPECT_TRUE(fs::is_directory(folder / "kept"));
  }
  // A folder output named by a file.
  std::ofstream(dir_ / "a_file") << "not a folder\n";
  EXPECT_EQ(run("population --nominal " + kKr16 + " --seeds 1 --out " + (dir_ / "a_file").string()),
            2)
      << message_;
  EXPECT_NE(message_.find("is a file, not a folder"), std::string::npos) << message_;
  EXPECT_EQ(read_text(dir_ / "a_file"), "not a folder\n");
  // A joint within the margin beyond its limit (A2 at 37.2 deg, 2.2 deg beyond): a warning with
  // file, line, column and limit, and the command runs.
  std::ofstream(dir_ / "near.csv") << joint_errors_with_a2("0.65");
  EXPECT_EQ(run("model-joint-errors --joint-errors " + (dir_ / "near.csv").string() + " --robot " +
                kKr16 + " --out " + (dir_ / "near_model.csv").string()),
            0)
      << message_;
  EXPECT_NE(message_.find("[warning] " + (dir_ / "near.csv").string() +
                          ":6: field 'q_desired_A2_rad': 0.65 rad (37.24 deg) is 2.24 deg beyond "
                          "joint A2's upper limit of 35 deg"),
            std::string::npos)
      << message_;
  // A missing folder of an output file is created.
  const fs::path nested = dir_ / "new" / "sub" / "model.csv";
  EXPECT_EQ(run(file_outputs[3].arguments + " --out " + nested.string()), 0) << message_;
  EXPECT_TRUE(fs::is_regular_file(nested));
}

}  // namespace
}  // namespace imscal
