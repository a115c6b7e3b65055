#pragma once
// One drive of the plant: motor (reflected inertia), gear (spring + damper with a dead zone for
// the backlash, periodic transmission error) and friction, with the effects switched as the
// JointEffects say. Everything in joint-side units: the "motor angle" theta is the motor angle
// divided by the gear ratio N (what the motor encoder reports as a joint angle), torques are at
// the gear output (N times the motor torque).
//
// Gear deflection delta = theta - q_link - te(theta). Spring torque k * dz(delta) with the dead
// zone dz of full width b (dz(x) = x - b/2 for x > b/2, x + b/2 for x < -b/2, else 0); the damper
// d * d(delta)/dt acts only while the teeth are in contact (|delta| > b/2): in the gap there is no
// material to dissipate. The gear torque tau_g pulls the link (+tau_g) and the motor
// (-(1 - te'(theta)) tau_g, the virtual-work factor of the transmission error).
//
// Friction (Coulomb + viscous, values of the robot file in joint-side units) acts on the motor
// side, i.e. on d(theta)/dt: most of a drive's friction sits in the motor bearings and the fast
// gear stages (JointEffects::friction_at_link moves it to the link velocity of an elastic
// drive, JointEffects::link_friction_fraction puts a share of it there: the output bearing; the KR
// 16 robot file's friction numbers are joint-side numbers either way). Smooth Coulomb law F_c
// tanh(v / v_s); with the reflected motor inertia N^2 J_m the slope F_c / (v_s N^2 J_m) is at most
// ~1500 1/s on the KR 16 (A6) for v_s = 0.01 rad/s, i.e. lambda * h = 0.75 at h = 0.5 ms, inside
// RK4's real-axis stability limit of 2.78.
//
// Massless motor (motor_inertia off, elastic_gear on): the motor is a torque source in series
// with the spring, so the gear passes the drive torque to the link unchanged (friction then acts
// at the link velocity) and the encoder reads the static position theta = q + te(theta) +
// dz^-1(tau_g / k) (backlash taken up on the side of the torque; centred at zero torque).
#include <vector>

#include "robot/robot_description.hpp"
#include "sim/plant_config.hpp"

namespace imscal::sim {

enum class DriveKind {
  kRigid,          // elastic gear off: q = theta - te(theta)
  kElastic,        // spring between a motor with inertia and the link
  kMasslessMotor,  // elastic gear, motor inertia off (torque source in series with the spring)
};

class DriveModel {
 public:
  DriveModel() = default;
  DriveModel(const calib::DriveParameters& drive, const JointEffects& effects);

  DriveKind kind() const { return kind_; }
  double reflected_inertia_kg_m2() const { return inertia_; }  // N^2 J_m, 0 when switched off

  // Transmission error te(theta) [rad at the link] and its derivatives w.r.t. theta.
  double te(double theta) const;
  double te_slope(double theta) const;      // d te / d theta (dimensionless)
  double te_curvature(double theta) const;  // d^2 te / d theta^2 [1/rad]

  double dead_zone(double deflection) const;          // dz(x) [rad]
  double inverse_dead_zone(double spring_rad) const;  // x with dz(x) = y, centred at y = 0
  bool in_contact(double deflection) const;

  // Gear torque at the link [N m] from deflection delta and its rate.
  double gear_torque_nm(double deflection, double deflection_rate) const;
  // Friction torque [N m] opposing the velocity v [rad/s].
  double friction_nm(double velocity) const;
  // Spring energy 0.5 k dz(delta)^2 [J].
  double spring_energy_j(double deflection) const;

  // Static motor angle theta with deflection from the gear torque: solves
  // theta = q + te(theta) + dz^-1(tau_g / k) (fixed point; |te'| << 1). Rigid drives: tau_g
  // is ignored (no deflection).
  double motor_angle_for(double q_link, double gear_torque_nm) const;

  double stiffness_nm_per_rad() const { return stiffness_; }
  // Elastic drives: the share of the friction acting on the link velocity (1 with
  // friction_at_link, else JointEffects::link_friction_fraction); 0 for other drives.
  double link_friction_share() const { return link_share_; }
  // The friction on the motor velocity / on the link velocity of an elastic drive [N m].
  double motor_friction_nm(double motor_velocity) const {
    return (1.0 - link_share_) * friction_nm(motor_velocity);
  }
  double link_friction_nm(double link_velocity) const {
    return link_share_ * friction_nm(link_velocity);
  }

 private:
  DriveKind kind_ = DriveKind::kRigid;
  double inertia_ = 0.0;
  double stiffness_ = 0.0;
  double damping_ = 0.0;
  double half_backlash_ = 0.0;
  double coulomb_ = 0.0;
  double coulomb_scale_ = 0.01;
  double viscous_ = 0.0;
  struct TeHarmonic {
    double amplitude = 0.0;  // [rad at the link]
    double frequency = 0.0;  // harmonic * N [1/rad of theta]
    double phase = 0.0;      // [rad]
  };
  std::vector<TeHarmonic> te_;  // empty: no transmission error
  double link_share_ = 0.0;
};

}  // namespace imscal::sim
