#pragma once
// A simulation scenario (datasets/scenarios/*.yaml, format in datasets/FORMAT.md §9): which robot
// runs which motion program with which plant effects, where the robot stands in W, how the IMS is
// mounted on its flange, which IMS (sensor spec) records at what rate, and the seed of every
// random draw. `imscal simulate` turns it into robot.csv, imu.csv and the truth.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/config_node.hpp"
#include "ims/earth_model.hpp"
#include "sim/plant_config.hpp"

namespace imscal::sim {

struct Scenario {
  std::string name;
  std::string description;
  std::filesystem::path file;  // the scenario file; relative paths below are resolved against it
  std::filesystem::path robot_file;
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

  std::optional<ConfigNode> effects;           // the plant's effects section (sim/plant_config.hpp)
  std::optional<ConfigNode> integration_step;  // the plant's step (sim/plant_config.hpp)
  double plant_output_interval_s = 0.001;      // link-side truth and the IMS's pose samples
  std::uint64_t seed = 1;
};

// InputError (file, line, key) on any problem; unknown keys are refused.
Scenario load_scenario(const std::filesystem::path& file);

// `--scenario NAME|FILE`: a path to an existing file, or the name of a shipped scenario looked up
// as <datasets>/scenarios/NAME.yaml, where <datasets> is $IMSCAL_DATASETS if set, else the
// repository's datasets/ folder this binary was built from.
std::filesystem::path resolve_scenario(const std::string& name_or_file);

// The plant of a scenario: its `effects` and `integration_step_s` sections on `robot` (the
// scenario's robot file, loaded by the caller). InputError on a bad key/value.
PlantConfig make_plant_config(const calib::RobotDescription& robot, const Scenario& scenario);

}  // namespace imscal::sim
