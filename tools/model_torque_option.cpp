#include "tools/model_torque_option.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/input_error.hpp"
#include "robot/robot_description.hpp"

namespace imscal::tools {

void ModelTorqueOption::add_to(CLI::App& command) {
  command.add_option(
      "--robot", robot,
      "Robot description (datasets/robots/kr16.yaml or a .urdf): the rigid-body model of the "
      "model-torque input");
  command
      .add_option("--gravity-m-s2", gravity_m_s2,
                  "Gravity in the robot base R [m/s²] (default 0 0 -9.80665: a level base)")
      ->expected(3);
}

eval::ModelTorqueSource ModelTorqueOption::source(const std::string& data_robot,
                                                  const std::string& data_file,
                                                  const std::string& needed_by_file,
                                                  const std::string& needed_by_field,
                                                  double data_cycle_s) const {
  if (robot.empty())
    throw InputError(needed_by_file, 0, needed_by_field,
                     "the models take the model torque: give the robot description with --robot "
                     "(e.g. datasets/robots/kr16.yaml)");
  eval::ModelTorqueSource model;
  model.robot = calib::load_robot_description(robot);
  if (model.robot.name != data_robot)
    throw InputError(robot, 0, "name",
                     fmt::format("robot '{}', but {} is of robot '{}'", model.robot.name, data_file,
                                 data_robot));
  const double robot_cycle_s = model.robot.controller_cycle_s;
  if (data_cycle_s > 0.0 && std::abs(robot_cycle_s - data_cycle_s) > 1e-9 * data_cycle_s)
    throw InputError(robot, 0, "controller_cycle_s",
                     fmt::format("the robot's controller cycle is {} s, but {} is sampled every "
                                 "{} s: a log of another controller or a robot file of another "
                                 "robot",
                                 robot_cycle_s, data_file, data_cycle_s));
  model.gravity_in_base_m_s2 = Eigen::Vector3d(gravity_m_s2[0], gravity_m_s2[1], gravity_m_s2[2]);
  return model;
}

}  // namespace imscal::tools
