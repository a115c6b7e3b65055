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
// file and line, and no run folder left behind. Every reader refuses at once a path that is not
// a regular file (a named pipe would block it forever), naming the file and what it is.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "calib/calibration_config.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "ims/imu_file.hpp"
#include "ims/psins_reader.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"
#include "sim/scenario.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"
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
  strip_byte_order_mark(first);  // a case with a byte-order mark is read past it
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
using test_support::read_text;
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
      {"duplicate-block",
       "imscal-run-config: 1\ninputs: {imu: joint_errors.csv}\nvalidate: {min_overlap_s: 1}\n"
       "validate: {min_overlap_s: 2}\n",
       ":4", "appears twice"},
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
    const std::string message = read_text(log);
    std::printf("%-32s %s", c.name.c_str(), message.c_str());
    EXPECT_NE(message.find(config.filename().string() + c.where), std::string::npos) << message;
    EXPECT_NE(message.find(c.words), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(out)) << "a run folder was left behind";
  }
}

// Every reader of the tool, given a named pipe, a folder or a device where a file belongs.
using NonRegularInputs = test_support::ScratchDirTest;

TEST_F(NonRegularInputs, EveryReaderRefusesAtOnceNamingTheFileAndWhatItIs) {
  const std::vector<std::pair<std::string, std::function<void(const fs::path&)>>> readers = {
      {"yaml config", [](const fs::path& f) { ConfigNode::load_file(f); }},
      {"imu file", [](const fs::path& f) { ims::read_imu_file(f); }},
      {"psins", [](const fs::path& f) { ims::read_psins(f); }},
      {"robot log", [](const fs::path& f) { calib::read_robot_log_csv(f); }},
      {"joint errors", [](const fs::path& f) { ident::read_joint_errors_csv(f); }},
      {"parameter table", [](const fs::path& f) { ident::read_parameters_json(f); }},
  };
  const fs::path fifo = dir_ / "input.csv", folder = dir_ / "folder.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_directories(folder);
  const std::vector<std::pair<fs::path, std::string>> inputs = {
      {fifo, "is a named pipe (FIFO), not a regular file"},
      {folder, "is a directory, not a regular file"},
      {"/dev/null", "is a device, not a regular file"},
      {dir_ / "missing" / "imu.csv", "No such file or directory"}};
  for (const auto& [reader, read] : readers) {
    for (const auto& [path, words] : inputs) {
      SCOPED_TRACE(reader + " on " + path.string());
      const auto start = std::chrono::steady_clock::now();
      try {
        read(path);
        ADD_FAILURE() << "accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(e.file(), path.string()) << e.what();
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      }
      // At once: well under a second (a blocked open would never return).
      EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
    }
  }
}

// A parameter table with a key given twice in one object: refused naming file, line and key.
TEST_F(NonRegularInputs, ParameterTableWithARepeatedKeyIsRefused) {
  const std::string text =
      "{\n \"schema\": \"imscal-parameter-table\",\n \"robot\": \"kr16\",\n"
      " \"robot\": \"kr6\"\n}\n";
  std::ofstream(dir_ / "parameters.json") << text;
  try {
    ident::read_parameters_json(dir_ / "parameters.json");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(fs::path(e.file()).filename(), "parameters.json") << e.what();
    EXPECT_EQ(e.line(), 4u) << e.what();
    EXPECT_EQ(e.field(), "robot") << e.what();
    EXPECT_NE(std::string(e.what()).find("appears twice"), std::string::npos) << e.what();
  }
}

// A payload against the robot's rated payload (core/payload_plausibility.hpp) in every command
// that takes one: far above the rating (5000 kg on the 16 kg KR 16: a wrong unit or column) is
// refused with exit 2 naming the file, the field and both masses; above it, but a load (20 kg),
// a warning. Each command is given only what it reads before the check (no IMS record: the
// payload is checked before the long work).
using PayloadPlausibility = test_support::ScratchDirTest;

// `source` with the payload column (the second) of every data line set to `payload_kg`.
std::string with_payload(const fs::path& source, const std::string& payload_kg) {
  std::istringstream in(read_text(source));
  std::string out, line;
  while (std::getline(in, line)) {
    const auto first = line.find(','), second = line.find(',', first + 1);
    if (line.empty() || line[0] == '#' || line.rfind("t_s", 0) == 0 || second == std::string::npos)
      out += line + "\n";
    else
      out += line.substr(0, first + 1) + payload_kg + line.substr(second) + "\n";
  }
  return out;
}

