// Mounting misalignment and clock offset between two inertial units on one vehicle, from their
// angular rates: a MEMS IMU (slave, 100 Hz increments) and a fibre-optic-gyro INS (master,
// 10 Hz attitude) of the PSINS transfer-alignment data set (tests/data/real/psins-fog-mems/
// SOURCE.md), through the tool-IMU rotation calibration (calib/master_slave_record.hpp), against
// PSINS's reference installation angles mu0 and gyro bias eb0.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/master_slave_record.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/numeric_table.hpp"
#include "tests/support/record_figure.hpp"

namespace imscal::calib {
namespace {

const std::filesystem::path kDir =
    std::filesystem::path(IMSCAL_TEST_DATA_DIR) / "real/psins-fog-mems";
constexpr double kArcmin = 180.0 * 60.0 / M_PI;
constexpr double kDegPerHour = 180.0 / M_PI * 3600.0;

// A vehicle turns slower than a robot: the rate-vector fits use samples above 3 deg/s (0.2 rad/s
// for robots), motion segments start at 1 deg/s.
ToolImuCheckOptions vehicle_check() {
  ToolImuCheckOptions check;
  check.min_rate_for_fit_rad_s = 0.05;
  check.segment_rate_rad_s = 0.02;
  return check;
}

// The rotation calibration of decision 0027: per-axis gyro scale, no cross-coupling, 1σ from
// 2 s blocks. The vehicle turns mostly about its vertical, so the gyro axes' coupling is barely
// seen (estimating it moves the mounting's z by 8.8 arcmin away from mu0, to -26.3 arcmin), and
// its slow turns hold few motion segments at the robot's thresholds to resample.
RotationCalibrationOptions vehicle_calibration() {
  RotationCalibrationOptions options;
  options.estimate_cross_coupling = false;
  options.sigma_resampling = SigmaResampling::kBlocks;
  return options;
}

struct Pair {
  ToolImuRecord record;
  ToolImuAnalysis analysis;
};

Pair load(double slave_clock_shift_s) {
  IncrementImu slave = read_increment_imu_csv(kDir / "mems_imu_100hz.csv");
  for (double& t : slave.t_end_s) t += slave_clock_shift_s;
  const InsAttitude master = read_psins_attitude_csv(kDir / "fog_ins_avp_10hz.csv");
  Pair pair{master_slave_record(slave, master), {}};
  pair.analysis = check_tool_imu_record(pair.record, vehicle_check());
  return pair;
}

Eigen::Vector3d rotation_vector(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q);
  return aa.angle() * aa.axis();
}

// The slave in the master: R_T_S = exp([mu0 x]) (SOURCE.md: C_master^n ~ C_slave^n exp(-[mu0 x])).
// Measured (gyro scale estimated, block-bootstrap 1σ, robust spread): (-3.99, -1.27, -17.51) ±
// (0.55, 4.88, 1.20) arcmin against mu0 = (-5.30, 2.47, -17.57): 2.4σ, 0.8σ, 0.1σ. Tolerance 3σ per
// axis: the bootstrap σ carries the MEMS noise and the residuals' time correlation over the 100 s;
// the reference is itself an estimate whose origin and σ PSINS does not state, so nothing tighter
// is justified. The y axis (forward) is weakly seen: the vehicle rolls about it, pitch and yaw
// rates are small. The gyro bias against eb0 (-213.6, 158.9, 84.5 deg/h): measured (-215.2,
// 171.9, 84.4); tolerance 20 deg/h, 4 % of the demo's 500 deg/h bias model.
TEST(RealPsinsMounting, MisalignmentAndBiasMatchThePsinsReference) {
  const Pair pair = load(0.0);
  const RotationCalibration c =
      calibrate_rotation(pair.record, pair.analysis, vehicle_calibration());
  const Eigen::Vector3d mu_arcmin = rotation_vector(c.q_T_S) * kArcmin;
  const Eigen::Vector3d sigma_arcmin = c.sigma_rotation_rad * kArcmin;
  const NumericTable reference = read_numeric_table(kDir / "reference_params.csv");
  const Eigen::Vector3d mu0_arcmin =
      Eigen::Vector3d(reference.at(0, 6), reference.at(0, 7), reference.at(0, 8)) * kArcmin;
  const Eigen::Vector3d eb0_deg_h =
      Eigen::Vector3d(reference.at(0, 0), reference.at(0, 1), reference.at(0, 2)) * kDegPerHour;
  const Eigen::Vector3d bias_deg_h = c.gyro_bias_rad_s * kDegPerHour;
  std::printf(
      "MEMS in FOG: (%.2f, %.2f, %.2f) +- (%.2f, %.2f, %.2f) arcmin (%s), PSINS mu0 (%.2f, %.2f, "
      "%.2f); clock offset %.4f +- %.4f s; bias (%.1f, %.1f, %.1f) deg/h, eb0 (%.1f, %.1f, %.1f); "
      "%zu windows, residual RMS %.4f deg\n",
      mu_arcmin.x(), mu_arcmin.y(), mu_arcmin.z(), sigma_arcmin.x(), sigma_arcmin.y(),
      sigma_arcmin.z(), c.sigma_from_bootstrap ? "block bootstrap" : "covariance", mu0_arcmin.x(),
      mu0_arcmin.y(), mu0_arcmin.z(), c.time_offset_s, c.sigma_time_offset_s, bias_deg_h.x(),
      bias_deg_h.y(), bias_deg_h.z(), eb0_deg_h.x(), eb0_deg_h.y(), eb0_deg_h.z(), c.window_count,
      c.rms_residual_rad * 180.0 / M_PI);
  const Eigen::Vector3d kabsch_arcmin =
      rotation_vector(Eigen::Quaterniond(pair.analysis.R_T_S)) * kArcmin;
  std::printf("rate-vector fit alone (the initial value): (%.2f, %.2f, %.2f) arcmin\n",
              kabsch_arcmin.x(), kabsch_arcmin.y(), kabsch_arcmin.z());
  for (int k = 0; k < 3; ++k) {
    test_support::record_figure(fmt::format("mems_in_fog_{}_arcmin", "xyz"[k]), mu_arcmin(k));
    test_support::record_figure(fmt::format("mems_in_fog_{}_sigma_arcmin", "xyz"[k]),
                                sigma_arcmin(k));
  }
  test_support::record_figure("mems_fog_clock_offset_ms", c.time_offset_s * 1e3);
  EXPECT_TRUE(c.sigma_from_bootstrap);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(mu_arcmin(k) - mu0_arcmin(k)), 3.0 * sigma_arcmin(k)) << "axis " << k;
    EXPECT_LT(std::abs(bias_deg_h(k) - eb0_deg_h(k)), 20.0) << "axis " << k;
  }
}

