// `imscal population`: the lab's chain on a population of plants around a nominal robot
// (eval/population_study.hpp: a folder and a row per plant, then OUT/population.csv and
// OUT/summary.txt). --step runs one step of one plant, for a workflow engine.
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "core/output_folder.hpp"
#include "core/progress_channel.hpp"
#include "eval/population_study.hpp"
#include "tools/command_registry.hpp"
#include "tools/stage_subcommand.hpp"

namespace {
namespace eval = imscal::eval;

struct PopulationArgs {
  eval::PopulationStudyOptions study;
  std::string seeds, out, step;
};

void run(PopulationArgs args) {
  const eval::SeedRange seeds = eval::parse_seed_range(args.seeds);
  args.study.out = args.out;
  args.study.imscal_binary = imscal::tools::imscal_binary();
  const eval::PopulationStudyOptions study = eval::with_defaults(args.study);
  const imscal::calib::RobotDescription nominal =
      imscal::calib::load_robot_description(study.nominal);
  imscal::create_output_folder(study.out);
  if (!args.step.empty()) {
    std::cout << eval::run_population_step(args.step, seeds, nominal, study);
    return;
  }
  const imscal::ProgressCallback progress = imscal::progress_channel();
  const int failed = eval::run_population(
      seeds, nominal, study,
      [&progress](std::uint64_t seed, std::uint64_t number_in_range, std::uint64_t count) {
        progress(fmt::format("plant {}", seed), double(number_in_range - 1) / double(count));
      });
  std::cout << eval::write_population_summary(seeds, study, failed);
  if (failed > 0)
    throw imscal::tools::CheckFailed(
        fmt::format("{} of {} plants failed", failed, seeds.last - seeds.first + 1));
}

imscal::tools::CommandRegistration registration{
    "population",
    "The chain on a population of plants drawn around a nominal robot: a row per plant, summary",
    [](CLI::App& sub) {
      auto args = std::make_shared<PopulationArgs>();
      sub.add_option("--nominal", args->study.nominal, "the nominal robot file (the data sheet)")
          ->required();
      sub.add_option("--seeds", args->seeds, "plant seeds, FIRST-LAST or one seed")->required();
      sub.add_option("--out", args->out, "output folder (a rerun skips finished plants)")
          ->required();
      sub.add_option("--cycles", args->study.cycles, "cycles per verification (ISO 9283: 10)");
      sub.add_flag("--second-transmission-error-order", args->study.second_order,
                   "identify also searches a second transmission-error harmonic per joint");
      sub.add_flag("--track-transmission-error-orders", args->study.track_orders,
                   "identify also takes each joint's transmission-error orders (up to two) from "
                   "the joint errors' order spectrum");
      sub.add_option("--ident-config", args->study.ident_config,
                     "identification config (default datasets/identification/ident-default.yaml)");
      sub.add_option("--calibrate-config", args->study.calibrate_config,
                     "calibrate config (default datasets/calibration/calibrate-default.yaml)");
      sub.add_option("--sensor", args->study.sensor,
                     "IMS sensor spec (default datasets/sensors/navigation-grade.yaml)");
      sub.add_option("--timeout-s", args->study.timeout_s,
                     "time limit of each step of a plant [s]");
      sub.add_option("--step", args->step,
                     "run one step of one plant in OUT/plant-SEED (scenarios, simulate-mounting, "
                     "simulate-identification, calibrate, calibrate-frames, identify, "
                     "verify-seed-line, verify-iso9283, row), or `summary` of the range; for a "
                     "workflow engine (workflows/population.smk)");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
