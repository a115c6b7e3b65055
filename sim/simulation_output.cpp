#include "sim/simulation_output.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "core/csv_text.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/units.hpp"
#include "ims/imu_file.hpp"
#include "ims/nav_trajectory_io.hpp"

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;

nlohmann::json pose_json(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  // Roll-pitch-yaw as in the YAML files: R = Rz(yaw) Ry(pitch) Rx(roll).
  const Eigen::Matrix3d R = pose.linear();
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {{"xyz_m", {t.x(), t.y(), t.z()}},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
          {"rpy_deg", {roll * 180.0 / M_PI, pitch * 180.0 / M_PI, yaw * 180.0 / M_PI}}};
}

std::string joints_csv(const SimulationResult& r) {
  std::string text = "# imscal-truth-joints: 1\n# robot: " + r.robot.name + "\nt_s";
  for (const char* prefix : {"q_link", "q_motor"}) {
    for (const auto& joint : r.robot.joints) text += fmt::format(",{}_{}_rad", prefix, joint.name);
  }
  text += '\n';
  for (const PlantSample& s : r.plant.samples) {
    csv::append_shortest(text, s.t_s);
    for (const calib::JointVector* q : {&s.q_link_rad, &s.q_motor_rad}) {
      for (int j = 0; j < calib::kJointCount; ++j) {
        text += ',';
        csv::append_shortest(text, (*q)[j]);
      }
    }
    text += '\n';
  }
  return text;
}

std::string flange_csv(const SimulationResult& r) {
  std::string text =
      "# imscal-truth-flange: 1\n# frame: T_R_H (flange H in the robot base R)\n"
      "t_s,x_m,y_m,z_m,qw,qx,qy,qz\n";
  const std::vector<Eigen::Isometry3d> poses = flange_poses(r.robot, r.plant);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Quaterniond q(poses[k].linear());
    csv::append_shortest(text, r.plant.samples[k].t_s);
    for (double v : {poses[k].translation().x(), poses[k].translation().y(),
                     poses[k].translation().z(), q.w(), q.x(), q.y(), q.z()}) {
      text += ',';
      csv::append_shortest(text, v);
    }
    text += '\n';
  }
  return text;
}

// The biases the record carries, turn-on + in-run, every `every_s` of the IMS clock (the in-run
// part changes over minutes; its mean over the sample interval at the stamp).
std::string imu_bias_csv(const SimulationResult& r, double every_s) {
  constexpr double kDegPerHourPerRadPerSecond = kDegPerRad * 3600.0;
  constexpr double kMicroGPerMeterPerSecond2 = 1e6 / kStandardGravity_m_s2;
  std::string text =
      "# imscal-truth-imu-bias: 1\n"
      "t_s,gyro_bias_x_deg_h,gyro_bias_y_deg_h,gyro_bias_z_deg_h,acc_bias_x_ug,acc_bias_y_ug,"
      "acc_bias_z_ug\n";
  const ims::InRunBias& in_run = r.imu_in_run_bias;
  double next = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < in_run.t_s.size(); ++k) {
    if (in_run.t_s[k] < next) continue;
    next = in_run.t_s[k] + every_s - 1e-9;
    csv::append_shortest(text, in_run.t_s[k]);
    const Eigen::Vector3d gyro = r.sensor_errors.gyro.bias + in_run.gyro_rad_s[k];
    const Eigen::Vector3d acc = r.sensor_errors.acc.bias + in_run.acc_m_s2[k];
    for (int i = 0; i < 3; ++i) {
      text += ',';
      csv::append_shortest(text, gyro[i] * kDegPerHourPerRadPerSecond);
    }
    for (int i = 0; i < 3; ++i) {
      text += ',';
      csv::append_shortest(text, acc[i] * kMicroGPerMeterPerSecond2);
    }
    text += '\n';
  }
  return text;
}

std::string segments_csv(const DesiredJointPath& path) {
  static const char* kKinds[] = {"rest", "ptp", "lin", "circ"};
  std::string text = "kind,begin_s,end_s,label\n";
  for (const PathSegment& s : path.segments) {
    std::string label = s.label;
    std::replace(label.begin(), label.end(), ',', ';');
    text += fmt::format("{},{},{},{}\n", kKinds[static_cast<int>(s.kind)],
                        csv::format_shortest(s.begin_s), csv::format_shortest(s.end_s), label);
  }
  return text;
}

