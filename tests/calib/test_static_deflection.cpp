// Static deflection correction (calib/static_deflection.hpp) against two independent truths:
// the gravity torques against KDL's ChainDynParam::JntToGravity (sim/kdl_chain.hpp builds the
// same arm with its inertias, tool and payload), and the corrected link-side angles against the
// simulator's link-side angles at the rests of the `mounting` (no payload) and `seed-line`
// (5 kg payload) scenarios, KR 16 with every drive effect on.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <kdl/chaindynparam.hpp>
#include <random>

#include "calib/static_deflection.hpp"
#include "ims/earth_model.hpp"
#include "robot/robot_description.hpp"
#include "sim/drive_model.hpp"
#include "sim/kdl_chain.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "sim/scenario.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

const fs::path kDatasets = fs::path(IMSCAL_SOURCE_DIR) / "datasets";

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

std::string fmt_vector(const JointVector& v) {
  std::string out;
  for (int i = 0; i < kJointCount; ++i) out += fmt::format("{:9.3f}", v(i));
  return out;
}

JointVector kdl_gravity(const RobotDescription& robot, const RigidBodyParameters* payload,
                        const JointVector& q, const Eigen::Vector3d& gravity) {
  sim::KdlChainOptions options;
  if (payload != nullptr) options.payload = *payload;
  const KDL::Chain chain = sim::build_kdl_chain(robot, options);
  KDL::ChainDynParam dyn(chain, KDL::Vector(gravity.x(), gravity.y(), gravity.z()));
  KDL::JntArray q_kdl(kJointCount), tau(kJointCount);
  for (int i = 0; i < kJointCount; ++i) q_kdl(i) = q(i);
  EXPECT_GE(dyn.JntToGravity(q_kdl, tau), 0);
  JointVector out;
  for (int i = 0; i < kJointCount; ++i) out(i) = tau(i);
  return out;
}

TEST(GravityTorques, MatchKdlInRandomPosesWithPayloadAndTiltedGravity) {
  const RobotDescription robot = load_robot_description(kDatasets / "robots" / "kr16.yaml");
  RigidBodyParameters payload;
  payload.mass_kg = 7.5;
  payload.com_m = {0.03, -0.02, 0.11};
  // A tilted gravity (a wall-mounted or inclined arm) exercises every component.
  const Eigen::Vector3d gravity = Eigen::Vector3d(0.8, -1.1, -9.7);
  std::mt19937_64 rng(7);
  double largest = 0.0, worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    JointVector q;
    for (int i = 0; i < kJointCount; ++i) {
      std::uniform_real_distribution<double> u(robot.kinematics.lower_limit_rad(i),
                                               robot.kinematics.upper_limit_rad(i));
      q(i) = u(rng);
    }
    const RigidBodyParameters* p = trial % 2 == 0 ? &payload : nullptr;
    const JointVector ours = gravity_torques(robot, p, q, gravity);
    const JointVector kdl = kdl_gravity(robot, p, q, gravity);
    largest = std::max(largest, kdl.cwiseAbs().maxCoeff());
    worst = std::max(worst, (ours - kdl).cwiseAbs().maxCoeff());
  }
  std::printf("gravity torques: max |tau| %.1f N m, max |ours - KDL| %.2e N m\n", largest, worst);
  EXPECT_GT(largest, 100.0);  // the poses do load the arm
  // Two exact evaluations of the same sums in double: agreement to rounding (1e-12 relative
  // of ~1e3 N m, with margin).
  EXPECT_LT(worst, 1e-9);
}

// One scenario's plant, and the mean internal and link-side angles over the last second of
// every rest of its program.
struct RestTruth {
  std::string label;
  JointVector q_internal, q_link;
};

struct PlantRun {
  RobotDescription robot;
  sim::PlantConfig config;
  std::optional<RigidBodyParameters> payload;
  std::vector<RestTruth> rests;
};

PlantRun run_plant(const std::string& scenario_name, double max_duration_s) {
  const sim::Scenario scenario =
      sim::load_scenario(kDatasets / "scenarios" / (scenario_name + ".yaml"));
  PlantRun run;
  run.robot = sim::load_plant_robot(scenario);
  sim::DesiredJointPath path =
      sim::plan_motion(run.robot, sim::load_motion_program(scenario.program_file));
  while (path.samples.size() > 1 && path.samples.back().t_s > max_duration_s) {
    path.samples.pop_back();
  }
  run.config = sim::make_plant_config(run.robot, scenario);
  // As sim/simulation.cpp: the site's gravity at the base, in R.
  const ims::EarthModel earth(scenario.site);
  run.config.gravity_in_base_m_s2 =
      scenario.T_W_R.linear().transpose() * earth.gravity_W(scenario.T_W_R.translation());
  if (!path.payloads.empty() && path.payloads.front().body.mass_kg > 0.0) {
    run.payload = path.payloads.front().body;
  }
  const sim::PlantLog log = sim::simulate_plant(run.config, path, path.cycle_s);
  for (const sim::PathSegment& segment : path.segments) {
    // Rests of at least 3 s: averaged over their last second, the plant has settled (the 1 s
    // pause of seed-line has not: its 5 % damped modes still ring at ~1 urad).
    if (segment.kind != sim::SegmentKind::kRest ||
        segment.end_s > log.samples.back().t_s + path.cycle_s ||
        segment.end_s - segment.begin_s < 2.9) {
      continue;
    }
    RestTruth truth{segment.label, JointVector::Zero(), JointVector::Zero()};
    int count = 0;
    for (const sim::PlantSample& s : log.samples) {
      if (s.t_s < segment.end_s - 1.0 || s.t_s > segment.end_s) continue;
      truth.q_internal += s.q_motor_rad;
      truth.q_link += s.q_link_rad;
      ++count;
    }
    truth.q_internal /= count;
    truth.q_link /= count;
    run.rests.push_back(truth);
  }
  return run;
}

