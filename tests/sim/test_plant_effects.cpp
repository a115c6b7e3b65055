// Each drive effect of the plant switched on alone (against the ideal plant: rigid gears, no
// motor inertia, no friction, no transmission error, no dead time, same controller) changes the
// output in the direction and by the size physics says. The truths are closed forms (c v, F_c,
// b/2, te(theta), G/k, m g r from our own forward kinematics) or KDL's recursive Newton-Euler
// inverse dynamics (a different algorithm from the simulator's mass-matrix forward solve).
#include <gtest/gtest.h>

#include <cmath>

#include "robot/forward_kinematics.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "sim/rigid_body_dynamics.hpp"
#include "tests/sim/plant_test_paths.hpp"

using imscal::kRadPerDeg;

namespace {

using imscal::calib::JointVector;
using namespace imscal::sim;
using test::home;
using test::kr16;
constexpr int kN = 6;
constexpr double kCycle = 0.002;

// The reference plant: rigid gears with the motor inertia (the controllers are tuned for
// M_ii + N^2 J_m; the stiff wrist loops of kr16.yaml are not stable on the link inertia alone:
// kp_velocity * T / M_66 > 2), no friction, no transmission error, no dead time.
PlantConfig ideal_config() {
  PlantConfig config = make_plant_config(kr16(), nullptr);
  for (JointEffects& e : config.effects) {
    e = JointEffects{};
    e.elastic_gear = e.gear_damping = e.backlash = false;
    e.coulomb_friction = e.viscous_friction = e.transmission_error = false;
  }
  return config;
}

// Sample of the log at time t (output every 2 ms from 0).
const PlantSample& at(const PlantLog& log, double t_s) {
  return log.samples.at(static_cast<std::size_t>(std::lround(t_s / kCycle)));
}

double deflection(const PlantSample& s, int joint) {
  return s.q_motor_rad(joint) - s.q_link_rad(joint);
}

// A1 by +90 deg in 2 s (0.3 s ramps, cruise 0.92 rad/s), rest, and back.
DesiredJointPath a1_there_and_back() {
  JointVector target = home();
  target(0) += 90.0 * kRadPerDeg;
  return test::build_path(home(), 0.2, {{target, 2.0, 0.3, 0.5, 0}, {home(), 2.0, 0.3, 0.5, 0}});
}

// Motor inertia switched off on the primary axes A1..A3 (see ideal_config for the wrist).
TEST(PlantEffects, MotorInertiaAddsReflectedInertiaTorque) {
  const PlantConfig config = ideal_config();
  PlantConfig no_motor = ideal_config();
  for (int i = 0; i < 3; ++i) no_motor.effects[i].motor_inertia = false;
  JointVector target;
  target << 60 * kRadPerDeg, -60 * kRadPerDeg, 60 * kRadPerDeg, 60 * kRadPerDeg, 0 * kRadPerDeg,
      90 * kRadPerDeg;
  const DesiredJointPath path = test::build_path(home(), 0.1, {{target, 1.2, 0.4, 0.2, 0}});
  const PlantLog with = simulate_plant(config, path, kCycle);
  const PlantLog without = simulate_plant(no_motor, path, kCycle);
  RigidBodyDynamics rne(kr16(), imscal::calib::RigidBodyParameters{}, config.gravity_in_base_m_s2);
  double max_extra = 0.0;
  for (std::size_t k = 0; k < with.samples.size(); k += 5) {
    for (const PlantLog* log : {&with, &without}) {
      const PlantSample& s = log->samples[k];
      const JointVector residual =
          s.tau_drive_nm - rne.inverse_dynamics(s.q_link_rad, s.qd_link_rad_s, s.qdd_link_rad_s2);
      for (int i = 0; i < kN; ++i) {
        const auto& drive = kr16().joints[i].drive;
        const bool on = log == &with || i >= 3;
        const double expected = on ? drive.gear_ratio * drive.gear_ratio *
                                         drive.motor_inertia_kg_m2 * s.qdd_link_rad_s2(i)
                                   : 0.0;
        if (log == &with) max_extra = std::max(max_extra, std::abs(expected));
        // Two algorithms (LDLT of KDL's mass matrix vs. recursive Newton-Euler) in double:
        // agreement to ~1e-9 of torques of ~1e3 N m; 1e-6 N m leaves margin.
        EXPECT_NEAR(residual(i), expected, 1e-6) << "joint " << i << " t " << s.t_s;
      }
    }
  }
  // The move must actually exercise the motor inertia (A1: 10 kg m^2 at ~5 rad/s^2).
  EXPECT_GT(max_extra, 20.0);
}

// The gear spring alone (massless motor on A1..A3: a torque source in series with the spring)
// and with the motor inertia (two-mass drive): both must settle at the static deflection G / k.
TEST(PlantEffects, ElasticGearDeflectsByGravityOverStiffness) {
  for (const bool motor_inertia : {false, true}) {
    SCOPED_TRACE(motor_inertia ? "two-mass drive" : "massless motor");
    PlantConfig config = ideal_config();
    for (int i = 0; i < kN; ++i) {
      config.effects[i].elastic_gear = config.effects[i].gear_damping = true;
      if (i < 3) config.effects[i].motor_inertia = motor_inertia;  // wrist: see ideal_config
    }
    JointVector target = home();
    target(1) = -50.0 * kRadPerDeg;  // A2 forward: the arm leans out, gravity torque on A2 grows
    target(2) = 60.0 * kRadPerDeg;
    const DesiredJointPath path = test::build_path(home(), 0.1, {{target, 1.0, 0.3, 2.0, 0}});
    const PlantLog log = simulate_plant(config, path, kCycle);
    const PlantSample& end = log.samples.back();
    RigidBodyDynamics rne(kr16(), imscal::calib::RigidBodyParameters{},
                          config.gravity_in_base_m_s2);
    const JointVector gravity = rne.gravity_torque(end.q_link_rad);
    ASSERT_GT(std::abs(gravity(1)), 300.0);  // a real load on A2 in this pose
    for (int i = 0; i < kN; ++i) {
      const double expected = gravity(i) / kr16().joints[i].drive.stiffness_nm_per_rad;
      // 2 s after the move the 15-30 Hz gear modes (5 % damping, exp(-0.05*94*2) < 1e-4) and
      // the controller (~10 rad/s) have settled: 1 % of the deflection plus 1e-8 rad.
      EXPECT_NEAR(deflection(end, i), expected, 0.01 * std::abs(expected) + 1e-8) << "joint " << i;
    }
    // Sign check on A2: the link sags in the direction of gravity's pull, below the motor.
    EXPECT_GT(deflection(end, 1) * gravity(1), 0.0);
  }
  // The ideal plant has no deflection at all.
  JointVector target = home();
  target(1) = -50.0 * kRadPerDeg;
  const DesiredJointPath path = test::build_path(home(), 0.1, {{target, 1.0, 0.3, 0.2, 0}});
  const PlantLog rigid = simulate_plant(ideal_config(), path, kCycle);
  EXPECT_LT(std::abs(deflection(rigid.samples.back(), 1)), 1e-12);
}

TEST(PlantEffects, BacklashOffsetsLinkByHalfDeadZoneAgainstLoad) {
  PlantConfig elastic = ideal_config();
  for (JointEffects& e : elastic.effects) e.elastic_gear = e.gear_damping = true;
  PlantConfig with_backlash = elastic;
  with_backlash.effects[0].backlash = true;  // A1: loaded only by acceleration
  with_backlash.effects[1].backlash = true;  // A2: loaded by gravity
  const double half_b1 = 0.5 * kr16().joints[0].drive.backlash_rad;
  const double half_b2 = 0.5 * kr16().joints[1].drive.backlash_rad;

  const DesiredJointPath path = a1_there_and_back();
  const PlantLog a = simulate_plant(elastic, path, kCycle);
  const PlantLog b = simulate_plant(with_backlash, path, kCycle);
  auto extra = [&](double t, int joint) {
    return deflection(at(b, t), joint) - deflection(at(a, t), joint);
  };
  // A2 at rest under gravity (G2 < 0 in this pose): the play is taken up on the loaded side.
  RigidBodyDynamics rne(kr16(), imscal::calib::RigidBodyParameters{}, elastic.gravity_in_base_m_s2);
  const double g2 = rne.gravity_torque(home())(1);
  ASSERT_GT(std::abs(g2), 100.0);
  // Both runs hold the same load: the deflections differ by exactly b/2 apart from the
  // controllers' slightly different transients (settled at rest: 1 % of b/2).
  EXPECT_NEAR(extra(0.1, 1), std::copysign(half_b2, g2), 0.01 * half_b2);
  EXPECT_NEAR(extra(path.samples.back().t_s, 1), std::copysign(half_b2, g2), 0.01 * half_b2);
  // A1 during the move: positive acceleration at the middle of the first ramp (t = 0.35 s),
  // deceleration in the middle of the last ramp (t = 2.05 s); back: the opposite signs. The gap
  // is crossed within ~20 ms after the torque reverses, so by mid-ramp the play is taken up on
  // the driving side; the link's response differs a little between runs (seen: 0.5 %; 2 % of b/2).
  EXPECT_NEAR(extra(0.35, 0), +half_b1, 0.02 * half_b1);
  EXPECT_NEAR(extra(2.05, 0), -half_b1, 0.02 * half_b1);
  EXPECT_NEAR(extra(2.85, 0), -half_b1, 0.02 * half_b1);
  EXPECT_NEAR(extra(4.55, 0), +half_b1, 0.02 * half_b1);
}

TEST(PlantEffects, ViscousFrictionAddsTorqueProportionalToVelocity) {
  PlantConfig config = ideal_config();
  for (JointEffects& e : config.effects) e.viscous_friction = true;
  const DesiredJointPath path = a1_there_and_back();
  const PlantLog with = simulate_plant(config, path, kCycle);
  const PlantLog without = simulate_plant(ideal_config(), path, kCycle);
  const double c = kr16().joints[0].drive.viscous_nm_s_per_rad;
  for (double t : {1.2, 1.8, 3.6, 4.2}) {  // cruise, there (0.5-1.9 s) and back (3.0-4.4 s)
    const double v = at(with, t).qd_link_rad_s(0);
    ASSERT_GT(std::abs(v), 0.8);  // cruising at ~0.92 rad/s
    const double extra = at(with, t).tau_drive_nm(0) - at(without, t).tau_drive_nm(0);
    // At cruise the integrator has absorbed the friction; what remains of the ramp transient
    // (PI zero 10 rad/s, >= 0.6 s later) is ~0.02 %; 0.5 % of c v.
    EXPECT_NEAR(extra, c * v, 0.005 * c * std::abs(v)) << "t " << t;
  }
}

TEST(PlantEffects, CoulombFrictionAddsTorqueStepWithVelocitySign) {
  PlantConfig config = ideal_config();
  for (JointEffects& e : config.effects) e.coulomb_friction = true;
  const DesiredJointPath path = a1_there_and_back();
  const PlantLog with = simulate_plant(config, path, kCycle);
  const PlantLog without = simulate_plant(ideal_config(), path, kCycle);
  const double fc = kr16().joints[0].drive.coulomb_nm;
  for (double t : {1.2, 1.8, 3.6, 4.2}) {
    const double v = at(with, t).qd_link_rad_s(0);
    const double extra = at(with, t).tau_drive_nm(0) - at(without, t).tau_drive_nm(0);
    // |v| / v_s ~ 90: tanh = 1 to 1e-70; ramp transient as for viscous: 0.5 %.
    EXPECT_NEAR(extra, std::copysign(fc, v), 0.005 * fc) << "t " << t;
  }
}

// Friction moved from the motor to the gear output (friction_at_link): the spring now carries
// the friction torque, so at cruise the gear deflects by an extra F_c sign(v) / k (A1).
TEST(PlantEffects, FrictionAtLinkDeflectsGearByFrictionOverStiffness) {
  PlantConfig motor_side = ideal_config();
  for (JointEffects& e : motor_side.effects) {
    e.elastic_gear = e.gear_damping = e.coulomb_friction = true;
    e.link_friction_fraction = 0.0;  // all of it on the motor, against all of it at the link
  }
  PlantConfig link_side = motor_side;
  for (JointEffects& e : link_side.effects) e.friction_at_link = true;
  const DesiredJointPath path = a1_there_and_back();
  const PlantLog a = simulate_plant(motor_side, path, kCycle);
  const PlantLog b = simulate_plant(link_side, path, kCycle);
  const double fc_over_k =
      kr16().joints[0].drive.coulomb_nm / kr16().joints[0].drive.stiffness_nm_per_rad;
  for (double t : {1.2, 1.8, 3.6, 4.2}) {
    const double v = at(b, t).qd_link_rad_s(0);
    const double extra = deflection(at(b, t), 0) - deflection(at(a, t), 0);
    // Cruise at ~0.92 rad/s; the gear mode (15 Hz, 5 % damping) has decayed since the ramp:
    // 2 % of F_c / k.
    EXPECT_NEAR(extra, std::copysign(fc_over_k, v), 0.02 * fc_over_k) << "t " << t;
  }
}

// The output bearing's share of the friction (link_friction_fraction) holds an unloaded link
// inside its play. A6 carries no gravity torque in this pose (the IMS's centre of mass lies on
// its axis), so after a move its link is free inside the 6 arcmin play: with no friction on the
// link it keeps moving for ever (the damper works only in contact); the share brings it to rest.
TEST(PlantEffects, LinkBearingFrictionHoldsAnUnloadedLinkInsideItsPlay) {
  auto link_speed_after_move = [](double fraction) {
    PlantConfig config = ideal_config();
    for (JointEffects& e : config.effects) {
      e.elastic_gear = e.gear_damping = e.backlash = true;
      e.coulomb_friction = e.viscous_friction = true;
      e.link_friction_fraction = fraction;
    }
    JointVector target = home();
    target(5) += 60.0 * kRadPerDeg;
    const DesiredJointPath path = test::build_path(home(), 0.2, {{target, 0.6, 0.2, 3.0, 0}});
    const PlantLog log = simulate_plant(config, path, kCycle);
    // RMS link speed of A6 over the last 2 s of the 3 s rest [rad/s].
    double sum = 0.0;
    int n = 0;
    for (double t = 1.8; t < 3.8; t += kCycle, ++n) sum += std::pow(at(log, t).qd_link_rad_s(5), 2);
    return std::sqrt(sum / n);
  };
  const double free_link = link_speed_after_move(0.0);
  const double held_link = link_speed_after_move(0.1);
  std::printf(
      "A6 link speed at rest after a move: %.3g rad/s without, %.3g rad/s with 10 %% of "
      "the friction at the link\n",
      free_link, held_link);
  // At rest a real link stands still: 1e-5 rad/s moves the flange by 2 um/s. Without the share
  // the link moves by whole mrad/s (the old plant's drift).
  EXPECT_LT(held_link, 1e-5);
  EXPECT_GT(free_link, 100.0 * held_link);
}

TEST(PlantEffects, TransmissionErrorIsPeriodicInMotorAngle) {
  PlantConfig config = ideal_config();
  const double amplitude = 20.0 / 3600.0 * kRadPerDeg;
  const double phase = 30.0 * kRadPerDeg;
  config.effects[0].transmission_error = true;
  config.effects[0].transmission_error_shape = {amplitude, 2.0, phase};
  JointVector target = home();
  target(0) += 5.0 * kRadPerDeg;  // 5 deg at the link = 2.2 motor revolutions (N = 160)
  const DesiredJointPath path = test::build_path(home(), 0.1, {{target, 2.0, 0.5, 2.5, 0}});
  const PlantLog log = simulate_plant(config, path, kCycle);
  const double n = kr16().joints[0].drive.gear_ratio;
  double lo = 0.0, hi = 0.0;
  for (const PlantSample& s : log.samples) {
    const double te = deflection(s, 0);
    // Closed form te = A sin(2 N theta + phase); the simulator solves q = theta - te(theta)
    // exactly (double rounding at ~1e0 rad: 1e-15).
    EXPECT_NEAR(te, amplitude * std::sin(2.0 * n * s.q_motor_rad(0) + phase), 1e-13);
    lo = std::min(lo, te);
    hi = std::max(hi, te);
  }
  // Over 4.4 periods the extremes +-A are reached; samples are 0.003 rad of phase apart at most,
  // so the sampled extremes lie within cos(0.003) ~ 1 - 5e-6 of A.
  EXPECT_NEAR(hi, amplitude, 1e-4 * amplitude);
  EXPECT_NEAR(lo, -amplitude, 1e-4 * amplitude);
  // The controller holds the motor encoder at the target: the link ends off by -te.
  const PlantSample& end = log.samples.back();
  EXPECT_NEAR(end.q_motor_rad(0), target(0), 1e-7);  // settled P-PI loop: 2.5 s rest
  EXPECT_NEAR(end.q_link_rad(0),
              target(0) - amplitude * std::sin(2.0 * n * end.q_motor_rad(0) + phase), 1e-7);
}

TEST(PlantEffects, PayloadChangesGravityTorqueByMassTimesLever) {
  PlantConfig config = ideal_config();
  JointVector pose;
  pose << 20 * kRadPerDeg, -40 * kRadPerDeg, 70 * kRadPerDeg, 10 * kRadPerDeg, 30 * kRadPerDeg, 0.0;
  DesiredJointPath path =
      test::build_path(home(), 0.1, {{pose, 1.0, 0.3, 2.5, 0}, {pose, 0.0, 0.0, 2.5, 1}});
  Payload load{"5 kg", {}};
  load.body.mass_kg = 5.0;
  load.body.com_m = Eigen::Vector3d(0.03, -0.02, 0.10);  // in the tool frame T
  load.body.inertia_kg_m2 = Eigen::Matrix3d::Identity() * 0.01;
  path.payloads.push_back(load);
  const PlantLog log = simulate_plant(config, path, kCycle);
  const double t_before = 3.59;  // end of the rest (1.1-3.6 s) before the payload comes
  const PlantSample& before = at(log, t_before);
  const PlantSample& after = log.samples.back();
  ASSERT_LT((before.q_link_rad - pose).norm(), 1e-6);  // settled: 2.5 s of rest
  // Closed form: the joint must hold the moment of the payload's weight about its axis,
  // tau_i = -z_i . ((c - o_i) x m g), frames from our own forward kinematics.
  const auto poses = imscal::calib::chain_poses<double>(kr16().kinematics, after.q_link_rad);
  const Eigen::Vector3d com = poses.T_R_H * kr16().tool.T_H_T * load.body.com_m;
  const Eigen::Vector3d weight = load.body.mass_kg * config.gravity_in_base_m_s2;
  for (int i = 0; i < kN; ++i) {
    const Eigen::Vector3d z = poses.T_R_axis[i].linear().col(2);
    const Eigen::Vector3d o = poses.T_R_axis[i].translation();
    const double expected = -z.dot((com - o).cross(weight));
    const double change = after.tau_drive_nm(i) - before.tau_drive_nm(i);
    // 2.5 s after the change the integrator has settled (PI zero >= 5 rad/s, exp(-12)): 0.2 %.
    EXPECT_NEAR(change, expected, 0.002 * std::abs(expected) + 1e-3) << "joint " << i;
  }
  // A2 carries the payload at ~1.5 m: the change is large.
  EXPECT_GT(std::abs(after.tau_drive_nm(1) - before.tau_drive_nm(1)), 30.0);
}

TEST(PlantEffects, DeadTimeShiftsResponseByWholeCycles) {
  const DesiredJointPath path = a1_there_and_back();
  PlantConfig delayed = ideal_config();
  for (JointEffects& e : delayed.effects) e.dead_time_s = 0.0031;  // rounds to 2 cycles, 4 ms
  PlantConfig big = ideal_config();
  for (JointEffects& e : big.effects) e.dead_time_s = 0.1;  // 50 cycles
  const PlantLog reference = simulate_plant(ideal_config(), path, kCycle);
  const PlantLog small_shift = simulate_plant(delayed, path, kCycle);
  const PlantLog large_shift = simulate_plant(big, path, kCycle);
  double moved = 0.0;
  for (std::size_t k = 50; k < reference.samples.size(); ++k) {
    // The plant is time-invariant and starts at rest with >= 0.1 s of rest: the delayed runs
    // are the reference shifted by whole cycles (same arithmetic: 1e-12 rad).
    for (int i = 0; i < kN; ++i) {
      EXPECT_NEAR(small_shift.samples[k].q_link_rad(i), reference.samples[k - 2].q_link_rad(i),
                  1e-12);
      EXPECT_NEAR(large_shift.samples[k].q_link_rad(i), reference.samples[k - 50].q_link_rad(i),
                  1e-12);
    }
    moved = std::max(
        moved, std::abs(large_shift.samples[k].q_link_rad(0) - reference.samples[k].q_link_rad(0)));
  }
  EXPECT_GT(moved, 0.05);  // 0.1 s at 0.92 rad/s: the shift is visible
}

}  // namespace
