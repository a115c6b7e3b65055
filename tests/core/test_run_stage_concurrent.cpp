// Stages of core/run_stage.hpp that run at the same time: two stages that read only an earlier
// one meet at a rendezvous that a one-at-a-time run can never reach (each waits for the other,
// with a time limit so that the test fails instead of hanging); forced to one stage at a time
// they do not meet and write the same bytes. Each stage's recorded CPU time is its own (a child
// stopped by its CPU limit burns a known amount while its sibling waits). A failed check or an
// exception in one of two running stages lets the other complete and starts nothing more.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/run_stage.hpp"
#include "core/subprocess.hpp"
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
using namespace std::chrono_literals;

// Two parties wait for each other; false when the other did not come within the time limit.
// Once both met, later calls meet at once.
class Rendezvous {
 public:
  bool meet(std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    ++arrived_;
    changed_.notify_all();
    if (changed_.wait_for(lock, limit, [&] { return arrived_ >= 2; })) return true;
    --arrived_;  // left alone: a later party finds nobody waiting
    return false;
  }
  // Marks an event (a stage's work done) and waits for one; false after the time limit.
  void signal() {
    const std::lock_guard lock(mutex_);
    signalled_ = true;
    changed_.notify_all();
  }
  bool wait_signal(std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return signalled_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int arrived_ = 0;
  bool signalled_ = false;
};

// A stage whose work is a function; it writes "<name>.txt" with what the function returns.
class ScriptedStage : public Stage {
 public:
  using Work = std::function<StageOutcome(StageWorkspace&, std::string& text)>;
  ScriptedStage(std::string name, std::vector<std::string> upstream, Work work,
                bool summarises = false)
      : name_(std::move(name)),
        upstream_(std::move(upstream)),
        work_(std::move(work)),
        summarises_(summarises) {}
  std::string name() const override { return name_; }
  StageInputs inputs() const override {
    StageInputs in;
    in.upstream = upstream_;
    return in;
  }
  StageOutcome run(StageWorkspace& ws) override {
    ++runs;
    std::string text = name_;
    for (const std::string& up : upstream_) {
      text += " " + up + ":";
      text += ws.upstream_dir(up) ? read_text(*ws.upstream_dir(up) / (up + ".txt")) : "absent";
    }
    const StageOutcome outcome = work_(ws, text);
    write_text(ws.output_dir() / (name_ + ".txt"), text);
    return outcome;
  }
  bool runs_after_failed_check() const override { return summarises_; }
  bool gates_later_stages() const override { return gates; }
  int runs = 0;
  bool gates = false;

 private:
  std::string name_;
  std::vector<std::string> upstream_;
  Work work_;
  bool summarises_;
};

StageOutcome ok(StageWorkspace&, std::string&) {
  return {};
}

class RunStageConcurrent : public imscal::test_support::ScratchDirTest {
 protected:
  // source -> left, right (both read only source) -> join (reads both); summary after all.
  std::vector<std::unique_ptr<Stage>> chain(const ScriptedStage::Work& left,
                                            const ScriptedStage::Work& right) {
    std::vector<std::unique_ptr<Stage>> stages;
    stages.push_back(std::make_unique<ScriptedStage>("source", std::vector<std::string>{}, ok));
    stages.push_back(
        std::make_unique<ScriptedStage>("left", std::vector<std::string>{"source"}, left));
    stages.push_back(
        std::make_unique<ScriptedStage>("right", std::vector<std::string>{"source"}, right));
    stages.push_back(
        std::make_unique<ScriptedStage>("join", std::vector<std::string>{"left", "right"}, ok));
    stages.push_back(std::make_unique<ScriptedStage>(
        "summary", std::vector<std::string>{"source", "join"}, ok, /*summarises=*/true));
    return stages;
  }
  RunOptions options(const fs::path& folder, unsigned max_parallel = 0) const {
    RunOptions o;
    o.folder = folder;
    o.tool_version = "imscal test";
    o.max_parallel_stages = max_parallel;
    return o;
  }
  // The stage outputs (everything but records, log and lock): name -> bytes.
  static std::map<std::string, std::string> outputs(const fs::path& folder) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(folder)) {
      const std::string rel = fs::relative(e.path(), folder).generic_string();
      if (e.is_regular_file() && e.path().filename() != "stage.json" &&
          rel.find('/') != std::string::npos)
        files[rel] = read_text(e.path());
    }
    return files;
  }
  static void expect_no_staging_left(const fs::path& folder) {
    for (const auto& e : fs::directory_iterator(folder))
      EXPECT_NE(e.path().filename().string().rfind(".staging-", 0), 0u) << "leftover " << e.path();
  }
};

