// What the rests of the real ABB records measure (tests/data/real/abb-mems/SOURCE.md; decision
// 0055), independent of the gyro model:
//   - the gyro bias, against the bias the rotation calibration fits from the motion windows.
//     Truth: at rest a gyro reads its bias alone, so the rests' mean is a direct measurement of b.
//   - gravity as the accelerometer reads it (through the calibrated R_T_S) against gravity as the
//     robot's reported tool orientation places it, both in T. Between rests where the robot
//     reports the same tool attitude, a rigid mount and a true report keep their difference; it
//     moves by 2.45-3.96 deg on every record (four sensors, six runs), after the fast turns. The
//     sensor and the robot's reported tool do not stay rigidly together, and an orientation error
//     against the robot of a few degrees is not the gyro's.
// Measured (deg/s, the fit's bias minus the rests', in calibrated units, mapped into the tool
// frame T): path 1 within 0.07 on every axis for three records; path 3, three different sensors
// (MPU9150, LSM9DS0, MPU6050 with different mountings), about T z -0.39, -0.75 and -0.66, about
// T x -0.19, -0.21, -0.14. The departure is a rate in the tool frame that the three sensors
// share, a property of the run, not of one gyro; no gyro model (a nonlinear scale of one sensor)
// holds it. With the rests as a prior the fit's bias follows them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "calib/gyro_rest_bias.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/units.hpp"

