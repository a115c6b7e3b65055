#pragma once
// Stage "report": report.html, one self-contained page (CSS and gnuplot SVG figures inline, no
// script, no external file) that a reader without the tool can follow: what ran on which inputs
// (checksums), the raw-input checks, the joint errors (paper Fig. 2 style), the identified
// models (order, dead time, fit, frequency response per joint), the operating-point coverage, and
// for every step of the paper's chain that did not run in this run folder a section saying so.
// The page depends only on the stages' outputs and the config, never on the clock, so the same
// inputs give the same bytes.
#include <string>
#include <vector>

#include "core/run_stage.hpp"
#include "tools/run_config.hpp"

namespace imscal::tools {

class ReportStage : public Stage {
 public:
  // upstream: the stages of the chain before the report, in order.
  ReportStage(const RunConfig& config, std::vector<std::string> upstream)
      : config_(config), upstream_(std::move(upstream)) {}
  std::string name() const override { return "report"; }
  StageInputs inputs() const override;
  StageOutcome run(StageWorkspace& workspace) override;
  bool runs_after_failed_check() const override { return true; }

 private:
  const RunConfig& config_;
  std::vector<std::string> upstream_;
};

}  // namespace imscal::tools
