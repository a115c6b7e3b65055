// The run-folder framework (core/run_stage.hpp) with small stages of known behaviour: unchanged
// inputs skip a stage (its record and outputs untouched, the second run fast); a changed input
// reruns the stage and its downstream stages, but a downstream stage whose upstream outputs did
// not change stays skipped; a run killed (SIGKILL) in the middle of a stage leaves no visible
// half-written folder and, resumed, gives the same bytes as an uninterrupted run; failures and
// refusals leave nothing behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <map>
#include <thread>

#include "core/input_error.hpp"
#include "core/run_record.hpp"
#include "core/run_stage.hpp"
#include "core/sha256.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/stage_outcome.hpp"
#include "tests/support/text_file.hpp"

namespace {
namespace fs = std::filesystem;
using imscal::RunOptions;
using imscal::RunSummary;
using imscal::Stage;
using imscal::StageInputs;
using imscal::StageOutcome;
using imscal::StageRun;
using imscal::StageStatus;
using imscal::StageWorkspace;
using imscal::test_support::read_text;
using imscal::test_support::stage_outcome;
using imscal::test_support::write_text;

// "upper": the input file in upper case, in two files (part1 = first half, part2 = rest). With
// a pause file set it writes part1, creates the pause file and sleeps, to be killed there.
class UpperStage : public Stage {
 public:
  UpperStage(fs::path input, std::string mode) : input_(std::move(input)), mode_(std::move(mode)) {}
  std::string name() const override { return "upper"; }
  StageInputs inputs() const override {
    StageInputs in;
    in.files.emplace_back("text", input_);
    in.config = {{"mode", mode_}};
    return in;
  }
  StageOutcome run(StageWorkspace& ws) override {
    ++runs;
    std::string text = read_text(input_);
    for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (mode_ == "reverse") std::reverse(text.begin(), text.end());
    write_text(ws.output_dir() / "part1.txt", text.substr(0, text.size() / 2));
    if (!pause_file.empty()) {
      write_text(pause_file, "paused");
      std::this_thread::sleep_for(std::chrono::seconds(30));  // killed long before
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(work_ms));
    fs::create_directories(ws.output_dir() / "sub");
    write_text(ws.output_dir() / "sub" / "part2.txt", text.substr(text.size() / 2));
    return {};
  }
  int runs = 0;
  int work_ms = 0;
  fs::path pause_file;

 private:
  fs::path input_;
  std::string mode_;
};

// "count": the number of characters upper wrote; fails its check when asked to.
class CountStage : public Stage {
 public:
  std::string name() const override { return "count"; }
  StageInputs inputs() const override {
    StageInputs in;
    in.upstream = {"upper"};
    in.config = {{"limit", limit}};
    return in;
  }
  StageOutcome run(StageWorkspace& ws) override {
    ++runs;
    const auto up = ws.upstream_dir("upper");
    if (!up) throw std::logic_error("count: upper did not run");
    const std::size_t n =
        read_text(*up / "part1.txt").size() + read_text(*up / "sub" / "part2.txt").size();
    write_text(ws.output_dir() / "count.txt", std::to_string(n) + "\n");
    StageOutcome outcome;
    if (static_cast<long>(n) > limit) {
      outcome.status = StageStatus::kCheckFailed;
      outcome.message = "too long";
    }
    return outcome;
  }
  int runs = 0;
  long limit = 1000;
};

// "summary": lists what it saw upstream; runs even after a failed check.
class SummaryStage : public Stage {
 public:
  std::string name() const override { return "summary"; }
  StageInputs inputs() const override {
    StageInputs in;
    in.upstream = {"upper", "count"};
    return in;
  }
  StageOutcome run(StageWorkspace& ws) override {
    ++runs;
    std::string text;
    for (const char* s : {"upper", "count"})
      text += std::string(s) + (ws.upstream_dir(s) ? " present\n" : " not run\n");
    write_text(ws.output_dir() / "summary.txt", text);
    return {};
  }
  bool runs_after_failed_check() const override { return true; }
  int runs = 0;
};

class RunStageTest : public imscal::test_support::ScratchDirTest {
 protected:
  void SetUp() override {
    ScratchDirTest::SetUp();
    input_ = dir_ / "input.txt";
    write_text(input_, "hello run folder\n");
    write_text(dir_ / "config.yaml", "# stands for the run config\n");
  }

