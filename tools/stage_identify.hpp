#pragma once
// Stage "identify": `imscal identify` (the same binary, as a child process, so that the stage
// writes exactly what the subcommand writes) on inputs.joint_errors with identify.config:
// parameters.json, parameters.csv, identification_report.json. The child's log goes to run.log,
// its "joint j/n" lines drive the progress line. Its exit codes map to the run's: 2 bad input,
// 1 a failed check.
#include "core/run_stage.hpp"
#include "tools/run_config.hpp"

namespace imscal::tools {

class IdentifyStage : public Stage {
 public:
  explicit IdentifyStage(const RunConfig& config) : config_(config) {}
  std::string name() const override { return "identify"; }
  StageInputs inputs() const override;
  StageOutcome run(StageWorkspace& workspace) override;

 private:
  const RunConfig& config_;
};

// The path of the running imscal binary (/proc/self/exe), to run its subcommands as stages.
std::filesystem::path imscal_binary();

}  // namespace imscal::tools