TEST_F(PayloadPlausibility, RefusedFarAboveTheRatingInEveryCommandThatTakesAPayload) {
  const fs::path source(IMSCAL_SOURCE_DIR);
  const std::string robot = (source / "datasets/robots/kr16.yaml").string();
  const std::string sensor = (source / "datasets/sensors/navigation-grade.yaml").string();
  const fs::path log = dir_ / "robot.csv", errors = dir_ / "joint_errors.csv";
  std::ofstream(log) << with_payload(source / "fuzz/corpus/robot_log/valid.csv", "5000");
  std::ofstream(errors) << with_payload(source / "fuzz/corpus/joint_errors/small.csv", "5000");
  std::ofstream(dir_ / "calibrate.yaml")
      << "imscal-calibration-config: 1\npayload: {mass_kg: 5000}\n";
  struct Case {
    std::string name, arguments, file, field;
  };
  const std::vector<Case> cases = {
      {"calibrate config",
       "calibrate --imu none.csv --robot-log " + log.string() + " --robot " + robot + " --sensor " +
           sensor + " --config " + (dir_ / "calibrate.yaml").string(),
       "calibrate.yaml", "payload.mass_kg"},
      {"calibrate log",
       "calibrate --imu " + (source / "fuzz/corpus/imu_csv/increments.csv").string() +
           " --robot-log " + log.string() + " --robot " + robot + " --sensor " + sensor,
       "robot.csv", "payload_kg"},
      {"compensate log",
       "compensate --table " + (source / "fuzz/corpus/parameter_table/table.json").string() +
           " --robot-log " + log.string(),
       "robot.csv", "payload_kg"},
      {"identify",
       "identify --joint-errors " + errors.string() + " --config " +
           (source / "datasets/identification/ident-paper.yaml").string(),
       "joint_errors.csv", "payload_kg"},
      {"model-joint-errors",
       "model-joint-errors --joint-errors " + errors.string() + " --robot " + robot,
       "joint_errors.csv", "payload_kg"},
      {"diagnose",
       "diagnose --joint-errors " + errors.string() + " --robot " + robot + " --table " +
           (source / "fuzz/corpus/parameter_table/table.json").string(),
       "joint_errors.csv", "payload_kg"},
      {"verify", "verify --joint-errors " + errors.string() + " --scenario seed-line",
       "joint_errors.csv", "payload_kg"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path out = dir_ / ("out-" + c.name.substr(0, c.name.find(' '))),
                   message_file = dir_ / "message.log";
    EXPECT_EQ(run_imscal(c.arguments + " --out " + out.string(), message_file), 2);
    const std::string message = read_text(message_file);
    std::printf("%-20s %s", c.name.c_str(), message.c_str());
    EXPECT_NE(message.find(c.file), std::string::npos) << message;
    EXPECT_NE(message.find("field '" + c.field + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("payload 5000 kg"), std::string::npos) << message;
    EXPECT_NE(message.find("rated payload of 16 kg"), std::string::npos) << message;
    EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << "an output was left behind";
  }
}

// Above the rating but a load the robot can lift (20 kg on the 16 kg KR 16): the command runs and
// warns with the file, the field, both masses and what follows.
TEST_F(PayloadPlausibility, AboveTheRatingIsAWarningWithTheReason) {
  const fs::path source(IMSCAL_SOURCE_DIR), errors = dir_ / "joint_errors.csv";
  std::ofstream(errors) << with_payload(source / "fuzz/corpus/joint_errors/small.csv", "20");
  const fs::path log = dir_ / "message.log";
  EXPECT_EQ(run_imscal("model-joint-errors --joint-errors " + errors.string() + " --robot " +
                           (source / "datasets/robots/kr16.yaml").string() + " --out " +
                           (dir_ / "model.csv").string(),
                       log),
            0)
      << read_text(log);
  const std::string message = read_text(log);
  EXPECT_NE(message.find("[warning] " + errors.string() + ": field 'payload_kg': payload 20 kg"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("above the rated payload of 16 kg"), std::string::npos) << message;
  EXPECT_NE(message.find("outside their rating"), std::string::npos) << message;
}

// The scenario's program (simulate, verify, population and `imscal run` load it): refused naming
// the program file and the line of the mass; 20 kg (above the rating, a load) loads with a warning.
TEST_F(PayloadPlausibility, AScenariosProgramPayloadIsCheckedAgainstThePlantRobot) {
  const fs::path source(IMSCAL_SOURCE_DIR);
  const auto scenario_with_payload = [&](const std::string& mass_kg) {
    std::ofstream(dir_ / "program.yaml")
        << "name: carry\nstart_joints_deg: [0, -90, 90, 0, 0, 0]\n"
           "joint_acceleration_deg_s2: [100, 100, 100, 100, 100, 100]\n"
           "payload: {name: box, mass_kg: "
        << mass_kg << "}\nsegments:\n  - rest: {duration_s: 1}\n";
    std::ofstream(dir_ / "scenario.yaml")
        << "imscal-scenario: 1\nname: carry\nrobot: "
        << (source / "datasets/robots/kr16.yaml").string() << "\nprogram: program.yaml\nsensor: "
        << (source / "datasets/sensors/navigation-grade.yaml").string()
        << "\nimu: {rate_hz: 1000}\nsite: {latitude_deg: 48.78, longitude_deg: 9.18, height_m: "
           "245}\nbase_in_world: {xyz_m: [0, 0, 0], rpy_deg: [0, 0, 0]}\n";
    return dir_ / "scenario.yaml";
  };
  try {
    sim::load_scenario(scenario_with_payload("5000"));
    ADD_FAILURE() << "5000 kg accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(fs::path(e.file()).filename(), "program.yaml") << e.what();
    EXPECT_EQ(e.line(), 4u) << e.what();
    EXPECT_EQ(e.field(), "payload.mass_kg") << e.what();
    EXPECT_NE(std::string(e.what()).find("rated payload of 16 kg"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(sim::load_scenario(scenario_with_payload("20")));
}

}  // namespace
}  // namespace imscal
