// The bundle with the frames known from an earlier session (FrameCalibrationInput::known_frames,
// what `imscal calibrate --frames` uses): T_R_W's rotation and T_S_H held at their TRUE values,
// the biases and the clock offset estimated from a record with few rests (1 or 2, where the
// frames alone would need >= 3), on a kinematic record (tests/calib/frame_calibration_scenes.hpp:
// quintic moves between mounting poses, ideal increments from a spline of the 1 ms flange poses,
// a navigation-grade unit's turn-on biases, white noise and quantisation drawn per seed; no bias
// instability, so the biases are constant and have one true value).
//
// Tolerance: every bias component and the clock offset within 3 of their reported 1-sigma
// (99.7 % each for an honest sigma; the seeds are fixed, so the outcome is deterministic). The
// sigmas are conditional on the frames, which are exact here. Also checked: the held frames come
// back unchanged (bit for bit: the blocks are constant), the frame part of the covariance is the
// one given, and the refusal of a record without rests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/frame_calibration.hpp"
#include "calib/time_offset.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "robot/robot_description.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace imscal::calib {
namespace {

using test_support::FrameScene;

struct Record {
  FrameScene scene;
  ims::SensorSpec spec;
};

// Home held 10 s (the alignment rest of a real record), then three moves of 2.5 s between
// mounting poses held 4 s each.
Record make_record(std::uint64_t seed) {
  Record out;
  const RobotDescription robot = load_robot_description(std::filesystem::path(IMSCAL_SOURCE_DIR) /
                                                        "datasets" / "robots" / "kr16.yaml");
  out.spec = ims::load_sensor_spec(std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets" /
                                   "sensors" / "navigation-grade.yaml");
  FrameScene& scene = out.scene;
  scene.kinematics = robot.kinematics;
  scene.T_W_R =
      Eigen::Translation3d(2.0, 1.0, 0.0) * Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ());
  scene.T_H_S = robot.tool.T_H_T * Eigen::Translation3d(0.0021, -0.0013, 0.0009) *
                Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.4, -0.2, 0.9).normalized());
  scene.clock_offset_s = 0.0371;
  const auto poses = test_support::mounting_poses();
  test_support::make_kinematic_motion(scene, {poses[0], poses[1], poses[4], poses[5]}, 4.0, 2.5);
  // The first rest 10 s: prepend 6 s at home (the motion starts at rest).
  {
    const double extra_s = 6.0, step_s = 0.001;
    const int n = static_cast<int>(std::lround(extra_s / step_s));
    for (double& t : scene.t_robot_s) t += extra_s;
    for (double& t : scene.rest_begin_s) t += extra_s;
    for (double& t : scene.rest_end_s) t += extra_s;
    scene.rest_begin_s.front() = 0.0;
    std::vector<double> t(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) t[static_cast<std::size_t>(k)] = k * step_s;
    scene.t_robot_s.insert(scene.t_robot_s.begin(), t.begin(), t.end());
    scene.q_rad.insert(scene.q_rad.begin(), static_cast<std::size_t>(n), poses[0]);
  }
  test_support::synthesize_scene_imu(scene);
  test_support::corrupt_scene_imu(scene, out.spec, seed);
  return out;
}

// The bundle's input with only the rests `keep` (indices into the scene's rests): the robot
// still stops at the others, the bundle does not know (as with too short pauses).
FrameCalibrationInput known_frames_input(const Record& record, const std::vector<std::size_t>& keep,
                                         const Eigen::Matrix<double, 9, 9>& frame_covariance) {
  FrameCalibrationInput in =
      test_support::frame_input(record.scene, test_support::noise_model_of(record.spec));
  std::vector<RestObservation> rests;
  for (std::size_t i : keep) rests.push_back(in.rests[i]);
  in.rests = rests;
  KnownFrames known;
  known.R_W_R = record.scene.T_W_R.linear();
  known.T_S_H = record.scene.T_S_H();
  known.covariance = frame_covariance;
  known.source = "truth";
  in.known_frames = known;
  in.time_offset_initial_s = test_support::automatic_time_offset(in);
  return in;
}

