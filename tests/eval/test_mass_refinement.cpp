// The model torque's mass parameters refined from joint errors: a record is synthesised from a
// "plant" whose link masses and centres of mass differ from the nominal robot's (the simulated
// truth), with the joint error a known drive response to the plant's torque; the refinement,
// given the nominal robot only, must bring the model torque to the plant's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "core/input_error.hpp"
#include "eval/mass_refinement.hpp"
#include "eval/model_torque.hpp"
#include "robot/robot_description.hpp"

namespace imscal::eval {
namespace {

ModelTorqueSource kr16() {
  return {calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml"),
          Eigen::Vector3d(0.0, 0.0, -9.81)};
}

// Smooth multi-sine moves of every joint in two runs of 20 s, without and with 10 kg.
ident::JointErrorLog desired_record() {
  ident::JointErrorLog log;
  log.robot = "kr16";
  log.joint_names = {"A1", "A2", "A3", "A4", "A5", "A6"};
  log.q_desired_rad.assign(6, {});
  log.q_measured_rad.assign(6, {});
  log.q_internal_rad.assign(6, {});
  const double dt = log.cycle_s;
  for (int run = 0; run < 2; ++run) {
    if (run == 1) log.segment_starts.push_back(log.time_s.size());
    for (int k = 0; k < 10000; ++k) {
      const double t = k * dt;
      log.time_s.push_back(run * 30.0 + t);
      log.payload_kg.push_back(run * 10.0);
      for (int j = 0; j < 6; ++j) {
        const double w = 0.4 + 0.13 * j + 0.05 * run;
        const double q = 0.8 * std::sin(w * t + j) + 0.3 * std::sin(2.7 * w * t);
        log.q_desired_rad[std::size_t(j)].push_back(j == 1 ? q - 1.2 : j == 2 ? q + 1.4 : q);
      }
    }
  }
  return log;
}

double rms_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(sum / double(a.size()));
}

// The record of a plant: the joint error is the gear's compliance under the plant's torque
// along the desired path, plus a following error proportional to the speed and 1 µrad of white
// measurement noise.
ident::JointErrorLog plant_record(const ModelTorqueSource& plant) {
  ident::JointErrorLog log = desired_record();
  const auto segments = log.segments();
  const auto truth =
      model_torques_along(plant, log.cycle_s, log.q_desired_rad, log.payload_kg, segments);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-6);
  const double compliance_rad_per_nm[6] = {2.5e-6, 2.2e-6, 5e-6, 3.3e-5, 2e-5, 2.5e-4};
  for (std::size_t j = 0; j < 6; ++j)
    for (const auto& [begin, end] : segments)
      for (std::size_t k = begin; k < end; ++k) {
        const std::size_t lo = k > begin ? k - 1 : k, hi = k + 1 < end ? k + 1 : k;
        const double speed =
            (log.q_desired_rad[j][hi] - log.q_desired_rad[j][lo]) / (double(hi - lo) * log.cycle_s);
        log.q_measured_rad[j].push_back(log.q_desired_rad[j][k] +
                                        compliance_rad_per_nm[j] * truth[j][k] - 2e-3 * speed +
                                        noise(rng));
      }
  log.q_internal_rad = log.q_measured_rad;
  return log;
}

TEST(MassRefinement, BringsTheModelTorqueToThePlantsFromJointErrors) {
  const ModelTorqueSource nominal = kr16();
  ModelTorqueSource plant = nominal;
  plant.robot.joints[1].link.mass_kg *= 1.25;
  plant.robot.joints[1].link.com_m += Eigen::Vector3d(0.03, -0.02, 0.0);
  plant.robot.joints[2].link.mass_kg *= 0.75;
  plant.robot.joints[2].link.com_m += Eigen::Vector3d(-0.02, 0.0, 0.03);

  ident::JointErrorLog log = plant_record(plant);
  const auto segments = log.segments();
  const auto truth =
      model_torques_along(plant, log.cycle_s, log.q_desired_rad, log.payload_kg, segments);
  const auto before =
      model_torques_along(nominal, log.cycle_s, log.q_desired_rad, log.payload_kg, segments);

  // One Gauss–Newton step (the default): linearised at the nominal values, it leaves the
  // centres of mass' nonlinearity (measured: A2 13 %, A3 4 % of the error before). Four steps
  // converge here, where the drive model is exact (the shipped record's is not: decision 0047).
  for (const auto& [iterations, bound] : {std::pair{1, 0.2}, std::pair{4, 0.1}}) {
    MassRefinementOptions options;
    options.iterations = iterations;
    const MassRefinement refined = refine_mass_parameters(log, nominal, options);
    const auto after = model_torques_along(refined.model, log.cycle_s, log.q_desired_rad,
                                           log.payload_kg, segments);
    // A2 and A3 carry the changed links' gravity.
    for (std::size_t j : {std::size_t(1), std::size_t(2)}) {
      const double error_before = rms_difference(before[j], truth[j]);
      const double error_after = rms_difference(after[j], truth[j]);
      EXPECT_GT(error_before, 5.0) << "joint " << j + 1 << ": the plant must differ [N m]";
      EXPECT_LT(error_after, bound * error_before) << "joint " << j + 1 << ", " << iterations;
    }
    // The mass of link 2 (the largest change, +10 kg) within 10 % of the plant's.
    EXPECT_NEAR(refined.links[1].mass_kg, plant.robot.joints[1].link.mass_kg,
                0.1 * plant.robot.joints[1].link.mass_kg)
        << iterations;
    for (const LinkMassEstimate& link : refined.links) EXPECT_TRUE(link.refined);
  }
}

