// Link masses from the motor encoders' torque balance, against simulated truth: the shipped
// identification program (datasets/programs/identification.yaml: 5 kg, then 16 kg payload) on a
// plant whose links 2 and 3 are +4 kg and −3 kg off the nominal robot; the estimator gets the
// desired path, the motor encoders, the logged payload mass and the nominal robot only. The
// payloads are point masses at T here (the model's payload) unless the test says otherwise: the
// test isolates what the payload's mass, the one datum the log has, does to the masses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "eval/link_mass_balance.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "tests/eval/encoder_record.hpp"
#include "tests/sim/plant_test_paths.hpp"

namespace imscal::eval {
namespace {

constexpr double kLink2Change_kg = 4.0, kLink3Change_kg = -3.0;

// The plant's run of the program: desired path, motor encoders and the logged payload mass; the
// plant carries payload_factor times the logged mass.
ident::JointErrorLog record_of(double payload_factor) {
  sim::DesiredJointPath path = sim::plan_motion(
      sim::test::kr16(),
      sim::load_motion_program(IMSCAL_SOURCE_DIR "/datasets/programs/identification.yaml"));
  for (auto& payload : path.payloads) {
    payload.body.com_m.setZero();
    payload.body.inertia_kg_m2.setZero();
  }
  calib::RobotDescription plant = sim::test::kr16();
  plant.joints[1].link.mass_kg += kLink2Change_kg;
  plant.joints[2].link.mass_kg += kLink3Change_kg;
  sim::PlantConfig config = sim::make_plant_config(plant, nullptr);
  config.payload_mass_factor = payload_factor;
  const sim::PlantLog run = sim::simulate_plant(config, path, path.cycle_s);
  return test::encoder_record(plant.name, path, run);
}

const ModelTorqueSource& nominal() {
  static const ModelTorqueSource model{sim::test::kr16(), Eigen::Vector3d(0.0, 0.0, -9.81)};
  return model;
}

// Links 2 and 3 from the rests and slow moves (gravity without the gear's dynamics).
LinkMassBalanceOptions quasi_static_links_2_3() {
  LinkMassBalanceOptions options;
  options.links = {1, 2};
  options.quasi_static_speed_rad_s = 0.05;
  return options;
}

void print(const char* name, const LinkMassBalance& b) {
  std::printf("%s: condition %.3g\n", name, b.condition_number);
  for (std::size_t i = 0; i < b.links.size(); ++i) {
    const auto& l = b.links[i];
    std::printf("  %s: %+.3g ± %.2g (jackknife %.2g)\n",
                l.link >= 0 ? ("link " + std::to_string(l.link + 1) + " [kg]").c_str()
                            : b.payload_names[i - 2].c_str(),
                l.change_kg, l.sigma_kg, l.jackknife_sigma_kg);
  }
}

// The larger of the two stated 1σ.
double sigma(const LinkMassEstimate& l) {
  return std::max(l.sigma_kg, l.jackknife_sigma_kg);
}

// Payload exactly as logged: links 2 and 3 found, the truth within 2σ. Measured +4.19 ± 0.52
// (jackknife 0.68) and −3.61 ± 0.31 (0.53) kg against +4 and −3; on the plant with the nominal
// masses +0.19 ± 0.53 and −0.62 ± 0.31. Tolerance 2σ (both within 1.2 of the jackknife's σ).
TEST(LinkMassBalance, FindsLinks2And3WhenThePayloadIsExactlyTheLogged) {
  if (sim::test::sanitized()) GTEST_SKIP() << "a 3-minute program's simulation: Release only";
  const auto found = identify_link_masses(record_of(1.0), nominal(), quasi_static_links_2_3());
  print("payload as logged", found);
  ASSERT_EQ(found.links.size(), 2u);
  EXPECT_NEAR(found.links[0].change_kg, kLink2Change_kg, 2.0 * sigma(found.links[0]));
  EXPECT_NEAR(found.links[1].change_kg, kLink3Change_kg, 2.0 * sigma(found.links[1]));
  EXPECT_LT(sigma(found.links[0]), 1.0);
}

// The payload 10 % heavier than logged (the lab's tolerance, the population's range): the
// torque scale's anchor is off by 10 % and the masses take it, amplified. Measured: link 2
// +22.2 ± 1.2, link 3 −19.3 ± 0.8 kg (truth +4 / −3); with the payload's factor estimated under a
// 5.8 % prior (uniform ±10 %), +16.9 ± 5.0 and −14.8 ± 4.4 kg, the factor +0.027 ± 0.028 (truth
// 0.1). Asserted: link 2 off by more than 10 kg and by more than 2 stated σ either way, the
// finding the masses are left nominal on (decision 0063).
TEST(LinkMassBalance, APayloadTenPercentOffMovesLink2ByMoreThan10Kg) {
  if (sim::test::sanitized()) GTEST_SKIP() << "a 3-minute program's simulation: Release only";
  const ident::JointErrorLog log = record_of(1.1);
  const auto fixed = identify_link_masses(log, nominal(), quasi_static_links_2_3());
  print("payload 1.1 x logged", fixed);
  LinkMassBalanceOptions prior = quasi_static_links_2_3();
  prior.payload_mass_prior_sigma = 0.058;
  const auto free = identify_link_masses(log, nominal(), prior);
  print("payload 1.1 x logged, factor under a 5.8 % prior", free);
  for (const LinkMassBalance* b : {&fixed, &free}) {
    const LinkMassEstimate& link2 = b->links[0];
    EXPECT_GT(std::abs(link2.change_kg - kLink2Change_kg), 10.0);
    EXPECT_GT(std::abs(link2.change_kg - kLink2Change_kg), 2.0 * sigma(link2));
  }
}

}  // namespace
}  // namespace imscal::eval
