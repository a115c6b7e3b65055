// Time offset between robot and IMS clocks (calib/time_offset.hpp) against simulated truth:
// a smooth random joint motion of the KR 16; the robot logs the joint angles (250 Hz, with
// encoder noise) on its clock, the IMS logs gyro rates or increments (1 kHz, with noise and the
// Earth rate) on a clock running `offset` ahead. The flange rate used for the truth is taken by
// differencing forward-kinematics rotations, independent of the Jacobian route under test.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>

#include "calib/time_offset.hpp"
#include "core/input_error.hpp"
#include "ims/imu_data.hpp"
#include "ims/so3.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"

using imscal::calib::JointVector;
using imscal::calib::RateMagnitudeSeries;

namespace {

const imscal::calib::KinematicModel& kr16() {
  static const imscal::calib::RobotDescription robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  return robot.kinematics;
}

// Under the sanitizers (5-10x slower) the records are shortened; 30 s still hold many motions.
double record_length_s() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr ? 30.0 : 60.0;
}

// q_j(t) = q0_j + sum_k a_jk sin(w_jk t + phi_jk): smooth, not periodic (random frequencies).
struct JointMotion {
  JointVector q0 = JointVector::Zero();
  std::vector<std::array<double, 3>> terms[6];  // {a [rad], w [rad/s], phi [rad]}

  JointVector q(double t) const {
    JointVector out = q0;
    for (int j = 0; j < 6; ++j) {
      for (const auto& c : terms[j]) out(j) += c[0] * std::sin(c[1] * t + c[2]);
    }
    return out;
  }
  // Bound of |q_j'''| summed over joints: sum a w^3 (for the central-difference error).
  double third_derivative_bound() const {
    double sum = 0.0;
    for (int j = 0; j < 6; ++j) {
      for (const auto& c : terms[j]) sum += c[0] * c[1] * c[1] * c[1];
    }
    return sum;
  }
};

JointMotion random_motion(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> amplitude(0.05, 0.3), frequency_hz(0.1, 0.8),
      phase(0.0, 2.0 * M_PI);
  JointMotion m;
  m.q0 << 0.3, -1.2, 1.9, 0.4, 0.8, -0.5;
  for (int j = 0; j < 6; ++j) {
    for (int k = 0; k < 3; ++k) {
      m.terms[j].push_back({amplitude(rng), 2.0 * M_PI * frequency_hz(rng), phase(rng)});
    }
  }
  return m;
}

// Flange rotation R_R_H at physical time t.
Eigen::Matrix3d R_R_H(const JointMotion& m, double t) {
  return imscal::calib::forward_kinematics<double>(kr16(), m.q(t)).linear();
}
// omega of H relative to R, in H [rad/s], by central differences of FK rotations over +-1e-5 s
// (truncation ~1e-10 relative, round-off ~1e-16/1e-5 = 1e-11 rad/s).
Eigen::Vector3d omega_H(const JointMotion& m, double t) {
  constexpr double kDelta = 1e-5;
  const Eigen::Matrix3d r = R_R_H(m, t - kDelta).transpose() * R_R_H(m, t + kDelta);
  return imscal::ims::quat_log(Eigen::Quaterniond(r).normalized()) / (2.0 * kDelta);
}

struct Records {
  std::vector<double> robot_t_s;
  std::vector<JointVector> robot_q;
  imscal::ims::ImuSeries imu;
  std::function<Eigen::Vector3d(double)> earth_rate_S;  // at IMS time
};

