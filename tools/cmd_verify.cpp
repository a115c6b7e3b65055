// `imscal verify`: the paper's verification (section 4) in the simulator. The scenario's path is
// run by the uncalibrated robot and with the precontrol in the loop, n cycles each
// (eval/verification_session.hpp); written per scenario into OUT/<scenario>/ (the files of
// eval/verification_files.hpp: the ISO 9283 tables, the paper's Fig. 5 and 6, the path files for
// `imscal evaluate`), with the figures drawn by gnuplot when it is installed.
// The table comes from --table, or is identified here from the simulator's truth of
// --identify-scenario (joint errors q_d - q_link; --joint-errors takes any joint_errors.csv
// instead). With joint errors at hand the ablation tables (backlash off, one cell) are identified
// from the same data.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include "core/input_error.hpp"
#include "core/progress_channel.hpp"
#include "eval/verification_session.hpp"
#include "tools/command_registry.hpp"

namespace {

namespace fs = std::filesystem;
namespace eval = imscal::eval;

struct VerifyArgs {
  eval::VerificationSessionOptions session;
  std::string out;
  double offset_tolerance_rad = 0.0;  // 0: from the table's envelope
  bool force = false;
};

// fig5.svg and fig6.svg from their scripts, when gnuplot is installed.
void draw_figures(const fs::path& dir) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    for (const char* gp : {"fig5.gp", "fig6.gp"}) {
      const std::string cmd = fmt::format("cd '{}' && gnuplot {} 2> /dev/null", dir.string(), gp);
      if (std::system(cmd.c_str()) != 0) spdlog::warn("gnuplot failed on {}", gp);
    }
  } else {
    spdlog::info("gnuplot not found: run `gnuplot fig5.gp fig6.gp` in {} for the SVGs",
                 dir.string());
  }
}

void run(VerifyArgs args) {
  const auto overwrite = args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse;
  const fs::path out(args.out);
  if (!args.force && fs::exists(out / "verification.json"))
    throw imscal::InputError(out.string(), 0, "", "output exists; use --force");
  if (args.offset_tolerance_rad > 0.0)
    args.session.verification.compensation.precontrol.offset_tolerance_rad.fill(
        args.offset_tolerance_rad);
  eval::verify_session(
      args.session, out, overwrite,
      [](const fs::path& dir, const std::string& text) {
        std::cout << text;
        draw_figures(dir);
      },
      imscal::progress_channel());
}

imscal::tools::CommandRegistration registration{
    "verify",
    "Closed-loop verification in the simulator: ISO 9283 before/after, ablation, Fig. 5/6",
    [](CLI::App& sub) {
      auto args = std::make_shared<VerifyArgs>();
      sub.add_option("--table", args->session.table, "parameters.json (imscal identify)");
      sub.add_option("--joint-errors", args->session.joint_errors,
                     "joint_errors.csv for the table and the ablation (instead of --table)");
      sub.add_option("--identify-scenario", args->session.identify_scenario,
                     "identify from this scenario's simulator truth (e.g. identification)");
      sub.add_option("--ident-config", args->session.ident_config,
                     "identification config (default datasets/identification/ident-default.yaml)");
      sub.add_option("--scenario", args->session.scenarios, "scenario name or file (repeatable)")
          ->required();
      sub.add_option("--segments", args->session.verification.segment_filter,
                     "evaluate the Cartesian segments whose label contains this (default all)");
      sub.add_option("--cycles", args->session.verification.cycles,
                     "cycles per case (ISO 9283: 10)");
      sub.add_option("--seed", args->session.verification.seed,
                     "seed of the per-cycle friction draws");
      sub.add_option("--look-ahead", args->session.verification.compensation.look_ahead_cycles,
                     "cycles of look-ahead of the precontrol's input");
      sub.add_option("--inversion-iterations",
                     args->session.verification.compensation.inversion_iterations,
                     "cascade stages inverting the loop (eval/closed_loop.hpp; 0: offset added "
                     "once)");
      sub.add_option("--offset-tolerance-rad", args->offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint [rad] (default: 1.5 x the table's "
                     "envelope of the identification data)");
      sub.add_flag("!--no-ablation", args->session.ablation, "skip the ablation tables");
      sub.add_flag("--search-transmission-error-order", args->session.search_order,
                   "find each joint's transmission-error harmonic per motor revolution (0.5 .. "
                   "4) from the joint errors' held-out fit instead of the config's");
      sub.add_flag("!--true-path", args->session.verification.measure_with_ims,
                   "evaluate the plant's true link-side path instead of the IMS chain's "
                   "measurement (faster; the IMS chain is the default)");
      sub.add_option("--out", args->out, "output folder")->required();
      sub.add_flag("--force", args->force, "Overwrite existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