void check_rests(const PlantRun& run) {
  StaticDeflectionOptions options;
  options.gravity_R_m_s2 = run.config.gravity_in_base_m_s2;
  std::array<sim::DriveModel, kJointCount> drives;
  for (int i = 0; i < kJointCount; ++i) {
    drives[i] = sim::DriveModel(run.robot.joints[i].drive, run.config.effects[i]);
  }
  JointVector worst_loaded = JointVector::Zero(), worst_floating = JointVector::Zero();
  JointVector worst_uncorrected = JointVector::Zero(), worst_with_te = JointVector::Zero();
  int loaded_count = 0;
  for (const RestTruth& rest : run.rests) {
    const StaticDeflection d = correct_static_deflection(
        run.robot, run.payload ? &*run.payload : nullptr, rest.q_internal, options);
    EXPECT_LT(d.iterations, options.max_iterations) << rest.label;
    for (int i = 0; i < kJointCount; ++i) {
      const double half_play = 0.5 * run.robot.joints[i].drive.backlash_rad;
      // The simulator's gear also has a transmission error te(theta), which the calibration
      // cannot know: q_corrected - q_link = te(theta) exactly for a settled loaded joint.
      const double te = drives[i].te(rest.q_internal(i));
      const double error = d.q_link_rad(i) - rest.q_link(i);
      worst_with_te(i) = std::max(worst_with_te(i), std::abs(error));
      worst_uncorrected(i) =
          std::max(worst_uncorrected(i), std::abs(rest.q_internal(i) - rest.q_link(i)));
      if (d.loaded[i]) {
        ++loaded_count;
        worst_loaded(i) = std::max(worst_loaded(i), std::abs(error - te));
        // Settled plant (5 % damped 15-30 Hz modes, >= 2 s of rest before the averaging second):
        // what remains after te is the residual settling, observed below 0.5 urad.
        EXPECT_NEAR(error, te, 1e-6) << rest.label << " joint " << i + 1;
      } else {
        worst_floating(i) = std::max(worst_floating(i), std::abs(error - te));
        // Floating in the play: anywhere within +-b/2 (margin: the residual settling above).
        EXPECT_LE(std::abs(error - te), half_play + 1e-6) << rest.label << " joint " << i + 1;
        EXPECT_NEAR(d.q_link_sigma_rad(i), run.robot.joints[i].drive.backlash_rad / std::sqrt(12.0),
                    0.1 * d.q_link_sigma_rad(i));
      }
      // The sigma covers the model part: at least the floor.
      EXPECT_GE(d.q_link_sigma_rad(i), options.sigma_floor_rad);
    }
  }
  EXPECT_GT(loaded_count, 0);
  const auto urad = [](const JointVector& v) { return fmt_vector(v * 1e6); };
  std::printf("%zu rests: max |q_internal - q_link| [urad]          %s\n", run.rests.size(),
              urad(worst_uncorrected).c_str());
  std::printf("          max |q_corrected - q_link| [urad]         %s\n",
              urad(worst_with_te).c_str());
  std::printf("  loaded: max |q_corrected - te - q_link| [urad]    %s\n",
              urad(worst_loaded).c_str());
  std::printf("floating: max |q_corrected - te - q_link| [urad]    %s\n",
              urad(worst_floating).c_str());
}

TEST(StaticDeflection, RecoversTheSimulatorsLinkAnglesAtTheMountingRests) {
  // Sanitized builds: the first 4 rests (the plant is the slow part).
  const PlantRun run = run_plant("mounting", sanitized() ? 40.0 : 1e9);
  ASSERT_GE(run.rests.size(), sanitized() ? 3u : 14u);
  check_rests(run);
}

TEST(StaticDeflection, RecoversTheSimulatorsLinkAnglesWithThePayloadOfSeedLine) {
  const PlantRun run = run_plant("seed-line", sanitized() ? 12.0 : 1e9);
  ASSERT_TRUE(run.payload.has_value());
  ASSERT_GE(run.rests.size(), sanitized() ? 1u : 3u);
  check_rests(run);
}

}  // namespace
}  // namespace imscal::calib