namespace imscal::calib {
namespace {

const std::string kDir = std::string(IMSCAL_TEST_DATA_DIR) + "/real/abb-mems/";

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

RotationCalibrationOptions no_bootstrap() {
  RotationCalibrationOptions options;
  options.bootstrap_replicates = 0;  // the estimates alone are compared
  return options;
}

// The fit's bias minus the rests', in calibrated units (divided by the gyro scale), in T [deg/s].
Eigen::Vector3d fit_minus_rests_T_deg_s(
    const std::string& file, const RotationCalibrationOptions& options = no_bootstrap()) {
  const ToolImuRecord record = read_tool_imu_record(kDir + file);
  const RotationCalibration c = calibrate_rotation(record, check_tool_imu_record(record), options);
  EXPECT_GT(c.rest_sample_count, 200u) << file;  // every record rests for over 2 s in all
  const Eigen::Vector3d difference_S =
      (c.gyro_bias_rad_s - c.rest_bias_rad_s).cwiseQuotient(c.gyro_scale);
  return c.q_T_S * difference_S * kDegPerRad;
}

TEST(RealAbbMemsRests, RestsMatchTheFitOnPathOneAndDepartAlikeOnPathThree) {
  if (sanitized()) GTEST_SKIP() << "six real-record calibrations: Release stage only";
  // Path 1 turns about one axis at a time with long rests: the fit agrees with the rests
  // (measured within 0.07 deg/s; bound 0.15, twice that).
  for (const char* file : {"V_500_Sequencia1/MPU9150.csv", "V_500_Sequencia1/LSM9DS0.csv",
                           "V_1500_Sequencia1/LSM9DS0.csv"}) {
    SCOPED_TRACE(file);
    EXPECT_LT(fit_minus_rests_T_deg_s(file).cwiseAbs().maxCoeff(), 0.15);
  }
  // Path 3: every sensor's fit departs from its rests about T z, by the same sign and size
  // (measured -0.39 to -0.75 deg/s; bounds -1.0 and -0.25 hold all three and exclude path 1's).
  for (const char* file : {"V_500_Sequencia3/MPU9150.csv", "V_500_Sequencia3/LSM9DS0.csv",
                           "V_800_Sequencia3/MPU6050RM3100.csv"}) {
    SCOPED_TRACE(file);
    const Eigen::Vector3d d = fit_minus_rests_T_deg_s(file);
    EXPECT_GT(d.z(), -1.0);
    EXPECT_LT(d.z(), -0.25);
  }
}

// Per rest (robot still over +-0.1 s, as calib/gyro_rest_bias.hpp judges it), gravity's
// direction in T from the robot's reported orientation and from the accelerometer's mean.
struct RestGravity {
  Eigen::Vector3d up_T_robot;
  Eigen::Vector3d up_T_sensor;
};

std::vector<RestGravity> rest_gravity(const ToolImuRecord& record, const RotationCalibration& c) {
  const RobotRateSeries robot = robot_tool_rate(record);
  std::vector<RestGravity> rests;
  Eigen::Vector3d acc_sum = Eigen::Vector3d::Zero(), robot_sum = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  auto close_rest = [&] {
    if (count >= 10) rests.push_back({robot_sum.normalized(), (c.q_T_S * acc_sum).normalized()});
    acc_sum.setZero();
    robot_sum.setZero();
    count = 0;
  };
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    const double t_robot_s = record.t_s[k] - c.time_offset_s;
    bool still = !record.acc_m_s2[k].isZero(0.0);
    for (double dt : {-0.1, 0.0, 0.1}) {
      Eigen::Vector3d w;
      still = still && robot_rate_at(robot, t_robot_s + dt, w) && w.norm() <= 0.01;
    }
    Eigen::Quaterniond q_B_T;
    if (!still || !robot_orientation_at(record, t_robot_s, q_B_T)) {
      close_rest();
      continue;
    }
    acc_sum += record.acc_m_s2[k];
    robot_sum += q_B_T.conjugate() * c.up_B;
    ++count;
  }
  close_rest();
  return rests;
}

TEST(RealAbbMemsRests, TheSensorTiltsAgainstTheRobotBetweenRestsOfOneAttitude) {
  if (sanitized()) GTEST_SKIP() << "six real-record calibrations: Release stage only";
  for (const char* file : {"V_500_Sequencia1/MPU9150.csv", "V_500_Sequencia3/MPU9150.csv",
                           "V_500_Sequencia1/LSM9DS0.csv", "V_500_Sequencia3/LSM9DS0.csv",
                           "V_1500_Sequencia1/LSM9DS0.csv", "V_800_Sequencia3/MPU6050RM3100.csv"}) {
    SCOPED_TRACE(file);
    const ToolImuRecord record = read_tool_imu_record(kDir + file);
    const RotationCalibration c =
        calibrate_rotation(record, check_tool_imu_record(record), no_bootstrap());
    const std::vector<RestGravity> rests = rest_gravity(record, c);
    // The largest change of (sensor gravity - robot gravity) between two rests whose reported
    // tool attitudes lie within 2 deg [deg]; measured 2.45-3.96 deg, bound 2.0. A rigid mount
    // and a true report hold it at the accelerometer's noise, under 0.1 deg over 20 samples.
    double largest_deg = 0.0;
    for (std::size_t i = 0; i < rests.size(); ++i) {
      for (std::size_t j = i + 1; j < rests.size(); ++j) {
        if (rests[i].up_T_robot.dot(rests[j].up_T_robot) < std::cos(2.0 / kDegPerRad)) continue;
        const Eigen::Vector3d change = (rests[i].up_T_sensor - rests[i].up_T_robot) -
                                       (rests[j].up_T_sensor - rests[j].up_T_robot);
        largest_deg = std::max(largest_deg, change.norm() * kDegPerRad);
      }
    }
    EXPECT_GT(largest_deg, 2.0);
    EXPECT_LT(largest_deg, 6.0);  // a few degrees, not a lost orientation
  }
}

// With the rests as a prior, the fit's bias lies within 3 sigma of the rests' mean on every axis
// (measured on V_500_Sequencia3/LSM9DS0: within 0.3 sigma; without it 0.76 deg/s away about S z,
// about 30 sigma).
TEST(RealAbbMemsRests, ThePriorHoldsTheBiasToTheRests) {
  if (sanitized()) GTEST_SKIP() << "a real-record calibration: Release stage only";
  const ToolImuRecord record = read_tool_imu_record(kDir + "V_500_Sequencia3/LSM9DS0.csv");
  const ToolImuAnalysis analysis = check_tool_imu_record(record);
  RotationCalibrationOptions options = no_bootstrap();
  const RotationCalibration free = calibrate_rotation(record, analysis, options);
  options.rest_bias_prior = true;
  const RotationCalibration held = calibrate_rotation(record, analysis, options);
  EXPECT_FALSE(free.rest_bias_prior_used);
  ASSERT_TRUE(held.rest_bias_prior_used);
  const Eigen::Vector3d sigmas_held =
      (held.gyro_bias_rad_s - held.rest_bias_rad_s).cwiseQuotient(held.sigma_rest_bias_rad_s);
  const Eigen::Vector3d sigmas_free =
      (free.gyro_bias_rad_s - free.rest_bias_rad_s).cwiseQuotient(free.sigma_rest_bias_rad_s);
  EXPECT_LT(sigmas_held.cwiseAbs().maxCoeff(), 3.0);
  EXPECT_GT(sigmas_free.cwiseAbs().maxCoeff(), 10.0);  // the free fit's departure, for contrast
}

// The rests' mean is the mean of the still samples: on a record whose gyro reads a constant, it
// is that constant with a zero sample scatter, and the rests are counted as separate spans.
TEST(GyroRestBias, AConstantReadingIsItsOwnMean) {
  ToolImuRecord record;
  record.has_raw_imu = true;
  const Eigen::Vector3d bias(0.001, -0.002, 0.003);
  for (int k = 0; k < 400; ++k) {
    const double t = 0.01 * k;
    // Still for 0-1 s and 3-4 s, turning about z at 0.5 rad/s in between.
    const double angle = t < 1.0 ? 0.0 : (t < 3.0 ? 0.5 * (t - 1.0) : 1.0);
    record.lines.push_back(static_cast<std::size_t>(k + 2));
    record.t_s.push_back(t);
    record.gyro_rad_s.push_back(bias + Eigen::Vector3d(0, 0, (t >= 1.0 && t < 3.0) ? 0.5 : 0.0));
    record.acc_m_s2.push_back(Eigen::Vector3d(0, 0, 9.80665));
    record.robot_position_m.push_back(Eigen::Vector3d::Zero());
    record.q_B_T.push_back(Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())));
    record.robot_quaternion_norm.push_back(1.0);
    record.robot_pose_valid.push_back(true);
  }
  GyroRestBias rest;
  ASSERT_TRUE(gyro_rest_bias(record, 0.0, 0.01, rest));
  EXPECT_LT((rest.mean_rad_s - bias).norm(), 1e-12);
  EXPECT_LT(rest.sigma_rad_s.norm(), 1e-12);
  EXPECT_EQ(rest.rest_count, 2u);
  // Of the 200 still samples, those within 0.1 s (the +-0.1 s probe) plus the rate's 0.05 s
  // difference span of a motion or of the record's ends are not counted: about 0.15-0.25 s of
  // each 1 s rest (measured 140 of 200).
  EXPECT_GT(rest.sample_count, 120u);
  EXPECT_LT(rest.sample_count, 180u);
}

}  // namespace
}  // namespace imscal::calib
