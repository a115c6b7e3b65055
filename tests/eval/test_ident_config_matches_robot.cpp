// The shipped identification config carries numbers of the robot it is for (the joints' maximum
// speeds, the nominal payload, and the gear ratios and stiffnesses of the
// transmission-error inputs): they must be the robot file's (datasets/robots/kr16.yaml, and
// ur10e.urdf for the UR10e's configs), or the speed bands and the error's phase would be those of
// another robot.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "calib/robot_description.hpp"
#include "core/config_node.hpp"
#include "ident/identification_config.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;

// The config's per-joint numbers against the robot's; returns the config.
ident::IdentificationConfig expect_robot_numbers(const fs::path& robot_file,
                                                 const fs::path& config_file) {
  const calib::RobotDescription robot = calib::load_robot_description(robot_file);
  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(config_file));
  EXPECT_EQ(config.gear_ratio.size(), robot.joints.size());
  EXPECT_EQ(config.gear_stiffness_nm_per_rad.size(), robot.joints.size());
  EXPECT_EQ(config.max_speed_rad_s.size(), robot.joints.size());
  EXPECT_EQ(config.nominal_payload_kg, robot.nominal_payload_kg);
  const std::size_t joints =
      std::min({config.gear_ratio.size(), config.max_speed_rad_s.size(),
                config.gear_stiffness_nm_per_rad.size(), robot.joints.size()});
  for (std::size_t j = 0; j < joints; ++j) {
    const auto& drive = robot.joints[j].drive;
    // Ratios and stiffnesses are written with the same digits in both files: equal exactly.
    EXPECT_EQ(config.gear_ratio[j], drive.gear_ratio) << robot.joints[j].name;
    EXPECT_EQ(config.gear_stiffness_nm_per_rad[j], drive.stiffness_nm_per_rad)
        << robot.joints[j].name;
    // The speeds are whole degrees per second in the config: within 0.5 deg/s of the robot's.
    EXPECT_NEAR(config.max_speed_rad_s[j], robot.joints[j].max_velocity_rad_s, 0.5 * M_PI / 180.0)
        << robot.joints[j].name;
  }
  return config;
}

TEST(IdentConfigMatchesRobot, DefaultConfigHasTheKr16sDriveNumbers) {
  const fs::path root(IMSCAL_SOURCE_DIR);
  const ident::IdentificationConfig config = expect_robot_numbers(
      root / "datasets/robots/kr16.yaml", root / "datasets/identification/ident-default.yaml");
  // The default takes the pair, with its phase from the deflected gear.
  EXPECT_TRUE(config.options.transmission_error_input);
  EXPECT_DOUBLE_EQ(config.joint_options(1).transmission_error_rad_per_rad, 160.0);
  EXPECT_DOUBLE_EQ(config.joint_options(1).transmission_error_compliance_rad_per_nm, 1.0 / 4.5e5);
}

// The UR10e's config (datasets/identification/ident-ur10e.yaml) against the URDF's speeds and the
// side file's payload and drives; the UR10e campaign's config names no gear data (its model has
// no transmission-error input) but the speeds and payload.
TEST(IdentConfigMatchesRobot, Ur10eConfigHasTheUr10esDriveNumbers) {
  const fs::path root(IMSCAL_SOURCE_DIR);
  const ident::IdentificationConfig config = expect_robot_numbers(
      root / "datasets/robots/ur10e.urdf", root / "datasets/identification/ident-ur10e.yaml");
  // Strain-wave gears: twice per wave-generator (motor) revolution, ratio 101.
  EXPECT_DOUBLE_EQ(config.joint_options(1).transmission_error_rad_per_rad, 2.0 * 101.0);
  const calib::RobotDescription robot =
      calib::load_robot_description(root / "datasets/robots/ur10e.urdf");
  const ident::IdentificationConfig campaign = ident::load_identification_config(
      ConfigNode::load_file(root / "datasets/campaign-ur10e/identify.yaml"));
  EXPECT_EQ(campaign.nominal_payload_kg, robot.nominal_payload_kg);
  ASSERT_EQ(campaign.max_speed_rad_s.size(), robot.joints.size());
  for (std::size_t j = 0; j < robot.joints.size(); ++j)
    EXPECT_NEAR(campaign.max_speed_rad_s[j], robot.joints[j].max_velocity_rad_s,
                0.5 * M_PI / 180.0);
}

}  // namespace
}  // namespace imscal