std::string frames_json(const Scenario& scenario, const SimulationResult& r) {
  const nlohmann::json json = {
      {"imscal-truth-frames", 1},
      {"T_R_W", pose_json(r.T_W_R.inverse())},
      {"T_W_R", pose_json(r.T_W_R)},
      {"T_S_H", pose_json(r.T_H_S.inverse())},
      {"T_H_S", pose_json(r.T_H_S)},
      {"imu_clock_offset_s", r.imu_clock_offset_s},
      {"site",
       {{"latitude_deg", scenario.site.latitude_deg},
        {"longitude_deg", scenario.site.longitude_deg},
        {"height_m", scenario.site.height_m}}},
      {"units", "m, deg; quaternion_wxyz: unit quaternion of the rotation part"}};
  return imscal::json_text(json, 2, "truth.json");
}

std::string scenario_yaml(const Scenario& scenario, std::uint64_t seed, const SimulationResult& r) {
  std::ifstream in(scenario.file);
  std::stringstream original;
  original << in.rdbuf();
  const Eigen::Quaterniond q_W_R(r.T_W_R.linear()), q_H_S(r.T_H_S.linear());
  return fmt::format(
      "# Scenario '{}' as run by imscal simulate with seed {} (original file: {}).\n"
      "# Drawn: T_W_R quaternion_wxyz [{:.17g}, {:.17g}, {:.17g}, {:.17g}];\n"
      "#        T_H_S xyz_m [{:.17g}, {:.17g}, {:.17g}], quaternion_wxyz [{:.17g}, {:.17g}, "
      "{:.17g}, {:.17g}]\n"
      "{}",
      scenario.name, seed, scenario.file.string(), q_W_R.w(), q_W_R.x(), q_W_R.y(), q_W_R.z(),
      r.T_H_S.translation().x(), r.T_H_S.translation().y(), r.T_H_S.translation().z(), q_H_S.w(),
      q_H_S.x(), q_H_S.y(), q_H_S.z(), original.str());
}

}  // namespace

std::vector<fs::path> simulation_outputs(const Scenario& scenario) {
  return {"imu." + scenario.imu_format, "robot.csv",
          "truth/joints.csv",           "truth/flange_poses.csv",
          "truth/trajectory.csv",       "truth/frames.json",
          "truth/sensor_errors.yaml",   "truth/imu_bias.csv",
          "truth/segments.csv",         "truth/scenario.yaml"};
}

calib::RobotLog make_robot_log(const SimulationResult& result) {
  calib::RobotLog log;
  log.robot_name = result.robot.name;
  log.cycle_s = result.path.cycle_s;
  for (int j = 0; j < calib::kJointCount; ++j) log.joint_names[j] = result.robot.joints[j].name;
  if (result.plant.samples.size() < 2) throw std::invalid_argument("make_robot_log: no plant data");
  const double interval = result.plant.samples[1].t_s - result.plant.samples[0].t_s;
  for (const DesiredJointSample& d : result.path.samples) {
    const auto k = static_cast<std::size_t>(std::llround(d.t_s / interval));
    if (k >= result.plant.samples.size()) break;
    calib::RobotLogSample s;
    s.t_s = d.t_s;
    s.payload_kg = result.path.payloads.at(static_cast<std::size_t>(d.payload_index)).body.mass_kg;
    s.q_desired_rad = d.q_rad;
    s.q_internal_rad = result.plant.samples[k].q_motor_rad;
    log.samples.push_back(s);
  }
  return log;
}

void write_simulation(const fs::path& folder, const Scenario& scenario, std::uint64_t seed,
                      const SimulationResult& result, Overwrite overwrite) {
  OutputFolder out(folder, simulation_outputs(scenario), overwrite);
  ims::write_imu_file(out.staged("imu." + scenario.imu_format), result.imu_raw, Overwrite::kAllow);
  calib::write_robot_log_csv(out.staged("robot.csv"), make_robot_log(result), Overwrite::kAllow);
  write_file_atomically(out.staged("truth/joints.csv"), joints_csv(result));
  write_file_atomically(out.staged("truth/flange_poses.csv"), flange_csv(result));
  ims::write_trajectory_csv(out.staged("truth/trajectory.csv"), result.sensor_truth);
  write_file_atomically(out.staged("truth/frames.json"), frames_json(scenario, result));
  write_file_atomically(out.staged("truth/sensor_errors.yaml"),
                        fmt::format("# Drawn errors of the simulated IMS '{}', seed {}\n",
                                    result.sensor_spec.name, seed) +
                            ims::to_yaml(result.sensor_errors));
  write_file_atomically(out.staged("truth/imu_bias.csv"), imu_bias_csv(result, 0.1));
  write_file_atomically(out.staged("truth/segments.csv"), segments_csv(result.path));
  write_file_atomically(out.staged("truth/scenario.yaml"), scenario_yaml(scenario, seed, result));
  out.commit();
}

}  // namespace imscal::sim
