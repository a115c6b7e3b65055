// Plant simulator basics: the `effects:` configuration (switches, overrides, refusals), the joint
// controller law against its closed form, and the start at rest without a transient.
#include <gtest/gtest.h>

#include <cmath>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "sim/joint_controller.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "tests/sim/plant_test_paths.hpp"

using imscal::kRadPerArcsec;
using imscal::kRadPerDeg;

namespace {

using imscal::ConfigNode;
using imscal::InputError;
using imscal::calib::JointVector;
using namespace imscal::sim;
using test::kr16;

PlantConfig parse(const std::string& yaml) {
  const ConfigNode root = ConfigNode::load_string(yaml, "scenario.yaml");
  const auto effects = root.optional_child("effects");
  const auto step = root.optional_child("integration_step_s");
  return make_plant_config(kr16(), effects ? &*effects : nullptr, step ? &*step : nullptr);
}

TEST(PlantConfig, DefaultsAreAllEffectsButTransmissionError) {
  const PlantConfig config = make_plant_config(kr16(), nullptr);
  EXPECT_DOUBLE_EQ(config.integration_step_s, 0.0005);
  for (const JointEffects& e : config.effects) {
    EXPECT_TRUE(e.motor_inertia && e.elastic_gear && e.gear_damping && e.backlash &&
                e.coulomb_friction && e.viscous_friction);
    EXPECT_FALSE(e.transmission_error);
    EXPECT_EQ(e.dead_time_s, 0.0);
  }
}

TEST(PlantConfig, AllThenPerJointOverrides) {
  const PlantConfig config = parse(R"(
effects:
  all: {backlash: false, dead_time_s: 0.004, coulomb_velocity_scale_rad_s: 0.02}
  transmission_error: {amplitude_arcsec: 10, harmonic_per_motor_rev: 2, phase_deg: 90}
  A2: {backlash: true, transmission_error: true, friction_at_link: true}
  A6: {elastic_gear: false, gear_damping: false, transmission_error_shape: {amplitude_arcsec: 5}}
integration_step_s: 0.00025
)");
  EXPECT_DOUBLE_EQ(config.integration_step_s, 0.00025);
  EXPECT_FALSE(config.effects[0].backlash);
  EXPECT_TRUE(config.effects[1].backlash);
  EXPECT_TRUE(config.effects[1].transmission_error);
  EXPECT_TRUE(config.effects[1].friction_at_link);
  EXPECT_FALSE(config.effects[0].friction_at_link);
  EXPECT_FALSE(config.effects[0].transmission_error);
  EXPECT_DOUBLE_EQ(config.effects[3].dead_time_s, 0.004);
  EXPECT_DOUBLE_EQ(config.effects[2].coulomb_velocity_scale_rad_s, 0.02);
  EXPECT_NEAR(config.effects[1].transmission_error_shape.amplitude_rad, 10 * kRadPerArcsec, 1e-15);
  EXPECT_DOUBLE_EQ(config.effects[1].transmission_error_shape.harmonic_per_motor_rev, 2.0);
  EXPECT_NEAR(config.effects[1].transmission_error_shape.phase_rad, M_PI / 2, 1e-15);
  EXPECT_FALSE(config.effects[5].elastic_gear);
  EXPECT_NEAR(config.effects[5].transmission_error_shape.amplitude_rad, 5 * kRadPerArcsec, 1e-15);
  EXPECT_DOUBLE_EQ(config.effects[5].transmission_error_shape.harmonic_per_motor_rev, 2.0);
}

TEST(PlantConfig, RefusesUnknownKeysAndInconsistentSwitches) {
  auto line_of_error = [](const std::string& yaml) -> std::size_t {
    try {
      parse(yaml);
    } catch (const InputError& e) {
      return e.line();
    }
    return 0;
  };
  EXPECT_EQ(line_of_error("effects:\n  all: {backlsh: false}\n"), 2u);        // typo
  EXPECT_EQ(line_of_error("effects:\n  A7: {backlash: false}\n"), 2u);        // no such joint
  EXPECT_EQ(line_of_error("effects:\n  A3: {elastic_gear: false}\n"), 2u);    // rigid + backlash
  EXPECT_EQ(line_of_error("effects:\n  all: {dead_time_s: -1}\n"), 2u);       // negative
  EXPECT_EQ(line_of_error("effects: {}\nintegration_step_s: 0.0007\n"), 2u);  // no divisor
  EXPECT_EQ(line_of_error("effects:\n  transmission_error: {amplitude: 3}\n"), 2u);
}

// Closed form of the P / PI cascade with the gains of KR 16 A1.
TEST(JointControllerLaw, MatchesClosedFormAndHoldsPreload) {
  const auto& gains = kr16().joints[0].controller;
  JointController controller(gains, 0.002);
  controller.preload(300.0);
  EXPECT_NEAR(controller.update(0.5, 0.0, 0.5, 0.0), 300.0, 1e-9);  // no error: holding torque
  // q error 0.01 rad, desired 0.1 rad/s, motor at 0.05 rad/s (feed-forward 1 in kr16.yaml).
  const double w = gains.velocity_feedforward * 0.1 + gains.kp_position_1_s * 0.01;
  const double e = w - 0.05;
  const double integral = 300.0 / gains.ki_velocity_nm_per_rad + e * 0.002;
  const double expected =
      gains.kp_velocity_nm_s_per_rad * e + gains.ki_velocity_nm_per_rad * integral;
  ASSERT_LT(std::abs(expected), gains.torque_limit_nm);  // unsaturated case
  EXPECT_NEAR(controller.update(0.01, 0.1, 0.0, 0.05), expected, 1e-9);
}

TEST(JointControllerLaw, AntiWindupStopsIntegratorWhileSaturated) {
  const auto& gains = kr16().joints[0].controller;
  JointController controller(gains, 0.002);
  const double limit = gains.torque_limit_nm;
  EXPECT_DOUBLE_EQ(controller.update(1.0, 0.0, 0.0, 0.0), limit);  // kp_v * kp * 1 rad >> limit
  const double integral = controller.integral_rad();
  for (int k = 0; k < 500; ++k) EXPECT_DOUBLE_EQ(controller.update(1.0, 0.0, 0.0, 0.0), limit);
  // Saturated: the integral has not grown (without anti-windup: +500 * kp * 0.002 rad).
  EXPECT_LE(controller.integral_rad(), integral);
  // An error of the other sign reverses the torque at once (no wound-up integral to unwind).
  EXPECT_LT(controller.update(-0.01, 0.0, 0.0, 0.0), 0.0);
}

// At rest with every effect on (transmission error and a payload too), the plant must stay put:
// gravity balanced by the preloaded springs and integrators.
TEST(PlantStart, AtRestWithoutTransient) {
  PlantConfig config = make_plant_config(kr16(), nullptr);
  for (JointEffects& e : config.effects) e.transmission_error = true;
  JointVector pose;
  pose << 30 * kRadPerDeg, -50 * kRadPerDeg, 60 * kRadPerDeg, 20 * kRadPerDeg, 40 * kRadPerDeg,
      10 * kRadPerDeg;
  DesiredJointPath path = test::build_path(pose, 1.0, {}, 1);
  Payload load{"5 kg", {}};
  load.body.mass_kg = 5.0;
  load.body.com_m = Eigen::Vector3d(0.02, 0.0, 0.1);
  path.payloads.push_back(load);
  const PlantLog log = simulate_plant(config, path, 0.0005);
  ASSERT_EQ(log.samples.size(), 2001u);  // 1 s at 0.5 ms, both ends included
  const PlantSample& first = log.samples.front();
  // Encoders at the desired pose; the link sags under gravity (A2 by ~G/k + b/2 ~ 1e-3 rad).
  EXPECT_LT((first.q_motor_rad - pose).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(std::abs(first.q_motor_rad(1) - first.q_link_rad(1)), 5e-4);
  for (const PlantSample& s : log.samples) {
    // Exact balance up to the fixed-point iteration and rounding: 1e-12 rad, 1e-8 N m.
    EXPECT_LT((s.q_link_rad - first.q_link_rad).cwiseAbs().maxCoeff(), 1e-12) << s.t_s;
    EXPECT_LT((s.tau_drive_nm - first.tau_drive_nm).cwiseAbs().maxCoeff(), 1e-8) << s.t_s;
    EXPECT_LT(s.qdd_link_rad_s2.cwiseAbs().maxCoeff(), 1e-9) << s.t_s;
  }
}

TEST(PlantStart, RefusesStepThatDoesNotDivideTheCycle) {
  PlantConfig config = make_plant_config(kr16(), nullptr);
  config.integration_step_s = 0.0007;
  const DesiredJointPath path = test::build_path(JointVector::Zero(), 0.1, {});
  EXPECT_THROW(simulate_plant(config, path, 0.0007), std::invalid_argument);
  config.integration_step_s = 0.0005;
  EXPECT_THROW(simulate_plant(config, path, 0.0012), std::invalid_argument);  // output interval
}

}  // namespace
