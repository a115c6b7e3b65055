// URDF robots: the DH model made from a URDF against three truths: the hand-transcribed DH file
// of the same arm (KR 16), the URDF's own joint chain (KR 16, UR10, UR10e) and a laser-tracker
// data set whose goal poses were computed from the UR10's nominal kinematics.
#include <gtest/gtest.h>

#include <urdf_parser/urdf_parser.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/inverse_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "robot/urdf_robot.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::calib {
namespace {

const std::filesystem::path kRobots = std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/robots";
const std::filesystem::path kTracker =
    std::filesystem::path(IMSCAL_TEST_DATA_DIR) / "real/ipa-ur10";

JointVector random_joints(const KinematicModel& model, std::mt19937& rng) {
  JointVector q;
  for (int i = 0; i < kJointCount; ++i) {
    std::uniform_real_distribution<double> within(model.lower_limit_rad(i),
                                                  model.upper_limit_rad(i));
    q(i) = within(rng);
  }
  return q;
}

struct PoseGap {
  double position_m = 0.0;
  double angle_rad = 0.0;
};
PoseGap gap(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return {(a.translation() - b.translation()).norm(),
          Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle()};
}

// Largest gap over `count` random joint sets within the limits of `limits`.
template <typename PoseA, typename PoseB>
PoseGap largest_gap(const KinematicModel& limits, int count, PoseA pose_a, PoseB pose_b) {
  std::mt19937 rng(27);
  PoseGap worst;
  for (int n = 0; n < count; ++n) {
    const JointVector q = random_joints(limits, rng);
    const PoseGap g = gap(pose_a(q), pose_b(q));
    worst.position_m = std::max(worst.position_m, g.position_m);
    worst.angle_rad = std::max(worst.angle_rad, g.angle_rad);
  }
  return worst;
}

// Both files describe the KR 16-2 with R = base_link and H = tool0 and q = the KUKA axis angles,
// so no fixed transform lies between them. Tolerance 1e-12 m / rad: both are exact products of
// the same numbers; what remains is double rounding (~1e-16 per operation).
TEST(UrdfRobot, Kr16UrdfMatchesTheDhFile) {
  const RobotDescription dh = load_robot_description(kRobots / "kr16.yaml");
  const RobotDescription urdf = load_robot_description(kRobots / "kr16.urdf");
  const PoseGap worst = largest_gap(
      dh.kinematics, 10000,
      [&](const JointVector& q) { return forward_kinematics<double>(dh.kinematics, q); },
      [&](const JointVector& q) { return forward_kinematics<double>(urdf.kinematics, q); });
  RecordProperty("kr16_position_gap_m", std::to_string(worst.position_m));
  std::printf("KR 16 URDF vs DH file over 10000 joint sets: %.3g m, %.3g rad\n", worst.position_m,
              worst.angle_rad);
  EXPECT_LT(worst.position_m, 1e-12);
  EXPECT_LT(worst.angle_rad, 1e-12);
  for (int i = 0; i < kJointCount; ++i) {
    EXPECT_DOUBLE_EQ(urdf.kinematics.lower_limit_rad(i), dh.kinematics.lower_limit_rad(i));
    EXPECT_DOUBLE_EQ(urdf.kinematics.upper_limit_rad(i), dh.kinematics.upper_limit_rad(i));
    EXPECT_NEAR(urdf.joints[i].max_velocity_rad_s, dh.joints[i].max_velocity_rad_s, 1e-12);
  }
}

// The DH conversion against the URDF's joint chain itself, for arms with offset wrists and
// parallel axes (UR) as well. Tolerance 1e-12 m / rad as above.
class UrdfChainTest : public ::testing::TestWithParam<const char*> {};
TEST_P(UrdfChainTest, DhModelEqualsTheUrdfChain) {
  const std::filesystem::path file = kRobots / GetParam();
  const RobotDescription robot = load_urdf_robot(file);
  const UrdfChain chain = read_urdf_chain(file, "", "tool0");
  const PoseGap worst = largest_gap(
      robot.kinematics, 2000,
      [&](const JointVector& q) { return forward_kinematics<double>(robot.kinematics, q); },
      [&](const JointVector& q) { return urdf_chain_pose(chain, q); });
  std::printf("%s: DH model vs URDF chain over 2000 joint sets: %.3g m, %.3g rad\n", GetParam(),
              worst.position_m, worst.angle_rad);
  EXPECT_LT(worst.position_m, 1e-12);
  EXPECT_LT(worst.angle_rad, 1e-12);
}
INSTANTIATE_TEST_SUITE_P(Robots, UrdfChainTest,
                         ::testing::Values("kr16.urdf", "ur10.urdf", "ur10e.urdf"));

// The closed-form IK works from the joint screws, not the DH numbers, so the converted KR 16
// solves as the DH file does: FK(q) -> IK(configuration of q) returns q. Tolerance 1e-9 rad:
// the solver's Newton refinement stops at its default tolerances (far below 1e-9).
TEST(UrdfRobot, Kr16UrdfSolvesTheInverseKinematics) {
  const RobotDescription robot = load_robot_description(kRobots / "kr16.urdf");
  const InverseKinematics ik(robot.kinematics);
  std::mt19937 rng(3);
  int solved = 0;
  for (int n = 0; n < 200; ++n) {
    const JointVector q = random_joints(robot.kinematics, rng);
    const IkResult result = ik.solve_nearest(forward_kinematics<double>(robot.kinematics, q), q);
    if (!result.ok()) continue;  // near a singularity or a limit: the solver says so
    ++solved;
    EXPECT_LT((result.q - q).cwiseAbs().maxCoeff(), 1e-9) << result.reason;
  }
  EXPECT_GT(solved, 150);
}

// --- the UR10 against the laser-tracker data set's goal poses --------------------------------

std::vector<std::vector<double>> read_csv_numbers(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

Eigen::Isometry3d read_matrix_mm(const std::filesystem::path& file) {
  std::ifstream in(file);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = m.topLeftCorner<3, 3>();
  pose.translation() = m.topRightCorner<3, 1>() / 1000.0;
  return pose;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// goal = T(base_link <- tool0)(q) * inverse(T_TMac_flange) (data set's SOURCE.md). The data set
// computed its goals from the same nominal UR10 kinematics; the residual (~0.1 mm median) is
// larger than the columns' rounding, so the joint columns are likely measured angles. Tolerances:
// median 0.15 mm, worst 0.7 mm (the whole series D: median 0.08-0.10, max 0.6 mm); orientation
// median 0.02 deg (series D: 0.01 deg).
TEST(UrdfRobot, Ur10ReproducesTheTrackerDataSetsGoalPoses) {
  const RobotDescription robot = load_robot_description(kRobots / "ur10.urdf");
  EXPECT_EQ(robot.name, "ur10");
  EXPECT_DOUBLE_EQ(robot.controller_cycle_s, 0.008);
  const Eigen::Isometry3d T_flange_tmac =
      read_matrix_mm(kTracker / "Trafo_TM_F_init.txt").inverse();
  std::vector<double> position_mm;
  std::vector<double> angle_deg;
  for (const std::vector<double>& row :
       read_csv_numbers(kTracker / "measurements_iso_cubes_head60.csv")) {
    const JointVector q = Eigen::Map<const JointVector>(&row[7]);
    const Eigen::Isometry3d goal = pose_from_xyz_rpy(Eigen::Vector3d(row[1], row[2], row[3]),
                                                     Eigen::Vector3d(row[4], row[5], row[6]));
    const PoseGap g = gap(forward_kinematics<double>(robot.kinematics, q) * T_flange_tmac, goal);
    position_mm.push_back(g.position_m * 1000.0);
    angle_deg.push_back(g.angle_rad * 180.0 / M_PI);
  }
  ASSERT_EQ(position_mm.size(), 60u);
  const double worst_mm = *std::max_element(position_mm.begin(), position_mm.end());
  std::printf("UR10 vs tracker goals (60 poses): median %.3f mm, max %.3f mm, median %.4f deg\n",
              median(position_mm), worst_mm, median(angle_deg));
  EXPECT_LT(median(position_mm), 0.15);
  EXPECT_LT(worst_mm, 0.7);
  EXPECT_LT(median(angle_deg), 0.02);
}

// The UR10e's link masses (physical_parameters.yaml of the UR description) reach the model.
TEST(UrdfRobot, Ur10eCarriesTheUrdfsInertials) {
  const RobotDescription robot = load_robot_description(kRobots / "ur10e.urdf");
  const std::array<double, kJointCount> masses{7.369, 13.051, 3.989, 2.1, 1.98, 0.615};
  for (int i = 0; i < kJointCount; ++i) {
    EXPECT_DOUBLE_EQ(robot.joints[i].link.mass_kg, masses[i]) << "link " << i + 1;
    EXPECT_GT(robot.joints[i].link.inertia_kg_m2.trace(), 0.0);
  }
  EXPECT_EQ(robot.joints[0].name, "shoulder_pan_joint");
}

// Each link's centre of mass and inertia tensor, turned into the base at random q, against the
// URDF's own <inertial> placed by the URDF's joint chain (read with urdfdom here). In the UR
// URDFs the child link of joint k sits at the joint frame, so its pose is the chain's product up
// to joint k. Tolerance 1e-12 (m, kg m^2): two products of the same numbers.
TEST(UrdfRobot, Ur10eInertialsLandWhereTheUrdfPutsThem) {
  const std::filesystem::path file = kRobots / "ur10e.urdf";
  const RobotDescription robot = load_urdf_robot(file);
  const UrdfChain chain = read_urdf_chain(file, "", "tool0");
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(file.string());
  std::mt19937 rng(5);
  for (int n = 0; n < 50; ++n) {
    const JointVector q = random_joints(robot.kinematics, rng);
    const ChainPoses<double> poses = chain_poses<double>(robot.kinematics, q);
    Eigen::Isometry3d T_R_link = Eigen::Isometry3d::Identity();
    for (int k = 0; k < kJointCount; ++k) {
      T_R_link = T_R_link * chain.fixed[k] * Eigen::AngleAxisd(q(k), chain.axis[k]);
      const urdf::Inertial& inertial =
          *model->getLink(model->getJoint(chain.joint_names[k])->child_link_name)->inertial;
      const Eigen::Vector3d com_urdf =
          T_R_link * Eigen::Vector3d(inertial.origin.position.x, inertial.origin.position.y,
                                     inertial.origin.position.z);
      const Eigen::Vector3d com_dh = poses.T_R_link[k + 1] * robot.joints[k].link.com_m;
      EXPECT_LT((com_urdf - com_dh).norm(), 1e-12) << "link " << k + 1;
      const urdf::Rotation& r = inertial.origin.rotation;
      const Eigen::Matrix3d R_R_inertial =
          T_R_link.linear() * Eigen::Quaterniond(r.w, r.x, r.y, r.z).toRotationMatrix();
      Eigen::Matrix3d tensor;
      tensor << inertial.ixx, inertial.ixy, inertial.ixz, inertial.ixy, inertial.iyy, inertial.iyz,
          inertial.ixz, inertial.iyz, inertial.izz;
      const Eigen::Matrix3d R_R_dh = poses.T_R_link[k + 1].linear();
      const Eigen::Matrix3d in_base_dh =
          R_R_dh * robot.joints[k].link.inertia_kg_m2 * R_R_dh.transpose();
      const Eigen::Matrix3d in_base_urdf = R_R_inertial * tensor * R_R_inertial.transpose();
      EXPECT_LT((in_base_dh - in_base_urdf).cwiseAbs().maxCoeff(), 1e-12) << "link " << k + 1;
    }
  }
}

// --- bad input -------------------------------------------------------------------------------

// Tests that write files get a folder of their own (ctest runs cases in parallel).
class UrdfFiles : public test_support::ScratchDirTest {
 protected:
  std::filesystem::path write_temp(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
};

InputError load_error(const std::filesystem::path& file) {
  try {
    load_robot_description(file);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError for " << file;
  return InputError("", 0, "", "");
}

TEST_F(UrdfFiles, RefusesAChainWithAPrismaticJoint) {
  std::string text = test_support::read_text(kRobots / "kr16.urdf");
  const std::string revolute = "<joint name=\"joint_a3\" type=\"revolute\"";
  text.replace(text.find(revolute), revolute.size(), "<joint name=\"joint_a3\" type=\"prismatic\"");
  const InputError e = load_error(write_temp("prismatic.urdf", text));
  EXPECT_EQ(e.field(), "joint_a3");
  EXPECT_EQ(e.line(), 90u);
  EXPECT_NE(e.problem().find("revolute"), std::string::npos);
}

TEST_F(UrdfFiles, RefusesAMissingTipLinkAndAnUnknownSideKey) {
  std::filesystem::copy_file(kRobots / "kr16.urdf", write_temp("kr16.urdf", ""),
                             std::filesystem::copy_options::overwrite_existing);
  const std::filesystem::path side = write_temp("kr16.imscal.yaml", "tip_link: tool9\n");
  EXPECT_EQ(load_error(side.parent_path() / "kr16.urdf").field(), "tool9");
  write_temp("kr16.imscal.yaml", "name: kr16\ncycle_s: 0.002\n");
  const InputError e = load_error(side.parent_path() / "kr16.urdf");
  EXPECT_EQ(e.line(), 2u);
  EXPECT_NE(e.file().find("kr16.imscal.yaml"), std::string::npos);
}

// The side file's joints give each joint its drive and controller, in the URDF's order.
std::string side_joints(const std::string& third_name) {
  std::string text = "joints:\n";
  for (int i = 1; i <= kJointCount; ++i) {
    const std::string name = i == 3 ? third_name : "joint_a" + std::to_string(i);
    text += "  - name: " + name + "\n    drive: {gear_ratio: " + std::to_string(100 + i) +
            ", motor_inertia_kg_m2: 1e-4, stiffness_nm_per_rad: 1e5, damping_nm_s_per_rad: 100,"
            " backlash_deg: 0.01, coulomb_nm: 10, viscous_nm_s_per_rad: 5}\n"
            "    controller: {kp_position_1_s: 12, kp_velocity_nm_s_per_rad: 1000,"
            " ki_velocity_nm_per_rad: 5000, velocity_feedforward: 1, torque_limit_nm: 900}\n";
  }
  return text;
}

TEST_F(UrdfFiles, SideFileGivesDrivesAndControllers) {
  std::filesystem::copy_file(kRobots / "kr16.urdf", write_temp("kr16.urdf", ""),
                             std::filesystem::copy_options::overwrite_existing);
  const std::filesystem::path side = write_temp("kr16.imscal.yaml", side_joints("joint_a3"));
  const RobotDescription robot = load_robot_description(side.parent_path() / "kr16.urdf");
  EXPECT_DOUBLE_EQ(robot.joints[2].drive.gear_ratio, 103.0);
  EXPECT_DOUBLE_EQ(robot.joints[5].controller.torque_limit_nm, 900.0);
  EXPECT_NEAR(robot.joints[0].drive.backlash_rad, 0.01 * M_PI / 180.0, 1e-15);

  write_temp("kr16.imscal.yaml", side_joints("joint_a4"));
  const InputError e = load_error(side.parent_path() / "kr16.urdf");
  EXPECT_EQ(e.line(), 8u) << e.what();  // the third entry's name (3 lines per entry)
  EXPECT_NE(e.problem().find("joint_a3"), std::string::npos) << e.what();
}

TEST_F(UrdfFiles, RefusesAFileThatIsNoUrdf) {
  const InputError e = load_error(write_temp("broken.urdf", "<robot name=\"x\"><link></robot>"));
  EXPECT_NE(e.file().find("broken.urdf"), std::string::npos);
}

}  // namespace
}  // namespace imscal::calib
