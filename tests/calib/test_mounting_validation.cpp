// Mounting validation (calib/mounting_validation.hpp):
//  - the difference of two T_S_H estimates against its closed form; the rest segments;
//  - the verdict thresholds on hand-made bundle results (pure logic, known inputs);
//  - on a simulated record (kinematic motion through the `mounting` poses, navigation-grade IMS
//    noise and biases): a clean session passes, its halves agree; the same session with the IMS
//    mount slipped between rest 10 and rest 11 (two syntheses with different T_H_S spliced at
//    that instant) is failed with "mount slipped between rest 10 and rest 11".
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include "calib/calibration_config.hpp"
#include "calib/mounting_validation.hpp"
#include "calib/robot_description.hpp"
#include "core/units.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/so3.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

Eigen::Isometry3d pose(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ims::quat_exp<double>(rotation_vector).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A bundle result with T_S_H, its 1-sigma (rotation rad, translation m) and `rests` rest blocks
// plus rests-1 motion blocks, none an outlier.
FrameCalibrationResult result_with(const Eigen::Isometry3d& T_S_H, double rotation_sigma,
                                   double translation_sigma, std::size_t rests = 10) {
  FrameCalibrationResult r;
  r.T_S_H = T_S_H;
  r.converged = true;
  r.iterations = 7;
  r.parameter_names = {"R_W_R.east", "R_W_R.north", "R_W_R.up", "R_S_H.x", "R_S_H.y",
                       "R_S_H.z",    "p_S_H.x",     "p_S_H.y",  "p_S_H.z"};
  Eigen::VectorXd variance(9);
  variance << 1e-6, 1e-6, 1e-6, Eigen::Vector3d::Constant(rotation_sigma * rotation_sigma),
      Eigen::Vector3d::Constant(translation_sigma * translation_sigma);
  r.covariance = variance.asDiagonal();
  for (std::size_t i = 0; i < rests; ++i) {
    r.rest_residuals.push_back({"rest " + std::to_string(i + 1), 1.0, 0.0, 0.0, false});
    if (i + 1 < rests)
      r.motion_residuals.push_back(
          {fmt::format("motion {}-{}", i + 1, i + 2), 1.0, 0.0, 0.0, false});
  }
  return r;
}

SessionPart part(const FrameCalibrationResult& r, std::size_t first, std::size_t last) {
  SessionPart p;
  p.label = fmt::format("rests {}-{}", first + 1, last + 1);
  p.first_rest = first;
  p.last_rest = last;
  p.calibrated = true;
  p.converged = true;
  p.estimate = mounting_estimate(r);
  return p;
}

const MountingCheck* find_check(const MountingValidation& v, const std::string& name) {
  for (const auto& c : v.checks)
    if (c.name == name) return &c;
  return nullptr;
}

TEST(MountingValidation, DifferenceMatchesItsClosedForm) {
  const double angle = 0.01 * kRadPerDeg, shift = 0.2e-3;
  const double sa = 0.001 * kRadPerDeg, sb = 0.002 * kRadPerDeg, ta = 0.01e-3, tb = 0.03e-3;
  const FrameCalibrationResult a =
      result_with(pose(Eigen::Vector3d(0, 0, angle), Eigen::Vector3d(shift, 0, 0)), sa, ta);
  const FrameCalibrationResult b = result_with(Eigen::Isometry3d::Identity(), sb, tb);
  const MountingDifference d = compare_mountings(mounting_estimate(a), mounting_estimate(b));
  // Exact up to the rotation log's rounding (1e-15 relative).
  EXPECT_NEAR(d.rotation_rad, angle, 1e-15);
  EXPECT_NEAR(d.translation_m, shift, 1e-15);
  EXPECT_NEAR(d.difference(2), angle, 1e-15);
  const double rotation_sigma = std::hypot(sa, sb), translation_sigma = std::hypot(ta, tb);
  EXPECT_NEAR(d.combined_sigma(0), rotation_sigma, 1e-18);
  EXPECT_NEAR(d.combined_sigma(5), translation_sigma, 1e-18);
  EXPECT_NEAR(d.normalised, std::max(angle / rotation_sigma, shift / translation_sigma), 1e-9);

  // The fallback through the reported estimates (deg, mm) gives the same sigmas.
  FrameCalibrationResult c = a;
  c.parameter_names.clear();
  c.covariance.resize(0, 0);
  c.estimates.push_back({"T_S_H.rotation_vector",
                         "deg",
                         {"x", "y", "z"},
                         Eigen::Vector3d::Zero(),
                         Eigen::Vector3d::Constant(sa / kRadPerDeg)});
  c.estimates.push_back({"T_S_H.translation",
                         "mm",
                         {"x", "y", "z"},
                         Eigen::Vector3d::Zero(),
                         Eigen::Vector3d::Constant(ta * 1e3)});
  const MountingEstimate e = mounting_estimate(c);
  ASSERT_TRUE(e.has_covariance);
  EXPECT_NEAR(std::sqrt(e.covariance(1, 1)), sa, 1e-18);
  EXPECT_NEAR(std::sqrt(e.covariance(4, 4)), ta, 1e-18);
}

TEST(MountingValidation, SegmentsCoverEveryRestOnce) {
  using Ranges = std::vector<std::pair<std::size_t, std::size_t>>;
  EXPECT_EQ(rest_segments(14, 5), (Ranges{{0, 4}, {5, 9}, {10, 13}}));
  EXPECT_EQ(rest_segments(11, 5), (Ranges{{0, 4}, {5, 10}}));  // a last single rest joins
  EXPECT_EQ(rest_segments(4, 5), (Ranges{{0, 3}}));
  EXPECT_TRUE(rest_segments(0, 5).empty());
}

TEST(MountingValidation, VerdictFollowsTheThresholds) {
  const MountingThresholds t;                           // 3 / 5 sigma, floors 0.002 deg and 0.02 mm
  const double rs = 0.001 * kRadPerDeg, ts = 0.005e-3;  // 1-sigma of each half
  const FrameCalibrationResult base = result_with(Eigen::Isometry3d::Identity(), rs, ts);
  const double combined = std::sqrt(2.0) * ts;  // translation sigma of a difference of halves
  auto halves_shifted = [&](double sigmas, double sigma) {
    const FrameCalibrationResult a = result_with(Eigen::Isometry3d::Identity(), rs, sigma);
    const FrameCalibrationResult b = result_with(
        pose(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, sigmas * std::sqrt(2.0) * sigma, 0)), rs,
        sigma);
    return std::vector<SessionPart>{part(a, 0, 4), part(b, 5, 9)};
  };

  // Clean: pass, one plain reason.
  MountingValidation v = assess_mounting(base, halves_shifted(0.5, ts), {}, t);
  EXPECT_EQ(v.verdict, Verdict::kPass);
  ASSERT_EQ(v.reasons.size(), 1u);
  EXPECT_NE(v.reasons[0].find("all checks passed"), std::string::npos);

  // Halves 4 sigma apart (0.028 mm, above the 0.02 mm floor): warn; 6 sigma: fail.
  EXPECT_GT(4.0 * combined, t.repeat_translation_floor_m);
  v = assess_mounting(base, halves_shifted(4.0, ts), {}, t);
  EXPECT_EQ(v.verdict, Verdict::kWarn);
  ASSERT_TRUE(v.halves_difference.has_value());
  EXPECT_NEAR(v.halves_difference->normalised, 4.0, 1e-9);
  v = assess_mounting(base, halves_shifted(6.0, ts), {}, t);
  EXPECT_EQ(v.verdict, Verdict::kFail);
  EXPECT_NE(v.reasons[0].find("not repeatable"), std::string::npos);
  // 6 sigma but only 0.004 mm (sigma 0.5 um): below the floors, no alarm.
  v = assess_mounting(base, halves_shifted(6.0, 0.5e-6), {}, t);
  EXPECT_EQ(find_check(v, "halves")->level, Verdict::kPass);

  // Outliers: 1 of 19 blocks warns, 5 of 19 (26 % > 20 %) fails.
  FrameCalibrationResult with_outliers = base;
  with_outliers.rest_residuals[3].outlier = true;
  EXPECT_EQ(assess_mounting(with_outliers, {}, {}, t).verdict, Verdict::kWarn);
  for (int i : {4, 5, 6}) with_outliers.rest_residuals[std::size_t(i)].outlier = true;
  with_outliers.motion_residuals[2].outlier = true;
  v = assess_mounting(with_outliers, {}, {}, t);
  EXPECT_EQ(v.verdict, Verdict::kFail);
  EXPECT_EQ(v.outlier_count, 5u);
  EXPECT_NE(v.reasons[0].find("rest 4"), std::string::npos);

  // Not converged: fail. Precision worse than 0.005 deg: warn. No covariance: warn.
  FrameCalibrationResult unconverged = base;
  unconverged.converged = false;
  EXPECT_EQ(assess_mounting(unconverged, {}, {}, t).verdict, Verdict::kFail);
  EXPECT_EQ(
      assess_mounting(result_with(Eigen::Isometry3d::Identity(), 0.006 * kRadPerDeg, ts), {}, {}, t)
          .verdict,
      Verdict::kWarn);
  FrameCalibrationResult no_covariance = base;
  no_covariance.covariance.resize(0, 0);
  EXPECT_EQ(assess_mounting(no_covariance, {}, {}, t).verdict, Verdict::kWarn);

  // A half the bundle refused: warn, with the bundle's words.
  std::vector<SessionPart> refused = halves_shifted(0.0, ts);
  refused[1].calibrated = false;
  refused[1].failure = "rotations about one axis only";
  v = assess_mounting(base, refused, {}, t);
  EXPECT_EQ(v.verdict, Verdict::kWarn);
  EXPECT_NE(v.reasons[0].find("rotations about one axis only"), std::string::npos);
}