// Robot at 250 Hz over [0, T] physical = robot time; IMS at 1 kHz, stamps s in [0, T] with
// physical time s - offset. Noise: joint angles N(0, encoder_sigma), gyro N(0, gyro_sigma) per
// axis and sample (rate) or its integral over the interval (increments).
Records simulate(const JointMotion& m, double offset_s, double length_s,
                 imscal::ims::ImuQuantity quantity, double encoder_sigma_rad,
                 double gyro_sigma_rad_s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Records r;
  const double robot_dt = 0.004;
  for (int k = 0; k * robot_dt <= length_s; ++k) {
    const double t = k * robot_dt;
    JointVector q = m.q(t);
    for (int j = 0; j < 6; ++j) q(j) += encoder_sigma_rad * normal(rng);
    r.robot_t_s.push_back(t);
    r.robot_q.push_back(q);
  }
  // Fixed frames: sensor on the flange, robot base in W; Earth rate at 48 deg latitude.
  const Eigen::Matrix3d R_S_H =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d R_R_W = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const double lat = 48.0 * M_PI / 180.0;
  const Eigen::Vector3d earth_W = 7.292115e-5 * Eigen::Vector3d(0.0, std::cos(lat), std::sin(lat));
  auto earth_S_physical = [=, &m](double t) -> Eigen::Vector3d {
    return R_S_H * R_R_H(m, t).transpose() * R_R_W * earth_W;
  };
  auto gyro_rate = [&](double t) -> Eigen::Vector3d {
    return R_S_H * omega_H(m, t) + earth_S_physical(t);
  };
  const double ims_dt = 0.001;
  r.imu.quantity = quantity;
  r.imu.nominal_dt_s = ims_dt;
  r.imu.source = "simulated IMS";
  for (int k = 1; k * ims_dt <= length_s; ++k) {
    const double s = k * ims_dt;
    const double t = s - offset_s;
    imscal::ims::ImuSample sample;
    sample.t_s = s;
    const Eigen::Vector3d noise(normal(rng), normal(rng), normal(rng));
    if (quantity == imscal::ims::ImuQuantity::kRates) {
      sample.gyro = gyro_rate(t) + gyro_sigma_rad_s * noise;
    } else {
      // Increment over (s - dt, s]: Simpson's rule (error ~dt^5 w^4 |omega| ~1e-16 rad) plus the
      // integral of white rate noise.
      sample.gyro = (gyro_rate(t - ims_dt) + 4.0 * gyro_rate(t - 0.5 * ims_dt) + gyro_rate(t)) *
                        (ims_dt / 6.0) +
                    gyro_sigma_rad_s * ims_dt * noise;
    }
    r.imu.samples.push_back(sample);
  }
  r.earth_rate_S = [=](double s) { return earth_S_physical(s - offset_s); };
  return r;
}

TEST(TimeOffset, FlangeRateFromJointsMatchesFkDifferences) {
  const JointMotion m = random_motion(3);
  const Records r = simulate(m, 0.0, 10.0, imscal::ims::ImuQuantity::kRates, 0.0, 0.0, 1);
  const RateMagnitudeSeries rates =
      imscal::calib::flange_rate_magnitude(kr16(), r.robot_t_s, r.robot_q);
  ASSERT_EQ(rates.t_s.size(), r.robot_t_s.size() - 2);
  // Central differences err by at most h^2/6 |q'''| per joint; every column of the angular
  // Jacobian is a unit axis, so |omega error| <= sum_j h^2/6 |q_j'''| (h = 4 ms); plus 1e-9 for
  // the FK-difference truth.
  const double h = 0.004;
  const double bound = h * h / 6.0 * m.third_derivative_bound() + 1e-9;
  double max_error = 0.0;
  for (std::size_t k = 0; k < rates.t_s.size(); ++k) {
    const double truth = omega_H(m, rates.t_s[k]).norm();
    max_error = std::max(max_error, std::abs(rates.rate_rad_s[k] - truth));
  }
  EXPECT_LT(max_error, bound);
  EXPECT_GT(max_error, 0.0);
}

// The brief's case: 37.3 ms, noise on both sides, rates at 1 kHz. Encoder noise 1e-5 rad gives
// 1e-5 / (sqrt(2) * 4 ms) ~ 2e-3 rad/s noise on the robot's rate; gyro noise 2e-3 rad/s per
// sample (far above a ring-laser gyro: a robustness margin).
TEST(TimeOffset, RecoversKnownOffsetFromNoisyRates) {
  const double true_offset_s = 0.0373;
  const JointMotion m = random_motion(7);
  const Records r = simulate(m, true_offset_s, record_length_s(), imscal::ims::ImuQuantity::kRates,
                             1e-5, 2e-3, 2);
  const auto robot = imscal::calib::flange_rate_magnitude(kr16(), r.robot_t_s, r.robot_q);
  const auto ims = imscal::calib::ims_rate_magnitude(r.imu, r.earth_rate_S);
  const auto result = imscal::calib::estimate_time_offset(robot, ims);
  fmt::print(
      "offset {:.4f} ms (true {:.4f} ms, error {:+.4f} ms), peak {:.5f}, secondary {:.4f}, "
      "curvature {:.1f} 1/s^2, width {:.2f} ms\n",
      result.offset_s * 1e3, true_offset_s * 1e3, (result.offset_s - true_offset_s) * 1e3,
      result.peak_correlation, result.secondary_peak_correlation, result.peak_curvature_1_s2,
      result.peak_width_s * 1e3);
  // 0.2 ms: the brief's requirement (1/20 of the robot's 4 ms sample interval).
  EXPECT_NEAR(result.offset_s, true_offset_s, 0.2e-3);
  // The two magnitudes are the same signal up to noise: correlation close to 1.
  EXPECT_GT(result.peak_correlation, 0.95);
  EXPECT_GT(result.peak_correlation - result.secondary_peak_correlation, 0.05);
  EXPECT_GT(result.peak_curvature_1_s2, 0.0);
  EXPECT_LT(result.peak_width_s, 0.5);
  // Overlap: the record less the +-0.5 s range on both sides (and the first/last robot sample).
  EXPECT_NEAR(result.overlap_s, record_length_s() - 1.0, 0.01);
}

