#pragma once
// A population study (`imscal population`): the lab's chain on plants drawn around a nominal
// robot (sim/plant_population.hpp). Per plant (seed), in OUT/plant-SEED/ (built in
// OUT/.plant-SEED.tmp and renamed when complete, so a plant's folder is all or nothing and a
// rerun skips it):
//   plant/*.yaml            the plant's scenarios (its drawn plant_deviations and effects)
//   sim-mounting/, sim-identification/   `imscal simulate` of the two sessions
//   unit-calibration.yaml   the IMS unit's lab calibration (scale factors and misalignments of
//                           the simulated unit, biases left to the bundle; as
//                           datasets/campaign/regenerate.sh)
//   calibrate/, calibrate-frames/, identify/   the lab's chain, given only the nominal robot
//   verify-seed-line/, verify-iso9283/          `imscal verify` with identify's table
//   row.csv                 the plant's draws and figures (eval/population_row.hpp)
// then OUT/population.csv (a row per finished plant of the range) and OUT/summary.txt. The chain's
// steps run the imscal binary as child processes (their logs in OUT/plant-SEED/STEP.log), so that
// a step writes exactly what the command writes.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "robot/robot_description.hpp"

namespace imscal::eval {

struct PopulationStudyOptions {
  std::filesystem::path imscal_binary;  // runs the chain's steps
  std::string nominal;                  // the nominal robot file (the data sheet)
  std::filesystem::path out;
  std::string ident_config, calibrate_config, sensor;  // empty: the datasets' defaults
  int cycles = 10;                                     // cycles per verification
  double timeout_s = 3600;                             // time limit of each step of a plant
  // identify also searches a second transmission-error harmonic per joint
  // (`--search-second-transmission-error-order`, eval/transmission_error_order.hpp).
  bool second_order = false;
  // identify also takes each joint's orders from the joint errors' order spectrum
  // (`--track-transmission-error-orders`, eval/transmission_error_order_spectrum.hpp).
  bool track_orders = false;
};

struct SeedRange {
  std::uint64_t first = 0, last = 0;
};

// "FIRST-LAST" or one seed; InputError naming --seeds otherwise.
SeedRange parse_seed_range(const std::string& text);

// The options with the datasets' defaults filled in; InputError on cycles < 1.
PopulationStudyOptions with_defaults(PopulationStudyOptions options);

// (plant seed, its number in the range from 1, plants in the range).
using PlantStarted =
    std::function<void(std::uint64_t seed, std::uint64_t number_in_range, std::uint64_t count)>;

// Runs every plant of the range not finished before (one failing plant is logged and counted,
// the others run on). Returns the number of failed plants.
int run_population(const SeedRange& seeds, const calib::RobotDescription& nominal,
                   const PopulationStudyOptions& options, const PlantStarted& on_plant = {});

// One named step of one plant in OUT/plant-SEED (for a workflow engine), or `summary` of the
// range (returns the summary's text; a plant's step returns ""). InputError for an unknown step
// or a range given to a plant's step.
std::string run_population_step(const std::string& step, const SeedRange& seeds,
                                const calib::RobotDescription& nominal,
                                const PopulationStudyOptions& options);

// OUT/population.csv and OUT/summary.txt of the range's finished plants; failed < 0: the plants
// of the range without a row. Returns the summary's text.
std::string write_population_summary(const SeedRange& seeds, const PopulationStudyOptions& options,
                                     int failed);

}  // namespace imscal::eval
