// No shipped scenario drives a joint into its torque limit: a saturated drive cannot follow its
// command whatever the command is, so data recorded in saturation are not those of the linear
// joint controller the error models describe, and no precontrol could remove its error. (With
// the robot file's earlier 2x limits, A3 and A5 saturated for ~0.4 s in the fast mixed moves of
// `identification` and A3 on the small ISO 9283 circle at 100 %.)
//
// The plant runs each scenario's whole program; the peak drive torque of every joint must stay
// below 95 % of its limit (the margin: a few % of friction drawn anew per verification cycle).
// Under the sanitizers only the KR 16's short scenarios run (the long ones take minutes there).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "calib/robot_description.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"
#include "sim/scenario.hpp"

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;

class ShippedScenario : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedScenario, StaysBelowEveryDrivesTorqueLimit) {
  // The UR10e's scenarios add ~1 min of plant time in Release: Release only too.
  const bool long_run = GetParam() == "identification" || GetParam() == "iso9283" ||
                        GetParam().rfind("ur10e-", 0) == 0;
  if (long_run && std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "minutes under sanitizers";
  const Scenario scenario = load_scenario(fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "scenarios" /
                                          (GetParam() + ".yaml"));
  const calib::RobotDescription robot = sim::load_plant_robot(scenario);
  const DesiredJointPath path = plan_motion(robot, load_motion_program(scenario.program_file));
  const PlantConfig config = make_plant_config(robot, scenario);
  const PlantLog log = simulate_plant(config, path, path.cycle_s);
  for (int j = 0; j < calib::kJointCount; ++j) {
    double peak = 0.0, at = 0.0;
    for (const PlantSample& s : log.samples) {
      if (std::abs(s.tau_drive_nm[j]) > peak) peak = std::abs(s.tau_drive_nm[j]), at = s.t_s;
    }
    const double limit = robot.joints[std::size_t(j)].controller.torque_limit_nm;
    std::printf("%s A%d: peak drive torque %.1f N m at %.2f s = %.0f %% of the limit %.0f N m\n",
                GetParam().c_str(), j + 1, peak, at, 100.0 * peak / limit, limit);
    EXPECT_LT(peak, 0.95 * limit) << GetParam() << " A" << j + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(Shipped, ShippedScenario,
                         ::testing::Values("seed-line", "identification", "iso9283", "mounting",
                                           "campaign", "ur10e-seed-line", "ur10e-identification",
                                           "ur10e-iso9283", "ur10e-mounting", "ur10e-campaign"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

}  // namespace
}  // namespace imscal::sim
