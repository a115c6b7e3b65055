// Coarse alignment at rest on synthetic static records built in closed form: a known attitude
// R_W_S, gyros reading omega_S = R_S_W omega_ie_W and accelerometers f_S = -R_S_W g_W (Earth
// rate and gravity from the EarthModel), optionally with white noise or a disturbance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>
#include <vector>

#include "core/units.hpp"
#include "ims/coarse_alignment.hpp"
#include "ims/so3.hpp"

namespace imscal::ims {
namespace {

const Site kSite{48.78, 9.18, 300.0};  // Stuttgart: horizontal Earth rate 9.9 deg/h

struct Noise {
  double gyro_rad_per_sqrt_s = 0.0;  // angle random walk
  double acc_m_s_per_sqrt_s = 0.0;   // velocity random walk
};

ImuSeries static_record(const EarthModel& earth, const Eigen::Matrix3d& R_W_S, double rate_hz,
                        double duration_s, ImuQuantity quantity, const Noise& noise = {},
                        std::mt19937_64* rng = nullptr) {
  const double dt = 1.0 / rate_hz;
  const Eigen::Vector3d omega_S = R_W_S.transpose() * earth.earth_rate_W();
  const Eigen::Vector3d f_S = -(R_W_S.transpose() * earth.gravity_origin_W());
  ImuSeries series;
  series.quantity = quantity;
  series.nominal_dt_s = dt;
  series.site = earth.site();
  const auto n = static_cast<std::size_t>(std::llround(duration_s * rate_hz));
  std::normal_distribution<double> normal;
  const double gyro_sigma = noise.gyro_rad_per_sqrt_s * std::sqrt(dt);
  const double acc_sigma = noise.acc_m_s_per_sqrt_s * std::sqrt(dt);
  series.samples.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    ImuSample& s = series.samples[k];
    s.t_s = 10.0 + static_cast<double>(k + 1) * dt;
    s.gyro = omega_S * dt;
    s.acc = f_S * dt;
    if (rng) {
      for (int a = 0; a < 3; ++a) {
        s.gyro[a] += gyro_sigma * normal(*rng);
        s.acc[a] += acc_sigma * normal(*rng);
      }
    }
    if (quantity == ImuQuantity::kRates) {
      s.gyro /= dt;
      s.acc /= dt;
    }
  }
  return series;
}

double wrapped(double a) {
  return std::remainder(a, 2 * M_PI);
}

TEST(AttitudeAngles, ConventionsOfTheAngles) {
  // Y axis pointing East (PSINS yaw -90 deg): heading 90 deg clockwise from North.
  const AttitudeAngles east = attitude_angles(R_W_S_from_angles(0.0, 0.0, -90.0 * kRadPerDeg));
  EXPECT_NEAR(east.heading_rad, 90.0 * kRadPerDeg, 1e-12);  // exact up to rounding
  EXPECT_NEAR(east.yaw_rad, -90.0 * kRadPerDeg, 1e-12);
  // Nose up: +Y above the horizontal gives positive pitch.
  const Eigen::Matrix3d up = R_W_S_from_angles(0.0, 10.0 * kRadPerDeg, 0.0);
  EXPECT_GT(up.col(1).z(), 0.0);
  // Positive roll puts the X (right) axis below the horizontal.
  const Eigen::Matrix3d rolled = R_W_S_from_angles(10.0 * kRadPerDeg, 0.0, 0.0);
  EXPECT_LT(rolled.col(0).z(), 0.0);
  // Round trip through the angles.
  const AttitudeAngles a = attitude_angles(R_W_S_from_angles(0.1, -0.2, 2.5));
  EXPECT_NEAR(a.roll_rad, 0.1, 1e-12);
  EXPECT_NEAR(a.pitch_rad, -0.2, 1e-12);
  EXPECT_NEAR(a.yaw_rad, 2.5, 1e-12);
  EXPECT_NEAR(a.heading_rad, 2 * M_PI - 2.5, 1e-12);
}

TEST(CoarseAlignment, NoiseFreeStaticRecordGivesTheTrueAttitude) {
  const EarthModel earth(kSite);
  const double attitudes_deg[][3] = {{0.0, 0.0, 0.0},
                                     {2.0, -3.0, 37.0},
                                     {-5.0, 4.0, -120.0},
                                     {1.0, 1.0, 179.5},
                                     {0.3, -0.2, -0.4}};
  for (const auto& att : attitudes_deg) {
    for (ImuQuantity quantity : {ImuQuantity::kIncrements, ImuQuantity::kRates}) {
      const Eigen::Matrix3d R =
          R_W_S_from_angles(att[0] * kRadPerDeg, att[1] * kRadPerDeg, att[2] * kRadPerDeg);
      const ImuSeries series = static_record(earth, R, 100.0, 120.0, quantity);
      const CoarseAlignment a = align_at_rest(series, SampleRange{0, series.samples.size()}, earth);
      // The model is exact for a static record; what remains is the first-order rotation
      // compensation of each sample (~(Omega dt)^2 ~ 5e-13) and the block averaging of the
      // Earth rotation (~(Omega T/16)^2/24 ~ 1e-8): 1e-7 rad (0.02 arcsec) holds both.
      EXPECT_LT(rotation_angle_between(a.q_W_S, Eigen::Quaterniond(R)), 1e-7)
          << att[0] << " " << att[1] << " " << att[2];
      EXPECT_NEAR(wrapped(a.angles.heading_rad + att[2] * kRadPerDeg), 0.0, 1e-7);
      EXPECT_NEAR(a.angles.roll_rad, att[0] * kRadPerDeg, 1e-7);
      EXPECT_NEAR(a.angles.pitch_rad, att[1] * kRadPerDeg, 1e-7);
      // The horizontal Earth rate comes out of the data, not the model: 1e-6 relative.
      EXPECT_NEAR(a.earth_rate_horizontal_rad_s / a.expected_earth_rate_horizontal_rad_s, 1.0,
                  1e-6);
      // Block means of a vector turning at Omega shrink by ~(Omega T/16)^2/24 ~ 1e-8 relative.
      EXPECT_NEAR(a.specific_force_m_s2, a.expected_gravity_m_s2, 1e-7);
      EXPECT_EQ(a.blocks_rejected, 0);
      // t_ref is the sample nearest the middle of (10, 130] s.
      EXPECT_NEAR(a.t_ref_s, 70.0, 0.01 + 1e-9);
    }
  }
}

// The reported 1-sigma must match the scatter of the angles over independent noise draws.
void check_sigma_against_scatter(const Noise& noise, int draws, bool check_tilt) {
  const EarthModel earth(kSite);
  const Eigen::Matrix3d R =
      R_W_S_from_angles(1.5 * kRadPerDeg, -2.0 * kRadPerDeg, 63.0 * kRadPerDeg);
  const AttitudeAngles truth = attitude_angles(R);
  std::mt19937_64 rng(20261121);
  double sum_err[3] = {0, 0, 0}, sum_sq_err[3] = {0, 0, 0}, sum_var[3] = {0, 0, 0};
  for (int d = 0; d < draws; ++d) {
    const ImuSeries series =
        static_record(earth, R, 100.0, 120.0, ImuQuantity::kIncrements, noise, &rng);
    const CoarseAlignment a = align_at_rest(series, SampleRange{0, series.samples.size()}, earth);
    const double err[3] = {a.angles.roll_rad - truth.roll_rad, a.angles.pitch_rad - truth.pitch_rad,
                           wrapped(a.angles.heading_rad - truth.heading_rad)};
    const double sig[3] = {a.sigma_roll_rad, a.sigma_pitch_rad, a.sigma_heading_rad};
    for (int i = 0; i < 3; ++i) {
      sum_err[i] += err[i];
      sum_sq_err[i] += err[i] * err[i];
      sum_var[i] += sig[i] * sig[i];
    }
  }
  const char* names[3] = {"roll", "pitch", "heading"};
  for (int i = check_tilt ? 0 : 2; i < 3; ++i) {
    const double mean = sum_err[i] / draws;
    const double scatter = std::sqrt((sum_sq_err[i] - draws * mean * mean) / (draws - 1));
    const double reported = std::sqrt(sum_var[i] / draws);
    std::cout << names[i] << ": reported sigma / scatter over " << draws
              << " draws = " << reported / scatter << "\n";
    // Goal of the issue: the reported sigma within [0.7, 1.4] of the observed scatter. (The
    // scatter of 200 draws is itself known to ~5 %, of 80 draws to ~8 %.)
    EXPECT_GT(reported / scatter, 0.7)
        << names[i] << " scatter " << scatter << " reported " << reported;
    EXPECT_LT(reported / scatter, 1.4)
        << names[i] << " scatter " << scatter << " reported " << reported;
    // No bias: the mean error is within 4 standard errors of zero.
    EXPECT_LT(std::abs(mean), 4.0 * scatter / std::sqrt(draws)) << names[i];
  }
}

int draw_count() {
  // Under ASan/UBSan (IMSCAL_SANITIZED set) 80 draws keep the run short; the scatter is then
  // known to ~8 % instead of ~5 %, still well inside the [0.7, 1.4] band.
  return std::getenv("IMSCAL_SANITIZED") ? 80 : 200;
}

TEST(CoarseAlignment, SigmaMatchesScatterWithGyroNoise) {
  // Navigation-grade RLG angle random walk 0.006 deg/sqrt(h) (1.8e-6 rad/sqrt(s)): heading
  // sigma ~0.2 deg over 120 s; tilt noise then comes from the gyro random walk alone.
  check_sigma_against_scatter(Noise{1.8e-6, 0.0}, draw_count(), true);
}

TEST(CoarseAlignment, SigmaMatchesScatterWithAccelerometerNoise) {
  // Accelerometer white noise 100 ug/sqrt(Hz) (1e-3 m/s/sqrt(s)) with near-perfect gyros.
  check_sigma_against_scatter(Noise{1e-9, 1e-3}, draw_count(), true);
}

TEST(CoarseAlignment, SigmaMatchesScatterWithBothNoises) {
  check_sigma_against_scatter(Noise{1.8e-6, 1e-3}, draw_count(), true);
}

// A disturbance: the sensor tilts by 2 mrad (and stays there) and is pushed 2 cm back and forth.
// Rotations are tracked by the gyros and the push averages out, so the alignment must still give
// the attitude at t_ref, whereas plain means of rate and specific force miss the heading by
// degrees.
TEST(CoarseAlignment, RobustToATiltStepAndAPush) {
  const EarthModel earth(kSite);
  const Eigen::Matrix3d R0 =
      R_W_S_from_angles(0.5 * kRadPerDeg, 1.0 * kRadPerDeg, -90.0 * kRadPerDeg);
  const Eigen::Vector3d tilt_axis_S = Eigen::Vector3d(1.0, 0.3, 0.0).normalized();
  const double tilt_rad = 2e-3, tilt_start = 30.0, tilt_length = 2.0;
  const double push_m = 0.02, push_start = 80.0, push_length = 1.0;
  const Eigen::Vector3d push_dir_W(0.6, 0.8, 0.0);
  // Tilt angle (smooth cosine ramp) and its rate.
  auto tilt = [&](double t) {
    if (t <= tilt_start) return 0.0;
    if (t >= tilt_start + tilt_length) return tilt_rad;
    return 0.5 * tilt_rad * (1 - std::cos(M_PI * (t - tilt_start) / tilt_length));
  };
  auto tilt_rate = [&](double t) {
    if (t <= tilt_start || t >= tilt_start + tilt_length) return 0.0;
    return 0.5 * tilt_rad * M_PI / tilt_length * std::sin(M_PI * (t - tilt_start) / tilt_length);
  };
  auto R_W_S = [&](double t) {
    return Eigen::Matrix3d(R0 * Eigen::AngleAxisd(tilt(t), tilt_axis_S));
  };
  // Push: x = d sin^2(pi u), u in [0, 1]: starts and ends at rest.
  auto push_velocity = [&](double t) {
    if (t <= push_start || t >= push_start + push_length) return 0.0;
    return push_m * M_PI / push_length * std::sin(2 * M_PI * (t - push_start) / push_length);
  };
  auto push_acceleration = [&](double t) {
    if (t <= push_start || t >= push_start + push_length) return 0.0;
    return 2 * push_m * M_PI * M_PI / (push_length * push_length) *
           std::cos(2 * M_PI * (t - push_start) / push_length);
  };
  const double rate_hz = 100.0, dt = 1.0 / rate_hz, duration = 120.0;
  const int substeps = 10;  // midpoint sums: rounding far below the check tolerance below
  ImuSeries series;
  series.quantity = ImuQuantity::kIncrements;
  series.nominal_dt_s = dt;
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero(), mean_force = Eigen::Vector3d::Zero();
  const auto n = static_cast<std::size_t>(duration * rate_hz);
  for (std::size_t k = 0; k < n; ++k) {
    ImuSample s;
    s.t_s = static_cast<double>(k + 1) * dt;
    Eigen::Quaterniond q_start_S = Eigen::Quaterniond::Identity();  // S at the sample start
    for (int j = 0; j < substeps; ++j) {
      const double h = dt / substeps;
      const double t = s.t_s - dt + (j + 0.5) * h;
      const Eigen::Matrix3d R = R_W_S(t);
      const Eigen::Vector3d omega_S =
          R.transpose() * earth.earth_rate_W() + tilt_rate(t) * tilt_axis_S;
      // Specific force in the rotating W: a + 2 omega_ie x v - g.
      const Eigen::Vector3d v_W = push_velocity(t) * push_dir_W;
      const Eigen::Vector3d f_W = push_acceleration(t) * push_dir_W +
                                  2.0 * earth.earth_rate_W().cross(v_W) - earth.gravity_origin_W();
      const Eigen::Vector3d dtheta = omega_S * h;
      const Eigen::Quaterniond q_mid = q_start_S * quat_exp(Eigen::Vector3d(0.5 * dtheta));
      s.acc += q_mid * (R.transpose() * f_W) * h;  // velocity increment in S at the sample start
      q_start_S = q_start_S * quat_exp(dtheta);
      s.gyro += dtheta;
    }
    series.samples.push_back(s);
    mean_rate += s.gyro / duration;
    mean_force += s.acc / duration;
  }
  const CoarseAlignment a = align_at_rest(series, SampleRange{0, n}, earth);
  const Eigen::Matrix3d truth = R_W_S(a.t_ref_s);
  // Remaining error: the sum of small-angle increments over the 2 s tilt ramp (coning of a
  // single-axis ramp is zero; the Earth rate adds ~Omega * tilt * dt ~ 1e-9) and the
  // sub-sample integration of the push: 1e-4 rad (0.006 deg) is ample and far below the
  // several-degree error of plain means checked below.
  EXPECT_LT(rotation_angle_between(a.q_W_S, Eigen::Quaterniond(truth)), 1e-4);
  const AttitudeAngles true_angles = attitude_angles(truth);
  EXPECT_NEAR(wrapped(a.angles.heading_rad - true_angles.heading_rad), 0.0, 1e-4);

  // The same disturbance is fatal for plain means (TRIAD of mean f and mean omega), which is
  // what makes this test meaningful: the heading is off by more than 1 deg.
  const Eigen::Vector3d up = mean_force.normalized();
  Eigen::Vector3d north = mean_rate - mean_rate.dot(up) * up;
  north.normalize();
  Eigen::Matrix3d R_S_W;
  R_S_W << north.cross(up), north, up;
  const AttitudeAngles plain = attitude_angles(R_S_W.transpose());
  EXPECT_GT(std::abs(wrapped(plain.heading_rad - true_angles.heading_rad)), 1.0 * kRadPerDeg);
}

TEST(CoarseAlignment, RejectsTooShortIntervalsAndPolarSites) {
  const EarthModel earth(kSite);
  const ImuSeries series =
      static_record(earth, Eigen::Matrix3d::Identity(), 100.0, 0.5, ImuQuantity::kIncrements);
  EXPECT_THROW(align_at_rest(series, SampleRange{0, series.samples.size()}, earth),
               std::invalid_argument);
  const EarthModel pole(Site{89.5, 0.0, 0.0});
  const ImuSeries polar =
      static_record(pole, Eigen::Matrix3d::Identity(), 100.0, 10.0, ImuQuantity::kIncrements);
  EXPECT_THROW(align_at_rest(polar, SampleRange{0, polar.samples.size()}, pole),
               std::invalid_argument);
}

TEST(CoarseAlignment, WindowsCoverTheIntervalDisjointly) {
  const EarthModel earth(kSite);
  const Eigen::Matrix3d R = R_W_S_from_angles(0.0, 0.0, 0.7);
  const ImuSeries series = static_record(earth, R, 50.0, 100.0, ImuQuantity::kIncrements);
  const auto windows = align_windows(series, SampleRange{0, series.samples.size()}, 30.0, earth);
  ASSERT_EQ(windows.size(), 3u);  // 100 s hold three 30 s windows
  for (std::size_t j = 0; j < windows.size(); ++j) {
    EXPECT_EQ(windows[j].sample_count, 1500u);  // 30 s at 50 Hz
    EXPECT_EQ(windows[j].first_sample, 1500u * j);
    EXPECT_NEAR(windows[j].start_s, 10.0 + 30.0 * j, 1e-9);
    EXPECT_LT(rotation_angle_between(windows[j].q_W_S, Eigen::Quaterniond(R)), 1e-7);
  }
  const AngleSpread heading = angle_spread(windows, AngleKind::kHeading);
  EXPECT_LT(heading.std_rad, 1e-7);  // identical noise-free windows
}

}  // namespace
}  // namespace imscal::ims
