#pragma once
// The link's rate against its motor at commanded standstill, from the joint controller's torque
// rate (calib/encoder_motion.hpp adds it to the creep velocities' sigma).
//
// At standstill the gear carries the drive torque, so its deflection d = tau / k follows the
// torque: d_dot = tau_dot / k (quasi-static: the creep is slow against the gear's 8-30 Hz mode;
// the motor's inertia and the change of the friction torque are left out, which overstates the
// link's rate: ~5x against the simulated plant, docs/decisions/0081). tau follows the robot
// file's controller law (robot/robot_description.hpp) with the target held (no feed-forward):
//   e_v = kp (q_d - q_m) - q_m_dot,  tau = kv e_v + ki integral(e_v),
//   tau_dot = kv e_v_dot + ki e_v,   e_v_dot = -kp q_m_dot - q_m_ddot.
// The gains and stiffness are the NOMINAL robot file's (what the chain believes), the angles and
// their rates the log's readings and targets; never the simulator's plant.
#include "robot/robot_description.hpp"

namespace imscal::calib {

// Per joint [rad/s]; q_motor_rad: the internal readings (motor angle / gear ratio), their rate
// [rad/s] and acceleration [rad/s^2]. A joint whose file gives no positive stiffness (a rigid
// gear) has none: 0.
JointVector gear_deflection_rate_rad_s(const RobotDescription& nominal_robot,
                                       const JointVector& q_desired_rad,
                                       const JointVector& q_motor_rad,
                                       const JointVector& q_motor_rate_rad_s,
                                       const JointVector& q_motor_accel_rad_s2);

}  // namespace imscal::calib
