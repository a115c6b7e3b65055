#pragma once
// The `--robot FILE` and `--gravity-m-s2 GX GY GZ` options of the subcommands whose models take
// the joint torque of the robot's rigid-body model (`imscal identify`, `imscal compensate`;
// eval/model_torque.hpp): the options and the model they describe.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "core/units.hpp"
#include "eval/model_torque.hpp"

namespace imscal::tools {

struct ModelTorqueOption {
  std::string robot;                                                   // robot description file
  std::vector<double> gravity_m_s2{0.0, 0.0, -kStandardGravity_m_s2};  // in the robot base R

  void add_to(CLI::App& command);

  // The rigid-body model for the data of `data_robot` (file `data_file`, for messages), or
  // InputError naming `needed_by` (file and field that asked for the torque) when --robot is
  // missing, and the robot file when its robot is not the data's or (data_cycle_s > 0) its
  // controller cycle is not the data's sample time [s].
  eval::ModelTorqueSource source(const std::string& data_robot, const std::string& data_file,
                                 const std::string& needed_by_file,
                                 const std::string& needed_by_field,
                                 double data_cycle_s = 0.0) const;
};

}  // namespace imscal::tools