// Negative offset, IMS increments (stamped at the interval end: the midpoint stamping matters
// here, a 0.5 ms bias otherwise), Earth rate removed by a constant instead of the attitude.
TEST(TimeOffset, RecoversNegativeOffsetFromIncrements) {
  const double true_offset_s = -0.12345;
  const JointMotion m = random_motion(11);
  const Records r = simulate(m, true_offset_s, record_length_s(),
                             imscal::ims::ImuQuantity::kIncrements, 1e-5, 2e-3, 4);
  const auto robot = imscal::calib::flange_rate_magnitude(kr16(), r.robot_t_s, r.robot_q);
  // Earth rate 7.3e-5 rad/s is far below the motion rates; a constant (here its value at the
  // start) leaves at most 1.5e-4 rad/s error in |omega|, negligible for the correlation.
  const auto ims = imscal::calib::ims_rate_magnitude(r.imu, r.earth_rate_S(0.0));
  const auto result = imscal::calib::estimate_time_offset(robot, ims);
  fmt::print("offset {:.4f} ms (true {:.4f} ms, error {:+.4f} ms), peak {:.5f}\n",
             result.offset_s * 1e3, true_offset_s * 1e3, (result.offset_s - true_offset_s) * 1e3,
             result.peak_correlation);
  EXPECT_NEAR(result.offset_s, true_offset_s, 0.2e-3);  // the brief's 0.2 ms
}

// Simulates `motion` for `duration_s` and expects estimate_time_offset to refuse it with an
// InputError on `field` whose message contains `text`.
void expect_refused(const JointMotion& motion, double duration_s, double gyro_noise,
                    double robot_noise, const std::string& field, const std::string& text) {
  const Records r = simulate(motion, 0.02, duration_s, imscal::ims::ImuQuantity::kRates, gyro_noise,
                             robot_noise, 2);
  const auto robot = imscal::calib::flange_rate_magnitude(kr16(), r.robot_t_s, r.robot_q);
  const auto ims = imscal::calib::ims_rate_magnitude(r.imu, r.earth_rate_S);
  try {
    imscal::calib::estimate_time_offset(robot, ims);
    FAIL() << "expected a refusal on " << field;
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.field(), field);
    EXPECT_THAT(e.what(), testing::HasSubstr(text));
  }
}

TEST(TimeOffset, ShortOverlapIsRefused) {
  // 4 s - 2 x 0.5 s search range = 3 s of overlap < 5 s.
  expect_refused(random_motion(7), 4.0, 0.0, 0.0, "overlap", "at least 5.000 s");
}

TEST(TimeOffset, RobotAtRestIsRefused) {
  JointMotion still;  // no terms: the robot stands still
  still.q0 << 0.3, -1.2, 1.9, 0.4, 0.8, -0.5;
  expect_refused(still, 20.0, 1e-5, 2e-3, "motion", "too poor");
}

TEST(TimeOffset, PeriodicMotionIsRefusedAsAmbiguous) {
  // Only joint 6, one sinusoid of 1.5 Hz: |omega| repeats every 1/3 s, inside the +-0.5 s range.
  JointMotion periodic;
  periodic.q0 << 0.3, -1.2, 1.9, 0.4, 0.8, -0.5;
  periodic.terms[5].push_back({0.5, 2.0 * M_PI * 1.5, 0.0});
  expect_refused(periodic, 20.0, 1e-5, 2e-3, "offset", "ambiguous");
}

TEST(TimeOffset, MalformedSeriesAreRefused) {
  RateMagnitudeSeries a;
  a.source = "a";
  a.t_s = {0.0, 0.1, 0.1, 0.3, 0.4};
  a.rate_rad_s = {1, 2, 3, 4, 5};
  EXPECT_THROW(imscal::calib::estimate_time_offset(a, a), imscal::InputError);
  a.t_s = {0.0, 0.1};
  EXPECT_THROW(imscal::calib::estimate_time_offset(a, a), imscal::InputError);
}

}  // namespace
