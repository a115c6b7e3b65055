#pragma once
// A simulation scenario (datasets/scenarios/*.yaml, format in datasets/FORMAT.md §9): which robot
// runs which motion program with which plant effects, where the robot stands in W, how the IMS is
// mounted on its flange, which IMS (sensor spec) records at what rate, and the seed of every
// random draw. `imscal simulate` turns it into robot.csv, imu.csv and the truth.
//
// Two robots: the plant (the robot that is: `robot:` with the optional `plant_deviations:`
// factors), which only the simulator reads, and the nominal robot (`nominal_robot:`, the data
// sheet and model the lab believes), the only robot the calibration chain is given. They are
// different types here (calib::RobotDescription inside sim::PlantConfig for the plant,
// sim::NominalRobot for the chain) so that no chain function can be handed the plant by mistake.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/config_node.hpp"
#include "ims/earth_model.hpp"
#include "robot/robot_description.hpp"
#include "sim/plant_config.hpp"

namespace imscal::sim {

struct Scenario {
  std::string name;
  std::string description;
  std::filesystem::path file;  // the scenario file; relative paths below are resolved against it
  // `robot:` the plant's robot file (before plant_deviations); read by the simulator only.
  std::filesystem::path plant_robot_file;
  // `nominal_robot:` the robot the lab believes; the plant's robot file when not given.
  std::filesystem::path nominal_robot_file;
  bool nominal_robot_given = false;
  std::filesystem::path program_file;
  std::filesystem::path sensor_file;  // IMS sensor spec (datasets/sensors/*.yaml)

  double imu_rate_hz = 1000.0;
  // The IMS clock runs ahead of the robot clock by this much: t_IMS = t_robot + offset [s].
  double imu_clock_offset_s = 0.0;
  std::string imu_format = "csv";  // csv or imsb

  ims::Site site;
  // Robot base R in W (the ENU frame at the site): nominal pose, and an optional random yaw about
  // the vertical drawn uniformly in [-pi, pi) when random_base_yaw is set.
  Eigen::Isometry3d T_W_R = Eigen::Isometry3d::Identity();
  bool random_base_yaw = false;
  // Sensor on the flange: T_H_S = T_H_T (the robot file's tool) * mount_offset, then a random
  // perturbation (rotation vector and translation, each component normal with these sigmas).
  Eigen::Isometry3d mount_offset = Eigen::Isometry3d::Identity();
  double mount_random_position_sigma_m = 0.0;
  double mount_random_rotation_sigma_rad = 0.0;

  // How the plant differs from its robot file: factors per joint (`plant_deviations:`, checked
  // by load_scenario; applied by load_plant_robot).
  std::optional<ConfigNode> plant_deviations;
  // `plant_deviations: payload_mass`: the payload the plant carries against the program's (and
  // the robot log's) as a factor on its mass and inertia (applied by make_plant_config).
  double plant_payload_mass_factor = 1.0;
  std::optional<ConfigNode> effects;           // the plant's effects section (sim/plant_config.hpp)
  std::optional<ConfigNode> integration_step;  // the plant's step (sim/plant_config.hpp)
  double plant_output_interval_s = 0.001;      // link-side truth and the IMS's pose samples
  std::uint64_t seed = 1;
};

// The robot the lab believes: its data sheet and nominal model. The calibration chain (model
// torque, identification, precontrol, the IMS chain's kinematics) takes only this.
struct NominalRobot {
  calib::RobotDescription description;
};

// InputError (file, line, key) on any problem; unknown keys are refused. Says in a log line when
// the scenario names no nominal robot (the chain then believes the plant's robot file).
Scenario load_scenario(const std::filesystem::path& file);

// The plant's robot: the `robot:` file with the `plant_deviations:` factors applied. For the
// simulator only. InputError on a bad factor.
calib::RobotDescription load_plant_robot(const Scenario& scenario);

// The nominal robot of a scenario (`nominal_robot:`, else the `robot:` file without deviations).
NominalRobot load_nominal_robot(const Scenario& scenario);

// `--scenario NAME|FILE`: a path to an existing file, or the name of a shipped scenario looked up
// as <datasets>/scenarios/NAME.yaml, where <datasets> is $IMSCAL_DATASETS if set, else the
// repository's datasets/ folder this binary was built from.
std::filesystem::path resolve_scenario(const std::string& name_or_file);

// The plant of a scenario: its `effects` and `integration_step_s` sections on `plant_robot`
// (load_plant_robot, loaded by the caller). InputError on a bad key/value.
PlantConfig make_plant_config(const calib::RobotDescription& plant_robot, const Scenario& scenario);

}  // namespace imscal::sim
