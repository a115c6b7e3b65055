#include "tools/stage_chain.hpp"

#include <fmt/format.h>

#include <optional>
#include <stdexcept>

#include "tools/stage_subcommand.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;

namespace {

// The output of an upstream stage that must exist for this stage to run.
fs::path upstream_file(const StageWorkspace& ws, const std::string& stage, const char* file) {
  const auto dir = ws.upstream_dir(stage);
  if (!dir || !fs::exists(*dir / file))
    throw std::runtime_error(fmt::format("the {} stage left no {}", stage, file));
  return *dir / file;
}

fs::path table_of(const StageWorkspace& ws) {
  return upstream_file(ws, "identify", "parameters.json");
}

// The forward error model for the gap diagnosis (its "sim" predicts the joint error from q_d):
// identify's forward_parameters.json beside an inverse-form table, else the table itself.
fs::path forward_table_of(const StageWorkspace& ws) {
  const auto dir = ws.upstream_dir("identify");
  if (dir && fs::exists(*dir / "forward_parameters.json")) return *dir / "forward_parameters.json";
  return table_of(ws);
}

// The joint errors as a stage input: the configured file (with its checksum), or calibrate's.
void declare_joint_errors(const RunConfig& config, StageInputs& in) {
  if (config.joint_errors)
    in.files.emplace_back("joint_errors", *config.joint_errors);
  else
    in.upstream.push_back("calibrate");
}

}  // namespace

std::optional<fs::path> chain_joint_errors(const RunConfig& config, const StageWorkspace& ws) {
  if (config.joint_errors) return *config.joint_errors;
  const auto dir = ws.upstream_dir("calibrate");
  if (dir && fs::exists(*dir / "joint_errors.csv")) return *dir / "joint_errors.csv";
  return std::nullopt;
}

namespace {
// calibrate's frames.json when that stage made the joint errors; none otherwise.
std::optional<fs::path> calibrate_frames_of(const RunConfig& config, const StageWorkspace& ws) {
  if (config.joint_errors) return std::nullopt;
  const auto dir = ws.upstream_dir("calibrate");
  if (dir && fs::exists(*dir / "frames.json")) return *dir / "frames.json";
  return std::nullopt;
}

fs::path joint_errors_of(const RunConfig& config, const StageWorkspace& ws) {
  const auto joint_errors = chain_joint_errors(config, ws);
  if (!joint_errors) throw std::runtime_error("the calibrate stage left no joint_errors.csv");
  return *joint_errors;
}
}  // namespace

std::unique_ptr<Stage> make_calibrate_stage(const RunConfig& config) {
  SubcommandSpec spec;
  spec.stage_name = spec.subcommand = "calibrate";
  spec.timeout_s = config.calibrate->timeout_s;
  spec.inputs = [&config] {
    StageInputs in;
    in.files = {{"imu", *config.imu},
                {"robot_log", *config.robot_log},
                {"calibrate_config", config.calibrate->config}};
    in.config = {{"config", config.calibrate->config.string()},
                 {"timeout_s", config.calibrate->timeout_s}};
    return in;
  };
  spec.arguments = [&config](const StageWorkspace&, const fs::path& out) {
    return std::vector<std::string>{"--imu",       config.imu->string(),
                                    "--robot-log", config.robot_log->string(),
                                    "--config",    config.calibrate->config.string(),
                                    "--out",       out.string()};
  };
  spec.success_message = "frames calibrated, mounting verdict and joint errors written";
  return std::make_unique<SubcommandStage>(std::move(spec));
}

