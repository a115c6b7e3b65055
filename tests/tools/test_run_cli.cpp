// `imscal run` end to end on a small campaign (tests/tools/run_campaign.hpp): the chain
// validate -> identify -> report, exit codes 0/1/2 with their reasons, a second run with nothing
// changed skips every stage and is fast, a changed input reruns its stage and the report, and a
// run killed (SIGKILL) during identification resumes to the same outputs as an uninterrupted run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/run_campaign.hpp"

namespace {
namespace fs = std::filesystem;
using imscal::test_support::read_text;
using imscal::test_support::run_imscal;
using nlohmann::json;

class RunCli : public imscal::test_support::ScratchDirTest {
 protected:
  int run(const fs::path& config, const fs::path& out, const std::string& extra = "") {
    return run_imscal("run " + config.string() + " --out " + out.string() + " " + extra,
                      dir_ / "log.txt");
  }
  std::string log() { return read_text(dir_ / "log.txt"); }
  static std::string stage_line(const std::string& log, const std::string& stage) {
    // The summary lines on stdout: "<stage padded> <what> <status> <seconds> s <message>".
    const auto at = log.find("\n" + stage + " ");
    if (at == std::string::npos) return "";
    return log.substr(at + 1, log.find('\n', at + 1) - at - 1);
  }
  // identification_report.json holds run times ("seconds"); everything else must be equal.
  static json without_seconds(json value) {
    if (value.is_object()) {
      value.erase("seconds");
      for (auto& [key, item] : value.items()) item = without_seconds(item);
    } else if (value.is_array()) {
      for (auto& item : value) item = without_seconds(item);
    }
    return value;
  }
  static void expect_same_outputs(const fs::path& a, const fs::path& b) {
    for (const char* file : {"validate/validation.json", "identify/parameters.json",
                             "identify/parameters.csv", "report/report.html"})
      EXPECT_EQ(read_text(a / file), read_text(b / file)) << file;
    EXPECT_EQ(without_seconds(json::parse(read_text(a / "identify/identification_report.json"))),
              without_seconds(json::parse(read_text(b / "identify/identification_report.json"))));
  }
};

TEST_F(RunCli, RunsTheChainThenSkipsItThenRerunsWhatChanged) {
  const fs::path config = imscal::test_support::write_campaign(dir_);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run(config, out), 0) << log();
  for (const char* stage : {"validate", "identify", "report"}) {
    EXPECT_NE(stage_line(log(), stage).find(" ran "), std::string::npos) << log();
    EXPECT_TRUE(fs::exists(out / stage / "stage.json")) << stage;
  }
  EXPECT_TRUE(fs::exists(out / "run.log"));
  // The table is the one `imscal identify` writes, from the configured data.
  const auto table = imscal::ident::read_parameters_json(out / "identify" / "parameters.json");
  EXPECT_EQ(table.joints.size(), 2u);
  const json record = json::parse(read_text(out / "identify" / "stage.json"));
  EXPECT_EQ(record["status"], "ok");
  EXPECT_EQ(record["inputs"]["files"][0]["sha256"], table.source.sha256);
  const json validation = json::parse(read_text(out / "validate" / "validation.json"));
  EXPECT_EQ(validation["robot_log"]["samples"], 10001);
  // The robot log spans 0..20 s; the IMS record starts at or before 0 and lasts 60 s.
  EXPECT_NEAR(validation["overlap"]["duration_s"].get<double>(), 20.0, 0.01);

