// `imscal run CONFIG.yaml [--out DIR] [--force]`: the calibration chain on one campaign's raw
// files, stage by stage, in a run folder (core/run_stage.hpp): unchanged stages are skipped, an
// interrupted run resumes. Exit codes: 0 success, 1 a check failed (the reason is printed),
// 2 bad input or config (file, line, field).
//
// The chain is the list built in make_chain(), in the order of the paper's chain: validate the
// raw files, calibrate (frames, mounting verdict, joint_errors.csv), identify (from
// inputs.joint_errors or calibrate's), verify (ISO 9283 before/after in the simulator), diagnose
// (sim-to-real gap), report. A stage joins the chain when its section (and inputs) are configured.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <memory>

#include "core/run_stage.hpp"
#include "core/sha256.hpp"
#include "core/version.hpp"
#include "tools/command_registry.hpp"
#include "tools/run_config.hpp"
#include "tools/stage_chain.hpp"
#include "tools/stage_report.hpp"
#include "tools/stage_subcommand.hpp"
#include "tools/stage_validate.hpp"

namespace {
namespace fs = std::filesystem;
namespace tools = imscal::tools;

struct RunArgs {
  std::string config;
  std::string out;
  bool force = false;
};

std::vector<std::unique_ptr<imscal::Stage>> make_chain(const tools::RunConfig& config) {
  std::vector<std::unique_ptr<imscal::Stage>> chain;
  if (config.imu || config.robot_log)
    chain.push_back(std::make_unique<tools::ValidateStage>(config));
  if (config.calibrate) chain.push_back(tools::make_calibrate_stage(config));
  if (config.identify) chain.push_back(tools::make_identify_stage(config));
  if (config.verify) chain.push_back(tools::make_verify_stage(config));
  if (config.diagnose) chain.push_back(tools::make_diagnose_stage(config));
  std::vector<std::string> before_report;
  for (const auto& stage : chain) before_report.push_back(stage->name());
  chain.push_back(std::make_unique<tools::ReportStage>(config, before_report));
  return chain;
}

void run(const RunArgs& args) {
  const tools::RunConfig config = tools::load_run_config(args.config);
  const fs::path out =
      args.out.empty() ? fs::path("out") / fs::path(args.config).stem() : fs::path(args.out);
  const auto chain = make_chain(config);
  imscal::RunOptions options;
  options.folder = out;
  options.config_file = config.file;
  // The binary's checksum too: a rebuilt imscal (changed code, same version) reruns every stage.
  options.tool_version =
      fmt::format("imscal {} (binary sha256 {})", imscal::kVersion,
                  imscal::sha256_hex_of_file(tools::imscal_binary()).substr(0, 16));
  options.force = args.force;
  const imscal::RunSummary summary = imscal::run_stages(chain, options);
  for (const auto& stage : summary.stages)
    std::cout << fmt::format(
        "{:<10} {:<27} {:<13} {:>7.2f} s  {}\n", stage.name, imscal::to_string(stage.what),
        stage.what == imscal::StageRun::What::kNotRun ? "-" : imscal::to_string(stage.status),
        stage.seconds, stage.message);
  std::cout << "report: " << (out / "report" / "report.html").string() << "\n";
  if (const auto failed = summary.failed_check()) throw tools::CheckFailed(*failed);
}

imscal::tools::CommandRegistration registration{
    "run", "Run the calibration chain on a campaign's raw files into a run folder, with a report",
    [](CLI::App& sub) {
      auto args = std::make_shared<RunArgs>();
      sub.add_option("config", args->config, "Run config (YAML; see tools/run_config.hpp)")
          ->required();
      sub.add_option("--out", args->out, "Run folder (default: out/<config name>)");
      sub.add_flag("--force", args->force,
                   "Rerun every stage, and accept a folder made by another config");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
