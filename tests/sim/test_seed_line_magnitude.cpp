// The default plant reproduces the paper's uncalibrated robot (section 4, Fig. 2 and 5/6): on the
// `seed-line` scenario the maximum path deviation (perpendicular, ISO 9283 style) of the flange is
// 8-20 mm (paper: about 14 mm), the primary axes' errors cause most of it, and the wrist joints'
// errors seen by the internal sensors are much smaller than at the link side.
#include <gtest/gtest.h>

#include <cmath>

#include "core/config_node.hpp"
#include "eval/path_deviation.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "sim/scenario.hpp"

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;

struct SeedLineRun {
  calib::RobotDescription robot;
  DesiredJointPath path;
  PlantLog plant;  // every cycle (2 ms)
};

const SeedLineRun& seed_line() {
  static const SeedLineRun run = [] {
    Scenario scenario =
        load_scenario(fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "scenarios" / "seed-line.yaml");
    // Every drive effect on every joint, the play of the unloaded A1, A4, A6 included (the
    // shipped scenario closes it for the IMS chain's sake; the plant's errors are judged here).
    scenario.effects =
        ConfigNode::load_string(
            "effects:\n"
            "  all: {motor_inertia: true, elastic_gear: true, gear_damping: true, backlash: true,\n"
            "        coulomb_friction: true, viscous_friction: true, transmission_error: true}\n"
            "  transmission_error: {amplitude_arcsec: 10, harmonic_per_motor_rev: 1, phase_deg: "
            "0}\n",
            "seed-line with every effect")
            .child("effects");
    SeedLineRun r;
    r.robot = sim::load_plant_robot(scenario);
    r.path = plan_motion(r.robot, load_motion_program(scenario.program_file));
    const PlantConfig config = make_plant_config(r.robot, scenario);
    r.plant = simulate_plant(config, r.path, r.path.cycle_s);
    return r;
  }();
  return run;
}

// Flange positions along the two line segments for joint angles chosen per joint from the
// desired or the actual (link-side) angles.
double max_path_deviation(const SeedLineRun& r, const std::array<bool, 6>& use_actual) {
  std::vector<eval::TimedPoint> desired, actual;
  for (const PathSegment& segment : r.path.segments) {
    if (segment.kind != SegmentKind::kLinear) continue;
    for (std::size_t k = 0; k < r.path.samples.size() && k < r.plant.samples.size(); ++k) {
      const double t = r.path.samples[k].t_s;
      if (t < segment.begin_s || t > segment.end_s) continue;
      calib::JointVector q = r.path.samples[k].q_rad;
      desired.push_back(
          {t, calib::forward_kinematics<double>(r.robot.kinematics, q).translation()});
      for (int j = 0; j < 6; ++j) {
        if (use_actual[j]) q[j] = r.plant.samples[k].q_link_rad[j];
      }
      actual.push_back({t, calib::forward_kinematics<double>(r.robot.kinematics, q).translation()});
    }
  }
  return eval::path_deviation(desired, actual, 0.5).max_m;
}

TEST(SeedLine, MaximumPathDeviationIsThePapersMagnitude) {
  const double all = max_path_deviation(seed_line(), {true, true, true, true, true, true});
  const double primary = max_path_deviation(seed_line(), {true, true, true, false, false, false});
  const double wrist = max_path_deviation(seed_line(), {false, false, false, true, true, true});
  std::printf(
      "seed-line max path deviation: all joints %.2f mm, A1-A3 only %.2f mm, "
      "A4-A6 only %.2f mm\n",
      all * 1e3, primary * 1e3, wrist * 1e3);
  // Paper: about 14 mm; the band for a plant "of the paper's class": 8-20 mm.
  EXPECT_GE(all, 0.008);
  EXPECT_LE(all, 0.020);
  // The largest share from the primary axes (their following error and deflection).
  EXPECT_GT(primary, 2.0 * wrist);
}

TEST(SeedLine, WristErrorsSeenByInternalSensorsAreMuchSmallerThanAtTheLink) {
  const SeedLineRun& r = seed_line();
  // RMS over the line segments of q_desired - q_internal (what the controller sees) and of
  // q_desired - q_link (what the IMS measures), per wrist joint.
  for (int j = 3; j < 6; ++j) {
    double internal = 0.0, link = 0.0;
    int n = 0;
    for (const PathSegment& segment : r.path.segments) {
      if (segment.kind != SegmentKind::kLinear) continue;
      for (std::size_t k = 0; k < r.path.samples.size() && k < r.plant.samples.size(); ++k) {
        const double t = r.path.samples[k].t_s;
        if (t < segment.begin_s || t > segment.end_s) continue;
        const double qd = r.path.samples[k].q_rad[j];
        internal += std::pow(qd - r.plant.samples[k].q_motor_rad[j], 2);
        link += std::pow(qd - r.plant.samples[k].q_link_rad[j], 2);
        ++n;
      }
    }
    internal = std::sqrt(internal / n);
    link = std::sqrt(link / n);
    std::printf("A%d: RMS error internal %.4f mrad, link side %.4f mrad\n", j + 1, internal * 1e3,
                link * 1e3);
    // "much smaller": at most a third (the paper's Fig. 2 shows roughly an order of magnitude).
    EXPECT_LT(internal, link / 3.0) << "joint A" << j + 1;
  }
}

}  // namespace
}  // namespace imscal::sim