TEST(MountingValidation, SegmentJumpIsASlipBetweenItsRests) {
  const MountingThresholds t;
  const double rs = 0.001 * kRadPerDeg, ts = 0.005e-3;
  const FrameCalibrationResult base = result_with(Eigen::Isometry3d::Identity(), rs, ts, 14);
  const FrameCalibrationResult moved = result_with(
      pose(Eigen::Vector3d(0.02 * kRadPerDeg, 0, 0), Eigen::Vector3d::Zero()), rs, ts, 14);
  const std::vector<SessionPart> segments = {part(base, 0, 4), part(base, 5, 9),
                                             part(moved, 10, 13)};
  const MountingValidation v = assess_mounting(base, {}, segments, t);
  EXPECT_EQ(v.verdict, Verdict::kFail);
  ASSERT_EQ(v.segment_comparisons.size(), 2u);
  EXPECT_FALSE(v.segment_comparisons[0].slipped);
  EXPECT_TRUE(v.segment_comparisons[1].slipped);
  ASSERT_EQ(v.reasons.size(), 1u);
  EXPECT_NE(v.reasons[0].find("mount slipped between rest 10 and rest 11"), std::string::npos)
      << v.reasons[0];
}

TEST(MountingValidation, SessionsCompareLikeHalves) {
  const MountingThresholds t;
  const double rs = 0.001 * kRadPerDeg, ts = 0.005e-3;
  const FrameCalibrationResult a = result_with(Eigen::Isometry3d::Identity(), rs, ts);
  // 0.01 deg about z: 7.1 combined sigma, above the 0.002 deg floor -> fail.
  const FrameCalibrationResult b =
      result_with(pose(Eigen::Vector3d(0, 0, 0.01 * kRadPerDeg), Eigen::Vector3d::Zero()), rs, ts);
  EXPECT_EQ(compare_sessions(a, a, t).level, Verdict::kPass);
  EXPECT_EQ(compare_sessions(a, b, t).level, Verdict::kFail);
}