  const auto record_time = fs::last_write_time(out / "identify" / "stage.json");
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run(config, out), 0) << log();
  const double second_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const char* stage : {"validate", "identify", "report"})
    EXPECT_NE(stage_line(log(), stage).find("skipped"), std::string::npos) << log();
  EXPECT_EQ(fs::last_write_time(out / "identify" / "stage.json"), record_time);
  // The goal "second run < 5 s" is a speed goal: printed here, not asserted (a timed assertion
  // fails on a loaded machine or under the sanitizers, 7.8 s seen under ASan with -j2). What
  // this test asserts is the cause of the speed: every stage skipped, no record rewritten.
  std::printf("second run with nothing changed: %.2f s\n", second_s);

  // A changed identification config: identify and the report rerun, validate does not.
  std::ofstream(dir_ / "ident.yaml", std::ios::app) << "# a comment changes the bytes\n";
  ASSERT_EQ(run(config, out), 0) << log();
  EXPECT_NE(stage_line(log(), "validate").find("skipped"), std::string::npos) << log();
  EXPECT_NE(stage_line(log(), "identify").find(" ran "), std::string::npos) << log();
  // Same data, same model: identify's tables are the same bytes, its report's run times are
  // not, so the report (which reads the stage records) reruns.
  EXPECT_NE(stage_line(log(), "report").find(" ran "), std::string::npos) << log();
}

TEST_F(RunCli, ExitCodesNameTheReason) {
  // 2: an unknown key, with file, line and key.
  const fs::path config = imscal::test_support::write_campaign(dir_, "reprot: {}\n");
  EXPECT_EQ(run(config, dir_ / "out"), 2) << log();
  EXPECT_NE(log().find("run.yaml:9"), std::string::npos) << log();
  EXPECT_NE(log().find("reprot"), std::string::npos) << log();
  EXPECT_FALSE(fs::exists(dir_ / "out"));

  // 1: clocks overlap less than required; the report still says why.
  const fs::path strict =
      imscal::test_support::write_campaign(dir_, "validate:\n  min_overlap_s: 30\n");
  EXPECT_EQ(run(strict, dir_ / "strict"), 1) << log();
  EXPECT_NE(log().find("check failed: validate: IMS record and robot log overlap"),
            std::string::npos)
      << log();
  EXPECT_FALSE(fs::exists(dir_ / "strict" / "identify"));
  const std::string report = read_text(dir_ / "strict" / "report" / "report.html");
  EXPECT_NE(report.find("less than validate.min_overlap_s = 30 s"), std::string::npos);
  EXPECT_NE(report.find("the identify stage did not run"), std::string::npos);

  // 2: a robot log that does not overlap the IMS record at all (shifted by 1000 s).
  std::string robot = read_text(dir_ / "robot.csv");
  std::ofstream shifted(dir_ / "robot.csv");
  std::istringstream lines(robot);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && std::isdigit(static_cast<unsigned char>(line[0]))) {
      const auto comma = line.find(',');
      line = std::to_string(std::stod(line.substr(0, comma)) + 1000.0) + line.substr(comma);
    }
    shifted << line << "\n";
  }
  shifted.close();
  EXPECT_EQ(run(config.parent_path() / "run.yaml", dir_ / "apart", "--force"), 2) << log();
  EXPECT_NE(log().find("do not overlap in time"), std::string::npos) << log();
  EXPECT_FALSE(fs::exists(dir_ / "apart" / "validate"));
}

// A log in which no joint moved: the identify stage's table would correct nothing, so the run
// ends with a failed check (exit 1) that says why, instead of "identify: ok".
TEST_F(RunCli, IdentificationThatCorrectsNothingIsAFailedCheck) {
  const fs::path config = imscal::test_support::write_campaign(dir_);
  imscal::ident::JointErrorLog errors =
      imscal::ident::read_joint_errors_csv(dir_ / "joint_errors.csv");
  for (std::size_t j = 0; j < errors.joint_count(); ++j) {
    std::fill(errors.q_desired_rad[j].begin(), errors.q_desired_rad[j].end(), 0.25);
    std::fill(errors.q_internal_rad[j].begin(), errors.q_internal_rad[j].end(), 0.25);
    std::fill(errors.q_measured_rad[j].begin(), errors.q_measured_rad[j].end(), 0.2501);
  }
  fs::remove(dir_ / "joint_errors.csv");
  imscal::ident::write_joint_errors_csv(dir_ / "joint_errors.csv", errors);
  EXPECT_EQ(run(config, dir_ / "out"), 1) << log();
  EXPECT_NE(log().find("no joint could be identified"), std::string::npos) << log();
  // The refusal names files the user can find, not the stage's hidden staging folder.
  const std::string text = log();
  const auto at = text.find("no joint could be identified");
  const std::string refusal = text.substr(text.rfind('\n', at) + 1, text.find('\n', at) - at);
  EXPECT_EQ(refusal.find(".staging-"), std::string::npos) << refusal;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "identify" / "parameters.json"));
}

