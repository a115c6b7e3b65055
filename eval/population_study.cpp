#include "eval/population_study.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "core/subprocess.hpp"
#include "eval/population_row.hpp"
#include "eval/population_summary.hpp"
#include "eval/verification_files.hpp"
#include "ims/earth_model.hpp"
#include "ims/sensor_error_model.hpp"
#include "sim/plant_population.hpp"
#include "sim/scenario.hpp"

namespace imscal::eval {

namespace fs = std::filesystem;

SeedRange parse_seed_range(const std::string& text) {
  SeedRange r;
  const auto dash = text.find('-');
  try {
    r.first = std::stoull(text.substr(0, dash));
    r.last = dash == std::string::npos ? r.first : std::stoull(text.substr(dash + 1));
  } catch (const std::exception&) {
    throw InputError("", 0, "--seeds", "expected FIRST-LAST or one seed, got '" + text + "'");
  }
  if (r.last < r.first) throw InputError("", 0, "--seeds", "LAST is below FIRST");
  return r;
}

namespace {

fs::path datasets_dir() {
  return sim::resolve_scenario("identification").parent_path().parent_path();
}

// One child `imscal` run, its output into DIR/STEP.log. 0 passes; 1 (a failed check with the
// outputs written: calibrate's verdict) passes where allowed; anything else fails the plant.
void run_step(const std::string& step, const std::vector<std::string>& arguments,
              const fs::path& dir, const PopulationStudyOptions& args,
              bool verdict_may_fail = false) {
  std::vector<std::string> argv{args.imscal_binary.string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  SubprocessOptions options;
  options.timeout_s = args.timeout_s;
  const SubprocessResult r = run_subprocess(argv, options);
  const fs::path log = dir / (step + ".log");
  std::string command = "$ imscal";  // the command line first: what the step was handed
  for (const std::string& argument : arguments) command += " " + argument;
  std::ofstream(log) << command << "\n" << r.output;
  if (r.exit_code == 0 || (verdict_may_fail && r.exit_code == 1 && !r.timed_out)) return;
  throw std::runtime_error(fmt::format("{} ended with {}{}; see {}", step, r.exit_code,
                                       r.timed_out ? " (timed out)" : "", log.string()));
}

struct PlantFiles {
  fs::path mounting, identification, seed_line, iso9283;
};

// The plant's four scenarios: the two lab sessions (same scenario seed: same base heading,
// mount and unit; a clock of their own each) and the two verification paths (fixed frames, as
// the shipped seed-line.yaml and iso9283.yaml).
PlantFiles plant_files(const fs::path& plant_dir) {
  const fs::path dir = plant_dir / "plant";
  return {dir / "mounting.yaml", dir / "identification.yaml", dir / "seed-line.yaml",
          dir / "iso9283.yaml"};
}

void write_plant_scenarios(const sim::PlantDraw& plant, const calib::RobotDescription& nominal,
                           const PopulationStudyOptions& args, const fs::path& plant_dir) {
  const fs::path programs = datasets_dir() / "programs";
  const PlantFiles files = plant_files(plant_dir);
  fs::create_directories(files.mounting.parent_path());
  const auto write = [&](const fs::path& file, const sim::PlantSession& session) {
    write_file_atomically(
        file, sim::plant_scenario_yaml(plant, nominal, args.nominal, args.sensor, session),
        Overwrite::kAllow);
  };
  write(files.mounting, {"mounting", programs / "mounting.yaml", 0.0123, true, plant.seed});
  write(files.identification,
        {"identification", programs / "identification.yaml", 0.0371, true, plant.seed});
  write(files.seed_line, {"seed-line", programs / "seed-line.yaml", 0.0123, false, 1});
  write(files.iso9283, {"iso9283", programs / "iso9283.yaml", 0.0123, false, 1});
}

// The unit's lab calibration: the simulated unit's scale factors and misalignments (a lab
// calibrates its IMS on a rate table, apart from any robot), biases left to the bundle.
fs::path write_unit_calibration(const fs::path& sim_dir, const fs::path& dir) {
  ims::SensorErrorModel lab =
      ims::load_sensor_error_model(sim_dir / "truth" / "sensor_errors.yaml");
  lab.gyro.bias.setZero();
  lab.acc.bias.setZero();
  const fs::path file = dir / "unit-calibration.yaml";
  write_file_atomically(file, ims::to_yaml(lab), Overwrite::kAllow);
  return file;
}

std::vector<std::string> calibrate_arguments(const fs::path& sim_dir, const fs::path& unit,
                                             const PopulationStudyOptions& args,
                                             const fs::path& out) {
  return {"calibrate",
          "--imu",
          (sim_dir / "imu.csv").string(),
          "--robot-log",
          (sim_dir / "robot.csv").string(),
          "--robot",
          args.nominal,
          "--sensor",
          args.sensor,
          "--config",
          args.calibrate_config,
          "--unit-calibration",
          unit.string(),
          "--out",
          out.string()};
}

// The site's normal gravity, downwards in the robot base (the lab knows where it stands).
std::string gravity_down(const fs::path& scenario) {
  const ims::EarthModel earth(sim::load_scenario(scenario).site);
  std::ostringstream text;
  text.precision(17);
  text << -earth.gravity_W(Eigen::Vector3d::Zero()).norm();
  return text.str();
}

void verify_plant(const fs::path& table, const fs::path& scenario, const std::string& segments,
                  const std::string& step, const PopulationStudyOptions& args,
                  const fs::path& dir) {
  std::vector<std::string> arguments{"verify",
                                     "--table",
                                     table.string(),
                                     "--scenario",
                                     scenario.string(),
                                     "--cycles",
                                     std::to_string(args.cycles),
                                     "--no-ablation",
                                     "--out",
                                     (dir / step).string()};
  if (!segments.empty()) arguments.insert(arguments.end(), {"--segments", segments});
  run_step(step, arguments, dir, args);
}

VerifiedFigures verified_figures(const fs::path& scenario, const std::string& step,
                                 const fs::path& dir) {
  return read_verified_figures(dir / step / sim::load_scenario(scenario).name /
                               "verification.json");
}

// One step of a plant's chain, run in the plant's folder DIR (OUT/plant-SEED when a workflow
// engine runs the steps one by one, a hidden folder when `population` runs them all).
struct PlantStepContext {
  std::uint64_t seed = 0;
  const calib::RobotDescription& nominal;
  const PopulationStudyOptions& args;
  fs::path dir;
};

struct PlantStep {
  const char* name;
  void (*run)(const PlantStepContext&);
};

void step_scenarios(const PlantStepContext& c) {
  write_plant_scenarios(sim::draw_plant(c.nominal, c.seed), c.nominal, c.args, c.dir);
}

void step_simulate(const PlantStepContext& c, const fs::path& scenario, const char* session) {
  run_step(fmt::format("simulate-{}", session),
           {"simulate", "--scenario", scenario.string(), "--out",
            (c.dir / fmt::format("sim-{}", session)).string()},
           c.dir, c.args);
}

// The unit's lab calibration, then calibrate on the mounting session: frames and verdict.
void step_calibrate(const PlantStepContext& c) {
  const fs::path unit = write_unit_calibration(c.dir / "sim-mounting", c.dir);
  run_step("calibrate",
           calibrate_arguments(c.dir / "sim-mounting", unit, c.args, c.dir / "calibrate"), c.dir,
           c.args, true);
}

// calibrate --frames on the identification session: its joint errors, with the mounting's frames.
void step_calibrate_frames(const PlantStepContext& c) {
  std::vector<std::string> frames =
      calibrate_arguments(c.dir / "sim-identification", c.dir / "unit-calibration.yaml", c.args,
                          c.dir / "calibrate-frames");
  frames.insert(frames.end(), {"--frames", (c.dir / "calibrate" / "frames.json").string()});
  run_step("calibrate-frames", frames, c.dir, c.args, true);
}

void step_identify(const PlantStepContext& c) {
  std::vector<std::string> arguments{"identify",
                                     "--joint-errors",
                                     (c.dir / "calibrate-frames" / "joint_errors.csv").string(),
                                     "--config",
                                     c.args.ident_config,
                                     "--robot",
                                     c.args.nominal,
                                     "--gravity-m-s2",
                                     "0",
                                     "0",
                                     gravity_down(plant_files(c.dir).identification),
                                     "--search-transmission-error-order",
                                     "--out",
                                     (c.dir / "identify").string()};
  if (c.args.second_order) arguments.emplace_back("--search-second-transmission-error-order");
  if (c.args.track_orders) arguments.emplace_back("--track-transmission-error-orders");
  run_step("identify", arguments, c.dir, c.args);
}

fs::path identified_table(const PlantStepContext& c) {
  return c.dir / "identify" / "parameters.json";
}

// The plant's row: its draws, the orders identify found and both paths' figures.
void step_row(const PlantStepContext& c) {
  const PlantFiles files = plant_files(c.dir);
  const VerifiedFigures line = verified_figures(files.seed_line, "verify-seed-line", c.dir);
  const VerifiedFigures iso = verified_figures(files.iso9283, "verify-iso9283", c.dir);
  const auto [header, row] =
      plant_row(sim::draw_plant(c.nominal, c.seed), found_orders(c.dir / "identify"), line, iso);
  write_file_atomically(c.dir / "row.csv", header + "\n" + row + "\n", Overwrite::kAllow);
  spdlog::info(
      "population: plant {}: seed-line {:.3f} -> {:.3f} mm ({:.1f} %), ISO 100 % {:.3f} "
      "-> {:.3f} mm ({:.1f} %)",
      c.seed, line.before_mm, line.after_mm, line.reduction_percent, iso.before_mm, iso.after_mm,
      iso.reduction_percent);
}

// simulate -> unit calibration -> calibrate -> calibrate --frames -> identify -> verify -> row:
// the lab's chain from the raw IMS records and robot logs, with the nominal robot file only.
const std::vector<PlantStep>& plant_steps() {
  static const std::vector<PlantStep> steps{
      {"scenarios", step_scenarios},
      {"simulate-mounting",
       [](const PlantStepContext& c) {
         step_simulate(c, plant_files(c.dir).mounting, "mounting");
       }},
      {"simulate-identification",
       [](const PlantStepContext& c) {
         step_simulate(c, plant_files(c.dir).identification, "identification");
       }},
      {"calibrate", step_calibrate},
      {"calibrate-frames", step_calibrate_frames},
      {"identify", step_identify},
      {"verify-seed-line",
       [](const PlantStepContext& c) {
         verify_plant(identified_table(c), plant_files(c.dir).seed_line, "", "verify-seed-line",
                      c.args, c.dir);
       }},
      {"verify-iso9283",
       [](const PlantStepContext& c) {
         verify_plant(identified_table(c), plant_files(c.dir).iso9283, "100%", "verify-iso9283",
                      c.args, c.dir);
       }},
      {"row", step_row}};
  return steps;
}

// One plant, all or nothing: its steps run in a hidden folder, renamed when its row is written.
void run_plant(std::uint64_t seed, const calib::RobotDescription& nominal,
               const PopulationStudyOptions& args) {
  const fs::path done = args.out / fmt::format("plant-{}", seed);
  const fs::path dir = args.out / fmt::format(".plant-{}.tmp", seed);
  fs::remove_all(dir);
  fs::create_directories(dir);
  const PlantStepContext plant{seed, nominal, args, dir};
  for (const PlantStep& step : plant_steps()) step.run(plant);
  fs::rename(dir, done);
}

}  // namespace

std::string write_population_summary(const SeedRange& seeds, const PopulationStudyOptions& args,
                                     int failed) {
  std::string csv;
  const PopulationTable table = read_population_rows(seeds.first, seeds.last, args.out, csv);
  if (failed < 0) failed = int(seeds.last - seeds.first + 1 - table.rows.size());
  std::string text = fmt::format(
      "imscal population: nominal robot {}, seeds {}-{}, {} cycles per verification; {} plants "
      "finished, {} failed (reductions of the maximum path deviation in %, as measured through "
      "the IMS chain)\n",
      args.nominal, seeds.first, seeds.last, args.cycles, table.rows.size(), failed);
  std::vector<fs::path> outputs{"summary.txt"};
  if (!table.rows.empty()) {
    for (const char* figure : {"seed_line_reduction_percent", "iso100_reduction_percent",
                               "seed_line_true_reduction_percent", "iso100_true_reduction_percent"})
      text += summarize_figure(table, figure, population_figure_columns());
    // The goals of the population: seed-line median 93 %, ISO 9283 at 100 % median 90 %.
    text += summarize_scatter_ceiling(table, "seed_line", 93.0);
    text += summarize_scatter_ceiling(table, "iso100", 90.0);
    outputs.emplace_back("population.csv");
  }
  // The table and its summary are published together (a rerun replaces both).
  OutputFolder folder(args.out, outputs, Overwrite::kAllow);
  if (!table.rows.empty()) write_file_atomically(folder.staged("population.csv"), csv);
  write_file_atomically(folder.staged("summary.txt"), text);
  folder.commit();
  return text;
}

std::string run_population_step(const std::string& step_name, const SeedRange& seeds,
                                const calib::RobotDescription& nominal,
                                const PopulationStudyOptions& args) {
  if (step_name == "summary") return write_population_summary(seeds, args, -1);
  std::string names = "summary";
  for (const PlantStep& step : plant_steps()) {
    names += std::string(", ") + step.name;
    if (step_name != step.name) continue;
    if (seeds.first != seeds.last)
      throw InputError("", 0, "--seeds", "a plant's step takes one seed, not a range");
    const fs::path dir = args.out / fmt::format("plant-{}", seeds.first);
    fs::create_directories(dir);
    step.run({seeds.first, nominal, args, dir});
    return "";
  }
  throw InputError("", 0, "--step", "no step '" + step_name + "'; steps: " + names);
}

int run_population(const SeedRange& seeds, const calib::RobotDescription& nominal,
                   const PopulationStudyOptions& args, const PlantStarted& on_plant) {
  int failed = 0;
  const std::uint64_t count = seeds.last - seeds.first + 1;
  for (std::uint64_t seed = seeds.first; seed <= seeds.last; ++seed) {
    const std::uint64_t number_in_range = seed - seeds.first + 1;
    if (fs::exists(args.out / fmt::format("plant-{}", seed) / "row.csv")) {
      spdlog::info("population: plant {} ({}/{}) finished before, skipped", seed, number_in_range,
                   count);
      continue;
    }
    spdlog::info("population: plant {} ({}/{})", seed, number_in_range, count);
    if (on_plant) on_plant(seed, number_in_range, count);
    const auto start = std::chrono::steady_clock::now();
    try {
      run_plant(seed, nominal, args);
    } catch (const std::exception& e) {
      ++failed;
      spdlog::error("population: plant {} failed: {}", seed, e.what());
    }
    spdlog::info("population: plant {} took {:.0f} s", seed,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return failed;
}

PopulationStudyOptions with_defaults(PopulationStudyOptions args) {
  const fs::path datasets = datasets_dir();
  if (args.ident_config.empty())
    args.ident_config = (datasets / "identification" / "ident-default.yaml").string();
  if (args.calibrate_config.empty())
    args.calibrate_config = (datasets / "calibration" / "calibrate-default.yaml").string();
  if (args.sensor.empty()) args.sensor = (datasets / "sensors" / "navigation-grade.yaml").string();
  if (args.cycles < 1) throw InputError("", 0, "--cycles", "must be >= 1");
  return args;
}

}  // namespace imscal::eval
