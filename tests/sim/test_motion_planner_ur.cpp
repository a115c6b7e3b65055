// Motion planning on the UR10e (datasets/robots/ur10e.urdf: kinematics, limits and
// the URDF's joint velocities): a Cartesian line of 800 mm (the paper's length) through the
// UR-class inverse kinematics, checked through forward kinematics (independent of the IK the
// planner used): the flange stays on the line with its orientation, and ends at the target.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <string>

#include "calib/forward_kinematics.hpp"
#include "calib/robot_description.hpp"
#include "core/config_node.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"

namespace imscal::sim {
namespace {

// Start: shoulder lifted 60 deg, elbow bent 100 deg, wrist 2 at -90 deg (away from the three
// singularities); UR-like joint acceleration and jerk limits.
constexpr const char* kProgram = R"(
name: ur10e-line
start_joints_deg: [0, -60, 100, -130, -90, 0]
profile: jerk_limited
joint_acceleration_deg_s2: [200, 200, 250, 600, 600, 900]
joint_jerk_deg_s3: [2000, 2000, 2500, 6000, 6000, 9000]
segments:
  - rest: {duration_s: 0.2}
  - lin: {by: {xyz_mm: [0, 800, 0]}, velocity_m_s: 0.4, acceleration_m_s2: 2, jerk_m_s3: 20,
          label: line}
  - rest: {duration_s: 0.2}
)";

TEST(MotionPlannerUr, Ur10eFollowsAnEightHundredMillimetreLine) {
  const calib::RobotDescription robot =
      calib::load_robot_description(std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/ur10e.urdf");
  const MotionProgram program =
      parse_motion_program(ConfigNode::load_string(kProgram, "ur10e-line.yaml"));
  const DesiredJointPath path = plan_motion(robot, program);
  ASSERT_GT(path.samples.size(), 100u);
  const Eigen::Isometry3d start =
      calib::forward_kinematics<double>(robot.kinematics, program.start_joints_rad);
  const Eigen::Vector3d p0 = start.translation();
  const Eigen::Vector3d u = Eigen::Vector3d::UnitY();
  double off_line_m = 0.0, turned_rad = 0.0;
  for (const DesiredJointSample& s : path.samples) {
    const Eigen::Isometry3d pose = calib::forward_kinematics<double>(robot.kinematics, s.q_rad);
    const Eigen::Vector3d r = pose.translation() - p0;
    off_line_m = std::max(off_line_m, (r - r.dot(u) * u).norm());
    turned_rad =
        std::max(turned_rad, Eigen::AngleAxisd(start.linear().transpose() * pose.linear()).angle());
  }
  const Eigen::Vector3d end =
      calib::forward_kinematics<double>(robot.kinematics, path.samples.back().q_rad).translation();
  // The planner's IK reaches each sample's pose to 1e-12 m / rad (IkOptions defaults); 1e-9
  // leaves room for the rounding of 800 mm sums.
  EXPECT_LT(off_line_m, 1e-9);
  EXPECT_LT(turned_rad, 1e-9);
  EXPECT_LT((end - (p0 + 0.8 * u)).norm(), 1e-9);
  std::printf("UR10e line: %zu samples, %.3f s, off the line %.3g m, turned %.3g rad\n",
              path.samples.size(), path.samples.back().t_s, off_line_m, turned_rad);
}

}  // namespace
}  // namespace imscal::sim
