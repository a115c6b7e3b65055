// Scenario files: every shipped scenario loads with its files found and its program planned; the
// values read are the ones written; bad scenarios are refused with file, line and key.
#include "sim/scenario.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/input_error.hpp"
#include "robot/robot_description.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;
const fs::path kScenarios = fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "scenarios";

TEST(Scenario, EveryShippedScenarioLoadsAndPlans) {
  int count = 0;
  for (const char* name :
       {"seed-line", "identification", "mounting", "iso9283", "deviating-identification",
        "deviating-seed-line", "deviating-iso9283"}) {
    SCOPED_TRACE(name);
    const Scenario s = load_scenario(resolve_scenario(name));
    EXPECT_EQ(s.name, name);
    const calib::RobotDescription robot = sim::load_plant_robot(s);
    const DesiredJointPath path = plan_motion(robot, load_motion_program(s.program_file));
    EXPECT_GT(path.samples.size(), 1000u);
    EXPECT_EQ(path.cycle_s, robot.controller_cycle_s);
    ++count;
  }
  EXPECT_EQ(count, 7);
}

TEST(Scenario, ValuesAreReadAsWritten) {
  const Scenario s = load_scenario(kScenarios / "seed-line.yaml");
  EXPECT_EQ(s.imu_rate_hz, 1000.0);
  EXPECT_EQ(s.imu_clock_offset_s, 0.0123);
  EXPECT_EQ(s.site.latitude_deg, 48.78232);
  // base: 30 deg yaw; x_R in W = (cos 30, sin 30, 0).
  EXPECT_NEAR(s.T_W_R.linear()(0, 0), std::cos(M_PI / 6), 1e-15);
  EXPECT_NEAR(s.T_W_R.linear()(1, 0), std::sin(M_PI / 6), 1e-15);
  EXPECT_EQ(s.T_W_R.translation(), Eigen::Vector3d(2.0, 1.0, 0.0));
  EXPECT_NEAR(s.mount_offset.translation().x(), 1.5e-3, 1e-18);
  EXPECT_TRUE(s.effects.has_value());
  EXPECT_FALSE(s.random_base_yaw);
  const Scenario m = load_scenario(kScenarios / "mounting.yaml");
  EXPECT_TRUE(m.random_base_yaw);
  EXPECT_NEAR(m.mount_random_rotation_sigma_rad, 1.5 * M_PI / 180.0, 1e-15);
}

using ScenarioErrors = test_support::ScratchDirTest;

TEST_F(ScenarioErrors, BadScenariosNameFileLineAndKey) {
  const std::string good = [] {
    std::string text = imscal::test_support::read_text(kScenarios / "seed-line.yaml");
    const std::string datasets = std::string(IMSCAL_SOURCE_DIR) + "/datasets/";
    for (std::size_t at; (at = text.find("../")) != std::string::npos;)
      text.replace(at, 3, datasets);
    return text;
  }();
  struct Case {
    std::string from, to, key;
  };
  const Case cases[] = {
      {"seed: 1", "seed: 1\nsede: 2", "sede"},         // unknown key (typo)
      {"rate_hz: 1000", "rate_hz: 5", "imu.rate_hz"},  // IMS rate out of range
      {"latitude_deg: 48.78232", "latitude_deg: 148", "site.latitude_deg"},
      {"program: ", "program: /no/such/folder", "program"},             // missing file
      {"imscal-scenario: 1", "imscal-scenario: 2", "imscal-scenario"},  // future version
      {"seed: 1", "seed: -1", "seed"},
      {"output_interval_s: 0.001", "output_interval_s: 0.01", "plant.output_interval_s"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    std::string text = good;
    ASSERT_NE(text.find(c.from), std::string::npos);
    text.replace(text.find(c.from), c.from.size(), c.to);
    const fs::path file = dir_ / "bad.yaml";
    std::ofstream(file) << text;
    try {
      load_scenario(file);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file.string());
      EXPECT_GT(e.line(), 0u);
      EXPECT_NE(e.field().find(c.key), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(resolve_scenario("no-such-scenario"), InputError);
}

}  // namespace
}  // namespace imscal::sim