// Meeting takes both stages running at once: 20 s is far beyond the start of a thread even
// under the sanitizers, and a one-at-a-time run would wait it out and fail.
TEST_F(RunStageConcurrent, IndependentStagesRunAtOnceAndWriteTheSequentialBytes) {
  Rendezvous together;
  bool left_met = false, right_met = false;
  const auto meets = [&](bool& met, std::chrono::milliseconds limit) {
    return [&met, &together, limit](StageWorkspace&, std::string&) {
      met = together.meet(limit);
      return StageOutcome{};
    };
  };
  const auto concurrent = chain(meets(left_met, 20s), meets(right_met, 20s));
  const RunSummary s = imscal::run_stages(concurrent, options(dir_ / "concurrent", 2));
  EXPECT_TRUE(left_met && right_met) << "left and right did not run at the same time";
  for (const auto& stage : s.stages) EXPECT_EQ(stage.what, StageRun::What::kRan) << stage.name;
  // The summary keeps the chain's order.
  std::vector<std::string> order;
  for (const auto& stage : s.stages) order.push_back(stage.name);
  EXPECT_EQ(order, (std::vector<std::string>{"source", "left", "right", "join", "summary"}));

  // One at a time (the option tests use): they cannot meet (a short limit, the outcome is known).
  Rendezvous apart;
  bool left_alone = true, right_alone = true;
  const auto waits = [&](bool& alone) {
    return [&alone, &apart](StageWorkspace&, std::string&) {
      alone = !apart.meet(300ms);
      return StageOutcome{};
    };
  };
  const auto sequential = chain(waits(left_alone), waits(right_alone));
  imscal::run_stages(sequential, options(dir_ / "sequential", 1));
  EXPECT_TRUE(left_alone && right_alone);
  EXPECT_EQ(outputs(dir_ / "concurrent"), outputs(dir_ / "sequential"));
  EXPECT_EQ(read_text(dir_ / "concurrent" / "join" / "join.txt"),
            "join left:left source:source right:right source:source");
  // Unchanged: every stage is skipped.
  const RunSummary again = imscal::run_stages(concurrent, options(dir_ / "concurrent", 2));
  for (const auto& stage : again.stages) EXPECT_EQ(stage.what, StageRun::What::kSkipped);
}

// Truth: a child shell stopped by its CPU limit (ulimit -t 1, SIGXCPU) has used 1 s of CPU; the
// kernel checks the limit at each tick, so 0.9-1.5 s. Its sibling waits on a condition variable
// meanwhile and uses next to no CPU (< 0.2 s), although the burner's child ends during its run.
TEST_F(RunStageConcurrent, EachStageRecordsItsOwnCpuTime) {
  Rendezvous started, burned;
  const auto burner = [&](StageWorkspace&, std::string&) {
    started.meet(20s);
    imscal::SubprocessOptions limit;
    limit.timeout_s = 60;
    imscal::run_subprocess({"sh", "-c", "ulimit -t 1; while :; do :; done"}, limit);
    burned.signal();
    return StageOutcome{};
  };
  const auto waiter = [&](StageWorkspace&, std::string&) {
    EXPECT_TRUE(started.meet(20s));
    EXPECT_TRUE(burned.wait_signal(60s));
    return StageOutcome{};
  };
  const auto stages = chain(burner, waiter);
  imscal::run_stages(stages, options(dir_ / "run", 2));
  const auto cpu_of = [&](const char* stage) {
    return nlohmann::json::parse(read_text(dir_ / "run" / stage / "stage.json"))["cpu_seconds"]
        .get<double>();
  };
  EXPECT_GT(cpu_of("left"), 0.9);
  EXPECT_LT(cpu_of("left"), 1.5);
  EXPECT_LT(cpu_of("right"), 0.2);
}

