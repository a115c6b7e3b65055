// `imscal population`: the lab's chain on a population of plants around a nominal robot
// (sim/plant_population.hpp). Per plant (seed), in OUT/plant-SEED/ (built in OUT/.plant-SEED.tmp
// and renamed when complete, so a plant's folder is all or nothing and a rerun skips it):
//   plant/*.yaml            the plant's scenarios (its drawn plant_deviations and effects)
//   sim-mounting/, sim-identification/   `imscal simulate` of the two sessions
//   unit-calibration.yaml   the IMS unit's lab calibration (scale factors and misalignments of
//                           the simulated unit, biases left to the bundle; as
//                           datasets/campaign/regenerate.sh)
//   calibrate/, calibrate-frames/, identify/   the lab's chain, given only the nominal robot
//   verify-seed-line/, verify-iso9283/          `imscal verify` with identify's table
//   row.csv                 the plant's draws and figures
// then OUT/population.csv (a row per finished plant of the range) and OUT/summary.txt.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "core/subprocess.hpp"
#include "eval/population_summary.hpp"
#include "ident/identification_report.hpp"
#include "ims/earth_model.hpp"
#include "ims/sensor_error_model.hpp"
#include "sim/plant_population.hpp"
#include "sim/scenario.hpp"
#include "tools/command_registry.hpp"
#include "tools/stage_subcommand.hpp"

