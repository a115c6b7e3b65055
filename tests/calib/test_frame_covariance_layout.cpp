// The frame bundle's covariance (calib/frame_covariance.hpp) does not depend on where the heap
// puts things. ceres::Covariance orders its Jacobian's columns by the parameter blocks'
// addresses, and its sparse QR rounds by that order; the bundle's blocks live in one buffer
// (calib/frame_bundle.hpp's FrameUnknowns) so that the order is the same whatever was allocated
// and freed before. The check: the same record calibrated after different heap histories (small
// and mid-sized blocks freed in between, so that later allocations land in different holes)
// gives the same estimate and covariance, bit for bit (tolerance zero: the same data through
// the same operations in the same order rounds the same). That holds under glibc's allocator,
// not under any allocator: the sparse QR's own buffers round by their alignment too (under
// valgrind's allocator at 16 bytes 3 of 6 histories differ, at 64 bytes none), so the check is
// skipped under the sanitizers, whose allocators place blocks otherwise, and runs in the Release
// stage (label `release`).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

#include "calib/frame_calibration.hpp"
#include "robot/robot_description.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace imscal::calib {
namespace {

// Leaves holes in the heap: allocates blocks of `sizes` (bytes) in turn `rounds` times and frees
// every other one; the kept ones are returned (held while the next calibration runs).
std::vector<std::unique_ptr<char[]>> punch_holes(const std::vector<std::size_t>& sizes,
                                                 int rounds) {
  std::vector<std::unique_ptr<char[]>> all, kept;
  for (int r = 0; r < rounds; ++r)
    for (std::size_t size : sizes) all.push_back(std::make_unique<char[]>(size));
  for (std::size_t i = 0; i < all.size(); ++i)
    if (i % 2 == 0) kept.push_back(std::move(all[i]));
  return kept;  // `all`'s other half is freed here
}

bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * std::size_t(a.size())) == 0;
}

TEST(FrameCovarianceLayout, SameRecordGivesTheSameBitsAfterAnyHeapHistory) {
  if (std::getenv("IMSCAL_SANITIZED") != nullptr)
    GTEST_SKIP() << "the sanitizers' allocators align the sparse QR's buffers otherwise";
  const RobotDescription robot = load_robot_description(std::filesystem::path(IMSCAL_SOURCE_DIR) /
                                                        "datasets" / "robots" / "kr16.yaml");
  test_support::FrameScene scene;
  scene.kinematics = robot.kinematics;
  scene.T_W_R =
      Eigen::Translation3d(2.0, 1.0, 0.0) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  scene.T_H_S = robot.tool.T_H_T * Eigen::Translation3d(0.0015, -0.0008, 0.0004) *
                Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, -0.5, 0.8).normalized());
  test_support::make_kinematic_motion(scene, test_support::mounting_poses(), 4.0, 2.5);
  test_support::synthesize_scene_imu(scene);
  const ims::SensorSpec spec = ims::load_sensor_spec(
      std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets" / "sensors" / "navigation-grade.yaml");
  FrameCalibrationInput in = test_support::frame_input(scene, test_support::noise_model_of(spec));
  // Every block kind in the covariance's columns: joint deviations free under a prior (one
  // block per rest), an accelerometer bias per rest (a drift), the scale factors.
  for (RestObservation& rest : in.rests) rest.q_link_sigma_rad = JointVector::Constant(20e-6);
  in.noise.acc_bias_drift_psd = 1e-10;  // [(m/s^2)^2/s], a small random walk
  in.time_offset_initial_s = test_support::automatic_time_offset(in);
  FrameCalibrationOptions options;
  options.estimate_scale_factors = true;

  const FrameCalibrationResult first = calibrate_frames(in, options);
  ASSERT_TRUE(first.converged) << first.solver_brief_report;
  ASSERT_GT(first.covariance.size(), 0);
  // Holes of the blocks' sizes (3 and 6 doubles per rest: 192 and 384 bytes for 8 rests) and
  // others, so that a block allocated on its own would land below or above its neighbours.
  const std::vector<std::vector<std::size_t>> histories = {
      {24}, {384}, {192}, {192, 384}, {384, 24, 192, 48}, {1000, 200, 400, 16}};
  for (std::size_t h = 0; h < histories.size(); ++h) {
    const auto held = punch_holes(histories[h], 5 + int(h));
    const FrameCalibrationResult again = calibrate_frames(in, options);
    ASSERT_TRUE(again.converged) << again.solver_brief_report;
    EXPECT_TRUE(same_bits(first.covariance, again.covariance)) << "heap history " << h;
    EXPECT_EQ(std::memcmp(first.T_S_H.data(), again.T_S_H.data(), sizeof(double) * 16), 0)
        << "heap history " << h;
  }
}

}  // namespace
}  // namespace imscal::calib
