// Robot description loading: the shipped KR 16 against its public source (the ROS-Industrial
// URDF numbers, converted by hand here), unit conversions at the file boundary, and refusal of
// bad input with file, line and key.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "robot/robot_description.hpp"
#include "tests/support/text_file.hpp"

using imscal::ConfigNode;
using imscal::InputError;
using imscal::calib::RobotDescription;

using imscal::kRadPerDeg;

namespace {

const char* const kKr16Path = IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml";

std::string kr16_text() {
  return imscal::test_support::read_text(kKr16Path);
}

// The KR 16 text with the first occurrence of `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to) {
  std::string text = kr16_text();
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

std::size_t line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + at, '\n'));
}

// Loads text and returns the InputError it must raise.
InputError error_of(const std::string& text) {
  try {
    imscal::calib::parse_robot_description(ConfigNode::load_string(text, "robot.yaml"));
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError";
  return InputError("", 0, "", "");
}

}  // namespace

TEST(RobotDescription, Kr16MatchesItsPublicSource) {
  const RobotDescription robot = imscal::calib::load_robot_description(kKr16Path);
  EXPECT_EQ(robot.name, "kr16");
  EXPECT_EQ(robot.source, kKr16Path);
  EXPECT_DOUBLE_EQ(robot.nominal_payload_kg, 16.0);
  // Limits and speeds of kr16_2_macro.xacro, in rad and rad/s.
  const double lower_deg[] = {-185, -155, -130, -350, -130, -350};
  const double upper_deg[] = {185, 35, 154, 350, 130, 350};
  const double speed_deg_s[] = {156, 156, 156, 330, 330, 615};
  for (int i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(robot.kinematics.lower_limit_rad(i), lower_deg[i] * kRadPerDeg);
    EXPECT_DOUBLE_EQ(robot.kinematics.upper_limit_rad(i), upper_deg[i] * kRadPerDeg);
    EXPECT_DOUBLE_EQ(robot.joints[i].max_velocity_rad_s, speed_deg_s[i] * kRadPerDeg);
    EXPECT_EQ(robot.joints[i].name, fmt::format("A{}", i + 1));
  }
  // The DH lengths are the URDF's (and the OPW parameters') link lengths.
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[0].a_m, 0.26);
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[0].d_m, -0.675);
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[1].a_m, 0.68);
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[2].a_m, 0.035);
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[3].d_m, -0.67);
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[5].d_m, -0.158);
  EXPECT_DOUBLE_EQ(robot.kinematics.dh[2].offset_rad, 90 * kRadPerDeg);
  // Moving mass + the ~87 kg base stated in the file make the data sheet's ~235 kg.
  double moving_kg = 0.0;
  for (const auto& joint : robot.joints) moving_kg += joint.link.mass_kg;
  EXPECT_NEAR(moving_kg + 87.0, 235.0, 1.0);  // the file's stated split, to its rounding
  // Conversions at the boundary: 3 arcmin of backlash on A2.
  EXPECT_NEAR(robot.joints[1].drive.backlash_rad, 3.0 / 60.0 * kRadPerDeg, 1e-6 * kRadPerDeg);
  // Tool 0.12 m out along z_H.
  EXPECT_LT((robot.tool.T_H_T.translation() - Eigen::Vector3d(0, 0, 0.12)).norm(), 1e-15);
}

TEST(RobotDescription, RollPitchYawFollowsUrdf) {
  // URDF rpy = fixed-axis x, y, z: R = Rz(yaw) Ry(pitch) Rx(roll). Pitch 90 deg turns x into -z.
  const Eigen::Isometry3d pose =
      imscal::calib::pose_from_xyz_rpy({1, 2, 3}, {0, 90 * kRadPerDeg, 0});
  EXPECT_LT((pose.linear() * Eigen::Vector3d::UnitX() + Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  // Roll then yaw by 90 deg: y -> z (roll) -> z (yaw keeps z); x -> x -> y.
  const Eigen::Isometry3d ry =
      imscal::calib::pose_from_xyz_rpy({0, 0, 0}, {90 * kRadPerDeg, 0, 90 * kRadPerDeg});
  EXPECT_LT((ry.linear() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  EXPECT_LT((ry.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_EQ(pose.translation(), Eigen::Vector3d(1, 2, 3));
}

TEST(RobotDescription, RefusesUnknownKeysWithFileLineAndKey) {
  // A typo in the second joint's drive.
  const std::string text = edited("      backlash_deg: 0.05", "      backlash_arcmin: 3");
  const InputError e = error_of(text);
  EXPECT_EQ(e.file(), "robot.yaml");
  EXPECT_EQ(e.field(), "joints[1].drive.backlash_arcmin");
  EXPECT_EQ(e.line(), line_of(text, "backlash_arcmin"));
  EXPECT_NE(std::string(e.what()).find("unknown key"), std::string::npos) << e.what();
}

TEST(RobotDescription, RefusesMissingKeys) {
  const InputError e = error_of(edited("    max_velocity_deg_s: 156\n", ""));
  EXPECT_EQ(e.field(), "joints[0].max_velocity_deg_s");
  EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
}

TEST(RobotDescription, RefusesImpossibleValues) {
  struct Case {
    std::string from, to, field;
  };
  const Case cases[] = {
      {"mass_kg: 60", "mass_kg: -60", "joints[0].link.mass_kg"},
      {"inertia_kg_m2: [2.4, 2.0, 2.6, 0, 0, 0]", "inertia_kg_m2: [0.1, 0.1, 2.6, 0, 0, 0]",
       "joints[0].link.inertia_kg_m2"},
      {"inertia_kg_m2: [2.4, 2.0, 2.6, 0, 0, 0]", "inertia_kg_m2: [2.4, 2.0, 2.6]",
       "joints[0].link.inertia_kg_m2"},
      {"limit_deg: [-155, 35]", "limit_deg: [35, -155]", "joints[1].limit_deg"},
      {"gear_ratio: 160", "gear_ratio: 0", "joints[0].drive.gear_ratio"},
      {"velocity_feedforward: 1.0", "velocity_feedforward: 1.5",
       "joints[0].controller.velocity_feedforward"},
      {"convention: standard_dh", "convention: dh", "convention"},
      {"a_m: 0.26", "a_m: .nan", "joints[0].a_m"},
      {"  xyz_m: [0, 0, 0.12]", "  xyz_m: [0, 0.12]", "tool.xyz_m"},
  };
  for (const Case& c : cases) {
    const InputError e = error_of(edited(c.from, c.to));
    EXPECT_EQ(e.field(), c.field) << c.to << ": " << e.what();
    EXPECT_GT(e.line(), 0u) << c.to;
  }
}

TEST(RobotDescription, RefusesAWrongNumberOfJoints) {
  std::string text = kr16_text();
  const std::size_t sixth = text.find("  - name: A6");
  const std::size_t after = text.find("flange:");
  text.erase(sixth, after - sixth);
  const InputError e = error_of(text);
  EXPECT_EQ(e.field(), "joints");
  EXPECT_NE(std::string(e.what()).find("expected 6 joints, got 5"), std::string::npos) << e.what();
}

TEST(RobotDescription, ReadsModifiedDh) {
  const RobotDescription robot = imscal::calib::parse_robot_description(
      ConfigNode::load_string(edited("convention: standard_dh", "convention: modified_dh"), "x"));
  EXPECT_EQ(robot.kinematics.convention, imscal::calib::DhConvention::kModified);
}
