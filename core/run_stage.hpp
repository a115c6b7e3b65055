#pragma once
// A run folder: a chain of stages, each writing its outputs into <run>/<stage>/, all or nothing,
// with a record <run>/<stage>/stage.json of what it used (input files with SHA-256, the upstream
// stages' output checksums, the resolved config subtree, the tool version), when it ran and how
// it ended. On the next run a stage whose recorded inputs equal its current ones, and whose
// outputs are intact, is skipped; a changed input reruns that stage, and its downstream stages
// rerun only if its outputs changed (their inputs hold the upstream checksums).
//
// Interruption: a stage writes into a hidden staging folder <run>/.staging-<stage>-<pid>/ that is
// renamed to <run>/<stage>/ only when the stage finished and its record is written, so a killed
// run leaves the completed stages and no visible half-written folder; the next run removes the
// leftovers and reruns the interrupted stage from scratch. One run at a time per folder (a lock).
//
// Concurrency: a stage starts as soon as the earlier stages (in chain order) whose outputs it
// reads, its declared upstream, have ended, while at most RunOptions::max_parallel_stages stages
// run at once, each on its own thread (a subcommand stage in its own child process): Stage::run
// must not touch what another stage's run uses. A stage that gates later stages (validation) and
// a stage that summarises the run wait for every earlier stage. A stage sees only its declared
// upstream stages, so the outputs are the bytes a one-at-a-time run writes, and the summary lists
// the stages in chain order. A failed check keeps the later stages that have not started from
// starting (except those that summarise); a stage already running completes. A stage's exception
// starts no other stage, lets the running ones complete (committed) and then propagates. Each
// stage.json records the stage's own wall and CPU time (its thread plus the children it waited
// for, from wait4), and the terminal's progress line shows the running stages side by side.
//
// Layout:
//   <run>/run.json          which config made this run folder
//   <run>/run.log           log of every run in this folder (appended)
//   <run>/<stage>/stage.json, <run>/<stage>/<outputs>
//
// Adding a stage to a chain is writing one Stage subclass and putting it into the list.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/progress.hpp"

namespace imscal {

// Everything a stage's outputs depend on, declared before it runs.
struct StageInputs {
  // (role, file): a raw input or a config file; recorded with its SHA-256.
  std::vector<std::pair<std::string, std::filesystem::path>> files;
  // Stages (of this chain, earlier) whose outputs this stage reads; recorded with their output
  // checksums, or as "not run" when they did not complete in this run.
  std::vector<std::string> upstream;
  // The resolved config of this stage (absolute paths, defaults filled in).
  nlohmann::json config = nlohmann::json::object();
};

enum class StageStatus { kOk, kCheckFailed };
const char* to_string(StageStatus status);

struct StageOutcome {
  StageStatus status = StageStatus::kOk;
  std::string message;  // one line: what the stage found, or why its check failed
  nlohmann::json summary = nlohmann::json::object();  // small figures kept in stage.json
};

// What a running stage sees: where to write, where its upstream stages' outputs are.
class StageWorkspace {
 public:
  StageWorkspace(std::filesystem::path output_dir, std::filesystem::path run_dir,
                 std::vector<std::string> completed_upstream, std::string stage_name,
                 Progress* progress);

  // The (staging) folder this stage writes its outputs into; it exists and is empty at start.
  const std::filesystem::path& output_dir() const { return output_dir_; }
  const std::filesystem::path& run_dir() const { return run_dir_; }
  // The committed folder of a declared upstream stage, or nullopt when it did not complete.
  std::optional<std::filesystem::path> upstream_dir(const std::string& stage) const;
  // Fraction in [0, 1] of this stage's work, for the terminal progress line.
  void progress(double fraction);

 private:
  std::filesystem::path output_dir_;
  std::filesystem::path run_dir_;
  std::vector<std::string> completed_upstream_;
  std::string stage_name_;
  Progress* progress_;
};

class Stage {
 public:
  virtual ~Stage() = default;
  // The stage's folder name in the run folder: lower-case letters, digits, '_' and '-'.
  virtual std::string name() const = 0;
  // Called before the stage would run, the last time just before it starts (so it sees the
  // files as they are then); its upstream list also orders the stages.
  virtual StageInputs inputs() const = 0;
  // Writes the outputs into workspace.output_dir(). Throws InputError for bad input (nothing is
  // committed); returns kCheckFailed when the data were read but a check on them failed (the
  // outputs are committed, later stages do not run, except those that summarise).
  virtual StageOutcome run(StageWorkspace& workspace) = 0;
  // True for stages that summarise the run (the report): they run even after a failed check.
  virtual bool runs_after_failed_check() const { return false; }
  // True for a stage whose failure must keep every later stage from starting (a validation of
  // the raw files): later stages wait for it even when they do not read its outputs.
  virtual bool gates_later_stages() const { return false; }
};

struct RunOptions {
  std::filesystem::path folder;
  std::filesystem::path config_file;  // the config that defines this run (recorded in run.json)
  std::string tool_version;           // "imscal 0.1.0": a new version reruns every stage
  bool force = false;  // rerun every stage; accept a folder made by another config or by no run
  unsigned max_parallel_stages = 0;  // stages running at once; 0: the hardware threads
};

struct StageRun {
  enum class What { kRan, kSkipped, kNotRun };
  std::string name;
  What what = What::kNotRun;
  StageStatus status = StageStatus::kOk;  // of the run or of the recorded (skipped) result
  std::string message;
  double seconds = 0.0;  // wall time of this invocation (checksums included)
};
const char* to_string(StageRun::What what);

struct RunSummary {
  std::vector<StageRun> stages;
  // The first failed check ("stage: message"), if any.
  std::optional<std::string> failed_check() const;
};

// Runs the chain (concurrently where the stages allow, see above). Throws InputError when the
// folder cannot be used (another config's run folder or a non-empty folder that is no run folder,
// without force; another run holds it) and lets a stage's exceptions through (that stage leaves
// nothing visible).
RunSummary run_stages(const std::vector<std::unique_ptr<Stage>>& stages, const RunOptions& options);

// The name of the record file in every stage folder.
inline constexpr const char* kStageRecordName = "stage.json";

}  // namespace imscal