  struct Chain {
    std::vector<std::unique_ptr<Stage>> stages;
    UpperStage* upper;
    CountStage* count;
    SummaryStage* summary;
  };
  Chain chain(const std::string& mode = "plain") const {
    Chain c;
    auto upper = std::make_unique<UpperStage>(input_, mode);
    auto count = std::make_unique<CountStage>();
    auto summary = std::make_unique<SummaryStage>();
    c.upper = upper.get();
    c.count = count.get();
    c.summary = summary.get();
    c.stages.push_back(std::move(upper));
    c.stages.push_back(std::move(count));
    c.stages.push_back(std::move(summary));
    return c;
  }
  RunOptions options(const fs::path& folder, bool force = false) const {
    RunOptions o;
    o.folder = folder;
    o.config_file = dir_ / "config.yaml";
    o.tool_version = "imscal test";
    o.force = force;
    return o;
  }
  // Every file of the run folder except records, the log and the lock: name -> bytes.
  static std::map<std::string, std::string> outputs(const fs::path& folder) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(folder)) {
      const std::string rel = fs::relative(e.path(), folder).generic_string();
      if (!e.is_regular_file() || e.path().filename() == "stage.json" || rel == "run.log" ||
          rel == "run.json" || rel == ".imscal-run.lock")
        continue;
      files[rel] = read_text(e.path());
    }
    return files;
  }
  fs::path input_;
};

TEST_F(RunStageTest, UnchangedInputsAreSkippedWithRecordsUntouched) {
  auto c = chain();
  c.upper->work_ms = 400;  // a stage with real work, so that skipping shows in the time
  const fs::path run = dir_ / "run";
  const auto t0 = std::chrono::steady_clock::now();
  const RunSummary first = imscal::run_stages(c.stages, options(run));
  const double first_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const char* s : {"upper", "count", "summary"})
    EXPECT_EQ(stage_outcome(first, s), StageRun::What::kRan);
  EXPECT_FALSE(first.failed_check());
  EXPECT_EQ(read_text(run / "upper" / "part1.txt") + read_text(run / "upper" / "sub" / "part2.txt"),
            "HELLO RUN FOLDER\n");
  EXPECT_EQ(read_text(run / "count" / "count.txt"), "17\n");
  EXPECT_TRUE(fs::exists(run / "run.log"));

  std::map<std::string, std::string> records;
  std::map<std::string, fs::file_time_type> times;
  for (const char* s : {"upper", "count", "summary"}) {
    records[s] = read_text(run / s / "stage.json");
    times[s] = fs::last_write_time(run / s / "stage.json");
  }
  const auto part1_time = fs::last_write_time(run / "upper" / "part1.txt");
  const auto t1 = std::chrono::steady_clock::now();
  const RunSummary second = imscal::run_stages(c.stages, options(run));
  const double second_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  for (const char* s : {"upper", "count", "summary"}) {
    EXPECT_EQ(stage_outcome(second, s), StageRun::What::kSkipped) << s;
    EXPECT_EQ(read_text(run / s / "stage.json"), records[s]) << s;  // started/finished times too
    EXPECT_EQ(fs::last_write_time(run / s / "stage.json"), times[s]) << s;
  }
  EXPECT_EQ(fs::last_write_time(run / "upper" / "part1.txt"), part1_time);
  EXPECT_EQ(c.upper->runs, 1);
  EXPECT_EQ(c.count->runs, 1);
  // The first run slept 400 ms in "upper"; the second only checksums a few small files. The
  // bound leaves 300 ms for the checksums and the log even under the sanitizers.
  EXPECT_GT(first_s, 0.4);
  EXPECT_LT(second_s, 0.3) << "first run " << first_s << " s";
  // --force reruns everything.
  const RunSummary forced = imscal::run_stages(c.stages, options(run, /*force=*/true));
  for (const char* s : {"upper", "count", "summary"})
    EXPECT_EQ(stage_outcome(forced, s), StageRun::What::kRan);
}