// --- On a simulated record -------------------------------------------------------------------

JointVector joints_deg(double a1, double a2, double a3, double a4, double a5, double a6) {
  JointVector q;
  q << a1, a2, a3, a4, a5, a6;
  return q * kRadPerDeg;
}

// The 14 poses of datasets/programs/mounting.yaml.
std::vector<JointVector> mounting_poses() {
  return {joints_deg(0, -90, 90, 0, 45, 0),        joints_deg(0, -90, 90, 0, 45, 90),
          joints_deg(0, -90, 90, 0, 45, -90),      joints_deg(0, -90, 90, 0, -45, 0),
          joints_deg(0, -90, 90, 90, 45, 0),       joints_deg(0, -90, 90, -90, 45, 0),
          joints_deg(30, -80, 100, 0, 90, 0),      joints_deg(-30, -100, 80, 45, 100, 45),
          joints_deg(45, -60, 110, -120, 60, 180), joints_deg(-45, -110, 70, 120, -60, -135),
          joints_deg(20, -70, 60, 180, 90, 90),    joints_deg(-20, -95, 120, -45, -100, 30),
          joints_deg(0, -80, 100, 90, 90, 90),     joints_deg(10, -90, 90, 0, 45, 0)};
}

struct SimulatedSession {
  test_support::FrameScene scene;
  FrameCalibrationInput input;
};

