#pragma once
// The config of `imscal run` (YAML, unknown keys refused): the raw inputs of a measurement
// campaign and one section per stage. Relative paths are relative to the config file's folder.
//
//   imscal-run-config: 1
//   title: KR 16 campaign 2026-11        # optional, heads the report
//   inputs:                               # every key optional; a stage runs when its inputs exist
//     imu: imu.imsb                       # raw IMS file (.csv, .imsb, .imu)
//     robot_log: robot.csv                # robot controller log (datasets/FORMAT.md §2)
//     joint_errors: joint_errors.csv      # joint angles for identification (FORMAT.md §10)
//   validate:                             # optional: checks on the raw inputs
//     robot: kr16                         # the robot the log must be from (default: any)
//     min_overlap_s: 1.0                  # IMS and robot clocks must overlap this long
//     allow_imu_gaps: false
//   calibrate:                            # needs inputs.imu and inputs.robot_log: frames,
//     config: ../calibration/calibrate-default.yaml   # mounting verdict, joint_errors.csv
//     timeout_s: 1800
//   identify:                             # needs joint errors: inputs.joint_errors, or else
//     config: ../identification/ident-default.yaml    # the calibrate stage's
//     robot: ../robots/kr16.yaml          # the rigid-body model of the model-torque input
//     timeout_s: 1800
//   verify:                               # needs identify: closed loop in the simulator with
//     scenarios: [seed-line]              # and without the precontrol (shipped names or files)
//     cycles: 3                           # ISO 9283 cycles per case (the standard: 10)
//     timeout_s: 1800
//   diagnose:                             # needs identify: the gap between the measured joint
//     robot: ../robots/kr16.yaml          # errors and the identified model's prediction
//     timeout_s: 1800
//   report:
//     gnuplot_timeout_s: 60               # per figure
//     max_points_per_curve: 2000          # longer curves are reduced to min/max per bin
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/config_node.hpp"

namespace imscal::tools {

struct ValidateSettings {
  std::string robot;  // empty: any
  double min_overlap_s = 1.0;
  bool allow_imu_gaps = false;
};

struct IdentifySettings {
  std::filesystem::path config;
  std::filesystem::path robot;  // robot description for the model torque (empty: none)
  double timeout_s = 1800.0;
};

struct CalibrateSettings {
  std::filesystem::path config;
  double timeout_s = 1800.0;
};

struct VerifySettings {
  // Shipped scenario names (datasets/scenarios/NAME.yaml) or scenario files (absolute).
  std::vector<std::string> scenarios{"seed-line"};
  std::vector<std::filesystem::path> scenario_files;  // the files among them, for checksums
  int cycles = 3;
  double timeout_s = 1800.0;
};

struct DiagnoseSettings {
  std::filesystem::path robot;
  // The scenario (name or file) of the nominal model (`diagnose --scenario`): the joint model is
  // then refined by re-simulating it. Empty: linear only.
  std::string scenario;
  std::filesystem::path scenario_file;  // when `scenario` is a file (a stage input)
  double timeout_s = 1800.0;
};

struct ReportSettings {
  double gnuplot_timeout_s = 60.0;
  int max_points_per_curve = 2000;
};

struct RunConfig {
  std::filesystem::path file;  // the config file itself (absolute)
  std::string title;
  std::optional<std::filesystem::path> imu, robot_log, joint_errors;  // absolute
  ValidateSettings validate;
  std::optional<CalibrateSettings> calibrate;
  std::optional<IdentifySettings> identify;
  std::optional<VerifySettings> verify;
  std::optional<DiagnoseSettings> diagnose;
  ReportSettings report;
};

// InputError (file, line, key) on unknown keys, wrong types, missing files, a stage section
// without its inputs (or its upstream stage) or inputs without their stage's section.
RunConfig load_run_config(const std::filesystem::path& file);

}  // namespace imscal::tools
