#pragma once
// Joint-space errors from the IMS (the paper's Fig. 2): with the calibrated frames,
//   W_T_S(t)   the sensor's trajectory by zero-velocity-aided smoothing (ims/zupt_smoother.hpp),
//              started at the first rest pose with R_W_S0 = R_W_R R_R_H(q_0) R_H_S and
//              p_W_S0 = T_W_R T_R_H(q_0) p_H_S (whatever the origin of W in T_R_W is: with the
//              convention of calib/frame_calibration.hpp it is 0), biases from the frames; the
//              robot's readings at commanded standstill say where it is really still and how it
//              creeps (calib/encoder_motion.hpp): rests only there, velocity updates while it
//              creeps (never during commanded motion, where the gears deflect); the smoothed
//              positions then corrected at the returns to poses stood at before (the robot's
//              repeatability; calib/revisited_poses.hpp): the smoother cannot observe position;
//   T_R_H(t)   = T_R_W W_T_S(t + dt) T_S_H at every robot sample (t robot clock, t + dt IMS clock;
//              the smoothed poses interpolated between IMS samples: linear position, slerp);
//   q_measured inverse kinematics (robot/ik_solver.hpp, the arm's class) in the configuration of
//   the
//              robot's own reading at that sample, the 2*pi branch nearest to it;
//   dq         = q_desired - q_measured per joint (the robot's internal reading beside it),
//              with the 1-sigma the smoother's own sigmas give it (position and attitude of
//              W_T_S through the inverse Jacobian, their correlations left out).
//
// The result holds the columns of joint_errors.csv (ident/joint_error_io.hpp, datasets/FORMAT.md
// section 10: t_s, payload_kg, q_desired, q_measured, q_internal); calib may not use ident, so
// the tools layer copies it into an ident::JointErrorLog and writes it there. Robot samples
// outside the smoothed IMS record or whose inverse kinematics fails are left out (counted): the
// identification treats the time gap as a split between runs.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "calib/encoder_motion.hpp"
#include "calib/frame_calibration.hpp"
#include "calib/imu_preintegration.hpp"
#include "calib/revisited_poses.hpp"
#include "ims/imu_data.hpp"
#include "ims/zupt_options.hpp"
#include "ims/zupt_smoother.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

// What the joint-space step needs of the calibration's result.
struct CalibratedFrames {
  Eigen::Isometry3d T_R_W = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  ImuBiases biases;            // constant part, initial value of the smoother's bias states
  double time_offset_s = 0.0;  // t_ims = t_robot + time_offset_s
};

struct JointSpaceInput {
  // Increments, already corrected for the unit's scale factors and misalignments (biases stay:
  // the frames' biases seed the smoother); IMS clock.
  const ims::ImuSeries* imu = nullptr;
  const RobotLog* log = nullptr;  // robot clock
  ims::Site site;
  KinematicModel kinematics;
  CalibratedFrames frames;
  // The first rest pose: the smoothing starts at its begin (the IMS record is cut there) from
  // the attitude and position of the forward kinematics of its link-side angles (for a
  // calibrated run: RestObservation::q_link_rad + FrameCalibrationResult::joint_deviation_rad).
  RestObservation first_rest;
  ims::ZuptOptions zupt;  // sensor part from ims::zupt_options_from_spec
  std::string source;     // for messages
};

// One row of joint_errors.csv with q_measured's 1-sigma [robot clock, SI].
struct JointErrorRow {
  double t_s = 0.0;
  double payload_kg = 0.0;
  JointVector q_desired_rad, q_measured_rad, q_internal_rad, q_measured_sigma_rad;
};

// Running figures over the rows, added in the rows' order (the same sums as over the columns).
struct JointErrorSums {
  std::size_t rows = 0;
  JointVector error_squared_rad2 = JointVector::Zero();  // sum of (q_desired - q_measured)^2
  JointVector error_max_abs_rad = JointVector::Zero();   // largest |q_desired - q_measured|
  JointVector sigma_squared_rad2 = JointVector::Zero();  // sum of q_measured_sigma^2

  void add(const JointErrorRow& row);
};

