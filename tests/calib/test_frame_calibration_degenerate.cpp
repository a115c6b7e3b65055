// Degenerate pose sets and records for the frame bundle: each must be refused with the
// reason (InputError, or HandEyeUnobservable naming the missing directions) or give a result
// whose weak directions name the problem — never a confident wrong answer. Records are noise-free
// kinematic ones (tests/calib/frame_calibration_scenes.hpp), so nothing but the geometry is at
// fault.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "calib/frame_calibration.hpp"
#include "calib/hand_eye.hpp"
#include "core/units.hpp"
#include "robot/robot_description.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace imscal::calib {
namespace {

using test_support::FrameScene;

JointVector joints_deg(double a1, double a2, double a3, double a4, double a5, double a6) {
  JointVector q;
  q << a1, a2, a3, a4, a5, a6;
  return q * kRadPerDeg;
}

FrameScene scene_with(const std::vector<JointVector>& poses) {
  const RobotDescription robot = load_robot_description(std::filesystem::path(IMSCAL_SOURCE_DIR) /
                                                        "datasets" / "robots" / "kr16.yaml");
  FrameScene scene;
  scene.kinematics = robot.kinematics;
  scene.T_W_R =
      Eigen::Translation3d(2.0, 1.0, 0.0) * Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitZ());
  scene.T_H_S = robot.tool.T_H_T * Eigen::AngleAxisd(0.03, Eigen::Vector3d(1, 2, -1).normalized());
  test_support::make_kinematic_motion(scene, poses, 3.0, 2.0);
  test_support::synthesize_scene_imu(scene);
  return scene;
}

ImuNoiseModel nominal_noise() {
  ImuNoiseModel n;  // navigation-grade white noise (datasets/sensors/navigation-grade.yaml)
  n.gyro_noise_density_rad_per_sqrt_s = 0.002 * kRadPerDeg / 60.0;
  n.acc_noise_density_m_s_per_sqrt_s = 2.2e-6 * 9.80665;
  return n;
}

TEST(FrameCalibrationDegenerate, TwoPosesAreRefused) {
  const FrameScene scene =
      scene_with({joints_deg(0, -90, 90, 0, 45, 0), joints_deg(0, -90, 90, 0, 45, 90)});
  FrameCalibrationInput in = test_support::frame_input(scene, nominal_noise());
  in.time_offset_initial_s = scene.clock_offset_s;
  try {
    calibrate_frames(in);
    FAIL() << "two rest poses were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3"), std::string::npos) << e.what();
  }
}

TEST(FrameCalibrationDegenerate, IdenticalPosesAreRefusedNamingTheDirections) {
  const JointVector q = joints_deg(10, -80, 95, 20, 50, 30);
  const FrameScene scene = scene_with({q, q, q, q});
  FrameCalibrationInput in = test_support::frame_input(scene, nominal_noise());
  in.time_offset_initial_s = scene.clock_offset_s;
  try {
    calibrate_frames(in);
    FAIL() << "identical poses were accepted";
  } catch (const HandEyeUnobservable& e) {
    EXPECT_FALSE(e.missing_directions().empty()) << e.what();
  }
}

TEST(FrameCalibrationDegenerate, RotationsAboutA6OnlyAreRefusedOrNamed) {
  const FrameScene scene =
      scene_with({joints_deg(0, -90, 90, 0, 45, 0), joints_deg(0, -90, 90, 0, 45, 60),
                  joints_deg(0, -90, 90, 0, 45, 150), joints_deg(0, -90, 90, 0, 45, -70),
                  joints_deg(0, -90, 90, 0, 45, -160)});
  FrameCalibrationInput in = test_support::frame_input(scene, nominal_noise());
  in.time_offset_initial_s = scene.clock_offset_s;
  try {
    const FrameCalibrationResult r = calibrate_frames(in);
    // Accepted: then the flange axes that were not turned about must be named.
    bool named = false;
    for (const WeakDirection& w : r.weak_directions) {
      named |= w.description.find("hardly turn the flange") != std::string::npos;
    }
    EXPECT_TRUE(named) << "A6-only poses accepted without naming the unexcited axes";
  } catch (const HandEyeUnobservable& e) {
    ASSERT_FALSE(e.missing_directions().empty()) << e.what();
    std::string all;
    for (const auto& d : e.missing_directions()) all += d + "; ";
    std::printf("A6 only: %s\n", all.c_str());
  }
}

TEST(FrameCalibrationDegenerate, TimeOffsetBeyondTheOverlapIsRefused) {
  const FrameScene scene =
      scene_with({joints_deg(0, -90, 90, 0, 45, 0), joints_deg(0, -90, 90, 0, 45, 90),
                  joints_deg(0, -90, 90, 0, -45, 0), joints_deg(0, -90, 90, 90, 45, 0)});
  FrameCalibrationInput in = test_support::frame_input(scene, nominal_noise());
  // The IMS clock 100 s ahead of the robot's: longer than the whole record, so the robot joint
  // series and the IMS motion do not overlap at all.
  in.time_offset_initial_s = 100.0;
  try {
    calibrate_frames(in);
    FAIL() << "a time offset longer than the records was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("do not overlap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace imscal::calib
