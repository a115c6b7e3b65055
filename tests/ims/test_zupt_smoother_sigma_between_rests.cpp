// The smoother's position 1-sigma against the exact truth in the standstills the chain cannot use
// as rests, right after fast moves: a robot-like program (a 10 s rest, fast moves of 0.6-0.8 m and
// 1.2-1.5 rad in 1.5 s, 2 s standstills in which only the encoders' creep velocity aids the
// smoother, a slow move home, an end rest) through the navigation-grade sensor model, the unit's
// scale factors and misalignments removed by its calibration sheet as in the chain, over many
// noise draws. What the smoother states there must be what it makes: RMS(error / sigma) near 1.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <utility>
#include <vector>

#include "ims/analytic_trajectory.hpp"
#include "ims/coarse_alignment.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/so3.hpp"
#include "ims/zupt_smoother.hpp"

namespace ims = imscal::ims;
using Eigen::Quaterniond;
using Eigen::Vector3d;
using Vector9d = Eigen::Matrix<double, 9, 1>;

namespace {

const ims::Site kSite{48.78, 9.18, 300.0};
constexpr double kRateHz = 1000.0;
constexpr double kDuration_s = 26.0;
// The two standstills after the fast moves (begin, end) [s]; the encoders' creep velocity aids
// from settle_s = 1 s after the stop (calib/encoder_motion.hpp), with its 1e-5 m/s floor.
constexpr std::pair<double, double> kUnusedRests_s[] = {{12.7, 14.7}, {17.7, 19.7}};
constexpr double kCreepSettle_s = 1.0;
constexpr double kCreepSigma_m_s = 1e-5;
constexpr double kRobotCycle_s = 0.002;

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

const ims::SensorSpec kSpec =
    ims::load_sensor_spec(IMSCAL_SOURCE_DIR "/datasets/sensors/navigation-grade.yaml");

// Rests 0-10 s and 23.7-26 s; moves as datasets' gap-chain-mixed-program.yaml orders them.
ims::AnalyticTrajectory robot_like_program(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto axis = [&] { return Vector3d(u(rng), u(rng), u(rng)).normalized(); };
  const auto along = [&](double m) {
    return Vector3d(m * Vector3d(u(rng), u(rng), 0.3 * u(rng)).normalized());
  };
  ims::AnalyticTrajectory motion(0.0, kDuration_s);
  motion.add_rotation(10.0, 11.5, axis(), 1.2);  // out fast: peak ~2 rad/s, ~3 m/s^2
  motion.add_translation(10.0, 11.5, along(0.6));
  motion.add_translation(11.5, 12.7, along(0.3));   // a line
  motion.add_translation(14.7, 16.2, along(0.33));  // back
  motion.add_rotation(16.2, 17.7, axis(), 1.5);     // cross fast: peak 2.5 rad/s, 3.3 m/s^2
  motion.add_translation(16.2, 17.7, along(0.8));
  motion.add_rotation(19.7, 23.7, axis(), 0.8);  // home slow
  motion.add_translation(19.7, 23.7, along(0.6));
  return motion;
}

// Sums of (error / sigma)^2 of the position per axis of W over the unused standstills.
struct NormalisedSums {
  Vector3d squared = Vector3d::Zero();
  double samples = 0.0;
  Vector3d rms() const { return (squared / samples).cwiseSqrt(); }
};

// One noise draw; `stated_vrw_scale` multiplies the accelerometer noise density the smoother is
// told (1: the data sheet's, as the chain does).
void add_draw(unsigned seed, double stated_vrw_scale, NormalisedSums& sums) {
  const ims::EarthModel earth(kSite);
  std::mt19937_64 rng(seed);
  const ims::AnalyticTrajectory motion = robot_like_program(rng);
  const ims::SensorErrorModel errors = ims::draw_sensor_errors(kSpec, rng);
  const ims::ImuSeries raw =
      ims::corrupt(ims::synthesize_ideal_increments(motion, earth, kRateHz), errors, kSpec, seed);
  ims::SensorErrorModel sheet = errors;  // the lab's sheet: biases are left to the chain
  sheet.gyro.bias.setZero();
  sheet.acc.bias.setZero();
  const ims::ImuSeries imu = ims::correct(raw, sheet);

  // Roll and pitch from the first rest, heading from the truth (in the chain a common heading
  // of W cancels against the robot base), position at the truth: what the chain starts from.
  const ims::KinematicState truth0 = motion.at(0.0);
  const ims::AttitudeAngles aligned =
      ims::align_at_rest(imu, ims::samples_in_interval(imu, 0.0, 9.9), earth).angles;
  ims::NavState initial;
  initial.p_W = truth0.p_W;
  initial.q_W_S = Quaterniond(
      ims::R_W_S_from_angles(aligned.roll_rad, aligned.pitch_rad,
                             ims::attitude_angles(truth0.q_W_S.toRotationMatrix()).yaw_rad));
  const double level_sigma = 3.0 * kSpec.acc.turn_on_bias_sigma / 9.81;  // bias-limited
  Vector9d sigma0;
  sigma0 << level_sigma, level_sigma, 1e-6, Vector3d::Constant(1e-6), Vector3d::Constant(1e-6);
  ims::ZuptOptions options = ims::zupt_options_from_spec(kSpec);
  options.acc_noise_density_m_s_per_sqrt_s *= stated_vrw_scale;
  ims::SmootherAids aids;
  aids.still = std::vector<ims::TimeInterval>{{0.0, 10.0}, {23.7, kDuration_s}};
  for (const auto& [begin, end] : kUnusedRests_s)
    for (double t = begin + kCreepSettle_s; t <= end; t += kRobotCycle_s)
      aids.velocity.push_back({t, Vector3d::Zero(), kCreepSigma_m_s});
  const auto result = ims::smooth_with_zupt(imu, earth, initial, sigma0, options, aids);

  for (const ims::SmoothedState& s : result.states) {
    const double t = s.state.t_s;
    bool unused_rest = false;
    for (const auto& [begin, end] : kUnusedRests_s) unused_rest |= (t > begin && t < end);
    if (!unused_rest) continue;
    const Vector3d error = motion.at(t).p_W - s.state.p_W;
    sums.squared += error.cwiseQuotient(s.sigma.tail<3>()).cwiseAbs2();
    sums.samples += 1.0;
  }
}

NormalisedSums pooled_over_draws(unsigned draws, double stated_vrw_scale) {
  NormalisedSums sums;
  for (unsigned seed = 101; seed < 101 + draws; ++seed) add_draw(seed, stated_vrw_scale, sums);
  const Vector3d rms = sums.rms();
  std::printf(
      "%u draws, stated VRW x%.1f: RMS(position error / sigma) %.2f %.2f %.2f (pooled %.2f)\n",
      draws, stated_vrw_scale, rms.x(), rms.y(), rms.z(), std::sqrt(rms.squaredNorm() / 3.0));
  return sums;
}

// The data-sheet model is honest there (measured over seeds 101..140: 0.94 0.97 1.14, pooled
// 1.02; docs/decisions/0076). Tolerance: in one 2 s standstill the position moves by <= 20 um
// (the creep velocity held to 1e-5 m/s) against ~60 um of error per axis, so each standstill
// gives about one independent value per axis: 80 per axis, 240 pooled; the RMS of n unit
// normals has a relative spread of 1/sqrt(2 n), 8 % and 4.6 %. Bounds at ~3.5 of those spreads
// (the two standstills of one draw share part of their error): pooled 0.85..1.15, per axis
// 0.7..1.3.
TEST(ZuptSmootherSigma, PositionInUnusedStandstillsAfterFastMovesIsHonest) {
  const unsigned draws = sanitized() ? 4u : 40u;
  const Vector3d rms = pooled_over_draws(draws, 1.0).rms();
  const double pooled = std::sqrt(rms.squaredNorm() / 3.0);
  if (sanitized()) {  // 24 values: only a gross error shows
    EXPECT_GT(pooled, 0.5);
    EXPECT_LT(pooled, 2.0);
    return;
  }
  EXPECT_GT(pooled, 0.85);
  EXPECT_LT(pooled, 1.15);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(rms[i], 0.7) << i;
    EXPECT_LT(rms[i], 1.3) << i;
  }
}

// The same figure finds a smoother that is wrong by a factor of 2 in its dominating noise (the
// accelerometer's white noise here; over 20 draws, with half of it stated, measured pooled 1.57,
// with twice 0.49): the check above can fail, in both directions.
TEST(ZuptSmootherSigma, FigureFindsAMisstatedNoiseModel) {
  if (sanitized()) GTEST_SKIP() << "Release-only: 20 draws twice";
  const auto pooled = [](const NormalisedSums& sums) {
    return std::sqrt(sums.rms().squaredNorm() / 3.0);
  };
  EXPECT_GT(pooled(pooled_over_draws(20, 0.5)), 1.4);
  EXPECT_LT(pooled(pooled_over_draws(20, 2.0)), 0.7);
}

}  // namespace
