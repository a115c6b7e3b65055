#pragma once
// Stage "validate": reads the raw IMS file and the robot log with the project's readers (every
// check of datasets/FORMAT.md §1.4 and §2) and records sample counts, time spans, rates and the
// overlap of the two clocks in validation.json. Bad files are InputError (exit 2); clocks that
// do not overlap at all are InputError too (the files do not belong together); an overlap
// shorter than validate.min_overlap_s is a failed check (exit 1).
#include "core/run_stage.hpp"
#include "tools/run_config.hpp"

namespace imscal::tools {

class ValidateStage : public Stage {
 public:
  explicit ValidateStage(const RunConfig& config) : config_(config) {}
  std::string name() const override { return "validate"; }
  StageInputs inputs() const override;
  StageOutcome run(StageWorkspace& workspace) override;
  // Files that fail validation must not reach calibrate, which does not read validate's outputs.
  bool gates_later_stages() const override { return true; }

 private:
  const RunConfig& config_;
};

}  // namespace imscal::tools
