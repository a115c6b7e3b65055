#include "calib/gear_torque_rate.hpp"

namespace imscal::calib {

JointVector gear_deflection_rate_rad_s(const RobotDescription& nominal_robot,
                                       const JointVector& q_desired_rad,
                                       const JointVector& q_motor_rad,
                                       const JointVector& q_motor_rate_rad_s,
                                       const JointVector& q_motor_accel_rad_s2) {
  JointVector rate = JointVector::Zero();
  for (int i = 0; i < kJointCount; ++i) {
    const JointDescription& joint = nominal_robot.joints[std::size_t(i)];
    const double stiffness = joint.drive.stiffness_nm_per_rad;
    if (!(stiffness > 0.0)) continue;
    const JointControllerGains& g = joint.controller;
    const double e_v =
        g.kp_position_1_s * (q_desired_rad[i] - q_motor_rad[i]) - q_motor_rate_rad_s[i];
    const double e_v_dot = -g.kp_position_1_s * q_motor_rate_rad_s[i] - q_motor_accel_rad_s2[i];
    const double torque_rate_nm_s =
        g.kp_velocity_nm_s_per_rad * e_v_dot + g.ki_velocity_nm_per_rad * e_v;
    rate[i] = torque_rate_nm_s / stiffness;
  }
  return rate;
}

}  // namespace imscal::calib
