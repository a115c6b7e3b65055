#include "sim/simulation.hpp"

#include <cmath>
#include <random>

#include "ims/earth_model.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/spline_trajectory.hpp"
#include "robot/forward_kinematics.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"

namespace imscal::sim {
namespace {

// Random draws of the scenario, in a fixed order from one generator (same seed, same draws):
// base yaw, mount perturbation (rotation vector, translation), then the sensor errors and the
// seed of the sensor noise (in run_simulation).
Eigen::Isometry3d draw_base(const Scenario& s, std::mt19937_64& rng) {
  Eigen::Isometry3d T_W_R = s.T_W_R;
  if (s.random_base_yaw) {
    std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
    T_W_R.linear() = Eigen::AngleAxisd(yaw(rng), Eigen::Vector3d::UnitZ()) * T_W_R.linear();
  }
  return T_W_R;
}

Eigen::Isometry3d draw_mount(const Scenario& s, const calib::RobotDescription& robot,
                             std::mt19937_64& rng) {
  Eigen::Isometry3d T_H_S = robot.tool.T_H_T * s.mount_offset;
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d rotation, translation;
  for (int i = 0; i < 3; ++i) rotation[i] = normal(rng) * s.mount_random_rotation_sigma_rad;
  for (int i = 0; i < 3; ++i) translation[i] = normal(rng) * s.mount_random_position_sigma_m;
  Eigen::Isometry3d perturbation = Eigen::Isometry3d::Identity();
  if (rotation.norm() > 0.0) {
    perturbation.linear() = Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).matrix();
  }
  perturbation.translation() = translation;
  return T_H_S * perturbation;
}

void truncate(DesiredJointPath& path, double max_duration_s) {
  if (path.samples.empty() || path.samples.back().t_s <= max_duration_s) return;
  while (!path.samples.empty() && path.samples.back().t_s > max_duration_s) path.samples.pop_back();
  while (!path.segments.empty() && path.segments.back().begin_s >= max_duration_s) {
    path.segments.pop_back();
  }
  if (!path.segments.empty()) path.segments.back().end_s = path.samples.back().t_s;
}

}  // namespace

std::vector<Eigen::Isometry3d> flange_poses(const calib::RobotDescription& robot,
                                            const PlantLog& plant) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(plant.samples.size());
  for (const PlantSample& s : plant.samples) {
    poses.push_back(calib::forward_kinematics<double>(robot.kinematics, s.q_link_rad));
  }
  return poses;
}

ImsRecording record_ims(const Scenario& scenario, const calib::RobotDescription& robot,
                        const ims::SensorSpec& spec, const PlantLog& plant,
                        const Eigen::Isometry3d& T_W_R, const Eigen::Isometry3d& T_H_S,
                        std::mt19937_64& rng) {
  const ims::EarthModel earth(scenario.site);
  const std::vector<Eigen::Isometry3d> T_R_H = flange_poses(robot, plant);
  std::vector<ims::PoseSample> poses(T_R_H.size());
  for (std::size_t k = 0; k < T_R_H.size(); ++k) {
    const Eigen::Isometry3d T_W_S = T_W_R * T_R_H[k] * T_H_S;
    poses[k] = {plant.samples[k].t_s, T_W_S.translation(),
                Eigen::Quaterniond(T_W_S.linear()).normalized()};
  }
  const ims::SplineTrajectory trajectory(poses);
  const ims::ImuSeries ideal =
      ims::synthesize_ideal_increments(trajectory, earth, scenario.imu_rate_hz);
  ImsRecording out;
  out.sensor_errors = ims::draw_sensor_errors(spec, rng);
  out.imu_raw = ims::corrupt(ideal, out.sensor_errors, spec, rng(), &out.in_run_bias);
  // Truth at the start of the first interval and at every sample, then both on the IMS clock.
  const double offset = scenario.imu_clock_offset_s;
  auto truth_at = [&](double t_robot) {
    const ims::KinematicState state = trajectory.at(t_robot);
    return ims::NavState{t_robot + offset, state.q_W_S, state.v_W, state.p_W};
  };
  out.sensor_truth.reserve(ideal.samples.size() + 1);
  out.sensor_truth.push_back(truth_at(trajectory.begin_s()));
  for (const ims::ImuSample& sample : ideal.samples)
    out.sensor_truth.push_back(truth_at(sample.t_s));
  for (ims::ImuSample& sample : out.imu_raw.samples) sample.t_s += offset;
  for (double& t : out.in_run_bias.t_s) t += offset;
  out.imu_raw.site = scenario.site;
  return out;
}

SimulationResult run_simulation(const Scenario& scenario, std::uint64_t seed,
                                const SimulationProgress& progress, double max_duration_s) {
  auto report = [&](const char* stage, double fraction) {
    if (progress) progress(stage, fraction);
  };
  SimulationResult result;
  result.robot = load_plant_robot(scenario);  // the simulated world: the plant
  result.sensor_spec = ims::load_sensor_spec(scenario.sensor_file);
  const MotionProgram program = load_motion_program(scenario.program_file);
  report("plan", 0.0);
  result.path = plan_motion(result.robot, program);
  truncate(result.path, max_duration_s);
  report("plan", 1.0);

  std::mt19937_64 rng(seed);
  result.T_W_R = draw_base(scenario, rng);
  result.T_H_S = draw_mount(scenario, result.robot, rng);
  result.imu_clock_offset_s = scenario.imu_clock_offset_s;

  PlantConfig config = make_plant_config(result.robot, scenario);
  // The arm feels the site's gravity (GeographicLib normal gravity at the base), in R.
  const ims::EarthModel earth(scenario.site);
  config.gravity_in_base_m_s2 =
      result.T_W_R.linear().transpose() * earth.gravity_W(result.T_W_R.translation());
  result.plant = simulate_plant(config, result.path, scenario.plant_output_interval_s,
                                [&](double fraction) { report("plant", fraction); });

  // The IMS frame S in W at every plant sample, interpolated by a spline for the synthesis.
  report("ims", 0.0);
  ImsRecording recording = record_ims(scenario, result.robot, result.sensor_spec, result.plant,
                                      result.T_W_R, result.T_H_S, rng);
  result.sensor_errors = std::move(recording.sensor_errors);
  result.imu_raw = std::move(recording.imu_raw);
  result.sensor_truth = std::move(recording.sensor_truth);
  result.imu_in_run_bias = std::move(recording.in_run_bias);
  result.imu_raw.metadata = {{"sensor", result.sensor_spec.name},
                             {"scenario", scenario.name},
                             {"seed", std::to_string(seed)},
                             {"generator", "imscal simulate"}};
  report("ims", 1.0);
  return result;
}

}  // namespace imscal::sim
