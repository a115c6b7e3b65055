#pragma once
// Configuration of the robot plant simulator: the robot description plus, per joint, which
// physical effect of the drive is simulated (scenario section `effects:`), the integration step
// and global switches (gravity, joint controller).
//
// Scenario YAML (every key optional; unknown keys are refused):
//   effects:
//     all: {motor_inertia: true, elastic_gear: true, gear_damping: true, backlash: true,
//           coulomb_friction: true, viscous_friction: true, transmission_error: false,
//           dead_time_s: 0.0, coulomb_velocity_scale_rad_s: 0.01, friction_at_link: false,
//           link_friction_fraction: 0.1}
//     transmission_error: {amplitude_arcsec: 20, harmonic_per_motor_rev: 1, phase_deg: 0}
//     A2: {backlash: true, ...}          # per-joint overrides by joint name (same keys as `all`,
//                                        # plus `transmission_error_shape: {...}` as above, or
//                                        # `transmission_error_shapes: [{...}, ...]`, summed)
//   integration_step_s: 0.0005           # scenario level, beside `effects:`
// Backlash and gear damping live in the elastic gear: a joint with elastic_gear false and
// backlash or gear_damping true is refused (the play of a rigid gear has no model here).
#include <array>
#include <vector>

#include "core/units.hpp"
#include "robot/robot_description.hpp"

namespace imscal {
class ConfigNode;
}

namespace imscal::sim {

// Periodic angle-transmission error of a gear, te(motor angle) = amplitude * sin(harmonic *
// motor angle + phase); motor angle in rad on the motor side, te in rad at the link.
struct TransmissionErrorShape {
  double amplitude_rad = 20.0 / 3600.0 * M_PI / 180.0;  // 20 arcsec: typical of RV gears
  double harmonic_per_motor_rev = 1.0;
  double phase_rad = 0.0;
};

struct JointEffects {
  bool motor_inertia = true;     // reflected rotor inertia N^2 J_m
  bool elastic_gear = true;      // gear spring (robot's stiffness) between motor/N and link
  bool gear_damping = true;      // gear damper (only with elastic_gear)
  bool backlash = true;          // dead zone of the robot's backlash in the spring
  bool coulomb_friction = true;  // F_c tanh(v / coulomb_velocity_scale)
  bool viscous_friction = true;  // c v
  // Where the friction of an elastic drive acts: false = motor side (on the motor velocity, the
  // controller feels it directly), true = gear output (on the link velocity, the controller
  // feels it only through the spring; the link lags by ~F_c / k). Rigid drives: no difference.
  bool friction_at_link = false;
  // Share of that friction which acts at the gear output (the output bearing and seals) on the
  // link velocity when friction_at_link is false (elastic drives; the rest acts on the motor).
  // Why not 0: without it nothing dissipates the link's motion inside the play of an unloaded
  // gear (the damper works only in contact), and the simulated links of A1/A4/A6 kept drifting
  // and bouncing inside their backlash at rest (±0.9 mrad on A6 for ever), which no real arm
  // does and which broke every rest-based step of the chain.
  double link_friction_fraction = 0.1;
  bool transmission_error = false;  // periodic te(motor angle)
  double dead_time_s = 0.0;         // desired value reaches the controller this much later
  // Velocity scale of the smooth Coulomb law [rad/s, joint side]: 0.01 rad/s = 0.6 deg/s, well
  // below any programmed joint speed, but large enough that the friction slope F_c / v_s stays
  // within RK4's stability limit on the motor inertia at a 0.5 ms step (see drive_model.hpp).
  double coulomb_velocity_scale_rad_s = 0.01;
  TransmissionErrorShape transmission_error_shape;
  // Further orders of the same gear's transmission error, added to transmission_error_shape
  // (a real gear's error has several: eccentricity, tooth meshing, ...).
  std::vector<TransmissionErrorShape> further_transmission_error_shapes;
};

struct PlantConfig {
  calib::RobotDescription robot;
  std::array<JointEffects, calib::kJointCount> effects{};
  double integration_step_s = 0.0005;  // RK4 step; must divide robot.controller_cycle_s
  bool gravity = true;
  // The payload the plant carries against the one the program names (and the robot log logs):
  // its mass and inertia tensor times this factor (scenario `plant_deviations: payload_mass`).
  double payload_mass_factor = 1.0;
  bool controller = true;  // false: drive torque 0 (free motion, e.g. for the energy check)
  // Gravity in the robot base R [m/s^2]: the base stands upright (z_R up) unless told otherwise;
  // the coordinator may set the site's local gravity here.
  Eigen::Vector3d gravity_in_base_m_s2{0.0, 0.0, -kStandardGravity_m_s2};
};

// All effects as JointEffects{} (everything on but the transmission error) unless the `effects`
// node (the scenario's `effects:` map, may be null) says otherwise; the step from the scenario's
// `integration_step_s` node when given (else 0.5 ms). Any bad key/value -> InputError.
PlantConfig make_plant_config(const calib::RobotDescription& robot,
                              const ConfigNode* effects_or_null,
                              const ConfigNode* integration_step_or_null = nullptr);

// Checks the numbers a simulation relies on (step divides the cycle, ...); throws
// std::invalid_argument with the reason.
void validate_plant_config(const PlantConfig& config);

}  // namespace imscal::sim
