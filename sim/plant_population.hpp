#pragma once
// A population of plausible plants around a nominal robot: each plant is the nominal robot file
// with deviations drawn from one seed, as a real robot of the type differs from its data sheet
// (masses, centres of mass, gear stiffness, friction, play, transmission error, controller gains,
// dead time, the payload it carries). A plant is reproducible from (nominal robot, seed): the
// draws use std::mt19937_64 (fixed by the standard) mapped to [0, 1) here, not the library's
// distributions (whose algorithms differ between standard libraries).
//
// A drawn plant is written as a scenario's `plant_deviations:` and `effects:` blocks
// (datasets/FORMAT.md §9), so that `imscal simulate` runs it like any other scenario and the
// chain, given only the nominal robot file, never reads it.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "robot/robot_description.hpp"

namespace imscal::sim {

// The ranges of the draws (uniform unless said).
struct PlantPopulationRanges {
  double link_mass = 0.20;                // factor 1 +- this
  double centre_of_mass_m = 0.03;         // per axis, +- this, added in the link's frame
  double gear_stiffness = 0.30;           // factor 1 +- this
  double friction_low = 0.5;              // Coulomb and viscous: factor in [low, high], log-uniform
  double friction_high = 2.0;             //
  double play_low_arcmin = 0.5;           // full width of the play on the joints that have one
  double play_high_arcmin = 5.0;          //
  int transmission_error_orders_max = 3;  // 1..max orders per joint
  double transmission_error_low_arcsec = 3.0;    // amplitude of each order
  double transmission_error_high_arcsec = 20.0;  //
  double controller_gain = 0.20;                 // position and velocity gains: factor 1 +- this
  int dead_time_cycles_max = 3;  // 0..max controller cycles, the same on every joint
  double payload_mass = 0.10;    // carried payload's mass: factor 1 +- this
};

// The orders per motor revolution a transmission error is drawn from (distinct per joint): the
// range the chain's order search covers (eval/transmission_error_order.hpp).
std::vector<double> transmission_error_order_choices();

struct TransmissionErrorOrder {
  double harmonic_per_motor_rev = 1.0;
  double amplitude_arcsec = 0.0;
  double phase_deg = 0.0;
};

struct JointDraw {
  double link_mass = 1.0;  // factors on the nominal robot file's values
  double gear_stiffness = 1.0;
  double coulomb_friction = 1.0;
  double viscous_friction = 1.0;
  double position_gain = 1.0;
  double velocity_gain = 1.0;
  std::array<double, 3> centre_of_mass_offset_mm{};  // added, link frame
  double play_arcmin = 0.0;  // 0: the play is closed (effects backlash: false)
  std::vector<TransmissionErrorOrder> transmission_error;
};

struct PlantDraw {
  std::uint64_t seed = 0;
  std::array<JointDraw, calib::kJointCount> joints;
  int dead_time_cycles = 0;
  double payload_mass = 1.0;  // factor on the program's payload (the robot log keeps it)
};

// Which joints may have play: A2 (the gravity-loaded gear) always, A3 and A5 at random (half the
// plants each). A1, A4 and A6 keep theirs closed as in the shipped scenarios: the simulated play
// has no stiction, so an unloaded link keeps sliding in it at rest and the IMS finds no rest
// (datasets/scenarios/seed-line.yaml).
constexpr std::array<bool, calib::kJointCount> kPlayAlways{false, true, false, false, false, false};
constexpr std::array<bool, calib::kJointCount> kPlayMaybe{false, false, true, false, true, false};

// The plant of `seed` around `nominal`. std::invalid_argument if a joint that may have play has
// none in the nominal robot (the play is written as a factor on it).
PlantDraw draw_plant(const calib::RobotDescription& nominal, std::uint64_t seed,
                     const PlantPopulationRanges& ranges = {});

// The scenario blocks of a plant, YAML at the top level (numbers with 17 significant digits:
// the loaded plant is the drawn one exactly): `plant_deviations:` and `effects:` (every drive
// effect on, the drawn play, transmission error and dead time).
std::string plant_scenario_blocks(const PlantDraw& plant, const calib::RobotDescription& nominal);

// A whole scenario file for `plant` running `program`, with the shipped scenarios' site, IMS,
// sensor mount and integration step. `random_frames`: base heading and mount drawn from the
// scenario seed (the two sessions of a plant share it, so they share base, mount and unit).
struct PlantSession {
  std::string name;
  std::filesystem::path program_file;
  double clock_offset_s = 0.0123;
  bool random_frames = false;
  std::uint64_t scenario_seed = 1;
};
std::string plant_scenario_yaml(const PlantDraw& plant, const calib::RobotDescription& nominal,
                                const std::filesystem::path& nominal_file,
                                const std::filesystem::path& sensor_file,
                                const PlantSession& session);

}  // namespace imscal::sim
