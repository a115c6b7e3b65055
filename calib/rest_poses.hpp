#pragma once
// From the raw records to the rest poses of the frame calibration (calib/frame_calibration.hpp):
//
// 1. Rest intervals on the IMS clock from the IMS alone (ims::detect_rest with the sensor's
//    noise model, ims::zupt_options_from_spec); those shorter than min_duration_s are dropped,
//    the others trimmed by edge_trim_s at both ends (the slow ends of smooth motions).
// 2. The robot must be still over the same interval on its own clock (t_robot = t_ims - dt):
//    every joint's internal reading may spread (max - min) by at most max_joint_spread_rad, and
//    the log must cover the interval; otherwise the rest is rejected with the reason. Of a still
//    rest only the settled part is used: its begin moves to where every joint's reading stays
//    within settle_tolerance_rad of its final value (at least min_settled_s must remain).
// 3. The internal readings are averaged and corrected for the static deflection
//    (calib/static_deflection.hpp) with the payload the robot carries then: its mass from the
//    log's payload_kg, its centre of mass from the given payload body (in the tool frame T).
//    The readings at the rest's ends relative to the mean and the joint rates there describe
//    what the arm still creeps (RestObservation::q_creep_*, q_rate_*).
// 2b. The IMS must be still there too, beyond what the readings explain (calib/rest_stillness:
//    a link sliding in its backlash, brakes settling or a slipping mount turn the flange where
//    the encoders do not see it, and bias the rest's mean gyro rate, the heading's only source):
//    a rest where the IMS shows such motion is trimmed to its still part, or rejected when that
//    is shorter than stillness.min_still_s; each trimmed rest is listed with the finding
//    (RestPoseResult::trimmed), each rejected one with it as the reason.
//
// Also: the log as a RobotJointSeries (calib/frame_calibration.hpp) and the initial time offset
// by cross-correlation of the angular-rate magnitudes (calib/time_offset.hpp).
#include <string>
#include <vector>

#include "calib/frame_calibration.hpp"
#include "calib/rest_stillness.hpp"
#include "calib/static_deflection.hpp"
#include "calib/time_offset.hpp"
#include "ims/imu_data.hpp"
#include "ims/rest_detector.hpp"
#include "ims/sensor_spec.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

struct RestPoseOptions {
  double min_duration_s = 2.0;  // detected rests shorter than this are not used
  // The IMS rest detector's threshold in noise standard deviations (ims/rest_detector.hpp).
  double detector_threshold_sigmas = 5.0;
  double edge_trim_s = 0.5;  // taken off both ends of every rest
  // Largest spread (max - min) of a joint's internal reading over a rest [rad]. A still robot's
  // encoders move by a few counts at most (1e-5 rad = 2 arcsec), but after a move the joint
  // controllers may still creep towards their target through friction for seconds (up to
  // 1.5e-4 rad over a trimmed 6 s rest on the simulated elastic KR 16, calib_test_calibrate_
  // campaign): such a rest is kept and its creep described (RestObservation::q_creep_*) for the
  // bundle to model. 3e-4 rad: twice that; a slow programmed motion moves far more.
  double max_joint_spread_rad = 3e-4;
  // The rest is used from where every joint's reading stays within settle_tolerance_rad of its
  // value at the rest's end (the joint controllers settle exponentially after a move; a drift of
  // 1e-6 rad over a 3 s rest is a mean rate of 0.07 deg/h, one sigma of a navigation-grade gyro
  // there) [rad]; 0: not checked (the default: on mounting-rigid the trimmed rests move by
  // <= 2.6e-6 rad and the check changes nothing measurable; creeping elastic drives never come
  // within 3e-7 rad). A rest with less than min_settled_s left is rejected.
  double settle_tolerance_rad = 0.0;
  double min_settled_s = 1.0;
  // The joint rates at the ends of a rest (RestObservation::q_rate_*) from a straight line
  // through the readings of this span at each end (encoder quantisation averages down) [s].
  double creep_fit_s = 0.05;
  // The IMS stillness check of every rest the readings accept (2b above); off: not checked.
  bool check_stillness = true;
  RestStillnessOptions stillness;
  StaticDeflectionOptions deflection;
};

struct RestPoseInput {
  const ims::ImuSeries* imu = nullptr;  // IMS clock
  const RobotLog* log = nullptr;        // robot clock
  const RobotDescription* robot = nullptr;
  ims::SensorSpec sensor;  // noise model of the rest detection
  ims::Site site;          // where the record was taken (Earth rate, gravity of the detector)
  // The payload's centre of mass (and shape) in the tool frame T; its mass is taken from the
  // log. Ignored while the log says 0 kg.
  RigidBodyParameters payload;
  double time_offset_s = 0.0;  // t_ims = t_robot + time_offset_s (initial value is fine)
  std::string source;          // for messages
};

// What was found at one accepted rest, beside its RestObservation.
struct RestPoseDetail {
  JointVector q_internal_mean_rad = JointVector::Zero();
  JointVector q_internal_spread_rad = JointVector::Zero();  // max - min over the trimmed rest
  double payload_kg = 0.0;
  std::size_t robot_samples = 0;
  StaticDeflection deflection;
};

struct RestPoseResult {
  std::vector<RestObservation> rests;   // accepted, in time order
  std::vector<RestPoseDetail> details;  // parallel to rests
  std::vector<std::string> rejected;    // rests not used, each with the reason in words
  // Rests used only in part because the IMS moved in the rest of them, each with the finding
  // (the unexplained rotation, its rate and span) and the part kept.
  std::vector<std::string> trimmed;
  ims::RestDetection detection;  // the IMS-only detection (all intervals)
};

// Throws InputError for missing inputs (null pointers, an empty log) and when the detector
// does (no increments, too short a record).
RestPoseResult find_rest_poses(const RestPoseInput& input, const RestPoseOptions& options = {});

// The log's internal joint readings as the frame calibration's joint series (robot clock);
// with the robot, also the lags of the links behind the readings per unit link share of the
// viscous friction, c_j / k_j of its drives (0 for rigid drives).
RobotJointSeries robot_joint_series(const RobotLog& log);
RobotJointSeries robot_joint_series(const RobotLog& log, const RobotDescription& robot);

// The initial time offset t_ims = t_robot + dt by cross-correlating the flange's angular-rate
// magnitude from the joint readings with that from the gyros; the Earth rate (plus gyro bias)
// in S is taken as the mean gyro rate over the first `initial_rest` (the record must start at
// rest; e.g. RestPoseResult::detection.intervals.front()).
TimeOffsetResult estimate_initial_time_offset(const ims::ImuSeries& imu, const RobotLog& log,
                                              const KinematicModel& kinematics,
                                              const ims::RestInterval& initial_rest,
                                              const TimeOffsetOptions& options = {});

}  // namespace imscal::calib
