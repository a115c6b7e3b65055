#pragma once
// The sensor's motion as the robot's joint readings see it while the controller commands
// standstill (q_desired constant), for the zero-velocity smoother (ims/smoother_aids.hpp).
//
// After a move the joint controllers keep working the remaining position error off through
// friction for seconds: the arm creeps (1e-4..5e-3 rad/s on the simulated elastic KR 16 after
// the seed-line moves). The IMS alone takes much of that creep for rest (its 20 ms test window
// cannot see turns below ~1e-3 rad/s through the 1 ms increments' quantisation), and a zero-
// velocity update on a flange moving at 1e-3 m/s bends the smoothed trajectory by millimetres.
// During commanded standstill the gear carries a constant load, so the link follows the motor:
// forward kinematics of the readings gives the sensor's velocity to about the gear's
// transmission error (A N ~ 1 % of the motion for 10 arcsec at N = 160) once the link's ringing
// against the motor has died down. Only standstill is used: during commanded motion the gear
// deflection, which the IMS is there to measure, changes.
//
//  - still: commanded standstill where the sensor's speed and angular rate from the readings
//    stay below still_velocity_m_s / still_rate_rad_s, for at least min_still_s (IMS clock);
//  - creep_velocity: the sensor's velocity in W from the readings at every robot sample of a
//    commanded standstill from settle_s after it began, with a 1-sigma of
//    velocity_sigma_fraction of it (+) velocity_sigma_floor_m_s.
#include <Eigen/Geometry>
#include <vector>

#include "ims/smoother_aids.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

struct EncoderMotionOptions {
  double fit_s = 0.02;               // joint rates: a line through the readings within +-fit_s
  double still_velocity_m_s = 3e-6;  // a third of a zero-velocity update's 1e-5 m/s
  double still_rate_rad_s = 3e-6;    // ~0.6 deg/h: below what a rest's gyro mean resolves in 1 s
  double min_still_s = 0.2;
  // After a stop the link moves against its motor: first the gears ring (8-30 Hz), then the
  // friction and the loop's integral action leave a creep tail that halves about every 0.5 s.
  // On the simulated elastic KR 16 the link's rate differs from the readings' by 3e-7..3.5e-5
  // rad/s 1.0-1.2 s after a stop (decision 0081).
  double settle_s = 1.0;
  double velocity_sigma_fraction = 0.02;
  double velocity_sigma_floor_m_s = 1e-5;
};

struct EncoderMotion {
  std::vector<ims::TimeInterval> still;             // IMS clock
  std::vector<ims::VelocitySample> creep_velocity;  // IMS clock, in W
};

// T_W_R: the robot base in W; p_H_S: the sensor's origin in the flange frame; time_offset_s:
// t_ims = t_robot + time_offset_s.
EncoderMotion encoder_motion(const RobotLog& log, const KinematicModel& kinematics,
                             const Eigen::Isometry3d& T_W_R, const Eigen::Vector3d& p_H_S,
                             double time_offset_s, const EncoderMotionOptions& options = {});

}  // namespace imscal::calib