// A stage that fails (here identify's first output cannot be written: a file-size limit,
// RLIMIT_FSIZE with SIGXFSZ ignored, stands in for a full disk) is reported with the file the
// user will look for, <run>/identify/..., and the system's reason: never the stage's hidden
// staging folder, which is gone when the message is read.
TEST_F(RunCli, AFailedStagesMessageNamesNoVanishedStagingFolder) {
  const fs::path config = imscal::test_support::write_campaign(dir_), out = dir_ / "out";
  // 32 KiB (ulimit counts 512-byte blocks in sh): the identification report is larger, run.log
  // and the validate stage's files are not.
  const std::string limited = "sh -c 'trap \"\" XFSZ; ulimit -f 64; " + std::string(IMSCAL_BINARY) +
                              " run " + config.string() + " --out " + out.string() +
                              "; echo exit=$?' 2>&1 | cat > " + (dir_ / "log.txt").string();
  ASSERT_EQ(std::system(limited.c_str()), 0);
  const std::string text = log();
  EXPECT_NE(text.find("exit=3"), std::string::npos) << text;
  EXPECT_NE(text.find((out / "identify" / "identification_report.json").string()),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("File too large"), std::string::npos) << text;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("[error]") != std::string::npos) {
      EXPECT_EQ(line.find(".staging-"), std::string::npos) << line;
    }
  }
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_NE(e.path().filename().string().rfind(".staging-", 0), 0u) << e.path();
  }
  EXPECT_FALSE(fs::exists(out / "identify"));
}

TEST_F(RunCli, KilledDuringIdentificationResumesToTheSameOutputs) {
  const fs::path config = imscal::test_support::write_campaign(dir_);
  const fs::path reference = dir_ / "reference", out = dir_ / "out";
  ASSERT_EQ(run(config, reference), 0) << log();

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string log_file = (dir_ / "killed.txt").string();
    const int fd = ::open(log_file.c_str(), O_CREAT | O_WRONLY | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(IMSCAL_BINARY, IMSCAL_BINARY, "run", config.c_str(), "--out", out.c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Kill as soon as `imscal identify` works in the staging folder (its outputs half there or not).
  bool in_identify = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!in_identify && std::chrono::steady_clock::now() < deadline) {
    std::error_code ignored;
    for (const auto& e : fs::directory_iterator(out, ignored))
      in_identify |= e.path().filename().string().rfind(".staging-identify-", 0) == 0;
    if (!in_identify) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(in_identify) << read_text(dir_ / "killed.txt");
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before it was killed";
  EXPECT_TRUE(fs::exists(out / "validate" / "stage.json"));
  EXPECT_FALSE(fs::exists(out / "identify"));
  EXPECT_FALSE(fs::exists(out / "report"));

  ASSERT_EQ(run(config, out), 0) << log();
  EXPECT_NE(stage_line(log(), "validate").find("skipped"), std::string::npos) << log();
  EXPECT_NE(stage_line(log(), "identify").find(" ran "), std::string::npos) << log();
  expect_same_outputs(reference, out);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_NE(e.path().filename().string().rfind(".staging-", 0), 0u) << e.path();
}

}  // namespace
