#pragma once
// The files of `imscal simulate --out DIR` (datasets/FORMAT.md §2 and §9):
//   DIR/imu.csv (or imu.imsb)      raw IMS record, IMS clock
//   DIR/robot.csv                  the controller's log: desired and internal joint angles
//   DIR/truth/joints.csv           link-side and motor-side joint angles, every plant sample
//   DIR/truth/flange_poses.csv     T_R_H of the link-side angles, every plant sample
//   DIR/truth/trajectory.csv       S in W at the IMS samples (IMS clock)
//   DIR/truth/frames.json          T_R_W, T_S_H (and inverses), clock offset, site
//   DIR/truth/sensor_errors.yaml   the IMS's drawn deterministic errors
//   DIR/truth/imu_bias.csv         the biases the record carries (turn-on + in-run), every 0.1 s
//   DIR/truth/segments.csv         the program's segments (robot clock)
//   DIR/truth/scenario.yaml        the scenario file as used, with the seed and the drawn values
// All or nothing (core/output_folder.hpp); existing outputs are refused unless overwrite allows.
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "robot/robot_log.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"

namespace imscal::sim {

std::vector<std::filesystem::path> simulation_outputs(const Scenario& scenario);

// The robot's log: one row per control cycle, the internal sensor sampled at the cycle instant.
calib::RobotLog make_robot_log(const SimulationResult& result);

void write_simulation(const std::filesystem::path& folder, const Scenario& scenario,
                      std::uint64_t seed, const SimulationResult& result, Overwrite overwrite);

}  // namespace imscal::sim
