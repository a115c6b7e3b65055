#pragma once
// Is the IMS still over a rest that the robot's readings call still? A link can move at a
// "rest" where its encoder cannot see it (sliding inside the gear's backlash, brakes settling, a
// slipping mount): the IMS sees it long before the rest detector's 20 ms windows do
// (ims/rest_detector.hpp resolves ~1e-3 rad/s; a link sliding 6e-4 rad over a 5 s rest turns at
// ~1e-4 rad/s and biases the rest's mean gyro rate, against which the heading is gyrocompassed
// to ~3e-7 rad/s, by 400 times that).
//
// Test: the interval is cut into blocks of block_s. At rest the sensor's attitude is constant,
// so between any two blocks a, b the IMS must show no rotation beyond what the robot's readings
// explain. The rotation of b relative to a is taken in three directions of S that the IMS
// resolves without knowing the heading:
//  - about up u (the mean specific force's direction): the gyro rate along u minus the Earth
//    rate's vertical part Omega sin(latitude), integrated (block means of the integral);
//  - about h, the horizontal part of the interval's mean gyro rate (the Earth rate's horizontal
//    part when still): the gyro rate along h minus Omega cos(latitude), integrated;
//  - about u x h: the tilt of the specific force, -(u x (f_b - f_a)) / g, along u x h.
// (A constant rotation perpendicular to both u and h turns h away from the horizontal Earth rate
// and only the accelerometers see it; a constant rotation along u or h the gyros see at once.)
// Noise of each at rest from the sensor spec: the gyro's ARW N integrated between block means
// d apart, N^2 (d - L/3), plus the quantisation residuals LSB^2 / 6; the accelerometers' VRW per
// block mean, 2 (VRW^2 / L + LSB^2 / (6 L^2)) / g^2 per difference, plus the in-run drift of
// their Gauss-Markov bias over d. The gyro bias (3 sigma of turn-on plus in-run) enters as a
// bound: b d rad. The readings explain the flange rotation |J_w(q) (q_b - q_a)| (block means of
// the joint readings, frame-independent as a magnitude), with readings_model_fraction for the
// gears' transmission error; each of the three components is reduced by that (and by the bias
// bound) before it is compared with its noise, so that at rest the sum of their squares is
// bounded by a chi-square with 3 degrees of freedom. A pair is flagged when it exceeds the
// quantile of false_alarm_per_rest / (number of pairs) (Bonferroni: the rate of still rests
// flagged stays below false_alarm_per_rest).
//
// A flagged interval is reduced to its longest run of blocks in which no pair is flagged (each
// candidate run tested on its own, with its own u and h); a run shorter than min_still_s means
// the rest is not usable.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <string>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/sensor_spec.hpp"

namespace imscal::calib {

struct RestStillnessOptions {
  // Length of the blocks compared [s]: the time resolution of a trim; long enough that a
  // block's mean specific force resolves a tilt of ~5e-6 rad (navigation-grade VRW).
  double block_s = 0.25;
  // Designed rate of still rests (over the whole interval) that the test flags [1].
  double false_alarm_per_rest = 1e-3;
  double min_still_s = 1.0;  // a still part shorter than this: the rest is not used
  // The flange rotation the joint readings show is trusted to this fraction (transmission error
  // of the gears, ~1 % of the motor motion; as FrameCalibrationOptions::creep_model_fraction).
  double readings_model_fraction = 0.02;
};

// The flange's mean rotation over [t0, t1] (IMS clock) from the robot's readings, relative to a
// fixed reference pose [rad] (any frame: only differences' magnitudes are used).
using ExplainedRotation = std::function<Eigen::Vector3d(double t0_ims_s, double t1_ims_s)>;

struct RestStillness {
  bool flagged = false;  // the IMS shows unexplained motion in [begin, end]
  bool usable = true;    // still over all of it, or a still part of >= min_still_s found
  double still_begin_ims_s = 0.0;
  double still_end_ims_s = 0.0;
  // The most significant unexplained motion over the whole interval: the rotation between the
  // blocks centred at motion_begin and motion_end beyond what the readings explain (and the
  // noise allows), its mean rate over that span, and what the readings explained.
  double unexplained_rotation_rad = 0.0;
  double rate_change_rad_s = 0.0;
  double explained_rotation_rad = 0.0;
  double motion_begin_ims_s = 0.0;
  double motion_end_ims_s = 0.0;
  double test_statistic = 0.0;  // sum of the squared normalised components (chi-square 3)
  double threshold = 0.0;       // its flagging threshold

  // The finding in words ("" when not flagged).
  std::string describe() const;
};

// The chi-square (3 degrees of freedom) quantile with upper tail `probability`.
double chi_square_3_upper_quantile(double probability);

// Tests [begin_ims_s, end_ims_s] of the record (increments or rates). explained may be empty
// (the readings show no motion). Intervals of fewer than 2 blocks are returned unflagged.
RestStillness assess_rest_stillness(const ims::ImuSeries& imu, const ims::EarthModel& earth,
                                    const ims::SensorSpec& sensor, double begin_ims_s,
                                    double end_ims_s, const ExplainedRotation& explained,
                                    const RestStillnessOptions& options = {});

}  // namespace imscal::calib
