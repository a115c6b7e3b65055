// Rest detection against known truth: hand-built static records (closed form: Earth rate and
// gravity in S plus white noise of the stated level), a constant rotation about the vertical
// that no variance test can see, and the random robot motion with pauses of
// ims/analytic_trajectory.hpp whose exact rest intervals are known.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "ims/analytic_trajectory.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/rest_detector.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/so3.hpp"

namespace ims = imscal::ims;
using Eigen::Vector3d;

namespace {

const ims::Site kSite{48.78, 9.18, 300.0};
constexpr double kRateHz = 1000.0;

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

// A sensor turning at `rate_W` [rad/s] (relative to W) about a fixed W axis through its origin,
// otherwise at rest: exact increments plus white noise of the given densities.
ims::ImuSeries rotating_record(const ims::EarthModel& earth, double duration_s,
                               const Vector3d& rate_W, double gyro_density, double acc_density,
                               unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const double dt = 1.0 / kRateHz;
  const Eigen::Quaterniond q0 = ims::quat_exp(Vector3d(0.2, -0.1, 0.7));
  ims::ImuSeries series;
  series.nominal_dt_s = dt;
  const int n = int(std::lround(duration_s * kRateHz));
  const Vector3d g_W = earth.gravity_origin_W();
  for (int k = 1; k <= n; ++k) {
    // Mid-interval attitude: for a constant rate the increments below are exact to O(dt^3).
    const Eigen::Quaterniond q_mid = ims::quat_exp(Vector3d(rate_W * (k - 0.5) * dt)) * q0;
    const Eigen::Matrix3d R_S_W = q_mid.toRotationMatrix().transpose();
    ims::ImuSample s;
    s.t_s = k * dt;
    s.gyro = R_S_W * (rate_W + earth.earth_rate_W()) * dt;
    s.acc = -R_S_W * g_W * dt;  // at rest (on the axis: no centripetal term): f = -g
    for (int i = 0; i < 3; ++i) {
      s.gyro[i] += gyro_density * std::sqrt(dt) * normal(rng);
      s.acc[i] += acc_density * std::sqrt(dt) * normal(rng);
    }
    series.samples.push_back(s);
  }
  return series;
}

ims::RestDetectorOptions options_for(double gyro_density, double acc_density) {
  ims::RestDetectorOptions o;
  o.gyro_noise_density_rad_per_sqrt_s = gyro_density;
  o.acc_noise_density_m_s_per_sqrt_s = acc_density;
  return o;
}

// The navigation-grade data sheet shipped with the project.
const ims::SensorSpec kSpec =
    ims::load_sensor_spec(IMSCAL_SOURCE_DIR "/datasets/sensors/navigation-grade.yaml");

TEST(RestDetector, StaticRecordIsOneRest) {
  const ims::EarthModel earth(kSite);
  const auto series = rotating_record(earth, 5.0, Vector3d::Zero(), kSpec.gyro.white_noise_density,
                                      kSpec.acc.white_noise_density, 1);
  const auto detection = ims::detect_rest(
      series, earth, options_for(kSpec.gyro.white_noise_density, kSpec.acc.white_noise_density));
  // The threshold is 5 sigma of the chi-square statistic (false alarm ~1e-6 per window), and a
  // sample is at rest as soon as one window holding it passes: the whole record must be one rest.
  ASSERT_EQ(detection.intervals.size(), 1u);
  EXPECT_EQ(detection.intervals[0].first_sample, 0u);
  EXPECT_EQ(detection.intervals[0].last_sample, series.samples.size() - 1);
}

TEST(RestDetector, NoiseAboveTheStatedLevelIsNotRest) {
  const ims::EarthModel earth(kSite);
  // Twice the stated noise: the scatter statistic is 4x its rest mean, far above 5 sigma.
  const auto series =
      rotating_record(earth, 2.0, Vector3d::Zero(), 2.0 * kSpec.gyro.white_noise_density,
                      2.0 * kSpec.acc.white_noise_density, 2);
  const auto detection = ims::detect_rest(
      series, earth, options_for(kSpec.gyro.white_noise_density, kSpec.acc.white_noise_density));
  EXPECT_TRUE(detection.intervals.empty());
}

TEST(RestDetector, ConstantRotationAboutTheVerticalIsNotRest) {
  const ims::EarthModel earth(kSite);
  // 0.01 rad/s about Up: gyro and accelerometer outputs are constant in S (f stays along the
  // axis), so only the rate-magnitude test can tell; 0.01 rad/s is ~100x the Earth rate.
  const Vector3d up_W = earth.gravity_origin_W().normalized() * -1.0;
  const auto series = rotating_record(earth, 2.0, 0.01 * up_W, kSpec.gyro.white_noise_density,
                                      kSpec.acc.white_noise_density, 3);
  const auto detection = ims::detect_rest(
      series, earth, options_for(kSpec.gyro.white_noise_density, kSpec.acc.white_noise_density));
  EXPECT_TRUE(detection.intervals.empty());
}

// Random robot motions with pauses, navigation-grade noise (white, bias instability,
// quantisation, turn-on biases, scale factors, misalignments), against the exact rest
// intervals of the motion.
TEST(RestDetector, FindsThePausesOfRobotMotion) {
  const ims::EarthModel earth(kSite);
  const double duration_s = sanitized() ? 20.0 : 60.0;  // lighter under the sanitizers
  for (unsigned seed : {11u, 12u, 13u}) {
    SCOPED_TRACE(seed);
    const auto motion = ims::make_motion_with_pauses(duration_s, 5.0, seed);
    const auto ideal = ims::synthesize_ideal_increments(*motion, earth, kRateHz);
    std::mt19937_64 rng(seed);
    const auto errors = ims::draw_sensor_errors(kSpec, rng);
    const auto raw = ims::corrupt(ideal, errors, kSpec, seed);
    ims::RestDetectorOptions options =
        options_for(kSpec.gyro.white_noise_density, kSpec.acc.white_noise_density);
    options.gyro_quantization_lsb_rad = kSpec.gyro.quantization_lsb;
    options.acc_quantization_lsb_m_s = kSpec.acc.quantization_lsb;
    // Bias bounds: 5 sigma of the turn-on bias plus the scale-factor error on gravity/Earth rate.
    options.gyro_bias_bound_rad_s = 5.0 * kSpec.gyro.turn_on_bias_sigma;
    options.acc_bias_bound_m_s2 =
        5.0 * (kSpec.acc.turn_on_bias_sigma + kSpec.acc.scale_factor_sigma * 9.81);
    const auto detection = ims::detect_rest(raw, earth, options);

    // Truth per sample: at rest if the whole increment interval lies in a true rest interval.
    // A sample flagged as rest during motion is judged by how far the robot has moved from the
    // pose of the nearest true rest: that is what a zero-velocity update there can spoil.
    const auto true_rests = motion->rest_intervals();
    double true_rest_time = 0.0, detected_true_rest_time = 0.0;
    double worst_displacement_m = 0.0, worst_rotation_rad = 0.0;
    const double dt = 1.0 / kRateHz;
    for (std::size_t i = 0; i < raw.samples.size(); ++i) {
      const double t = raw.samples[i].t_s;
      bool truly_at_rest = false;
      double nearest_rest_time = 0.0, nearest_distance_s = 1e9;
      for (const auto& [b, e] : true_rests) {
        truly_at_rest |= (t - dt >= b && t <= e);
        for (double edge : {b, e}) {
          if (std::abs(t - edge) < nearest_distance_s) {
            nearest_distance_s = std::abs(t - edge);
            nearest_rest_time = edge;
          }
        }
      }
      if (truly_at_rest) {
        true_rest_time += dt;
        if (detection.at_rest[i]) detected_true_rest_time += dt;
      } else if (detection.at_rest[i]) {
        const auto state = motion->at(t);
        const auto rest_state = motion->at(nearest_rest_time);
        worst_displacement_m = std::max(worst_displacement_m, (state.p_W - rest_state.p_W).norm());
        worst_rotation_rad = std::max(worst_rotation_rad,
                                      ims::rotation_angle_between(state.q_W_S, rest_state.q_W_S));
      }
    }
    const double overlap = detected_true_rest_time / true_rest_time;
    std::printf(
        "seed %u: %zu true rests, %zu detected, overlap %.4f, worst false rest: "
        "displacement %.2e m, rotation %.2e rad\n",
        seed, true_rests.size(), detection.intervals.size(), overlap, worst_displacement_m,
        worst_rotation_rad);
    EXPECT_EQ(detection.intervals.size(), true_rests.size());
    // >= 95 % of the true rest time found (the brief's requirement).
    EXPECT_GE(overlap, 0.95);
    // No false rest during motion. The onsets and ends of the smooth steps (first four
    // derivatives zero) stay below the noise for ~0.1 s, so the detector cannot help flagging
    // some of them; what counts is that the robot has not moved by more than the smoother's
    // error budget allows there: 5 um (2.5 % of the 0.2 mm target) and 2e-5 rad (a quarter of
    // the 0.005 deg target).
    EXPECT_LT(worst_displacement_m, 5e-6);
    EXPECT_LT(worst_rotation_rad, 2e-5);
  }
}

// A part of a record read through ImuSamples (no copy) gives exactly what a copy of that part
// gives: the same rests, sample for sample (a copy's first sample has the nominal interval, as the
// view's has). 30 s at 1 kHz crosses the detector's blocks of windows (16384 samples) and of
// running sums (4096); the rests found are the motion's true pauses after the cut.
TEST(RestDetector, PartOfARecordReadsAsItsCopy) {
  const ims::EarthModel earth(kSite);
  const auto motion = ims::make_motion_with_pauses(30.0, 5.0, 21u);
  const auto raw = ims::synthesize_ideal_increments(*motion, earth, kRateHz);
  ims::RestDetectorOptions options =
      options_for(kSpec.gyro.white_noise_density, kSpec.acc.white_noise_density);
  options.gyro_bias_bound_rad_s = 5.0 * kSpec.gyro.turn_on_bias_sigma;
  options.acc_bias_bound_m_s2 = 5.0 * (kSpec.acc.turn_on_bias_sigma + 9.81e-4);
  const std::size_t first = 1234;
  ims::ImuSeries copy = raw;
  copy.samples.erase(copy.samples.begin(), copy.samples.begin() + std::ptrdiff_t(first));
  const auto from_copy = ims::detect_rest(copy, earth, options);
  const auto from_view = ims::detect_rest(ims::ImuSamples(raw, first), earth, options);
  std::size_t true_rests = 0;
  for (const auto& [begin_s, end_s] : motion->rest_intervals())
    true_rests += end_s > raw.samples[first].t_s ? 1 : 0;
  EXPECT_EQ(from_copy.intervals.size(), true_rests);
  EXPECT_EQ(from_view.at_rest, from_copy.at_rest);
  ASSERT_EQ(from_view.intervals.size(), from_copy.intervals.size());
  for (std::size_t i = 0; i < from_copy.intervals.size(); ++i) {
    EXPECT_EQ(from_view.intervals[i].first_sample, from_copy.intervals[i].first_sample);
    EXPECT_EQ(from_view.intervals[i].last_sample, from_copy.intervals[i].last_sample);
  }
}

}  // namespace