TEST_F(RunStageTest, ChangedInputRerunsTheStageAndDownstreamOnlyIfItsOutputsChanged) {
  const fs::path run = dir_ / "run";
  auto c = chain();
  imscal::run_stages(c.stages, options(run));
  // Different bytes, same upper-case text: upper reruns, its outputs are the same bytes, so
  // count and summary (whose inputs are upper's output checksums) stay skipped.
  write_text(input_, "HELLO run FOLDER\n");
  RunSummary s = imscal::run_stages(c.stages, options(run));
  EXPECT_EQ(stage_outcome(s, "upper"), StageRun::What::kRan);
  EXPECT_EQ(stage_outcome(s, "count"), StageRun::What::kSkipped);
  EXPECT_EQ(stage_outcome(s, "summary"), StageRun::What::kSkipped);
  // A longer text: upper's outputs change, so everything downstream reruns.
  write_text(input_, "hello longer run folder\n");
  s = imscal::run_stages(c.stages, options(run));
  for (const char* name : {"upper", "count", "summary"})
    EXPECT_EQ(stage_outcome(s, name), StageRun::What::kRan);
  EXPECT_EQ(read_text(run / "count" / "count.txt"), "24\n");
  // A changed config subtree reruns the stage too.
  auto reversed = chain("reverse");
  s = imscal::run_stages(reversed.stages, options(run));
  EXPECT_EQ(stage_outcome(s, "upper"), StageRun::What::kRan);
  EXPECT_EQ(read_text(run / "upper" / "part1.txt"), "\nREDLOF NUR ");
  // An output changed by hand is detected: its stage reruns and restores it.
  write_text(run / "count" / "count.txt", "3\n");
  s = imscal::run_stages(reversed.stages, options(run));
  EXPECT_EQ(stage_outcome(s, "upper"), StageRun::What::kSkipped);
  EXPECT_EQ(stage_outcome(s, "count"), StageRun::What::kRan);
  EXPECT_EQ(read_text(run / "count" / "count.txt"), "24\n");
}

TEST_F(RunStageTest, KilledMidStageResumesToTheSameBytesAsAnUninterruptedRun) {
  const fs::path reference = dir_ / "reference", run = dir_ / "run";
  {
    auto c = chain();
    imscal::run_stages(c.stages, options(reference));
  }
  const fs::path pause = dir_ / "paused";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto c = chain();
    c.upper->pause_file = pause;
    try {
      imscal::run_stages(c.stages, options(run));
    } catch (...) {
    }
    ::_exit(0);
  }
  // Wait until the child is inside "upper" with part of its outputs written.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!fs::exists(pause) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(fs::exists(pause)) << "the child never reached the middle of the stage";
  // While it runs, the folder is locked against a second run.
  {
    auto c = chain();
    EXPECT_THROW(imscal::run_stages(c.stages, options(run)), imscal::InputError);
    // Refused with another config and --force too, and without touching run.json (the record of
    // the run that holds the folder).
    const std::string record = read_text(run / "run.json");
    write_text(dir_ / "other.yaml", "# another config\n");
    RunOptions other = options(run, /*force=*/true);
    other.config_file = dir_ / "other.yaml";
    EXPECT_THROW(imscal::run_stages(c.stages, other), imscal::InputError);
    EXPECT_EQ(read_text(run / "run.json"), record);
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));

  // Nothing half-written is visible: no stage folder, only the hidden staging folder.
  EXPECT_FALSE(fs::exists(run / "upper"));
  bool staging_left = false;
  for (const auto& e : fs::directory_iterator(run))
    staging_left |= e.path().filename().string().rfind(".staging-upper-", 0) == 0;
  EXPECT_TRUE(staging_left);

  auto resumed = chain();
  const RunSummary s = imscal::run_stages(resumed.stages, options(run));
  for (const char* name : {"upper", "count", "summary"})
    EXPECT_EQ(stage_outcome(s, name), StageRun::What::kRan);
  for (const auto& e : fs::directory_iterator(run))
    EXPECT_NE(e.path().filename().string().rfind(".staging-", 0), 0u) << "leftover " << e.path();
  EXPECT_EQ(outputs(run), outputs(reference));
  EXPECT_EQ(outputs(run).size(), 4u);  // part1, sub/part2, count, summary
}

TEST_F(RunStageTest, AFailedCheckStopsTheChainButTheSummaryRuns) {
  const fs::path run = dir_ / "run";
  auto c = chain();
  c.count->limit = 5;
  const RunSummary s = imscal::run_stages(c.stages, options(run));
  ASSERT_TRUE(s.failed_check());
  EXPECT_EQ(*s.failed_check(), "count: too long");
  EXPECT_TRUE(fs::exists(run / "count" / "count.txt"));  // a failed check keeps its outputs
  EXPECT_EQ(read_text(run / "summary" / "summary.txt"), "upper present\ncount present\n");
  // Skipped the second time, and the failure is reported again.
  const RunSummary again = imscal::run_stages(c.stages, options(run));
  EXPECT_EQ(stage_outcome(again, "count"), StageRun::What::kSkipped);
  ASSERT_TRUE(again.failed_check());
}