// A session through the mounting poses; with `slip`, the IMS mount changes by `slip` (applied
// as T_H_S * slip) 0.2 s before the end of rest 10, inside its trimmed tail.
void simulate_session(SimulatedSession& s, const std::optional<Eigen::Isometry3d>& slip) {
  const fs::path root(IMSCAL_SOURCE_DIR);
  const RobotDescription robot = load_robot_description(root / "datasets/robots/kr16.yaml");
  const ims::SensorSpec spec =
      ims::load_sensor_spec(root / "datasets/sensors/navigation-grade.yaml");
  auto& scene = s.scene;
  scene.kinematics = robot.kinematics;
  scene.T_W_R = calib::pose_from_xyz_rpy(Eigen::Vector3d(2.0, 1.0, 0.0),
                                         Eigen::Vector3d(0.0, 0.0, 30.0 * kRadPerDeg));
  scene.T_H_S = robot.tool.T_H_T * pose(Eigen::Vector3d(0.3, -0.2, 0.5) * kRadPerDeg,
                                        Eigen::Vector3d(1.5, -0.8, 0.4) * 1e-3);
  test_support::make_kinematic_motion(scene, mounting_poses(), 6.0, 3.0);
  test_support::synthesize_scene_imu(scene);
  if (slip) {
    test_support::FrameScene moved = scene;
    moved.T_H_S = scene.T_H_S * *slip;
    test_support::synthesize_scene_imu(moved);
    const double t_slip = scene.rest_end_s[9] - 0.2 + scene.clock_offset_s;
    for (std::size_t k = 0; k < scene.imu.samples.size(); ++k)
      if (scene.imu.samples[k].t_s > t_slip) scene.imu.samples[k] = moved.imu.samples[k];
  }
  test_support::corrupt_scene_imu(scene, spec, 11);
  s.input = test_support::frame_input(scene, imu_noise_model(spec, {}));
  s.input.imu = &s.scene.imu;
  // The robot's own log gives the initial time offset in the command; here the truth (the
  // bundle estimates it; its automatic initialisation is the bundle's test).
  s.input.time_offset_initial_s = scene.clock_offset_s;
}

