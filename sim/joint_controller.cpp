#include "sim/joint_controller.hpp"

#include <algorithm>
#include <stdexcept>

namespace imscal::sim {

JointController::JointController(const calib::JointControllerGains& gains, double cycle_s)
    : gains_(gains), cycle_s_(cycle_s) {
  if (!(cycle_s > 0.0) || !(gains.torque_limit_nm > 0.0)) {
    throw std::invalid_argument("joint controller: cycle and torque limit must be > 0");
  }
}

void JointController::preload(double holding_torque_nm) {
  integral_ =
      gains_.ki_velocity_nm_per_rad > 0.0 ? holding_torque_nm / gains_.ki_velocity_nm_per_rad : 0.0;
}

double JointController::update(double q_desired_rad, double qd_desired_rad_s, double q_motor_rad,
                               double qd_motor_rad_s) {
  const double w_cmd = gains_.velocity_feedforward * qd_desired_rad_s +
                       gains_.kp_position_1_s * (q_desired_rad - q_motor_rad);
  const double velocity_error = w_cmd - qd_motor_rad_s;
  const double limit = gains_.torque_limit_nm;
  const double candidate = integral_ + velocity_error * cycle_s_;
  const double unclamped =
      gains_.kp_velocity_nm_s_per_rad * velocity_error + gains_.ki_velocity_nm_per_rad * candidate;
  // Conditional integration: keep the old integral while saturated further in the same direction.
  const bool winding_up =
      (unclamped > limit && velocity_error > 0.0) || (unclamped < -limit && velocity_error < 0.0);
  if (!winding_up) integral_ = candidate;
  const double torque =
      gains_.kp_velocity_nm_s_per_rad * velocity_error + gains_.ki_velocity_nm_per_rad * integral_;
  return std::clamp(torque, -limit, limit);
}

}  // namespace imscal::sim
