// `imscal verify`, `imscal evaluate` and `imscal compensate` end to end: with a table whose models
// predict no error the compensated runs equal the uncompensated ones (reduction 0), every output
// file is written, `imscal evaluate` on the written path files gives the same AT_p as `verify`
// computed in memory, and `compensate` writes zero offsets, or refuses a table for another robot
// with exit code 2 and no output.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "ident/parameter_table_io.hpp"
#include "robot/robot_log.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/scenario.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using VerifyCli = test_support::ScratchDirTest;

constexpr auto* run = &imscal::test_support::run_imscal;

using imscal::test_support::read_text;

// q̂ = q_d for every joint: no offset at all.
ident::ParameterTable zero_error_table(const std::string& robot) {
  ident::ParameterTable table;
  table.robot = robot;
  table.sample_time_s = 0.002;
  table.created_by = "test";
  table.source = {"none", std::string(64, '0'), 0, "hand-made"};
  for (int j = 0; j < 6; ++j) {
    ident::JointParameters joint;
    joint.name = fmt::format("A{}", j + 1);
    joint.dimensions = {{ident::OperatingQuantity::kSpeed, {0.0, 100.0}}};
    ident::CellParameters cell;
    cell.bands = {0};
    cell.structure.na = 0;
    cell.structure.nb = 1;
    cell.structure.dead_time = 0;
    cell.b = {1.0};
    joint.cells.push_back(cell);
    table.joints.push_back(joint);
  }
  return table;
}

TEST_F(VerifyCli, ZeroTableVerifiesUnchangedAndEvaluateAgrees) {
  const fs::path table = dir_ / "zero.json", out = dir_ / "out";
  ident::write_parameters_json(table, zero_error_table("kr16"));
  ASSERT_EQ(run("verify --table " + table.string() +
                    " --scenario seed-line --segments 'line -y' --cycles 2 --out " + out.string(),
                dir_ / "verify.log"),
            0)
      << read_text(dir_ / "verify.log");
  const fs::path s = out / "seed-line";
  for (const char* f :
       {"verification.json", "verification.csv", "verification.txt", "fig5_paths.csv",
        "fig6_deviation.csv", "fig5.gp", "fig6.gp", "commanded.csv", "attained_uncompensated_0.csv",
        "attained_uncompensated_1.csv", "attained_compensated_1.csv"}) {
    EXPECT_TRUE(fs::exists(s / f)) << f;
  }
  // Again without --force: refused before any work (exit 2), naming the existing output.
  const std::string earlier = read_text(s / "verification.json");
  EXPECT_EQ(run("verify --table " + table.string() + " --scenario seed-line --out " + out.string(),
                dir_ / "again.log"),
            2);
  EXPECT_NE(
      read_text(dir_ / "again.log").find((s / "verification.json").string() + ": field '--out'"),
      std::string::npos)
      << read_text(dir_ / "again.log");
  EXPECT_EQ(read_text(s / "verification.json"), earlier);
  const auto doc = nlohmann::json::parse(earlier);
  ASSERT_EQ(doc["cases"].size(), 2u);
  const auto& before = doc["cases"][0];
  const auto& after = doc["cases"][1];
  // Zero offsets: the same deterministic runs, so exactly the same figures.
  EXPECT_EQ(before["max_path_deviation_mm"], after["max_path_deviation_mm"]);
  EXPECT_EQ(after["reduction_of_max_path_deviation_percent"].get<double>(), 0.0);
  EXPECT_GT(before["max_path_deviation_mm"].get<double>(), 1.0);  // the uncalibrated robot errs
  // The cycles' scatter floor (eval::scatter_floor_m): the same for both, under the maximum, and
  // in the text report.
  EXPECT_EQ(before["scatter_floor_mm"], after["scatter_floor_mm"]);
  EXPECT_LE(before["scatter_floor_mm"].get<double>(),
            before["max_path_deviation_mm"].get<double>());
  EXPECT_GT(before["scatter_floor_mm"].get<double>(), 0.0);  // friction drawn anew per cycle
  EXPECT_NE(read_text(s / "verification.txt").find("Scatter floor"), std::string::npos);

  // `imscal evaluate` on the written files over the evaluated segment, same window.
  ASSERT_EQ(
      run(fmt::format("evaluate --commanded {} --attained {} --attained {} --from-s {} "
                      "--to-s {} --window-s 0.25 --out {}",
                      (s / "commanded.csv").string(), (s / "attained_uncompensated_0.csv").string(),
                      (s / "attained_uncompensated_1.csv").string(),
                      doc["evaluated_from_s"].get<double>() - 1e-6,
                      doc["evaluated_to_s"].get<double>() + 1e-6, (dir_ / "figures.json").string()),
          dir_ / "evaluate.log"),
      0)
      << read_text(dir_ / "evaluate.log");
  const auto figures = nlohmann::json::parse(read_text(dir_ / "figures.json"));
  // Same commanded samples and crossings; only the 17-digit round trip of the files differs.
  EXPECT_NEAR(figures["AT_p_mm"].get<double>(), before["AT_p_mm"].get<double>(), 1e-6);
  EXPECT_NEAR(figures["RT_p_mm"].get<double>(), before["RT_p_mm"].get<double>(), 1e-6);
  // Refuses to overwrite without --force, and names the file.
  EXPECT_EQ(
      run(fmt::format("evaluate --commanded {} --attained {} --out {}",
                      (s / "commanded.csv").string(), (s / "attained_uncompensated_0.csv").string(),
                      (dir_ / "figures.json").string()),
          dir_ / "again.log"),
      2);
}