void check_recovers_biases_and_clock(const std::vector<std::size_t>& keep) {
  // A frame covariance as an earlier session reports it (0.001 deg, 0.01 mm; heading 0.06 deg).
  Eigen::Matrix<double, 9, 1> frame_sigma;
  frame_sigma << 0.001 * kRadPerDeg, 0.001 * kRadPerDeg, 0.06 * kRadPerDeg, 0.001 * kRadPerDeg,
      0.001 * kRadPerDeg, 0.002 * kRadPerDeg, 1e-5, 1e-5, 2e-5;
  const Eigen::Matrix<double, 9, 9> frame_covariance =
      frame_sigma.cwiseProduct(frame_sigma).asDiagonal();
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const Record record = make_record(seed);
    const FrameCalibrationInput in = known_frames_input(record, keep, frame_covariance);
    const FrameCalibrationResult r = calibrate_frames(in);
    ASSERT_TRUE(r.converged) << r.solver_brief_report;
    // The frames are held: exactly the given ones (rotation; T_S_H whole).
    EXPECT_LT((r.T_R_W.linear().transpose() - record.scene.T_W_R.linear()).norm(), 1e-12);
    EXPECT_LT((r.T_S_H.matrix() - record.scene.T_S_H().matrix()).norm(), 1e-12);
    EXPECT_LT((r.covariance.topLeftCorner<9, 9>() - frame_covariance).norm(), 1e-30);
    // The estimates by name are the result's own fields (the same doubles).
    EXPECT_EQ(r.value("time_offset"), r.time_offset_s);
    EXPECT_EQ(r.value("gyro_bias.z"), r.biases.gyro_rad_s.z());
    EXPECT_EQ(r.value("acc_bias.x"), r.biases.acc_m_s2.x());
    EXPECT_DOUBLE_EQ(r.sigma("R_W_R.up"), frame_sigma[2]);  // sqrt of its square: a few ulp
    const ims::SensorErrorModel& truth = record.scene.sensor_errors;
    const char* axes[] = {"x", "y", "z"};
    double worst = 0.0;
    std::printf("%zu rest(s), seed %llu: error / sigma", in.rests.size(),
                static_cast<unsigned long long>(seed));
    for (int k = 0; k < 3; ++k) {
      const double g = (r.biases.gyro_rad_s[k] - truth.gyro.bias[k]) /
                       r.sigma(std::string("gyro_bias.") + axes[k]);
      const double a =
          (r.biases.acc_m_s2[k] - truth.acc.bias[k]) / r.sigma(std::string("acc_bias.") + axes[k]);
      std::printf("  gyro %s %+.2f (sigma %.3g deg/h)  acc %s %+.2f (sigma %.3g ug)", axes[k], g,
                  r.sigma(std::string("gyro_bias.") + axes[k]) / kRadPerDeg * 3600.0, axes[k], a,
                  r.sigma(std::string("acc_bias.") + axes[k]) / 9.80665 * 1e6);
      EXPECT_LT(std::abs(g), 3.0) << "gyro bias " << axes[k];
      EXPECT_LT(std::abs(a), 3.0) << "acc bias " << axes[k];
      worst = std::max({worst, std::abs(g), std::abs(a)});
    }
    const double dt_sigma = r.sigma("time_offset.dt");
    const double dt = (r.time_offset_s - record.scene.clock_offset_s) / dt_sigma;
    std::printf("  dt %+.2f (sigma %.3g us; initial error %.3g ms)\n", dt, dt_sigma * 1e6,
                (in.time_offset_initial_s - record.scene.clock_offset_s) * 1e3);
    EXPECT_LT(std::abs(dt), 3.0) << "time offset";
  }
}

TEST(FrameCalibrationKnownFrames, OneRestRecoversBiasesAndClockOffsetWithin3Sigma) {
  check_recovers_biases_and_clock({0});
}

TEST(FrameCalibrationKnownFrames, TwoRestsRecoverBiasesAndClockOffsetWithin3Sigma) {
  check_recovers_biases_and_clock({0, 3});
}

TEST(FrameCalibrationKnownFrames, RefusesARecordWithoutRests) {
  const Record record = make_record(1);
  FrameCalibrationInput in =
      known_frames_input(record, {0}, Eigen::Matrix<double, 9, 9>::Identity() * 1e-12);
  in.rests.clear();
  try {
    calibrate_frames(in);
    FAIL() << "a record without rests was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "rests");
    EXPECT_NE(e.problem().find("at least one"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace imscal::calib
