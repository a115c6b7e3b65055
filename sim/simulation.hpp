#pragma once
// One run of the simulator (`imscal simulate`): plan the scenario's motion program, run the plant,
// place the robot in W and the IMS on its flange, and synthesise what the IMS records. The truth
// of every step stays in the result so that tests and `imscal simulate` can write it out.
#include <Eigen/Geometry>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "ims/imu_data.hpp"
#include "ims/imu_noise.hpp"
#include "ims/nav_state.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/plant_simulator.hpp"
#include "sim/scenario.hpp"

namespace imscal::sim {

struct SimulationResult {
  calib::RobotDescription robot;  // the plant's (load_plant_robot): the simulated world
  ims::SensorSpec sensor_spec;
  DesiredJointPath path;  // robot clock
  PlantLog plant;         // robot clock, every Scenario::plant_output_interval_s
  Eigen::Isometry3d T_W_R = Eigen::Isometry3d::Identity();  // robot base in W (as drawn)
  Eigen::Isometry3d T_H_S = Eigen::Isometry3d::Identity();  // IMS on the flange (as drawn)
  double imu_clock_offset_s = 0.0;                          // t_IMS = t_robot + offset
  ims::SensorErrorModel sensor_errors;                      // drawn from the spec
  // The in-run part of the biases the record carries (beside sensor_errors' turn-on biases),
  // at the IMS samples, IMS clock.
  ims::InRunBias imu_in_run_bias;
  ims::ImuSeries imu_raw;                   // what the IMS records, IMS clock
  std::vector<ims::NavState> sensor_truth;  // S in W at the start and every IMS sample, IMS clock
};

// Stage callback: (stage name, fraction of that stage done in [0, 1]).
using SimulationProgress = std::function<void(const char* stage, double fraction)>;

// max_duration_s: simulate only the first part of the program (benchmarks); the path is cut there.
SimulationResult run_simulation(const Scenario& scenario, std::uint64_t seed,
                                const SimulationProgress& progress = {},
                                double max_duration_s = std::numeric_limits<double>::infinity());

// What the scenario's IMS records of a plant run: the link-side flange motion carried through the
// mount T_H_S into W (base T_W_R), synthesised at the scenario's rate with the Earth model of its
// site, corrupted by sensor errors drawn from `spec` and noise seeded from `rng` (in that order);
// time stamps on the IMS clock (robot clock + the scenario's offset).
struct ImsRecording {
  ims::SensorErrorModel sensor_errors;
  ims::ImuSeries imu_raw;
  std::vector<ims::NavState> sensor_truth;  // S in W at the start and every sample, IMS clock
  ims::InRunBias in_run_bias;               // the biases as they drift in the record, IMS clock
};
ImsRecording record_ims(const Scenario& scenario, const calib::RobotDescription& robot,
                        const ims::SensorSpec& spec, const PlantLog& plant,
                        const Eigen::Isometry3d& T_W_R, const Eigen::Isometry3d& T_H_S,
                        std::mt19937_64& rng);

// The link-side flange pose T_R_H at every plant sample (robot clock).
std::vector<Eigen::Isometry3d> flange_poses(const calib::RobotDescription& robot,
                                            const PlantLog& plant);

}  // namespace imscal::sim
