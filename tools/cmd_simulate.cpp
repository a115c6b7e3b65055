// `imscal simulate --scenario NAME|FILE --out DIR [--seed N] [--force]`: runs a scenario
// (sim/scenario.hpp) and writes the raw IMS file, the robot's log and the truth
// (sim/simulation_output.hpp). Same scenario and seed, same bytes.
#include <spdlog/spdlog.h>

#include <memory>
#include <optional>
#include <string>

#include "core/output_folder.hpp"
#include "core/progress.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"
#include "sim/simulation_output.hpp"
#include "tools/command_registry.hpp"

namespace {
using namespace imscal;

struct SimulateArgs {
  std::string scenario;
  std::string out;
  std::optional<std::uint64_t> seed;
  bool force = false;
};

void run(const SimulateArgs& args) {
  const sim::Scenario scenario = sim::load_scenario(sim::resolve_scenario(args.scenario));
  const std::uint64_t seed = args.seed.value_or(scenario.seed);
  const Overwrite overwrite = args.force ? Overwrite::kAllow : Overwrite::kRefuse;
  // Refuse existing outputs before the work, not after it.
  { OutputFolder check(args.out, sim::simulation_outputs(scenario), overwrite); }
  spdlog::info("simulating scenario '{}' ({}), seed {}", scenario.name, scenario.file.string(),
               seed);
  Progress progress;
  const sim::SimulationResult result = sim::run_simulation(
      scenario, seed,
      [&](const char* stage, double fraction) { progress.update(stage, fraction); });
  progress.update("write", 0.0);
  sim::write_simulation(args.out, scenario, seed, result, overwrite);
  progress.finish();
  spdlog::info("{} s of robot motion, {} IMS samples at {} Hz, written to {}",
               result.path.samples.empty() ? 0.0 : result.path.samples.back().t_s,
               result.imu_raw.samples.size(), scenario.imu_rate_hz, args.out);
}

tools::CommandRegistration registration{
    "simulate",
    "Simulate a robot with its IMS: robot.csv, a raw IMS file and the truth, from a scenario",
    [](CLI::App& sub) {
      auto args = std::make_shared<SimulateArgs>();
      sub.add_option("--scenario", args->scenario,
                     "Shipped scenario name (datasets/scenarios/NAME.yaml) or a scenario file")
          ->required();
      sub.add_option("--out", args->out, "Output folder")->required();
      sub.add_option("--seed", args->seed, "Seed of every random draw (default: the scenario's)");
      sub.add_flag("--force", args->force, "Replace existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
