#include "tools/stage_identify.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <regex>

#include "core/input_error.hpp"
#include "core/subprocess.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;

fs::path imscal_binary() {
  return fs::read_symlink("/proc/self/exe");
}

StageInputs IdentifyStage::inputs() const {
  StageInputs in;
  in.files.emplace_back("joint_errors", *config_.joint_errors);
  in.files.emplace_back("identify_config", config_.identify->config);
  in.config = {{"config", config_.identify->config.string()},
               {"timeout_s", config_.identify->timeout_s}};
  return in;
}

StageOutcome IdentifyStage::run(StageWorkspace& workspace) {
  const std::vector<std::string> argv = {imscal_binary().string(),
                                         "identify",
                                         "--joint-errors",
                                         config_.joint_errors->string(),
                                         "--config",
                                         config_.identify->config.string(),
                                         "--out",
                                         workspace.output_dir().string()};
  // `imscal identify` logs "joint A2 (2/6): ..." when it starts a joint.
  static const std::regex joint_line(R"(joint \S+ \((\d+)/(\d+)\))");
  std::string last_error;
  SubprocessOptions options;
  options.timeout_s = config_.identify->timeout_s;
  options.on_line = [&](std::string_view line) {
    spdlog::debug("identify| {}", line);
    const std::string text(line);
    if (const auto at = text.find("[error] "); at != std::string::npos)
      last_error = text.substr(at + 8);
    std::smatch match;
    if (std::regex_search(text, match, joint_line)) {
      const double joint = std::stod(match[1]), joints = std::stod(match[2]);
      workspace.progress((joint - 1.0) / std::max(1.0, joints));
    }
  };
  spdlog::info("identify: {}", fmt::join(argv, " "));
  const SubprocessResult result = run_subprocess(argv, options);
  if (result.timed_out)
    throw std::runtime_error(
        fmt::format("identify: `imscal identify` did not finish within identify.timeout_s = {} s",
                    config_.identify->timeout_s));
  if (result.exit_code == 2)
    throw InputError("imscal identify", 0, "", last_error.empty() ? result.output : last_error);
  StageOutcome outcome;
  if (result.exit_code == 1) {
    outcome.status = StageStatus::kCheckFailed;
    outcome.message = last_error;
    return outcome;
  }
  if (result.exit_code != 0)
    throw std::runtime_error(fmt::format("identify: `imscal identify` ended with code {}: {}",
                                         result.exit_code,
                                         last_error.empty() ? result.output : last_error));
  outcome.message = "parameter tables written";
  return outcome;
}

}  // namespace imscal::tools
