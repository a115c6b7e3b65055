// A robot file without drive and controller blocks (a nominal robot, a URDF without its side
// file's joints) serves kinematics, masses and the chain; only the simulator's plant refuses it,
// naming the robot file and the first joint's missing block.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/input_error.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/scenario.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;
const fs::path kRobots = fs::path(IMSCAL_SOURCE_DIR) / "datasets/robots";

// The test's own folder (ctest runs cases in parallel), from the scratch fixture.
fs::path scratch_dir;
fs::path scratch(const std::string& name) {
  return scratch_dir / name;
}
class KinematicsOnlyRobot : public test_support::ScratchDirTest {
 protected:
  void SetUp() override {
    ScratchDirTest::SetUp();
    scratch_dir = dir_;
  }
};

// kr16.yaml without its joints' `drive:` and `controller:` blocks (4-space keys whose content
// is indented deeper).
fs::path kr16_without_drives() {
  std::ifstream in(kRobots / "kr16.yaml");
  std::ostringstream out;
  bool skipping = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("    drive:", 0) == 0 || line.rfind("    controller:", 0) == 0) {
      skipping = true;
      continue;
    }
    if (skipping && line.rfind("      ", 0) == 0) continue;
    skipping = false;
    out << line << '\n';
  }
  const fs::path file = scratch("kr16-no-drives.yaml");
  std::ofstream(file) << out.str();
  return file;
}

fs::path scenario_with(const fs::path& plant, const fs::path& nominal) {
  const fs::path datasets = fs::path(IMSCAL_SOURCE_DIR) / "datasets";
  const fs::path file = scratch("scenario.yaml");
  std::ofstream(file) << "imscal-scenario: 1\nname: kinematics-only\nrobot: " << plant.string()
                      << "\nnominal_robot: " << nominal.string()
                      << "\nprogram: " << (datasets / "programs/seed-line.yaml").string()
                      << "\nsensor: " << (datasets / "sensors/navigation-grade.yaml").string()
                      << "\nimu: {rate_hz: 1000}\n"
                         "site: {latitude_deg: 48.78, longitude_deg: 9.18, height_m: 245}\n"
                         "base_in_world: {xyz_m: [0, 0, 0], rpy_deg: [0, 0, 0]}\n";
  return file;
}

// The same numbers as kr16.yaml, so the model is identical bit for bit.
TEST_F(KinematicsOnlyRobot, LoadsWithTheSameKinematicsAndMasses) {
  const calib::RobotDescription full = calib::load_robot_description(kRobots / "kr16.yaml");
  const calib::RobotDescription bare = calib::load_robot_description(kr16_without_drives());
  const calib::JointVector q = (calib::JointVector() << 0.1, -1.2, 1.4, 0.3, -0.5, 2.0).finished();
  EXPECT_EQ(calib::forward_kinematics<double>(bare.kinematics, q).matrix(),
            calib::forward_kinematics<double>(full.kinematics, q).matrix());
  for (int i = 0; i < calib::kJointCount; ++i) {
    EXPECT_EQ(bare.joints[i].link.mass_kg, full.joints[i].link.mass_kg);
    EXPECT_EQ(bare.joints[i].drive.stiffness_nm_per_rad, 0.0);
  }
}

TEST_F(KinematicsOnlyRobot, ServesAsNominalRobotButNotAsPlant) {
  const fs::path bare = kr16_without_drives();
  const Scenario scenario = load_scenario(scenario_with(kRobots / "kr16.yaml", bare));
  EXPECT_EQ(load_nominal_robot(scenario).description.name, "kr16");
  try {
    load_scenario(scenario_with(bare, kRobots / "kr16.yaml"));
    ADD_FAILURE() << "a plant without drives was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(fs::path(e.file()).filename(), "kr16-no-drives.yaml");
    EXPECT_EQ(e.field(), "A1.drive");
  }
  // A URDF without the joints of a side file: the same refusal as a plant.
  try {
    load_scenario(scenario_with(kRobots / "ur10.urdf", kRobots / "kr16.yaml"));
    ADD_FAILURE() << "a URDF plant without drives was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "shoulder_pan_joint.drive") << e.what();
  }
}

}  // namespace
}  // namespace imscal::sim
