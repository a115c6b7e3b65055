// Rotation calibration and attitude filter on a simulated tool IMU whose truth is known: the
// tool turns with a smooth, multi-axis rate; the gyro sees it through a known R_T_S, scale,
// cross-coupling of its axes (1-2 %, as measured on the real MPU9150) and bias, 0.08 s late on
// its clock; the accelerometer sees gravity only (no lever arm).
#include <gtest/gtest.h>

#include <cmath>

#include "calib/attitude_filter.hpp"
#include "calib/orientation_error.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

constexpr double kOffset = 0.08;  // t_sensor = t_robot + offset

Eigen::Vector3d true_rate_T(double t) {
  // Rest for 2 s (bias), then three incommensurate components [rad/s] under a smooth sin^2
  // envelope (no jump a trapezoid would smear), rest at the end.
  if (t < 2.0 || t > 28.0) return Eigen::Vector3d::Zero();
  const double s = t - 2.0;
  const double envelope = std::pow(std::sin(M_PI * s / 26.0), 2);
  return Eigen::Vector3d(0.8 * std::sin(0.9 * s), 0.6 * std::sin(1.3 * s + 1.0),
                         1.0 * std::sin(0.5 * s + 2.0)) *
         envelope;
}

struct Simulated {
  ToolImuRecord record;
  Eigen::Quaterniond q_T_S;
  Eigen::Vector3d bias, scale, coupling;
};

Simulated simulate() {
  Simulated sim;
  sim.q_T_S = ims::quat_exp<double>(Eigen::Vector3d(0.3, -1.2, 1.9));
  sim.bias = Eigen::Vector3d(0.002, -0.001, 0.003);
  sim.scale = Eigen::Vector3d(1.02, 0.99, 1.01);
  sim.coupling = Eigen::Vector3d(0.015, -0.01, 0.02);  // c_xy, c_xz, c_yz
  const Eigen::Matrix3d gyro_matrix = gyro_scale_matrix(sim.scale, sim.coupling);
  const Eigen::Vector3d up_B = Eigen::Vector3d::UnitZ();
  auto& r = sim.record;
  r.file = "simulated";
  r.has_raw_imu = true;
  // Robot orientation by fine integration (1 ms, midpoint rate), sampled every 10 ms; the
  // sensor sample at sensor time t sees the rate of robot time t - offset.
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const double fine = 1e-3;
  double t = 0.0;
  for (int k = 0; k <= 3000; ++k) {
    const double t_sample = 0.01 * k;
    while (t < t_sample - 1e-12) {
      q = (q * ims::quat_exp<double>(true_rate_T(t + 0.5 * fine) * fine)).normalized();
      t += fine;
    }
    r.t_s.push_back(t_sample);
    r.lines.push_back(static_cast<std::size_t>(k + 2));
    r.q_B_T.push_back(q);
    r.robot_pose_valid.push_back(true);
    r.robot_quaternion_norm.push_back(1.0);
    r.robot_position_m.push_back(Eigen::Vector3d::Zero());
  }
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    const Eigen::Vector3d omega_S = sim.q_T_S.conjugate() * true_rate_T(r.t_s[k] - kOffset);
    r.gyro_rad_s.push_back(gyro_matrix * omega_S + sim.bias);
    Eigen::Quaterniond q_robot;
    robot_orientation_at(r, std::max(0.0, r.t_s[k] - kOffset), q_robot);
    r.acc_m_s2.push_back(sim.q_T_S.conjugate() * (q_robot.conjugate() * up_B) * 9.80665);
  }
  return sim;
}

