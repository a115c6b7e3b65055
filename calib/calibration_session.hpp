#pragma once
// One calibration session (`imscal calibrate`, the wrist/sensor calibration of the paper): from
// the raw IMS record and the robot's log, the rest poses (calib/rest_poses.hpp) with the initial
// clock offset, the frame-and-bias bundle (calib/frame_calibration.hpp: T_R_W, T_S_H, biases,
// time offset with covariance), the mounting validation (calib/mounting_validation.hpp) and the
// joint errors (calib/joint_space_errors.hpp). The command, the campaign test and the benchmark
// call this one function; reading the files is calib/calibration_session_inputs.hpp, the text
// report calib/calibration_session_summary.hpp.
//
// With an earlier session's frames (SessionInputs::previous, `calibrate --frames`): T_R_W's
// rotation and T_S_H are held at them; the bundle estimates the biases and the clock offset from
// as few as one rest, takes that session's link share as its prior, and the mounting check gives
// this record's residuals against those frames instead of the halves and segments.
#include <functional>
#include <optional>
#include <string>

#include "calib/calibration_config.hpp"
#include "calib/frame_calibration.hpp"
#include "calib/frames_json.hpp"
#include "calib/joint_space_errors.hpp"
#include "calib/mounting_validation.hpp"
#include "calib/rest_poses.hpp"
#include "calib/time_offset.hpp"
#include "ims/imu_data.hpp"
#include "ims/sensor_spec.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

struct SessionInputs {
  // Increments on the IMS clock, corrected with the unit's lab calibration, with its site.
  ims::ImuSeries imu;
  RobotLog log;
  RobotDescription robot;
  ims::SensorSpec sensor;
  std::optional<SessionFrames> previous;  // an earlier session's frames.json (held)
  std::string source;                     // the IMS record's name, for messages
};

struct SessionOptions {
  CalibrationConfig config;
  // Set: the joint-error rows are handed to it as computed and not kept in
  // SessionResult::joint_errors' columns (JointSpaceOptions::row_sink).
  std::function<void(const JointErrorRow&)> joint_error_rows;
};

struct SessionResult {
  TimeOffsetResult initial_time_offset;  // cross-correlation, before the bundle
  RestPoseResult rests;                  // at the initial clock offset
  FrameCalibrationResult frames;
  MountingValidation validation;
  std::optional<JointSpaceErrors> joint_errors;  // when config.joint_errors
  // Why the record lacks the rests the chain needs (calib/rest_sufficiency.hpp); empty: it has.
  std::string rest_shortage;
};

// Stage names in order: "rests", "time offset", "rests" (0.5), "bundle", the validation's
// ("halves", "segments"), "joint errors"; fraction in [0, 1].
using SessionProgress = std::function<void(const std::string& stage, double fraction)>;

// Throws InputError when the record holds no rest or when the bundle refuses (fewer than 3
// rests, none with held frames), and HandEyeUnobservable (calib/hand_eye.hpp).
SessionResult calibrate_session(const SessionInputs& inputs, const SessionOptions& options,
                                const SessionProgress& progress = {});

// The mounting check of a record calibrated with an earlier session's frames: the bundle's
// outlier check on this record's rests and motions against those frames (a slipped or
// re-mounted IMS shows up as outliers there) and what the record can say at all.
MountingValidation previous_frames_validation(const FrameCalibrationResult& result,
                                              const MountingThresholds& thresholds,
                                              double outlier_threshold_sigma,
                                              const SessionFrames& previous);

}  // namespace imscal::calib
