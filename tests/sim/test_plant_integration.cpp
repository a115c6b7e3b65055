// Numerical soundness of the plant's integration: conservation of mechanical energy with the
// non-conservative parts switched off, and convergence in the integration step (RK4 at 0.5 ms
// against 0.25 ms) with every effect on.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "tests/sim/plant_test_paths.hpp"

using imscal::kRadPerDeg;

namespace {

using imscal::calib::JointVector;
using namespace imscal::sim;
using test::home;
using test::kr16;
constexpr int kN = 6;

// Controller, friction and gear damping off; gravity, gear springs with backlash, motor
// inertias and the transmission error on: a conservative system. It starts statically balanced
// but without drive torque, plus motor velocities, so the arm falls and swings (non-trivial).
TEST(PlantIntegration, EnergyIsConservedWithoutControllerFrictionAndDamping) {
  PlantConfig config = make_plant_config(kr16(), nullptr);
  config.controller = false;
  for (JointEffects& e : config.effects) {
    e.coulomb_friction = e.viscous_friction = e.gear_damping = false;
    e.transmission_error = true;
  }
  // Sanitizer builds are 5-10x slower: 2 s instead of 10 s (same drift criterion).
  const double duration = test::sanitized() ? 2.0 : 10.0;
  const DesiredJointPath path = test::build_path(home(), duration, {});
  PlantSimulator simulator(config, path);
  PlantState start = simulator.state();
  start.thetad_rad_s << 0.3, -0.2, 0.4, 1.0, -1.0, 2.0;
  simulator.set_state(start);
  const double e0 = simulator.mechanical_energy_j();
  double max_drift = 0.0, max_kinetic = 0.0;
  while (simulator.run_cycle()) {
    const double e = simulator.mechanical_energy_j();
    max_drift = std::max(max_drift, std::abs(e - e0));
    // Kinetic (links + motors) plus spring energy: the energy exchanged with gravity.
    const double potential = simulator.dynamics().potential_energy_j(simulator.state().q_rad);
    max_kinetic = std::max(max_kinetic, e - potential);
  }
  std::cout << "energy: E0 " << e0 << " J, max |E - E0| " << max_drift << " J, max kinetic+spring "
            << max_kinetic << " J\n";
  // The arm must really move: it falls by tens of centimetres, converting > 100 J.
  EXPECT_GT(max_kinetic, 100.0);
  // Drift < 0.1 % of the energy in play. The total E depends on the arbitrary zero of the
  // potential, so the reference is the largest kinetic + spring energy reached.
  EXPECT_LT(max_drift, 1e-3 * max_kinetic);
}

// All effects on (transmission error included), a multi-joint move with payload: the following
// error q_desired - q_link at 0.5 ms and at 0.25 ms steps differ by < 1 % of its peak per joint.
TEST(PlantIntegration, HalvingTheStepChangesFollowingErrorByLessThanOnePercent) {
  PlantConfig coarse = make_plant_config(kr16(), nullptr);
  for (JointEffects& e : coarse.effects) e.transmission_error = true;
  PlantConfig fine = coarse;
  fine.integration_step_s = 0.5 * coarse.integration_step_s;
  JointVector target;
  target << 50 * kRadPerDeg, -60 * kRadPerDeg, 60 * kRadPerDeg, -40 * kRadPerDeg, 70 * kRadPerDeg,
      120 * kRadPerDeg;
  const double move_s = test::sanitized() ? 0.8 : 1.5;
  DesiredJointPath path = test::build_path(
      home(), 0.1, {{target, move_s, 0.4, 0.3, 0}, {home(), move_s, 0.4, 0.3, 0}}, 1);
  Payload load{"10 kg", {}};
  load.body.mass_kg = 10.0;
  load.body.com_m = Eigen::Vector3d(0.0, 0.05, 0.15);
  load.body.inertia_kg_m2 = Eigen::Matrix3d::Identity() * 0.05;
  path.payloads.push_back(load);
  for (auto& sample : path.samples) sample.payload_index = 1;
  const PlantLog a = simulate_plant(coarse, path, 0.002);
  const PlantLog b = simulate_plant(fine, path, 0.002);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  JointVector peak = JointVector::Zero(), change = JointVector::Zero();
  for (std::size_t k = 0; k < a.samples.size(); ++k) {
    const JointVector error_a = path.samples[k].q_rad - a.samples[k].q_link_rad;
    const JointVector error_b = path.samples[k].q_rad - b.samples[k].q_link_rad;
    peak = peak.cwiseMax(error_a.cwiseAbs());
    change = change.cwiseMax((error_a - error_b).cwiseAbs());
  }
  std::cout << "peak following error [deg]: " << (peak / kRadPerDeg).transpose() << "\n"
            << "max change on halving [deg]: " << (change / kRadPerDeg).transpose() << "\n";
  for (int i = 0; i < kN; ++i) {
    ASSERT_GT(peak(i), 1e-3) << "joint " << i;  // every joint moves with a real following error
    // The brief's criterion: halving the step changes the result by < 1 %.
    EXPECT_LT(change(i), 0.01 * peak(i)) << "joint " << i;
  }
}

}  // namespace
