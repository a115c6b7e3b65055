#include "sim/plant_population.hpp"
#include "core/units.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace imscal::sim {
namespace {

// Uniform draws in [0, 1) from the top 53 bits of mt19937_64: the same numbers on every standard
// library (std::uniform_real_distribution's algorithm is not specified).
class PlantRandom {
 public:
  explicit PlantRandom(std::uint64_t seed) : engine_(seed) {}
  double unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double low, double high) { return low + (high - low) * unit(); }
  double around_one(double spread) { return uniform(1.0 - spread, 1.0 + spread); }
  double log_uniform(double low, double high) {
    return std::exp(uniform(std::log(low), std::log(high)));
  }
  int integer(int low, int high) {  // in [low, high]
    return std::min(high, low + static_cast<int>(unit() * (high - low + 1)));
  }

 private:
  std::mt19937_64 engine_;
};

std::vector<TransmissionErrorOrder> draw_transmission_error(PlantRandom& random,
                                                            const PlantPopulationRanges& ranges) {
  std::vector<double> choices = transmission_error_order_choices();
  const int count = random.integer(1, ranges.transmission_error_orders_max);
  std::vector<TransmissionErrorOrder> orders;
  for (int k = 0; k < count; ++k) {
    const int pick = random.integer(0, static_cast<int>(choices.size()) - 1);
    TransmissionErrorOrder order;
    order.harmonic_per_motor_rev = choices[static_cast<std::size_t>(pick)];
    choices.erase(choices.begin() + pick);
    order.amplitude_arcsec =
        random.uniform(ranges.transmission_error_low_arcsec, ranges.transmission_error_high_arcsec);
    order.phase_deg = random.uniform(0.0, 360.0);
    orders.push_back(order);
  }
  return orders;
}

JointDraw draw_joint(PlantRandom& random, const PlantPopulationRanges& ranges, bool play) {
  JointDraw j;
  j.link_mass = random.around_one(ranges.link_mass);
  for (double& offset : j.centre_of_mass_offset_mm)
    offset = random.uniform(-ranges.centre_of_mass_m, ranges.centre_of_mass_m) * 1e3;
  j.gear_stiffness = random.around_one(ranges.gear_stiffness);
  j.coulomb_friction = random.log_uniform(ranges.friction_low, ranges.friction_high);
  j.viscous_friction = random.log_uniform(ranges.friction_low, ranges.friction_high);
  j.position_gain = random.around_one(ranges.controller_gain);
  j.velocity_gain = random.around_one(ranges.controller_gain);
  // Drawn on every joint so that a joint's other draws do not depend on whether it has play.
  const double play_arcmin = random.uniform(ranges.play_low_arcmin, ranges.play_high_arcmin);
  j.play_arcmin = play ? play_arcmin : 0.0;
  j.transmission_error = draw_transmission_error(random, ranges);
  return j;
}

std::string number(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

std::string joint_deviations(const JointDraw& j, const calib::JointDescription& nominal) {
  std::string text =
      "{link_mass: " + number(j.link_mass) + ", centre_of_mass_offset_mm: [" +
      number(j.centre_of_mass_offset_mm[0]) + ", " + number(j.centre_of_mass_offset_mm[1]) + ", " +
      number(j.centre_of_mass_offset_mm[2]) + "], gear_stiffness: " + number(j.gear_stiffness) +
      ", coulomb_friction: " + number(j.coulomb_friction) +
      ", viscous_friction: " + number(j.viscous_friction) +
      ", position_gain: " + number(j.position_gain) + ", velocity_gain: " + number(j.velocity_gain);
  if (j.play_arcmin > 0.0)
    text += ", backlash: " + number(j.play_arcmin / (nominal.drive.backlash_rad * kArcminPerRad));
  return text + "}";
}

std::string joint_effects(const JointDraw& j) {
  std::string text = std::string("{backlash: ") + (j.play_arcmin > 0.0 ? "true" : "false") +
                     ", transmission_error_shapes: [";
  for (std::size_t k = 0; k < j.transmission_error.size(); ++k) {
    const TransmissionErrorOrder& o = j.transmission_error[k];
    text += (k ? ", " : "") + std::string("{amplitude_arcsec: ") + number(o.amplitude_arcsec) +
            ", harmonic_per_motor_rev: " + number(o.harmonic_per_motor_rev) +
            ", phase_deg: " + number(o.phase_deg) + "}";
  }
  return text + "]}";
}

}  // namespace

