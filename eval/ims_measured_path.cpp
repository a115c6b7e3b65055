#include "eval/ims_measured_path.hpp"

#include <cmath>
#include <random>

#include "calib/joint_space_errors.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/zupt_options.hpp"
#include "robot/robot_log.hpp"
#include "sim/simulation.hpp"

namespace imscal::eval {

ImsJointMeasurement measure_joints_with_ims(const sim::Scenario& scenario,
                                            const calib::RobotDescription& plant_robot,
                                            const sim::NominalRobot& nominal,
                                            const sim::DesiredJointPath& desired,
                                            const sim::PlantLog& plant, double lead_in_s,
                                            std::uint64_t seed) {
  // The measurement setup: the scenario's base and nominal mount, its IMS and clock offset.
  const ims::SensorSpec spec = ims::load_sensor_spec(scenario.sensor_file);
  const Eigen::Isometry3d T_W_R = scenario.T_W_R;
  const Eigen::Isometry3d T_H_S = plant_robot.tool.T_H_T * scenario.mount_offset;
  std::mt19937_64 rng(seed);
  const sim::ImsRecording recording =
      sim::record_ims(scenario, plant_robot, spec, plant, T_W_R, T_H_S, rng);
  // The unit's calibration sheet: its scale factors and misalignments (the biases stay; the
  // smoother starts from the setup's bias values and estimates what drifts).
  ims::SensorErrorModel unit = recording.sensor_errors;
  unit.gyro.bias.setZero();
  unit.acc.bias.setZero();
  const ims::ImuSeries imu = ims::correct(recording.imu_raw, unit);

  // The controller's log of the run: its desired angles, what its encoders read.
  calib::RobotLog log;
  log.robot_name = nominal.description.name;
  log.cycle_s = desired.cycle_s;
  const std::size_t n = std::min(desired.samples.size(), plant.samples.size());
  for (std::size_t k = 0; k < n; ++k) {
    const sim::DesiredJointSample& c = desired.samples[k];
    log.samples.push_back({c.t_s,
                           desired.payloads.empty()
                               ? 0.0
                               : desired.payloads[std::size_t(c.payload_index)].body.mass_kg,
                           c.q_rad, plant.samples[k].q_motor_rad});
  }

  calib::JointSpaceInput input;
  input.imu = &imu;
  input.log = &log;
  input.site = scenario.site;
  input.kinematics = nominal.description.kinematics;
  input.frames.T_R_W = T_W_R.inverse();
  input.frames.T_S_H = T_H_S.inverse();
  // The biases as the record carries them at its start (turn-on plus in-run part: what a
  // calibration at the rest before the run estimates); the smoother follows their drift.
  input.frames.biases.gyro_rad_s = recording.sensor_errors.gyro.bias;
  input.frames.biases.acc_m_s2 = recording.sensor_errors.acc.bias;
  if (!recording.in_run_bias.t_s.empty()) {
    input.frames.biases.gyro_rad_s += recording.in_run_bias.gyro_rad_s.front();
    input.frames.biases.acc_m_s2 += recording.in_run_bias.acc_m_s2.front();
  }
  input.frames.time_offset_s = scenario.imu_clock_offset_s;
  // The plant starts at rest: the first lead-in is the smoother's first rest, its pose the
  // forward kinematics of the link angles there (a rest pose whose deflection the frame
  // calibration has modelled).
  input.first_rest.begin_ims_s = recording.sensor_truth.front().t_s;
  input.first_rest.end_ims_s = input.first_rest.begin_ims_s + 0.9 * lead_in_s;
  input.first_rest.q_link_rad = plant.samples.front().q_link_rad;
  input.zupt = ims::zupt_options_from_spec(spec);
  input.source = "verification of scenario " + scenario.name;
  const calib::JointSpaceErrors errors = calib::joint_space_errors(input);

  ImsJointMeasurement out;
  out.q_rad.assign(plant.samples.size(), calib::JointVector::Zero());
  out.valid.assign(plant.samples.size(), false);
  out.smoother = errors.smoother;
  const double t0 = plant.samples.front().t_s;
  for (std::size_t i = 0; i < errors.t_s.size(); ++i) {
    const auto k = static_cast<std::size_t>(std::llround((errors.t_s[i] - t0) / desired.cycle_s));
    if (k >= out.q_rad.size()) continue;
    out.q_rad[k] = errors.q_measured_rad[i];
    out.valid[k] = true;
  }
  return out;
}

}  // namespace imscal::eval