TEST(RotationCalibration, RecoversSimulatedMountingBiasScaleCouplingAndOffset) {
  const Simulated sim = simulate();
  const auto analysis = check_tool_imu_record(sim.record);
  const auto cal = calibrate_rotation(sim.record, analysis);
  // Errors left by the simulation itself: the robot poses are slerped between 10 ms samples and
  // the gyro integrated with a trapezoid over 10 ms at rates up to ~1.5 rad/s (a few 1e-4 rad
  // per 0.5 s window); the tolerances allow for that.
  EXPECT_LT(ims::rotation_angle_between(cal.q_T_S, sim.q_T_S) * kDegPerRad, 0.03);
  EXPECT_NEAR(cal.time_offset_s, kOffset, 1e-3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(cal.gyro_bias_rad_s[i], sim.bias[i], 2e-4);
    EXPECT_NEAR(cal.gyro_scale[i], sim.scale[i], 2e-3);
    EXPECT_NEAR(cal.gyro_cross_coupling[i], sim.coupling[i], 2e-3);
  }
  EXPECT_LT(cal.rms_residual_rad * kDegPerRad, 0.01);
  EXPECT_NEAR(cal.up_B.z(), 1.0, 1e-4);
  // The mounting's 1 sigma: the 3x3 tangent block of the rotation, positive on every axis and
  // below the 0.03 deg the estimate is held to above (the residuals are ~0.01 deg).
  EXPECT_TRUE(cal.covariance_ok);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(cal.sigma_rotation_rad[i], 0.0) << i;
    EXPECT_LT(cal.sigma_rotation_rad[i] * kDegPerRad, 0.03) << i;
  }
}

TEST(AttitudeFilter, TracksTheSimulatedToolWithTheTrueCalibration) {
  const Simulated sim = simulate();
  RotationCalibration truth;
  truth.q_T_S = sim.q_T_S;
  truth.gyro_bias_rad_s = sim.bias;
  truth.gyro_scale = sim.scale;
  truth.gyro_cross_coupling = sim.coupling;
  truth.time_offset_s = kOffset;
  for (bool gravity : {false, true}) {
    AttitudeFilterOptions options;
    options.use_gravity = gravity;
    const auto track = run_attitude_filter(sim.record, truth, options);
    const auto error = orientation_error(sim.record, kOffset, track.t_s, track.q_B_T);
    // Integration error of the 10 ms trapezoid at rates up to 1.5 rad/s and of the slerped
    // reference: measured 0.026 deg RMS, 0.08 deg max; bound 0.15 deg. Gravity aiding is exact
    // here (no lever arm) and must not add error.
    EXPECT_LT(error.max_rad * kDegPerRad, 0.15) << "gravity " << gravity;
    EXPECT_LT(error.rms_rad * kDegPerRad, 0.05) << "gravity " << gravity;
    EXPECT_GT(error.sample_count, 2900u);
  }
  // With a wrong bias (0.5 deg/s on every axis) the tilt is held by gravity, the heading is not.
  RotationCalibration wrong = truth;
  wrong.gyro_bias_rad_s += Eigen::Vector3d::Constant(0.5 / kDegPerRad);
  AttitudeFilterOptions no_gravity;
  no_gravity.use_gravity = false;
  const auto free = run_attitude_filter(sim.record, wrong, no_gravity);
  // Gain 1 rad/s: the tilt error settles near bias / gain = 0.5 deg.
  AttitudeFilterOptions strong;
  strong.gravity_gain_rad_s = 1.0;
  const auto aided = run_attitude_filter(sim.record, wrong, strong);
  auto tilt_error = [&](const AttitudeTrack& track) {
    Eigen::Quaterniond q_robot;
    robot_orientation_at(sim.record, track.t_s.back() - kOffset, q_robot);
    const Eigen::Vector3d up_true = q_robot.conjugate() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up_est = track.q_B_T.back().conjugate() * Eigen::Vector3d::UnitZ();
    return std::acos(std::min(1.0, up_true.dot(up_est)));
  };
  // Free integration: 0.87 deg/s x 30 s of drift, much of it in tilt; aided: held near 0.5 deg.
  EXPECT_LT(tilt_error(aided), 0.5 * tilt_error(free));
}

}  // namespace
}  // namespace imscal::calib