namespace {
namespace fs = std::filesystem;
namespace sim = imscal::sim;
namespace eval = imscal::eval;
using nlohmann::json;

struct PopulationArgs {
  std::string nominal, seeds, out, ident_config, calibrate_config, sensor, step;
  int cycles = 10;
  double timeout_s = 3600;
};

struct SeedRange {
  std::uint64_t first = 0, last = 0;
};

SeedRange parse_seeds(const std::string& text) {
  SeedRange r;
  const auto dash = text.find('-');
  try {
    r.first = std::stoull(text.substr(0, dash));
    r.last = dash == std::string::npos ? r.first : std::stoull(text.substr(dash + 1));
  } catch (const std::exception&) {
    throw imscal::InputError("", 0, "--seeds",
                             "expected FIRST-LAST or one seed, got '" + text + "'");
  }
  if (r.last < r.first) throw imscal::InputError("", 0, "--seeds", "LAST is below FIRST");
  return r;
}

fs::path datasets_dir() {
  return sim::resolve_scenario("identification").parent_path().parent_path();
}

// One child `imscal` run, its output into DIR/STEP.log. 0 passes; 1 (a failed check with the
// outputs written: calibrate's verdict) passes where allowed; anything else fails the plant.
void run_step(const std::string& step, const std::vector<std::string>& arguments,
              const fs::path& dir, const PopulationArgs& args, bool verdict_may_fail = false) {
  std::vector<std::string> argv{imscal::tools::imscal_binary().string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  imscal::SubprocessOptions options;
  options.timeout_s = args.timeout_s;
  const imscal::SubprocessResult r = imscal::run_subprocess(argv, options);
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

void write_plant_scenarios(const sim::PlantDraw& plant,
                           const imscal::calib::RobotDescription& nominal,
                           const PopulationArgs& args, const fs::path& plant_dir) {
  const fs::path programs = datasets_dir() / "programs";
  const PlantFiles files = plant_files(plant_dir);
  fs::create_directories(files.mounting.parent_path());
  const auto write = [&](const fs::path& file, const sim::PlantSession& session) {
    imscal::write_file_atomically(
        file, sim::plant_scenario_yaml(plant, nominal, args.nominal, args.sensor, session),
        imscal::Overwrite::kAllow);
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
  imscal::ims::SensorErrorModel lab =
      imscal::ims::load_sensor_error_model(sim_dir / "truth" / "sensor_errors.yaml");
  lab.gyro.bias.setZero();
  lab.acc.bias.setZero();
  const fs::path file = dir / "unit-calibration.yaml";
  imscal::write_file_atomically(file, imscal::ims::to_yaml(lab), imscal::Overwrite::kAllow);
  return file;
}

std::vector<std::string> calibrate_arguments(const fs::path& sim_dir, const fs::path& unit,
                                             const PopulationArgs& args, const fs::path& out) {
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
  const imscal::ims::EarthModel earth(sim::load_scenario(scenario).site);
  std::ostringstream text;
  text.precision(17);
  text << -earth.gravity_W(Eigen::Vector3d::Zero()).norm();
  return text.str();
}

struct VerifiedFigures {
  double before_mm = 0.0, after_mm = 0.0, reduction_percent = 0.0, true_reduction_percent = 0.0;
  double scatter_floor_mm = 0.0;  // the cycles' own scatter with the precontrol, as measured
  double systematic_mm = 0.0;     // the largest deviation of the cycles' mean path with it
};

VerifiedFigures read_verification(const fs::path& file) {
  std::ifstream in(file);
  const json doc = json::parse(in);
  const json& cases = doc.at("cases");
  for (const json& c : cases) {
    if (c.at("case") != "compensated") continue;
    return {cases.front().at("max_path_deviation_mm").get<double>(),
            c.at("max_path_deviation_mm").get<double>(),
            c.at("reduction_of_max_path_deviation_percent").get<double>(),
            c.at("true_path").at("reduction_of_max_path_deviation_percent").get<double>(),
            c.at("scatter_floor_mm").get<double>(),
            c.at("systematic_max_mm").get<double>()};
  }
  throw std::runtime_error(file.string() + ": no compensated case");
}

void verify_plant(const fs::path& table, const fs::path& scenario, const std::string& segments,
                  const std::string& step, const PopulationArgs& args, const fs::path& dir) {
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
  return read_verification(dir / step / sim::load_scenario(scenario).name / "verification.json");
}

std::string number(double value) {
  return fmt::format("{:.6g}", value);
}

// The transmission error's order per motor revolution identify chose per joint (its report).
std::vector<double> found_orders(const fs::path& identify_dir) {
  const fs::path file = identify_dir / "identification_report.json";
  const imscal::ident::IdentificationReport report =
      imscal::ident::read_identification_report(file);
  if (!report.header.order_search)
    throw imscal::InputError(file.string(), 0, "transmission_error_order_search",
                             "missing: identify ran without --search-transmission-error-order");
  std::vector<double> orders;
  for (const imscal::ident::OrderSearchJoint& joint : report.header.order_search->joints)
    orders.push_back(joint.chosen_harmonic_per_motor_rev);
  return orders;
}

// The plant's row: its draws (per joint, then the whole robot's) and its figures.
std::pair<std::string, std::string> plant_row(const sim::PlantDraw& plant,
                                              const std::vector<double>& orders,
                                              const VerifiedFigures& line,
                                              const VerifiedFigures& iso) {
  std::string header = "seed", row = std::to_string(plant.seed);
  const auto add = [&](const std::string& name, double value) {
    header += "," + name;
    row += "," + number(value);
  };
  for (int i = 0; i < imscal::calib::kJointCount; ++i) {
    const sim::JointDraw& j = plant.joints[i];
    const std::string a = fmt::format("A{}", i + 1);
    double te_arcsec = 0.0, main_order = 0.0, main_amplitude = 0.0;
    for (const auto& o : j.transmission_error) {
      te_arcsec += o.amplitude_arcsec;
      if (o.amplitude_arcsec > main_amplitude)
        main_amplitude = o.amplitude_arcsec, main_order = o.harmonic_per_motor_rev;
    }
    add("link_mass_" + a, j.link_mass);
    add("com_offset_mm_" + a,
        std::hypot(j.centre_of_mass_offset_mm[0], j.centre_of_mass_offset_mm[1],
                   j.centre_of_mass_offset_mm[2]));
    add("gear_stiffness_" + a, j.gear_stiffness);
    add("coulomb_" + a, j.coulomb_friction);
    add("viscous_" + a, j.viscous_friction);
    add("play_arcmin_" + a, j.play_arcmin);
    add("te_orders_" + a, static_cast<double>(j.transmission_error.size()));
    add("te_sum_arcsec_" + a, te_arcsec);
    add("te_main_order_" + a, main_order);
    add("position_gain_" + a, j.position_gain);
    add("velocity_gain_" + a, j.velocity_gain);
  }
  add("dead_time_cycles", plant.dead_time_cycles);
  add("payload_mass", plant.payload_mass);
  for (std::size_t j = 0; j < orders.size(); ++j)
    add(fmt::format("te_found_order_A{}", j + 1), orders[j]);
  for (const auto& [prefix, f] : {std::pair<const char*, const VerifiedFigures&>{"seed_line", line},
                                  std::pair<const char*, const VerifiedFigures&>{"iso100", iso}}) {
    add(fmt::format("{}_before_mm", prefix), f.before_mm);
    add(fmt::format("{}_after_mm", prefix), f.after_mm);
    add(fmt::format("{}_reduction_percent", prefix), f.reduction_percent);
    add(fmt::format("{}_true_reduction_percent", prefix), f.true_reduction_percent);
    add(fmt::format("{}_scatter_floor_mm", prefix), f.scatter_floor_mm);
    add(fmt::format("{}_systematic_mm", prefix), f.systematic_mm);
  }
  return {header, row};
}

// The row's outcomes (not draws): left out of the correlations.
const std::vector<std::string> kFigures{"te_found_order_A1",
                                        "te_found_order_A2",
                                        "te_found_order_A3",
                                        "te_found_order_A4",
                                        "te_found_order_A5",
                                        "te_found_order_A6",
                                        "seed_line_before_mm",
                                        "seed_line_after_mm",
                                        "seed_line_reduction_percent",
                                        "seed_line_true_reduction_percent",
                                        "seed_line_scatter_floor_mm",
                                        "seed_line_systematic_mm",
                                        "iso100_systematic_mm",
                                        "iso100_before_mm",
                                        "iso100_after_mm",
                                        "iso100_reduction_percent",
                                        "iso100_true_reduction_percent",
                                        "iso100_scatter_floor_mm"};

// One step of a plant's chain, run in the plant's folder DIR (OUT/plant-SEED when a workflow
// engine runs the steps one by one, a hidden folder when `population` runs them all).
struct PlantStepContext {
  std::uint64_t seed = 0;
  const imscal::calib::RobotDescription& nominal;
  const PopulationArgs& args;
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
  run_step(
      "identify",
      {"identify", "--joint-errors", (c.dir / "calibrate-frames" / "joint_errors.csv").string(),
       "--config", c.args.ident_config, "--robot", c.args.nominal, "--gravity-m-s2", "0", "0",
       gravity_down(plant_files(c.dir).identification), "--search-transmission-error-order",
       "--out", (c.dir / "identify").string()},
      c.dir, c.args);
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
  imscal::write_file_atomically(c.dir / "row.csv", header + "\n" + row + "\n",
                                imscal::Overwrite::kAllow);
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
void run_plant(std::uint64_t seed, const imscal::calib::RobotDescription& nominal,
               const PopulationArgs& args) {
  const fs::path done = fs::path(args.out) / fmt::format("plant-{}", seed);
  const fs::path dir = fs::path(args.out) / fmt::format(".plant-{}.tmp", seed);
  fs::remove_all(dir);
  fs::create_directories(dir);
  const PlantStepContext plant{seed, nominal, args, dir};
  for (const PlantStep& step : plant_steps()) step.run(plant);
  fs::rename(dir, done);
}

// Reads the finished plants' rows of the range into one table.
eval::PopulationTable collect_rows(const SeedRange& seeds, const fs::path& out, std::string& csv) {
  eval::PopulationTable table;
  for (std::uint64_t seed = seeds.first; seed <= seeds.last; ++seed) {
    std::ifstream in(out / fmt::format("plant-{}", seed) / "row.csv");
    std::string header, row;
    if (!std::getline(in, header) || !std::getline(in, row)) continue;
    if (!csv.empty() && header + "\n" != csv.substr(0, csv.find('\n') + 1)) {
      spdlog::warn("population: plant {}'s row has other columns (an older imscal); left out",
                   seed);
      continue;
    }
    if (table.columns.empty()) {
      std::stringstream names(header);
      for (std::string name; std::getline(names, name, ',');) table.columns.push_back(name);
      csv = header + "\n";
    }
    std::stringstream values(row);
    std::vector<double> parsed;
    for (std::string value; std::getline(values, value, ',');) parsed.push_back(std::stod(value));
    table.rows.push_back(parsed);
    csv += row + "\n";
  }
  return table;
}

// failed < 0: the plants of the range without a row (a workflow engine ran and reported them).
void write_summary(const SeedRange& seeds, const PopulationArgs& args, int failed) {
  std::string csv;
  const eval::PopulationTable table = collect_rows(seeds, args.out, csv);
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
      text += eval::summarize_figure(table, figure, kFigures);
    outputs.emplace_back("population.csv");
  }
  // The table and its summary are published together (a rerun replaces both).
  imscal::OutputFolder folder(args.out, outputs, imscal::Overwrite::kAllow);
  if (!table.rows.empty()) imscal::write_file_atomically(folder.staged("population.csv"), csv);
  imscal::write_file_atomically(folder.staged("summary.txt"), text);
  folder.commit();
  std::cout << text;
}

// One named step of one plant (--step), in OUT/plant-SEED, or the range's summary.
void run_one_step(const SeedRange& seeds, const imscal::calib::RobotDescription& nominal,
                  const PopulationArgs& args) {
  if (args.step == "summary") return write_summary(seeds, args, -1);
  std::string names = "summary";
  for (const PlantStep& step : plant_steps()) {
    names += std::string(", ") + step.name;
    if (args.step != step.name) continue;
    if (seeds.first != seeds.last)
      throw imscal::InputError("", 0, "--seeds", "a plant's step takes one seed, not a range");
    const fs::path dir = fs::path(args.out) / fmt::format("plant-{}", seeds.first);
    fs::create_directories(dir);
    return step.run({seeds.first, nominal, args, dir});
  }
  throw imscal::InputError("", 0, "--step", "no step '" + args.step + "'; steps: " + names);
}

void run_plants(const SeedRange& seeds, const imscal::calib::RobotDescription& nominal,
                const PopulationArgs& args) {
  int failed = 0;
  const std::uint64_t count = seeds.last - seeds.first + 1;
  for (std::uint64_t seed = seeds.first; seed <= seeds.last; ++seed) {
    const std::uint64_t number_in_range = seed - seeds.first + 1;
    if (fs::exists(fs::path(args.out) / fmt::format("plant-{}", seed) / "row.csv")) {
      spdlog::info("population: plant {} ({}/{}) finished before, skipped", seed, number_in_range,
                   count);
      continue;
    }
    spdlog::info("population: plant {} ({}/{})", seed, number_in_range, count);
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
  write_summary(seeds, args, failed);
  if (failed > 0)
    throw imscal::tools::CheckFailed(fmt::format("{} of {} plants failed", failed, count));
}

void run(PopulationArgs args) {
  const SeedRange seeds = parse_seeds(args.seeds);
  const fs::path datasets = datasets_dir();
  if (args.ident_config.empty())
    args.ident_config = (datasets / "identification" / "ident-default.yaml").string();
  if (args.calibrate_config.empty())
    args.calibrate_config = (datasets / "calibration" / "calibrate-default.yaml").string();
  if (args.sensor.empty()) args.sensor = (datasets / "sensors" / "navigation-grade.yaml").string();
  if (args.cycles < 1) throw imscal::InputError("", 0, "--cycles", "must be >= 1");
  const imscal::calib::RobotDescription nominal =
      imscal::calib::load_robot_description(args.nominal);
  imscal::create_output_folder(args.out);
  if (args.step.empty()) return run_plants(seeds, nominal, args);
  run_one_step(seeds, nominal, args);
}

imscal::tools::CommandRegistration registration{
    "population",
    "The chain on a population of plants drawn around a nominal robot: a row per plant, summary",
    [](CLI::App& sub) {
      auto args = std::make_shared<PopulationArgs>();
      sub.add_option("--nominal", args->nominal, "the nominal robot file (the data sheet)")
          ->required();
      sub.add_option("--seeds", args->seeds, "plant seeds, FIRST-LAST or one seed")->required();
      sub.add_option("--out", args->out, "output folder (a rerun skips finished plants)")
          ->required();
      sub.add_option("--cycles", args->cycles, "cycles per verification (ISO 9283: 10)");
      sub.add_option("--ident-config", args->ident_config,
                     "identification config (default datasets/identification/ident-default.yaml)");
      sub.add_option("--calibrate-config", args->calibrate_config,
                     "calibrate config (default datasets/calibration/calibrate-default.yaml)");
      sub.add_option("--sensor", args->sensor,
                     "IMS sensor spec (default datasets/sensors/navigation-grade.yaml)");
      sub.add_option("--timeout-s", args->timeout_s, "time limit of each step of a plant [s]");
      sub.add_option("--step", args->step,
                     "run one step of one plant in OUT/plant-SEED (scenarios, simulate-mounting, "
                     "simulate-identification, calibrate, calibrate-frames, identify, "
                     "verify-seed-line, verify-iso9283, row), or `summary` of the range; for a "
                     "workflow engine (workflows/population.smk)");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
