#pragma once
// A stage that runs one imscal subcommand (the same binary, as a child process, so that the stage
// writes exactly what the subcommand writes) into the stage's staging folder. The stages of the
// chain (calibrate, identify, verify, diagnose) differ only in their arguments and inputs; the
// child reports its progress through core/progress_channel.hpp; the child's log goes to run.log,
// and its exit codes map to the run's: 2 bad input (InputError, nothing committed), 1 a failed
// check (outputs committed, the chain stops), anything else a failure.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/run_stage.hpp"

namespace imscal::tools {

struct SubcommandSpec {
  std::string stage_name;   // run folder name of the stage, e.g. "calibrate"
  std::string subcommand;   // imscal subcommand, e.g. "calibrate"
  double timeout_s = 1800;  // the child is killed after this long
  // The subcommand's arguments after its name; `out` is the folder to write into.
  std::function<std::vector<std::string>(const StageWorkspace& ws,
                                         const std::filesystem::path& out)>
      arguments;
  std::function<StageInputs()> inputs;
  // For a subcommand that does not report through the progress channel: the stage's progress in
  // [0, 1] that a log line of the child tells, if any (empty: none).
  std::function<std::optional<double>(const std::string& line)> progress_of_line;
  std::string success_message;  // the stage's one-line result when the child ends with 0
};

class SubcommandStage : public Stage {
 public:
  explicit SubcommandStage(SubcommandSpec spec) : spec_(std::move(spec)) {}
  std::string name() const override { return spec_.stage_name; }
  StageInputs inputs() const override { return spec_.inputs(); }
  StageOutcome run(StageWorkspace& workspace) override;

 private:
  SubcommandSpec spec_;
};

// The path of the running imscal binary (/proc/self/exe), to run its subcommands as stages.
std::filesystem::path imscal_binary();

}  // namespace imscal::tools
