#include "tools/model_torque_option.hpp"

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
  return eval::load_model_torque_source(
      robot, Eigen::Vector3d(gravity_m_s2[0], gravity_m_s2[1], gravity_m_s2[2]), data_robot,
      data_file, needed_by_file, needed_by_field, data_cycle_s);
}

}  // namespace imscal::tools