// The gravity's columns only (the links' first moments, masses nominal): on the plant with links
// 2 and 3 at +4 and −3 kg the refined model's gravity torque, and so the gear deflection it
// gives (torque × compliance), comes to the plant's, though no mass moves. The static gravity
// torque along the desired path is the truth compared (the deflection the precontrol needs).
TEST(MassRefinement, GravityColumnsBringTheDeflectionToThePlantsWithMassesNominal) {
  const ModelTorqueSource nominal = kr16();
  ModelTorqueSource plant = nominal;
  plant.robot.joints[1].link.mass_kg += 4.0;
  plant.robot.joints[2].link.mass_kg -= 3.0;
  const ident::JointErrorLog log = plant_record(plant);
  const auto gravity = [&](const ModelTorqueSource& model) {
    std::vector<std::vector<double>> out(6);
    PayloadDynamics dynamics(model);
    for (std::size_t k = 0; k < log.time_s.size(); ++k) {
      calib::JointVector q;
      for (int j = 0; j < 6; ++j) q(j) = log.q_desired_rad[std::size_t(j)][k];
      const calib::JointVector t = dynamics.torque(log.payload_kg[k], q, calib::JointVector::Zero(),
                                                   calib::JointVector::Zero());
      for (int j = 0; j < 6; ++j) out[std::size_t(j)].push_back(t(j));
    }
    return out;
  };
  MassRefinementOptions options;
  options.gravity_first_moments = true;
  const MassRefinement refined = refine_mass_parameters(log, nominal, options);
  const auto truth = gravity(plant), before = gravity(nominal), after = gravity(refined.model);
  const double compliance_rad_per_nm[6] = {2.5e-6, 2.2e-6, 5e-6, 3.3e-5, 2e-5, 2.5e-4};
  for (std::size_t j : {std::size_t(1), std::size_t(2)}) {
    const double before_rad = compliance_rad_per_nm[j] * rms_difference(before[j], truth[j]);
    const double after_rad = compliance_rad_per_nm[j] * rms_difference(after[j], truth[j]);
    // The deflection's RMS difference (measured: A2 11.7, A3 13.5 µrad).
    EXPECT_GT(before_rad, 5e-6) << "joint " << j + 1 << ": the plant must differ";
    std::printf("A%zu deflection off the plant's: %.2f µrad nominal, %.2f µrad refined\n", j + 1,
                1e6 * before_rad, 1e6 * after_rad);
    // 12 % of the difference (measured A2 7.5 %, A3 1.1 %): the one step is linearised
    // about the drive's fitted torque taps, which take up part of the mismatch as a scale.
    EXPECT_LT(after_rad, 0.12 * before_rad) << "joint " << j + 1;
  }
  for (std::size_t i = 0; i < 6; ++i)
    EXPECT_EQ(refined.model.robot.joints[i].link.mass_kg, nominal.robot.joints[i].link.mass_kg);
}

// With nominal = plant and an exact drive model the held-out scores stay within noise (standard
// normal: the test's threshold 2.94 is passed with probability 1 % over the six links) and,
// with the held-out test, the model stays the nominal one.
TEST(MassRefinement, HeldOutTestKeepsTheNominalModelWhereItIsThePlants) {
  const ModelTorqueSource nominal = kr16();
  MassRefinementOptions options;
  options.held_out_test = true;
  const MassRefinement refined = refine_mass_parameters(plant_record(nominal), nominal, options);
  for (const LinkMassEstimate& link : refined.links) {
    EXPECT_FALSE(link.refined) << link.held_out_z;
    EXPECT_LT(std::abs(link.held_out_z), 4.0);  // 4σ: a standard normal exceeds it at 6e-5
  }
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(refined.model.robot.joints[i].link.mass_kg, nominal.robot.joints[i].link.mass_kg);
    EXPECT_EQ(refined.model.robot.joints[i].link.com_m, nominal.robot.joints[i].link.com_m);
  }
}

// The table's links: the refined ones replace the robot file's values, the others stay; a table
// refined from another robot file is refused, naming the table and the link.
TEST(MassRefinement, TableLinksReplaceOnlyTheRefinedLinks) {
  const ModelTorqueSource nominal = kr16();
  ident::ParameterTable table;
  for (std::size_t i = 0; i < 6; ++i) {
    const calib::RigidBodyParameters& link = nominal.robot.joints[i].link;
    ident::LinkMassParameters l;
    l.refined = i == 1;
    l.nominal_mass_kg = link.mass_kg;
    l.mass_kg = link.mass_kg + 5.0;
    l.nominal_com_m = {link.com_m.x(), link.com_m.y(), link.com_m.z()};
    l.com_m = {link.com_m.x() + 0.01, link.com_m.y(), link.com_m.z()};
    table.model_torque_links.push_back(l);
  }
  const ModelTorqueSource model = with_table_links(nominal, table, "parameters.json");
  for (std::size_t i = 0; i < 6; ++i) {
    const double expected = nominal.robot.joints[i].link.mass_kg + (i == 1 ? 5.0 : 0.0);
    EXPECT_EQ(model.robot.joints[i].link.mass_kg, expected) << i;
    EXPECT_EQ(model.robot.joints[i].link.com_m.x(),
              nominal.robot.joints[i].link.com_m.x() + (i == 1 ? 0.01 : 0.0))
        << i;
  }
  EXPECT_TRUE(
      with_table_links(nominal, ident::ParameterTable{}, "p.json").robot.joints[1].link.mass_kg ==
      nominal.robot.joints[1].link.mass_kg);
  ModelTorqueSource other = nominal;
  other.robot.joints[3].link.mass_kg *= 1.1;
  try {
    with_table_links(other, table, "parameters.json");
    ADD_FAILURE() << "accepted a table of another robot file";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "parameters.json");
    EXPECT_EQ(e.field(), "model_torque_links/3") << e.what();
  }
}

}  // namespace
}  // namespace imscal::eval