struct JointSpaceOptions {
  // 1-sigma of the initial state handed to the smoother: attitude [rad] (the first rest's
  // joint-angle uncertainty through the kinematics, plus the frames'), velocity [m/s] (at rest),
  // position [m] (defines W_T_S's origin: small).
  double initial_attitude_sigma_rad = 2e-5;
  double initial_velocity_sigma_m_s = 1e-5;
  double initial_position_sigma_m = 1e-6;
  // Samples whose measured wrist bend has |sin A5| below this are left out: there axes 4 and 6
  // nearly align and the flange orientation fixes only A4 + A6; an orientation error e of the
  // IMS path moves A4 and A6 by ~e / |sin A5| in opposite directions (1e-4 rad at 0.05 gives
  // 2 mrad; at 1e-4, a whole radian). 0.05: ~2.9 deg around A5 = 0.
  double min_wrist_sin = 0.05;
  // The robot's readings at commanded standstill: rests only where they are still, velocity
  // updates while the arm creeps (calib/encoder_motion.hpp). Off: the IMS's own rests only.
  bool encoder_stillness = true;
  bool creep_velocity_updates = true;
  EncoderMotionOptions encoder;
  // The smoothed positions corrected at the returns to poses stood at before
  // (calib/revisited_poses.hpp).
  bool revisited_pose_correction = true;
  RevisitedPoseOptions revisited_poses;
  // Keep the smoothed trajectory in JointSpaceErrors::trajectory (160 bytes per IMS sample:
  // 19 MB per recorded minute at 2 kHz); off, it is used block by block and not kept.
  bool keep_trajectory = false;
  // Smoothed states per block (160 bytes each; 65536: 10 MB); the rows do not depend on it.
  std::size_t states_per_block = std::size_t(1) << 16;
  // Set: each row is handed to it as it is computed (in time order) and not kept in
  // JointSpaceErrors' columns (208 bytes per robot sample; 6.2 MB per recorded minute at 500 Hz).
  std::function<void(const JointErrorRow&)> row_sink;
};

// One row per kept robot sample (the joint_errors.csv columns) [robot clock, SI].
struct JointSpaceErrors {
  std::string robot;
  double cycle_s = 0.002;
  std::vector<double> t_s;
  std::vector<double> payload_kg;
  std::vector<JointVector> q_desired_rad;
  std::vector<JointVector> q_measured_rad;  // from the IMS chain
  std::vector<JointVector> q_internal_rad;
  // 1-sigma of q_measured from the smoother's sigmas (zero along a trajectory without them).
  std::vector<JointVector> q_measured_sigma_rad;
  JointErrorSums sums;             // over every row, kept in the columns or handed to the row sink
  std::size_t outside_record = 0;  // robot samples without IMS data (before/after the record)
  std::size_t ik_failures = 0;     // robot samples whose inverse kinematics failed
  std::size_t near_wrist_singularity = 0;  // left out: |sin A5| < JointSpaceOptions::min_wrist_sin
  std::string first_ik_failure;            // reason of the first failure, in words
  ims::ZuptSummary smoother;               // rests, innovation statistics
  // The smoothed position's errors found and removed at the settled standstills
  // (calib/revisited_poses.hpp; empty when off).
  std::vector<PositionErrorSample> revisited_pose_errors;
  // The smoothed trajectory (IMS clock), for checks; JointSpaceOptions::keep_trajectory only.
  std::vector<ims::SmoothedState> trajectory;
};

// Throws InputError when the inputs cannot be used (null pointers, no increments, the first rest
// outside the record, inverse kinematics impossible for the first rest).
JointSpaceErrors joint_space_errors(const JointSpaceInput& input,
                                    const JointSpaceOptions& options = {});

// RMS over the samples of q_measured's 1-sigma per joint [rad]: the IMS noise floor in joint
// space (the gap diagnosis' measurement budget reads it); from the sums when the rows went to a
// sink. Zero without samples.
JointVector q_measured_sigma_rms_rad(const JointSpaceErrors& errors);

// Steps 2-3 alone: the flange poses and inverse kinematics at the robot samples from a given
// sensor trajectory W_T_S (IMS clock, sorted by time), e.g. the smoother's or a reference's.
// Fills everything but `smoother` and `trajectory`.
JointSpaceErrors joint_errors_along(const std::vector<ims::SmoothedState>& trajectory,
                                    const RobotLog& log, const KinematicModel& kinematics,
                                    const CalibratedFrames& frames,
                                    double min_wrist_sin = JointSpaceOptions{}.min_wrist_sin);

// The sensor pose W_T_S at IMS time t from the smoothed states (sorted by time): linear in
// position, slerp in attitude between the two samples around t; false outside their span.
bool interpolate_sensor_pose(const std::vector<ims::SmoothedState>& states, double t_ims_s,
                             Eigen::Isometry3d& T_W_S);

}  // namespace imscal::calib
