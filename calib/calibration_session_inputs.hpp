#pragma once
// The files of a calibration session read into calib::SessionInputs (calib/calibration_session.hpp)
// as `imscal calibrate` names them: the config (calib/calibration_config.hpp), whose robot and
// sensor files the command line may override, the IMS record (rates turned into increments,
// corrected with the unit's lab calibration), the robot log, and an earlier session's
// frames.json. Checked here: the payload against the robot's rating, the IMS record's site, and
// that the two records overlap in time (up to the clock-offset search range).
#include <filesystem>
#include <optional>
#include <string>

#include "calib/calibration_session.hpp"

namespace imscal::calib {

struct SessionFiles {
  std::string imu;
  std::string robot_log;
  std::string robot;             // empty: the config's
  std::string sensor;            // empty: the config's
  std::string config;            // empty: the built-in defaults
  std::string unit_calibration;  // empty: the config's (if any)
  std::string frames;            // an earlier session's frames.json; empty: estimate the frames
  // "DEG,SIGMA_DEG": a surveyed yaw of T_W_R with its 1-sigma (calib/frame_calibration.hpp,
  // HeadingReference), instead of the config's heading_reference; empty: the config's.
  std::string heading_reference;
};

struct LoadedSession {
  SessionInputs inputs;
  SessionOptions options;
  // The files used, after the command line and the config (for the outputs' provenance).
  std::filesystem::path robot_file, sensor_file;
  std::optional<std::filesystem::path> unit_calibration_file;
};

// Throws InputError (file, line, field) for any unusable file or value.
LoadedSession read_session_inputs(const SessionFiles& files);

}  // namespace imscal::calib
