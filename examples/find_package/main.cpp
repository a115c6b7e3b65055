// Reads a robot file (imscal's DH YAML or a URDF) and prints the flange pose T_R_H for the joint
// angles given in degrees: `flange_pose ROBOT_FILE q1 .. q6`.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "core/input_error.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"

int main(int argc, char** argv) {
  if (argc != 8) {
    std::fprintf(stderr, "usage: %s ROBOT_FILE q1_deg q2_deg q3_deg q4_deg q5_deg q6_deg\n",
                 argv[0]);
    return 2;
  }
  try {
    const imscal::calib::RobotDescription robot = imscal::calib::load_robot_description(argv[1]);
    imscal::calib::JointVector q;
    for (int i = 0; i < imscal::calib::kJointCount; ++i) {
      q(i) = std::atof(argv[2 + i]) * M_PI / 180.0;
    }
    const Eigen::Isometry3d T_R_H = imscal::calib::forward_kinematics<double>(robot.kinematics, q);
    const Eigen::Quaterniond rotation(T_R_H.linear());
    std::printf(
        "robot %s\nflange xyz_m %.6f %.6f %.6f\nflange quaternion_wxyz %.6f %.6f %.6f %.6f\n",
        robot.name.c_str(), T_R_H.translation().x(), T_R_H.translation().y(),
        T_R_H.translation().z(), rotation.w(), rotation.x(), rotation.y(), rotation.z());
  } catch (const imscal::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