// The clock offset has no published reference; its truth is made here: the slave's stamps moved
// by +40 ms move the estimate by 40 ms (within 3σ of the two estimates combined, plus 1 ms for
// the master's slerp between 10 Hz samples). Measured on the record as it is: -15.9 ± 0.5 ms
// (the slave's stamps early, or the master's attitude late), the rate-magnitude cross-correlation
// (calib/time_offset) -13.2 ms: both below half the master's 100 ms step.
TEST(RealPsinsMounting, ClockOffsetFollowsAKnownShift) {
  RotationCalibrationOptions options = vehicle_calibration();
  options.bootstrap_replicates = 10;  // σ for the bound only; 10 keep the test short
  const Pair as_is = load(0.0);
  const Pair shifted = load(0.040);
  const RotationCalibration a = calibrate_rotation(as_is.record, as_is.analysis, options);
  const RotationCalibration b = calibrate_rotation(shifted.record, shifted.analysis, options);
  std::printf("clock offset %.4f +- %.4f s, shifted by 40 ms: %.4f +- %.4f s (xcorr %.4f)\n",
              a.time_offset_s, a.sigma_time_offset_s, b.time_offset_s, b.sigma_time_offset_s,
              as_is.analysis.time_offset_s);
  EXPECT_LT(std::abs(a.time_offset_s), 0.05);
  EXPECT_LT(std::abs(a.time_offset_s - as_is.analysis.time_offset_s), 0.005);
  EXPECT_NEAR(b.time_offset_s - a.time_offset_s, 0.040,
              3.0 * std::hypot(a.sigma_time_offset_s, b.sigma_time_offset_s) + 0.001);
}

}  // namespace
}  // namespace imscal::calib
