// robot.csv: exact round trip, degrees converted, and every bad log in
// tests/data/bad_inputs/robot/ (made by make_cases.py there) refused with the file, line, field
// and message its NAME.expected states.
#include "robot/robot_log.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;
using RobotLogTest = test_support::ScratchDirTest;

RobotLog random_log(std::size_t rows) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  RobotLog log;
  log.robot_name = "kr16";
  log.cycle_s = 0.002;
  for (std::size_t k = 0; k < rows; ++k) {
    RobotLogSample s;
    s.t_s = 12.5 + 0.002 * static_cast<double>(k);
    s.payload_kg = k < rows / 2 ? 5.0 : 16.0;
    for (int j = 0; j < kJointCount; ++j) {
      s.q_desired_rad[j] = angle(rng);
      s.q_internal_rad[j] = angle(rng);
    }
    log.samples.push_back(s);
  }
  return log;
}

TEST_F(RobotLogTest, RoundTripIsExact) {
  const RobotLog log = random_log(500);
  write_robot_log_csv(dir_ / "robot.csv", log, Overwrite::kRefuse);
  // Read into memory and into a temporary file (as calibrate reads): the same samples.
  for (const bool samples_to_file : {false, true}) {
    const RobotLog back =
        read_robot_log_csv(dir_ / "robot.csv", "kr16", "the robot description", samples_to_file);
    EXPECT_EQ(back.samples.on_file(), samples_to_file);
    ASSERT_EQ(back.samples.size(), log.samples.size());
    EXPECT_EQ(back.robot_name, "kr16");
    EXPECT_EQ(back.cycle_s, 0.002);
    for (std::size_t k = 0; k < log.samples.size(); ++k) {
      // Shortest round-trip formatting: bit-identical doubles.
      EXPECT_EQ(back.samples[k].t_s, log.samples[k].t_s);
      EXPECT_EQ(back.samples[k].payload_kg, log.samples[k].payload_kg);
      EXPECT_EQ(back.samples[k].q_desired_rad, log.samples[k].q_desired_rad);
      EXPECT_EQ(back.samples[k].q_internal_rad, log.samples[k].q_internal_rad);
    }
  }
  // An existing log is not overwritten by accident.
  EXPECT_THROW(write_robot_log_csv(dir_ / "robot.csv", log, Overwrite::kRefuse), std::exception);
}

TEST_F(RobotLogTest, DegreeColumnsAreConverted) {
  std::ofstream fix(dir_ / "deg.csv");
  fix << "# imscal-robot-log: 1\n# robot: kr16\n# cycle_s: 0.004\nt_s,payload_kg";
  for (const char* p : {"q_desired", "q_internal"}) {
    for (int j = 1; j <= 6; ++j) fix << "," << p << "_A" << j << "_deg";
  }
  fix << "\n0,0,90,-90,180,45,30,1,90,-90,180,45,30,1\n"
         "0.004,0,90,-90,180,45,30,1,90,-90,180,45,30,1\n";
  fix.close();
  const RobotLog log = read_robot_log_csv(dir_ / "deg.csv");
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_DOUBLE_EQ(log.samples[1].q_desired_rad[0], M_PI / 2);  // 90 deg, one rounding
  EXPECT_DOUBLE_EQ(log.samples[1].q_internal_rad[2], M_PI);
  EXPECT_EQ(log.cycle_s, 0.004);
}

struct Expected {
  std::size_t line = 0;
  std::string field, contains;
};

Expected load_expected(const fs::path& file) {
  std::ifstream in(file);
  Expected e;
  std::string text;
  while (std::getline(in, text)) {
    if (text.starts_with("line: ")) e.line = std::stoul(text.substr(6));
    if (text.starts_with("field: ")) e.field = text.substr(7);
    if (text.starts_with("field:") && text.size() == 6) e.field.clear();
    if (text.starts_with("contains: ")) e.contains = text.substr(10);
  }
  return e;
}

TEST(RobotLogBadInputs, EveryCaseIsRefusedWithFileLineAndField) {
  const fs::path folder = fs::path(IMSCAL_TEST_DATA_DIR) / "bad_inputs" / "robot";
  int cases = 0;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".csv") continue;
    ++cases;
    const fs::path file = entry.path();
    const Expected expected = load_expected(fs::path(file).replace_extension(".expected"));
    // The same refusal with the samples read into a temporary file (as calibrate reads).
    for (const bool samples_to_file : {false, true}) {
      SCOPED_TRACE(file.filename().string() + (samples_to_file ? ", to a file" : ""));
      try {
        read_robot_log_csv(file, "kr16", "the robot description", samples_to_file);
        ADD_FAILURE() << "accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(e.file(), file.string());
        EXPECT_EQ(e.line(), expected.line) << e.what();
        EXPECT_EQ(e.field(), expected.field) << e.what();
        EXPECT_NE(std::string(e.what()).find(expected.contains), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_EQ(cases, 23);  // make_cases.py writes 23: none may go missing silently
}

// Two faults in one file: the rows are read as they come, but the log's own checks speak only
// once the file's structure is checked to its end, so the first error is the one a whole table
// read first gave. The line and field of each are known from the file written here.
TEST_F(RobotLogTest, TheFirstOfTwoFaultsIsTheOneTheTableGave) {
  const auto write = [&](const std::string& name, const std::string& robot,
                         const std::vector<std::string>& rows) {
    std::ofstream out(dir_ / name);
    out << "# imscal-robot-log: 1\n# robot: " << robot << "\n# cycle_s: 0.002\nt_s,payload_kg";
    for (const char* p : {"q_desired", "q_internal"})
      for (int j = 1; j <= 6; ++j) out << "," << p << "_A" << j << "_rad";
    out << "\n";  // header on line 4, rows from line 5
    for (const std::string& row : rows) out << row << ",0,0,0,0,0,0,0,0,0,0,0,0\n";
    return dir_ / name;
  };
  const auto refusal = [](const fs::path& file) {
    try {
      read_robot_log_csv(file, "kr16");
    } catch (const InputError& e) {
      return std::pair(e.line(), e.field());
    }
    return std::pair(std::size_t{0}, std::string("accepted"));
  };
  // Another robot (header) and a word in a later row (structure): the structure first.
  EXPECT_EQ(refusal(write("robot_then_word.csv", "kr6", {"0,0", "0.002,x", "0.004,0"})),
            std::pair(std::size_t{6}, std::string("payload_kg")));
  // A negative payload on line 6 and a gap on line 8: the earlier row's.
  EXPECT_EQ(refusal(write("payload_then_gap.csv", "kr16", {"0,0", "0.002,-1", "0.004,0", "0.1,0"})),
            std::pair(std::size_t{6}, std::string("payload_kg")));
  // A gap on line 7 and a word on line 8: the word (structure) first.
  EXPECT_EQ(refusal(write("gap_then_word.csv", "kr16", {"0,0", "0.002,0", "0.1,0", "0.102,y"})),
            std::pair(std::size_t{8}, std::string("payload_kg")));
  // Another robot alone: the header's error, on its line.
  EXPECT_EQ(refusal(write("robot.csv", "kr6", {"0,0", "0.002,0"})),
            std::pair(std::size_t{2}, std::string("robot")));
}

TEST(RobotLogBadInputs, MissingFileIsAnInputError) {
  EXPECT_THROW(read_robot_log_csv("/nonexistent/robot.csv"), InputError);
}

}  // namespace
}  // namespace imscal::calib
