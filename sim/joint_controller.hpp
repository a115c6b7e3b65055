#pragma once
// The "simplified joint controller" of an industrial robot (paper, Table 1), one per joint, as
// calib::JointControllerGains describes it: cascaded P position loop and PI velocity loop on the
// MOTOR encoder (q_m = motor angle / N, joint-side units), run once per control cycle; the
// torque is held until the next cycle. It never sees gear deflection or backlash.
//   w_cmd = ff * qd_desired + kp_position * (q_desired - q_m)
//   e_w   = w_cmd - qd_m
//   tau   = clamp(kp_velocity * e_w + ki_velocity * I, +-torque_limit),  I += e_w * T
// Anti-windup by conditional integration: while the torque is saturated, I does not grow in the
// direction that drives it further into the limit. The drive's velocity estimate qd_m is taken
// as exact at the sampling instant (no encoder quantisation).
#include "robot/robot_description.hpp"

namespace imscal::sim {

class JointController {
 public:
  JointController() = default;
  JointController(const calib::JointControllerGains& gains, double cycle_s);

  // Sets the integrator so that the controller outputs `holding_torque_nm` with zero errors
  // (start at rest without a transient). Needs ki_velocity > 0; otherwise the integrator stays 0.
  void preload(double holding_torque_nm);

  // One control cycle: returns the joint-side drive torque [N m] to hold until the next one.
  double update(double q_desired_rad, double qd_desired_rad_s, double q_motor_rad,
                double qd_motor_rad_s);

  double integral_rad() const { return integral_; }

 private:
  calib::JointControllerGains gains_;
  double cycle_s_ = 0.002;
  double integral_ = 0.0;  // integral of the velocity error [rad]
};

}  // namespace imscal::sim