TEST_F(RunStageTest, AStageThatThrowsLeavesNothingVisible) {
  const fs::path run = dir_ / "run";
  fs::remove(input_);  // upper's input file is missing: the checksum throws InputError
  auto c = chain();
  EXPECT_THROW(imscal::run_stages(c.stages, options(run)), imscal::InputError);
  EXPECT_FALSE(fs::exists(run / "upper"));
  write_text(input_, "back\n");
  // A stage that throws from its work: its staging folder is removed.
  class Broken : public Stage {
   public:
    std::string name() const override { return "broken"; }
    StageInputs inputs() const override { return {}; }
    StageOutcome run(StageWorkspace& ws) override {
      write_text(ws.output_dir() / "half.txt", "half");
      throw std::runtime_error("broken");
    }
  };
  std::vector<std::unique_ptr<Stage>> stages;
  stages.push_back(std::make_unique<Broken>());
  EXPECT_THROW(imscal::run_stages(stages, options(run)), std::runtime_error);
  for (const auto& e : fs::directory_iterator(run))
    EXPECT_EQ(e.path().filename().string().find("broken"), std::string::npos) << e.path();
}

TEST_F(RunStageTest, RefusesForeignFoldersWithoutForce) {
  const fs::path foreign = dir_ / "foreign";
  fs::create_directories(foreign);
  write_text(foreign / "thesis.tex", "precious");
  auto c = chain();
  EXPECT_THROW(imscal::run_stages(c.stages, options(foreign)), imscal::InputError);
  EXPECT_FALSE(fs::exists(foreign / "upper"));
  // A run folder made by another config.
  const fs::path run = dir_ / "run";
  imscal::run_stages(c.stages, options(run));
  RunOptions other = options(run);
  write_text(dir_ / "other.yaml", "# another config\n");
  other.config_file = dir_ / "other.yaml";
  EXPECT_THROW(imscal::run_stages(c.stages, other), imscal::InputError);
  other.force = true;
  EXPECT_NO_THROW(imscal::run_stages(c.stages, other));
  EXPECT_EQ(read_text(foreign / "thesis.tex"), "precious");
}

// A run refused because another run holds the folder's lock leaves that run's run.json as it
// is, even with --force and another config; once the lock is free the first config runs on.
TEST_F(RunStageTest, ARunRefusedByTheFolderLockLeavesRunJsonAlone) {
  const fs::path run = dir_ / "run";
  auto c = chain();
  imscal::run_stages(c.stages, options(run));
  const std::string record = read_text(run / "run.json");
  // The lock as another imscal run holds it (flock conflicts across open file descriptions).
  const int other_run = ::open((run / ".imscal-run.lock").c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(other_run, 0);
  ASSERT_EQ(::flock(other_run, LOCK_EX | LOCK_NB), 0);
  write_text(dir_ / "other.yaml", "# another config\n");
  RunOptions other = options(run, /*force=*/true);
  other.config_file = dir_ / "other.yaml";
  try {
    imscal::run_stages(c.stages, other);
    ADD_FAILURE() << "a second run in a locked folder was accepted";
  } catch (const imscal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another imscal run is working in this folder"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(read_text(run / "run.json"), record);
  ::close(other_run);
  EXPECT_NO_THROW(imscal::run_stages(c.stages, options(run)));
}

// run.json is read through its reader (core/run_record.hpp): a damaged record is refused naming
// the file and the field, and left as it is; --force replaces it with this run's record.
TEST_F(RunStageTest, ADamagedRunRecordIsRefusedNamingTheFieldAndReplacedWithForce) {
  const fs::path run = dir_ / "run";
  auto c = chain();
  imscal::run_stages(c.stages, options(run));
  const std::string damaged =
      R"({"schema": "imscal-run-folder", "schema_version": 1, "config": 7, "created_by": "x"})";
  write_text(run / "run.json", damaged);
  try {
    imscal::run_stages(c.stages, options(run));
    ADD_FAILURE() << "a damaged run.json was accepted";
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.file(), (run / "run.json").string());
    EXPECT_EQ(e.field(), "config") << e.what();
    EXPECT_NE(std::string(e.what()).find("--force"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(run / "run.json"), damaged);
  EXPECT_NO_THROW(imscal::run_stages(c.stages, options(run, /*force=*/true)));
  EXPECT_EQ(imscal::read_run_record(run / "run.json").config,
            fs::weakly_canonical(options(run).config_file).string());
}

}  // namespace
