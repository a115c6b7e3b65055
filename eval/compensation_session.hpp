#pragma once
// The precontrol (ident/precontrol.hpp) run offline on a robot log, as `imscal compensate` runs
// it: for every controller cycle of robot.csv the offsets it would hand to the controller, with
// its state, and the supervisor's events (logged as warnings). The same calls a controller
// integrator makes online. Its output is the offsets file of datasets/FORMAT.md
// (# imscal-offsets: 1; t_s, state, outside_table, offset_<joint>_rad).
#include <functional>
#include <string>

#include "eval/model_torque.hpp"

namespace imscal::eval {

struct CompensationSessionOptions {
  std::string table;      // parameters.json
  std::string robot_log;  // robot.csv (desired joints, payload)
  std::string robot;      // robot file, for the payload rating of a table without payload cells
  // The rigid-body model for the log's robot, asked only for a table with the model-torque
  // input (tools/model_torque_option.hpp).
  std::function<ModelTorqueSource(const std::string& data_robot, const std::string& data_file,
                                  const std::string& needed_by_file,
                                  const std::string& needed_by_field)>
      model_torque;
  double offset_tolerance_rad = 0.0;  // 0: the precontrol's default
};

struct CompensationRunSummary {
  std::string offsets_csv;  // the offsets file's content
  std::size_t cycles = 0, active_cycles = 0, events = 0;
};

CompensationRunSummary compensate_robot_log(const CompensationSessionOptions& options);

}  // namespace imscal::eval