// left fails its check while right still runs: right completes and is committed, join (later,
// not summarising) does not start, summary does.
TEST_F(RunStageConcurrent, AFailedCheckLetsTheRunningSiblingCompleteAndStartsNoLaterStage) {
  Rendezvous together;
  const auto fails = [&](StageWorkspace&, std::string&) {
    together.meet(20s);
    StageOutcome outcome;
    outcome.status = StageStatus::kCheckFailed;
    outcome.message = "left failed";
    return outcome;
  };
  const auto slow = [&](StageWorkspace&, std::string&) {
    together.meet(20s);
    std::this_thread::sleep_for(200ms);  // still running when left ends
    return StageOutcome{};
  };
  const auto stages = chain(fails, slow);
  const RunSummary s = imscal::run_stages(stages, options(dir_ / "run", 2));
  ASSERT_TRUE(s.failed_check());
  EXPECT_EQ(*s.failed_check(), "left: left failed");
  EXPECT_EQ(stage_outcome(s, "right"), StageRun::What::kRan);
  EXPECT_TRUE(fs::exists(dir_ / "run" / "right" / "stage.json"));
  EXPECT_EQ(stage_outcome(s, "join"), StageRun::What::kNotRun);
  EXPECT_FALSE(fs::exists(dir_ / "run" / "join"));
  EXPECT_EQ(stage_outcome(s, "summary"), StageRun::What::kRan);
  EXPECT_EQ(read_text(dir_ / "run" / "summary" / "summary.txt"),
            "summary source:source join:absent");
}

// left throws while right still runs: run_stages throws only after right has completed (its
// folder committed, its thread ended), left leaves nothing, join and summary do not start.
TEST_F(RunStageConcurrent, AnExceptionWaitsForTheRunningSiblingAndLeavesNothingOfItsStage) {
  Rendezvous together;
  const auto throws = [&](StageWorkspace& ws, std::string&) -> StageOutcome {
    together.meet(20s);
    write_text(ws.output_dir() / "half.txt", "half");
    throw std::runtime_error("left broke");
  };
  const auto slow = [&](StageWorkspace&, std::string&) {
    together.meet(20s);
    std::this_thread::sleep_for(300ms);  // still running when left throws
    return StageOutcome{};
  };
  auto stages = chain(throws, slow);
  EXPECT_THROW(imscal::run_stages(stages, options(dir_ / "run", 2)), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir_ / "run" / "left"));
  EXPECT_TRUE(fs::exists(dir_ / "run" / "right" / "stage.json"));
  EXPECT_EQ(static_cast<ScriptedStage&>(*stages[2]).runs, 1);
  for (const char* never : {"join", "summary"}) {
    EXPECT_FALSE(fs::exists(dir_ / "run" / never)) << never;
    EXPECT_EQ(static_cast<ScriptedStage&>(*stages[never == std::string("join") ? 3 : 4]).runs, 0);
  }
  expect_no_staging_left(dir_ / "run");
}

// A gating stage (a validation) that fails its check keeps a later stage that reads nothing of it
// from starting; without the gate, that stage runs beside it.
TEST_F(RunStageConcurrent, AGatingStageHoldsBackEveryLaterStage) {
  for (const bool gates : {true, false}) {
    std::vector<std::unique_ptr<Stage>> stages;
    auto gate = std::make_unique<ScriptedStage>("gate", std::vector<std::string>{},
                                                [](StageWorkspace&, std::string&) {
                                                  std::this_thread::sleep_for(100ms);
                                                  StageOutcome outcome;
                                                  outcome.status = StageStatus::kCheckFailed;
                                                  return outcome;
                                                });
    gate->gates = gates;
    stages.push_back(std::move(gate));
    stages.push_back(std::make_unique<ScriptedStage>("free", std::vector<std::string>{}, ok));
    const fs::path run = dir_ / (gates ? "gated" : "free");
    const RunSummary s = imscal::run_stages(stages, options(run, 2));
    EXPECT_EQ(stage_outcome(s, "free"), gates ? StageRun::What::kNotRun : StageRun::What::kRan)
        << gates;
  }
}

}  // namespace