std::vector<double> transmission_error_order_choices() {
  return {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0};
}

PlantDraw draw_plant(const calib::RobotDescription& nominal, std::uint64_t seed,
                     const PlantPopulationRanges& ranges) {
  PlantRandom random(seed);
  PlantDraw plant;
  plant.seed = seed;
  for (int i = 0; i < calib::kJointCount; ++i) {
    const bool play = kPlayAlways[i] || (kPlayMaybe[i] && random.unit() < 0.5);
    if ((kPlayAlways[i] || kPlayMaybe[i]) && !(nominal.joints[i].drive.backlash_rad > 0.0))
      throw std::invalid_argument("plant population: joint " + nominal.joints[i].name +
                                  " has no play in the nominal robot to scale");
    plant.joints[i] = draw_joint(random, ranges, play);
  }
  plant.dead_time_cycles = random.integer(0, ranges.dead_time_cycles_max);
  plant.payload_mass = random.around_one(ranges.payload_mass);
  return plant;
}

std::string plant_scenario_blocks(const PlantDraw& plant, const calib::RobotDescription& nominal) {
  std::string text = "plant_deviations:\n  payload_mass: " + number(plant.payload_mass) + "\n";
  for (int i = 0; i < calib::kJointCount; ++i)
    text += "  " + nominal.joints[i].name + ": " +
            joint_deviations(plant.joints[i], nominal.joints[i]) + "\n";
  text +=
      "effects:\n  all: {motor_inertia: true, elastic_gear: true, gear_damping: true, "
      "backlash: true,\n        coulomb_friction: true, viscous_friction: true, "
      "transmission_error: true,\n        dead_time_s: " +
      number(plant.dead_time_cycles * nominal.controller_cycle_s) + "}\n";
  for (int i = 0; i < calib::kJointCount; ++i)
    text += "  " + nominal.joints[i].name + ": " + joint_effects(plant.joints[i]) + "\n";
  return text;
}

std::string plant_scenario_yaml(const PlantDraw& plant, const calib::RobotDescription& nominal,
                                const std::filesystem::path& nominal_file,
                                const std::filesystem::path& sensor_file,
                                const PlantSession& session) {
  const std::string random = session.random_frames ? "true" : "false";
  const std::string sigma_mm = session.random_frames ? "2.0" : "0";
  const std::string sigma_deg = session.random_frames ? "1.5" : "0";
  return "# Plant " + std::to_string(plant.seed) + " of a population around " +
         nominal_file.string() +
         " (sim/plant_population.hpp)\nimscal-scenario: 1\nname: " + session.name +
         "\ndescription: \"plant " + std::to_string(plant.seed) +
         "\"\nrobot: " + std::filesystem::absolute(nominal_file).string() +
         "\nnominal_robot: " + std::filesystem::absolute(nominal_file).string() +
         "\nprogram: " + std::filesystem::absolute(session.program_file).string() +
         "\nsensor: " + std::filesystem::absolute(sensor_file).string() +
         "\nimu: {rate_hz: 1000, clock_offset_s: " + number(session.clock_offset_s) +
         "}\nsite: {latitude_deg: 48.78232, longitude_deg: 9.18162, height_m: 245.4}\n"
         "base_in_world: {xyz_m: [2.0, 1.0, 0.0], rpy_deg: [0, 0, 30], random_yaw: " +
         random +
         "}\nsensor_mount:\n  offset_xyz_mm: [1.5, -0.8, 0.4]\n  offset_rpy_deg: [0.3, -0.2, "
         "0.5]\n  random_position_sigma_mm: " +
         sigma_mm + "\n  random_rotation_sigma_deg: " + sigma_deg + "\n" +
         plant_scenario_blocks(plant, nominal) +
         "plant: {integration_step_s: 0.0005, output_interval_s: 0.001}\nseed: " +
         std::to_string(session.scenario_seed) + "\n";
}

}  // namespace imscal::sim
