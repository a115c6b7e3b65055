#include "tools/stage_subcommand.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "core/input_error.hpp"
#include "core/progress_channel.hpp"
#include "core/subprocess.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;

fs::path imscal_binary() {
  return fs::read_symlink("/proc/self/exe");
}

namespace {

// The subcommand names its --out, the stage's hidden staging folder, which is renamed when the
// stage ends: the message names the folder the user will find.
std::string with_stage_folder(std::string text, const StageWorkspace& workspace,
                              const std::string& stage_name) {
  const std::string staging = workspace.output_dir().string();
  const std::string visible = (workspace.run_dir() / stage_name).string();
  for (auto at = text.find(staging); at != std::string::npos;
       at = text.find(staging, at + visible.size()))
    text.replace(at, staging.size(), visible);
  return text;
}

}  // namespace

StageOutcome SubcommandStage::run(StageWorkspace& workspace) {
  std::vector<std::string> argv = {imscal_binary().string(), spec_.subcommand};
  for (std::string& a : spec_.arguments(workspace, workspace.output_dir()))
    argv.push_back(std::move(a));
  std::string last_error;
  SubprocessOptions options;
  options.timeout_s = spec_.timeout_s;
  const std::string tag = spec_.stage_name;
  request_progress_lines_from_children();
  options.on_line = [&](std::string_view line) {
    if (const std::optional<ProgressReport> report = parse_progress_line(line)) {
      workspace.progress(report->fraction);
      return;
    }
    spdlog::debug("{}| {}", tag, line);
    const std::string text(line);
    if (const auto at = text.find("[error] "); at != std::string::npos)
      last_error = text.substr(at + 8);
    if (spec_.progress_of_line)
      if (const std::optional<double> fraction = spec_.progress_of_line(text))
        workspace.progress(std::clamp(*fraction, 0.0, 1.0));
  };
  spdlog::info("{}: {}", tag, fmt::join(argv, " "));
  const SubprocessResult result = run_subprocess(argv, options);
  last_error = with_stage_folder(last_error, workspace, spec_.stage_name);
  const std::string why = last_error.empty()
                              ? with_stage_folder(result.output, workspace, spec_.stage_name)
                              : last_error;
  if (result.timed_out)
    throw std::runtime_error(fmt::format("{}: `imscal {}` did not finish within {} s", tag,
                                         spec_.subcommand, spec_.timeout_s));
  if (result.exit_code == 2) throw InputError("imscal " + spec_.subcommand, 0, "", why);
  StageOutcome outcome;
  if (result.exit_code == 1) {
    outcome.status = StageStatus::kCheckFailed;
    outcome.message = last_error;
    return outcome;
  }
  if (result.exit_code != 0)
    throw std::runtime_error(fmt::format("{}: `imscal {}` ended with code {}: {}", tag,
                                         spec_.subcommand, result.exit_code, why));
  outcome.message = spec_.success_message;
  return outcome;
}

}  // namespace imscal::tools
