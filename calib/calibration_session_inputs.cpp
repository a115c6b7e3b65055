// Reading a calibration session's files (calib/calibration_session_inputs.hpp).
#include "calib/calibration_session_inputs.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/input_error.hpp"
#include "core/payload_plausibility.hpp"
#include "core/units.hpp"
#include "ims/imu_conversion.hpp"
#include "ims/imu_file.hpp"
#include "ims/sensor_error_model.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

// A robot file without drive stiffness (a kinematics-only URDF, say) makes the bundle treat the
// arm as rigid: no gear wind-up, backlash or friction terms, and sigmas that do not contain them.
void warn_if_rigid(const RobotDescription& robot) {
  std::string rigid;
  for (const JointDescription& joint : robot.joints) {
    if (joint.drive.stiffness_nm_per_rad <= 0.0) rigid += (rigid.empty() ? "" : ", ") + joint.name;
  }
  if (rigid.empty()) return;
  spdlog::warn(
      "calibrate: robot {} ({}) gives no drive for {}: the arm is taken as rigid there (no gear "
      "wind-up or backlash at rest, no friction at the link); the sigmas do not include them",
      robot.name, robot.source, rigid);
}

// The config, the robot and the sensor (the command line's files before the config's).
void read_config_robot_sensor(const SessionFiles& files, LoadedSession& s) {
  CalibrationConfig& config = s.options.config;
  if (!files.config.empty()) config = load_calibration_config(files.config);
  auto pick = [&](const std::string& given, const std::optional<fs::path>& from_config,
                  const char* option) {
    if (!given.empty()) return fs::path(given);
    if (from_config) return *from_config;
    throw InputError(
        files.config.empty() ? "command line" : files.config, 0, option,
        fmt::format("no {} file: give {} or the config key '{}'", option + 2, option, option + 2));
  };
  s.robot_file = pick(files.robot, config.robot_file, "--robot");
  s.sensor_file = pick(files.sensor, config.sensor_file, "--sensor");
  RobotDescription& robot = s.inputs.robot;
  robot = load_robot_description(s.robot_file);
  warn_if_rigid(robot);
  check_payload_plausible(
      config.payload.mass_kg, robot.nominal_payload_kg,
      {files.config.empty() ? "the calibration defaults" : files.config, 0, "payload.mass_kg",
       fmt::format("robot {} ({})", robot.name, robot.source)});
  s.inputs.sensor = ims::load_sensor_spec(s.sensor_file);
}

// The IMS record as increments, corrected with the unit's lab calibration (scale factors,
// misalignments) first.
void read_imu_record(const SessionFiles& files, LoadedSession& s) {
  const ims::SensorSpec& spec = s.inputs.sensor;
  ims::ImuReadOptions read_options;
  if (spec.gyro.range > 0.0) read_options.gyro_range_rad_s = spec.gyro.range;
  if (spec.acc.range > 0.0) read_options.acc_range_m_s2 = spec.acc.range;
  // The stages read the record by interval: in a temporary file it does not stay resident.
  read_options.samples_to_file = true;
  ims::ImuSeries& imu = s.inputs.imu;
  imu = ims::read_imu_file(files.imu, read_options);
  if (imu.quantity == ims::ImuQuantity::kRates) imu = ims::rates_to_increments(std::move(imu));
  s.unit_calibration_file = s.options.config.unit_calibration_file;
  if (!files.unit_calibration.empty()) s.unit_calibration_file = fs::path(files.unit_calibration);
  if (s.unit_calibration_file) {
    const ims::SensorErrorModel unit = ims::load_sensor_error_model(*s.unit_calibration_file);
    imu = ims::correct(std::move(imu), unit);
    spdlog::info("calibrate: corrected {} with the unit calibration {}", files.imu,
                 s.unit_calibration_file->string());
  }
  if (!imu.site)
    throw InputError(files.imu, 0, "site",
                     "the IMS file does not state its site (site_latitude_deg, "
                     "site_longitude_deg, site_height_m): gravity and Earth rate need it");
}

// The robot log, its payload against the robot's rating, and its overlap with the IMS record.
void read_robot_log(const SessionFiles& files, LoadedSession& s) {
  const RobotDescription& robot = s.inputs.robot;
  RobotLog& log = s.inputs.log;
  log = read_robot_log_csv(files.robot_log, robot.name, "the robot description",
                           /*samples_to_file=*/true);
  check_robot_log_joint_limits(log, files.robot_log, robot);
  std::vector<double> payload_kg, t_s;
  for (const RobotLogSample& sample : log.samples) {
    payload_kg.push_back(sample.payload_kg);
    t_s.push_back(sample.t_s);
  }
  check_payload_series(
      payload_kg, t_s, robot.nominal_payload_kg,
      {files.robot_log, 0, "payload_kg", fmt::format("robot {} ({})", robot.name, robot.source)});
  // The two records must overlap in time (up to the time-offset search range).
  const ims::ImuSeries& imu = s.inputs.imu;
  const double imu_begin = imu.samples.front().t_s, imu_end = imu.samples.back().t_s;
  const double log_begin = log.samples.front().t_s, log_end = log.samples.back().t_s;
  const double margin = s.options.config.max_abs_time_offset_s;
  if (imu_end + margin < log_begin || log_end + margin < imu_begin)
    throw InputError(files.imu, 0, "t_s",
                     fmt::format("the IMS record [{:.3f}, {:.3f}] s and the robot log {} "
                                 "[{:.3f}, {:.3f}] s do not overlap in time (clock offsets up to "
                                 "{} s are searched)",
                                 imu_begin, imu_end, files.robot_log, log_begin, log_end, margin));
}

// "DEG,SIGMA_DEG" of --heading-reference.
HeadingReference heading_reference_of(const std::string& text) {
  const auto refuse = [&](const std::string& why) {
    throw InputError(
        "command line", 0, "--heading-reference",
        fmt::format("'{}': {}; expected YAW_DEG,SIGMA_DEG (e.g. 30.0,0.01)", text, why));
  };
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos) refuse("no comma");
  HeadingReference reference;
  double yaw_deg = 0.0, sigma_deg = 0.0;
  try {
    std::size_t used_yaw = 0, used_sigma = 0;
    yaw_deg = std::stod(text.substr(0, comma), &used_yaw);
    sigma_deg = std::stod(text.substr(comma + 1), &used_sigma);
    if (used_yaw != comma || used_sigma != text.size() - comma - 1) refuse("not two numbers");
  } catch (const std::logic_error&) {
    refuse("not two numbers");
  }
  if (!std::isfinite(yaw_deg) || !(sigma_deg > 0.0) || !std::isfinite(sigma_deg))
    refuse("the yaw must be finite and the sigma a number > 0");
  reference.yaw_rad = yaw_deg * kRadPerDeg;
  reference.sigma_rad = sigma_deg * kRadPerDeg;
  reference.source = "--heading-reference " + text;
  return reference;
}

}  // namespace

LoadedSession read_session_inputs(const SessionFiles& files) {
  LoadedSession s;
  read_config_robot_sensor(files, s);
  if (!files.heading_reference.empty())
    s.options.config.heading_reference = heading_reference_of(files.heading_reference);
  // The earlier session's frames before the (long) records: a wrong file fails fast.
  if (!files.frames.empty())
    s.inputs.previous = read_frames_json(files.frames, s.inputs.robot.name);
  read_imu_record(files, s);
  read_robot_log(files, s);
  s.inputs.source = files.imu;
  return s;
}

}  // namespace imscal::calib
