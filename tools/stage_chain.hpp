#pragma once
// The paper's chain as stages of `imscal run` (core/run_stage.hpp), each one imscal subcommand
// run as a child process (tools/stage_subcommand.hpp):
//   calibrate  `imscal calibrate` on inputs.imu + inputs.robot_log: frames.json,
//              mounting_report.json, summary.txt, joint_errors.csv (a failed mounting verdict
//              is a failed check: the chain stops, the report says why);
//   identify   `imscal identify` on inputs.joint_errors, or else on calibrate's joint_errors.csv:
//              parameters.json/.csv, identification_report.json;
//   verify     `imscal verify` with identify's table on the configured scenarios: ISO 9283
//              before/after, ablation, Fig. 5/6 (fig5.svg, fig6.svg);
//   diagnose   `imscal diagnose`: the measured joint errors against identify's model.
#include <memory>

#include "core/run_stage.hpp"
#include "tools/run_config.hpp"

namespace imscal::tools {

std::unique_ptr<Stage> make_calibrate_stage(const RunConfig& config);
std::unique_ptr<Stage> make_identify_stage(const RunConfig& config);
std::unique_ptr<Stage> make_verify_stage(const RunConfig& config);
std::unique_ptr<Stage> make_diagnose_stage(const RunConfig& config);

// The joint errors the chain identifies from: inputs.joint_errors, or else calibrate's output
// (nullopt when calibrate did not complete).
std::optional<std::filesystem::path> chain_joint_errors(const RunConfig& config,
                                                        const StageWorkspace& workspace);

}  // namespace imscal::tools
