#pragma once
// The start of the shipped `seed-line` scenario (the paper's 800 mm line): the scenario, its
// plant robot and the desired joint path planned for its program, cut after a given time. The
// tests that run the plant or the precontrol in a loop on it take this piece, not the whole run.
#include <cstdlib>
#include <filesystem>

#include "robot/robot_description.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/scenario.hpp"

namespace imscal::test_support {

struct SeedLineStart {
  sim::Scenario scenario;
  calib::RobotDescription robot;  // the plant's
  sim::DesiredJointPath path;     // samples up to until_s
};

// The scenario's path kept up to `until_s` [s] (the samples after it dropped).
inline SeedLineStart seed_line_until(double until_s) {
  SeedLineStart s;
  s.scenario = sim::load_scenario(std::filesystem::path(IMSCAL_SOURCE_DIR) /
                                  "datasets/scenarios/seed-line.yaml");
  s.robot = sim::load_plant_robot(s.scenario);
  s.path = sim::plan_motion(s.robot, sim::load_motion_program(s.scenario.program_file));
  while (s.path.samples.back().t_s > until_s) s.path.samples.pop_back();
  return s;
}

// The first 8 s: the initial rest and most of the PTP move to the line (every joint moves).
// Under the sanitizers (IMSCAL_SANITIZED) 6.6 s, 0.6 s of motion, keeps the run short.
inline double seed_line_move_s() {
  return std::getenv("IMSCAL_SANITIZED") ? 6.6 : 8.0;
}

}  // namespace imscal::test_support
