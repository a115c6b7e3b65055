#pragma once
// The time offset between the robot clock and the IMS clock, without a user guess: both record
// the same rotation of the flange, whose magnitude |omega| does not depend on the frame it is
// expressed in. The robot gives it through the joint readings (Jacobian times differentiated
// joint angles), the IMS through its gyros (minus the Earth rate). The offset is the lag that
// maximises the normalised cross-correlation of the two magnitude series.
//
// Convention: an instant stamped t_robot by the robot clock is stamped t_robot + offset_s by the
// IMS clock, i.e. ims_rate(t) = robot_rate(t - offset_s).
//
// Method: the IMS samples inside the robot record (shrunk by the search range on both sides, so
// that every lag sees the same samples) are compared with the robot series interpolated (cubic
// Hermite) at t - lag; a coarse search over lags in steps of the robot sample interval finds the
// peak, golden-section search refines it below one sample. The peak's sharpness (curvature) and
// its margin over the best secondary peak are reported as the confidence figures; too short an
// overlap, too little motion, a weak or ambiguous peak, or a peak at the edge of the range are
// refused (InputError naming what is wrong).
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "ims/imu_data.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

// A scalar angular-rate magnitude series [rad/s] at increasing times [s] of one clock.
struct RateMagnitudeSeries {
  std::vector<double> t_s;
  std::vector<double> rate_rad_s;
  std::string source;  // for messages
};

// |omega| of the flange from joint readings q_rad[k] at t_s[k]: joint rates by central
// differences (second order, no time shift), omega = J_w(q_k) q_dot_k. The first and last sample
// have no central difference and are left out.
RateMagnitudeSeries flange_rate_magnitude(const KinematicModel& model,
                                          const std::vector<double>& t_s,
                                          const std::vector<JointVector>& q_rad,
                                          const std::string& source = "robot joint log");

// |gyro - omega_ie_S(t)| from IMS samples. Rates are used at their stamps; increments are
// divided by their interval and stamped at the interval's middle (their mean rate belongs
// there, not at the end stamp). earth_rate_S(t) gives the Earth rate in S [rad/s] at IMS time t
// (from the navigation attitude); the constant form takes e.g. the mean gyro reading of an
// initial rest period (Earth rate plus gyro bias in S).
RateMagnitudeSeries ims_rate_magnitude(const ims::ImuSeries& imu,
                                       const std::function<Eigen::Vector3d(double)>& earth_rate_S);
RateMagnitudeSeries ims_rate_magnitude(const ims::ImuSeries& imu,
                                       const Eigen::Vector3d& earth_rate_S);

struct TimeOffsetOptions {
  double max_abs_offset_s = 0.5;  // search range +-this
  double coarse_step_s = 0.0;     // 0: the robot series' median sample interval
  double min_overlap_s = 5.0;     // IMS time usable for every lag
  // Standard deviation of |omega| in the overlap, each series [rad/s]; below it the motion
  // carries no timing information (0.01 rad/s = 0.57 deg/s).
  double min_rate_std_rad_s = 0.01;
  double min_peak_correlation = 0.5;  // normalised cross-correlation at the peak
  // Peak minus the best local maximum outside the peak's lobe (the lags above half the peak
  // height over the curve's minimum); below it the peak is ambiguous (periodic motion).
  double min_peak_margin = 0.05;
  double tolerance_s = 1e-7;  // golden-section stop
};

struct TimeOffsetResult {
  double offset_s = 0.0;                     // t_ims = t_robot + offset_s
  double peak_correlation = 0.0;             // at offset_s
  double secondary_peak_correlation = -1.0;  // best outside the main lobe (-1: none)
  // Sharpness: -d^2 rho / d lag^2 at the peak [1/s^2], and the lag change that lowers the
  // correlation by 0.01 [s] (sqrt(0.02 / curvature)): the narrower, the better located.
  double peak_curvature_1_s2 = 0.0;
  double peak_width_s = 0.0;
  double overlap_s = 0.0;        // IMS time used for every lag
  std::size_t sample_count = 0;  // IMS samples used
  std::size_t lags_evaluated = 0;
};

TimeOffsetResult estimate_time_offset(const RateMagnitudeSeries& robot,
                                      const RateMagnitudeSeries& ims,
                                      const TimeOffsetOptions& options = {});

}  // namespace imscal::calib
