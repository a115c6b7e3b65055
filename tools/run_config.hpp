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
//   identify:                             # required when inputs.joint_errors is given
//     config: ../identification/ident-default.yaml
//     timeout_s: 1800
//   report:
//     gnuplot_timeout_s: 60               # per figure
//     max_points_per_curve: 2000          # longer curves are reduced to min/max per bin
#include <filesystem>
#include <optional>
#include <string>

#include "core/config_node.hpp"

namespace imscal::tools {

struct ValidateSettings {
  std::string robot;  // empty: any
  double min_overlap_s = 1.0;
  bool allow_imu_gaps = false;
};

struct IdentifySettings {
  std::filesystem::path config;
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
  std::optional<IdentifySettings> identify;
  ReportSettings report;
};

// InputError (file, line, key) on unknown keys, wrong types, missing files, a stage section
// without its inputs or inputs without their stage's section.
RunConfig load_run_config(const std::filesystem::path& file);

}  // namespace imscal::tools