std::unique_ptr<Stage> make_identify_stage(const RunConfig& config) {
  SubcommandSpec spec;
  spec.stage_name = spec.subcommand = "identify";
  spec.timeout_s = config.identify->timeout_s;
  spec.inputs = [&config] {
    StageInputs in;
    declare_joint_errors(config, in);
    in.files.emplace_back("identify_config", config.identify->config);
    if (!config.identify->robot.empty()) in.files.emplace_back("robot", config.identify->robot);
    in.config = {{"config", config.identify->config.string()},
                 {"robot", config.identify->robot.string()},
                 {"timeout_s", config.identify->timeout_s}};
    return in;
  };
  spec.arguments = [&config](const StageWorkspace& ws, const fs::path& out) {
    const fs::path joint_errors = joint_errors_of(config, ws);
    std::vector<std::string> arguments{"--joint-errors", joint_errors.string(),
                                       "--config",       config.identify->config.string(),
                                       "--out",          out.string()};
    if (!config.identify->robot.empty()) {
      arguments.emplace_back("--robot");
      arguments.push_back(config.identify->robot.string());
    }
    return arguments;
  };
  spec.success_message = "parameter tables written";
  return std::make_unique<SubcommandStage>(std::move(spec));
}

std::unique_ptr<Stage> make_verify_stage(const RunConfig& config) {
  SubcommandSpec spec;
  spec.stage_name = spec.subcommand = "verify";
  spec.timeout_s = config.verify->timeout_s;
  spec.inputs = [&config] {
    StageInputs in;
    in.upstream = {"identify"};
    for (std::size_t i = 0; i < config.verify->scenario_files.size(); ++i)
      in.files.emplace_back(fmt::format("scenario_{}", i + 1), config.verify->scenario_files[i]);
    in.config = {{"scenarios", config.verify->scenarios},
                 {"cycles", config.verify->cycles},
                 {"timeout_s", config.verify->timeout_s}};
    return in;
  };
  spec.arguments = [&config](const StageWorkspace& ws, const fs::path& out) {
    std::vector<std::string> args = {"--table", table_of(ws).string(), "--cycles",
                                     std::to_string(config.verify->cycles)};
    for (const std::string& scenario : config.verify->scenarios) {
      args.push_back("--scenario");
      args.push_back(scenario);
    }
    args.push_back("--out");
    args.push_back(out.string());
    return args;
  };
  spec.success_message = "ISO 9283 before/after written";
  return std::make_unique<SubcommandStage>(std::move(spec));
}

std::unique_ptr<Stage> make_diagnose_stage(const RunConfig& config) {
  SubcommandSpec spec;
  spec.stage_name = spec.subcommand = "diagnose";
  spec.timeout_s = config.diagnose->timeout_s;
  spec.inputs = [&config] {
    StageInputs in;
    in.upstream = {"identify"};
    declare_joint_errors(config, in);
    in.files.emplace_back("robot", config.diagnose->robot);
    if (!config.diagnose->scenario_file.empty())
      in.files.emplace_back("scenario", config.diagnose->scenario_file);
    in.config = {{"robot", config.diagnose->robot.string()},
                 {"scenario", config.diagnose->scenario},
                 {"timeout_s", config.diagnose->timeout_s}};
    return in;
  };
  spec.arguments = [&config](const StageWorkspace& ws, const fs::path& out) {
    const fs::path joint_errors = joint_errors_of(config, ws);
    std::vector<std::string> args{"--joint-errors", joint_errors.string(),
                                  "--table",        forward_table_of(ws).string(),
                                  "--robot",        config.diagnose->robot.string(),
                                  "--figures",      "--out",
                                  out.string()};
    // The chain's frames with their covariance (the measurement budget's prior) when calibrate
    // made the joint errors.
    if (const auto frames = calibrate_frames_of(config, ws)) {
      args.emplace_back("--frames");
      args.push_back(frames->string());
    }
    if (!config.diagnose->scenario.empty()) {
      args.emplace_back("--scenario");
      args.push_back(config.diagnose->scenario);
    }
    return args;
  };
  spec.success_message = "gap diagnosis written";
  return std::make_unique<SubcommandStage>(std::move(spec));
}

}  // namespace imscal::tools