TEST(MountingValidation, CleanSessionPassesAndSlippedMountIsLocated) {
  MountingValidationOptions options;  // halves, segments of 5 rests, default thresholds
  // 12 bundle solves take ~10 s in Release; under the sanitizers (IMSCAL_SANITIZED, 5-10x
  // slower) the clean session checks its halves only (3 solves instead of 6).
  const bool sanitized = std::getenv("IMSCAL_SANITIZED") != nullptr;
  {
    SimulatedSession clean;
    simulate_session(clean, std::nullopt);
    const FrameCalibrationResult combined = calibrate_frames(clean.input);
    MountingValidationOptions clean_options = options;
    clean_options.check_segments = !sanitized;
    const MountingValidation v = validate_mounting(clean.input, {}, combined, clean_options);
    for (const auto& c : v.checks)
      std::printf("clean  %-12s %-4s %s\n", c.name.c_str(), to_string(c.level), c.message.c_str());
    ASSERT_EQ(v.halves.size(), 2u);
    ASSERT_TRUE(v.halves_difference.has_value());
    // The halves see the same mount: their difference is noise, within the 3-sigma warn level
    // (max over 6 components: ~1.6 % chance above 3 sigma for an honest covariance; fixed seed).
    EXPECT_LT(v.halves_difference->normalised, options.thresholds.repeat_warn_sigma);
    ASSERT_EQ(v.segments.size(), sanitized ? 0u : 3u);
    for (const auto& c : v.segment_comparisons) EXPECT_FALSE(c.slipped);
    EXPECT_EQ(v.verdict, Verdict::kPass);
  }
  {
    // 0.05 deg about x_S and 0.3 mm: a knock on the adapter plate; 25x / 15x the floors.
    SimulatedSession slipped;
    simulate_session(slipped,
                     pose(Eigen::Vector3d(0.05 * kRadPerDeg, 0, 0), Eigen::Vector3d(0, 0.3e-3, 0)));
    const FrameCalibrationResult combined = calibrate_frames(slipped.input);
    const MountingValidation v = validate_mounting(slipped.input, {}, combined, options);
    for (const auto& c : v.checks)
      std::printf("slip   %-12s %-4s %s\n", c.name.c_str(), to_string(c.level), c.message.c_str());
    EXPECT_EQ(v.verdict, Verdict::kFail);
    ASSERT_EQ(v.segment_comparisons.size(), 2u);
    EXPECT_FALSE(v.segment_comparisons[0].slipped);  // rests 1-5 vs 6-10: same mount
    EXPECT_TRUE(v.segment_comparisons[1].slipped);   // rests 6-10 vs 11-14
    // The located difference is the slip: 0.05 deg within 20 % (each segment's estimate has
    // ~0.001 deg noise, and the combined rests of a segment do not see every axis equally).
    EXPECT_NEAR(v.segment_comparisons[1].difference.rotation_rad, 0.05 * kRadPerDeg,
                0.01 * kRadPerDeg);
    bool named = false;
    for (const auto& r : v.reasons)
      named |= r.find("mount slipped between rest 10 and rest 11") != std::string::npos;
    EXPECT_TRUE(named);
  }
}

TEST(MountingValidation, PartsMountIsThatOfTheBundleWithTheClockOffsetWindows) {
  // A half or segment is calibrated without the robot joint series (calibrate_part): the rate
  // windows carry the clock offset and the link share only, so the part's T_S_H is the one the
  // bundle with them finds, up to where the solver stops (its relative tolerance is on the total
  // cost, to which the windows add). Tolerance: 1 % of the combined sigma, 300x below the
  // 3-sigma warn level of the checks that use the parts.
  SimulatedSession s;
  simulate_session(s, std::nullopt);
  const std::size_t first = 0, last = 6;
  FrameCalibrationInput with_windows = s.input;
  with_windows.rests.assign(s.input.rests.begin() + first, s.input.rests.begin() + last + 1);
  ASSERT_FALSE(with_windows.robot.t_robot_s.empty());
  const FrameCalibrationResult bundle = calibrate_frames(with_windows);
  ASSERT_TRUE(bundle.converged);
  EXPECT_NO_THROW((void)bundle.parameter_index("time_offset"));  // the windows were there
  const SessionPart part = calibrate_part(s.input, {}, first, last, "first 7 rests");
  ASSERT_TRUE(part.calibrated) << part.failure;
  const MountingDifference d = compare_mountings(mounting_estimate(bundle), part.estimate);
  std::printf("part without windows vs bundle with them: %.3g sigma (%.3g deg, %.3g mm)\n",
              d.normalised, d.rotation_rad * kDegPerRad, d.translation_m * 1e3);
  EXPECT_LT(d.normalised, 0.01);
}

}  // namespace
}  // namespace imscal::calib
