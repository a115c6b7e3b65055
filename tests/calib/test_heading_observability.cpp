// The heading of the robot base in W (rotation of T_R_W about the vertical) is seen by the IMS
// only through the horizontal Earth rate at the rests (gyrocompassing): its 1-sigma falls as
// 1 / sqrt(total rest time), sigma = k ARW / (Omega cos(latitude) sqrt(T_rest)) with k >= 1 (the
// gyro bias is estimated from the same rests). Measured here on the bundle's own covariance
// (calib/frame_calibration.hpp) for the navigation-grade spec: the same 8 poses of the mounting
// program held 8, 32 and 128 s each, a noise-free record (the covariance depends on the noise
// model and the geometry, not on the draws). The 0.005 deg goal for T_R_W then needs the rest
// time printed below.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/calibration_config.hpp"
#include "calib/frame_calibration.hpp"
#include "core/units.hpp"
#include "ims/sensor_spec.hpp"
#include "robot/robot_description.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace imscal::calib {
namespace {

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

struct HeadingFigure {
  double rest_time_s = 0.0;  // total over the rests the bundle uses (trimmed)
  double sigma_rad = 0.0;
};

HeadingFigure heading_sigma(const RobotDescription& robot, const ims::SensorSpec& spec,
                            double rest_s) {
  test_support::FrameScene scene;
  scene.kinematics = robot.kinematics;
  scene.T_W_R =
      Eigen::Translation3d(2.0, 1.0, 0.0) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  scene.T_H_S = robot.tool.T_H_T;
  test_support::make_kinematic_motion(scene, test_support::mounting_poses(), rest_s, 2.5);
  test_support::synthesize_scene_imu(scene);
  FrameCalibrationInput in = test_support::frame_input(scene, test_support::noise_model_of(spec));
  in.time_offset_initial_s = scene.clock_offset_s;
  const FrameCalibrationResult r = calibrate_frames(in);
  EXPECT_TRUE(r.converged) << r.solver_brief_report;
  HeadingFigure f;
  for (const RestObservation& rest : in.rests) f.rest_time_s += rest.end_ims_s - rest.begin_ims_s;
  f.sigma_rad = r.sigma("R_W_R.up");
  return f;
}

TEST(HeadingObservability, SigmaFallsAsOneOverTheSquareRootOfTheRestTime) {
  const RobotDescription robot = load_robot_description(std::filesystem::path(IMSCAL_SOURCE_DIR) /
                                                        "datasets" / "robots" / "kr16.yaml");
  const ims::SensorSpec spec = ims::load_sensor_spec(
      std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets" / "sensors" / "navigation-grade.yaml");
  const ims::EarthModel earth(test_support::FrameScene{}.site);
  const double horizontal_earth_rate = earth.earth_rate_W().head<2>().norm();  // [rad/s]
  const double goal_rad = 0.005 * kRadPerDeg;
  // Rests of 8, 32, 128 s (32 s at most under the sanitizers: 8 poses, a 270 s record). Shorter
  // rests are not in the 1 / sqrt(T) regime: with 1 s of each 2 s rest used, the moves between
  // them (2.5 s each) add gyrocompassing of their own and the bias is not yet the rests' alone
  // (2 s rests: 0.70 deg sqrt(s), 1.01 x the closed form).
  const std::vector<double> rests =
      sanitized() ? std::vector<double>{8.0, 32.0} : std::vector<double>{8.0, 32.0, 128.0};
  std::vector<HeadingFigure> figures;
  for (double rest_s : rests) {
    figures.push_back(heading_sigma(robot, spec, rest_s));
    const HeadingFigure& f = figures.back();
    // Closed form of gyrocompassing alone (the gyro bias known).
    const double closed_form =
        spec.gyro.white_noise_density / (horizontal_earth_rate * std::sqrt(f.rest_time_s));
    std::printf(
        "rests of %4.0f s (%6.1f s in all): heading 1-sigma %.4f deg, sigma * sqrt(T) %.4f "
        "deg sqrt(s), %.2f x the closed form ARW / (Omega cos(lat) sqrt(T)); 0.005 deg needs "
        "%.0f s (%.1f h) of rest\n",
        rest_s, f.rest_time_s, f.sigma_rad / kRadPerDeg,
        f.sigma_rad * std::sqrt(f.rest_time_s) / kRadPerDeg, f.sigma_rad / closed_form,
        f.rest_time_s * std::pow(f.sigma_rad / goal_rad, 2.0),
        f.rest_time_s * std::pow(f.sigma_rad / goal_rad, 2.0) / 3600.0);
    // The bias is estimated from the same rests, so the closed form is a lower bound; the poses
    // turn the sensor far enough that the bias costs less than a factor 2.
    EXPECT_GE(f.sigma_rad, 0.99 * closed_form);
    EXPECT_LT(f.sigma_rad, 2.0 * closed_form);
  }
  // 1 / sqrt(T): sigma * sqrt(T) the same for all rest lengths, within 5 % (measured: 1.009 and
  // 1.004 times that of the 8 s rests; the moves between the rests add a little of their own).
  for (std::size_t i = 1; i < figures.size(); ++i) {
    const double a = figures[0].sigma_rad * std::sqrt(figures[0].rest_time_s);
    const double b = figures[i].sigma_rad * std::sqrt(figures[i].rest_time_s);
    EXPECT_NEAR(b / a, 1.0, 0.05) << "rests of " << rests[i] << " s";
  }
  // The goal needs hours of rest: more than 2 h for this unit (measured: see the printout).
  const HeadingFigure& longest = figures.back();
  EXPECT_GT(longest.rest_time_s * std::pow(longest.sigma_rad / goal_rad, 2.0), 2.0 * 3600.0);
}

}  // namespace
}  // namespace imscal::calib