// Every regular file below `folder` (relative path -> content).
std::map<std::string, std::string> files_below(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder))
    if (e.is_regular_file()) files[fs::relative(e.path(), folder).string()] = read_text(e.path());
  return files;
}

// All or nothing: a rerun whose writes fail leaves every earlier output as it was and names the
// target, never the staging copy. A file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored: EFBIG as a
// full disk's ENOSPC) of 8 KiB, below the size of the path files, stands in for a full disk; the
// rerun draws other friction (--seed), so that every file it would write differs.
TEST_F(VerifyCli, AFailingWriteLeavesTheEarlierOutputsAsTheyWere) {
  const fs::path table = dir_ / "zero.json", out = dir_ / "out";
  ident::write_parameters_json(table, zero_error_table("kr16"));
  const std::string arguments = "verify --table " + table.string() +
                                " --scenario seed-line --segments \"line -y\" --cycles 1 --out " +
                                out.string();
  ASSERT_EQ(run(arguments, dir_ / "verify.log"), 0) << read_text(dir_ / "verify.log");
  const auto before = files_below(out);
  ASSERT_GE(before.size(), 9u);  // scenario files, path files of one cycle before and after
  const std::string limited = "sh -c 'trap \"\" XFSZ; ulimit -f 16; " + std::string(IMSCAL_BINARY) +
                              " " + arguments + " --seed 7 --force; echo exit=$?' > " +
                              (dir_ / "limited.log").string() + " 2>&1";
  ASSERT_EQ(std::system(limited.c_str()), 0);
  const std::string message = read_text(dir_ / "limited.log");
  EXPECT_NE(message.find("exit=3"), std::string::npos) << message;
  EXPECT_NE(message.find("File too large"), std::string::npos) << message;
  // It names what it could not write: the target, or the smoother's temporary file for its
  // covariances (core/record_file.hpp), which a disk this full refuses before any output.
  const bool names_target = message.find((out / "seed-line").string()) != std::string::npos;
  const bool names_smoother = message.find("smoother's covariances") != std::string::npos;
  EXPECT_TRUE(names_target || names_smoother) << message;
  EXPECT_EQ(message.find(".imscal-staging-"), std::string::npos) << message;
  EXPECT_EQ(files_below(out), before);  // no staging copy left either
}

TEST_F(VerifyCli, CompensateWritesOffsetsOrRefusesAnotherRobotsTable) {
  const sim::Scenario scenario = sim::load_scenario(sim::resolve_scenario("seed-line"));
  const calib::RobotDescription robot = sim::load_nominal_robot(scenario).description;
  const sim::DesiredJointPath path =
      sim::plan_motion(robot, sim::load_motion_program(scenario.program_file));
  calib::RobotLog log;
  log.robot_name = robot.name;
  log.cycle_s = path.cycle_s;
  for (std::size_t k = 0; k < path.samples.size() && path.samples[k].t_s <= 7.0; ++k) {
    log.samples.push_back({path.samples[k].t_s, 5.0, path.samples[k].q_rad, path.samples[k].q_rad});
  }
  calib::write_robot_log_csv(dir_ / "robot.csv", log, Overwrite::kAllow);
  ident::write_parameters_json(dir_ / "zero.json", zero_error_table("kr16"));
  ASSERT_EQ(run("compensate --table " + (dir_ / "zero.json").string() + " --robot-log " +
                    (dir_ / "robot.csv").string() + " --out " + (dir_ / "offsets.csv").string(),
                dir_ / "compensate.log"),
            0)
      << read_text(dir_ / "compensate.log");
  std::ifstream in(dir_ / "offsets.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("t_s", 0) == 0) continue;
    ++rows;
    // t, state, outside_table, then six offsets: all exactly 0 with this table; engaging for the
    // first 0.4 s (settle and fade-in), active afterwards.
    const bool early = rows <= 210;  // 200 cycles of 2 ms, and rounding of the sum
    EXPECT_TRUE(line.find(",active,0,0,0,0,0,0,0") != std::string::npos ||
                (early && line.find(",engaging,0,0,0,0,0,0,0") != std::string::npos))
        << line;
  }
  EXPECT_EQ(rows, log.samples.size());
  ident::write_parameters_json(dir_ / "other.json", zero_error_table("other"));
  EXPECT_EQ(run("compensate --table " + (dir_ / "other.json").string() + " --robot-log " +
                    (dir_ / "robot.csv").string() + " --out " + (dir_ / "other.csv").string(),
                dir_ / "other.log"),
            2)
      << read_text(dir_ / "other.log");
  EXPECT_FALSE(fs::exists(dir_ / "other.csv"));
  // The refusal names the table as the robot's source, not "the robot description".
  EXPECT_NE(read_text(dir_ / "other.log").find("the parameter table"), std::string::npos)
      << read_text(dir_ / "other.log");
  // A missing output folder is created, as every command creates its --out folder.
  EXPECT_EQ(run("compensate --table " + (dir_ / "zero.json").string() + " --robot-log " +
                    (dir_ / "robot.csv").string() + " --out " +
                    (dir_ / "new" / "folder" / "offsets.csv").string(),
                dir_ / "new_folder.log"),
            0)
      << read_text(dir_ / "new_folder.log");
  EXPECT_TRUE(fs::is_regular_file(dir_ / "new" / "folder" / "offsets.csv"));
}

}  // namespace
}  // namespace imscal
