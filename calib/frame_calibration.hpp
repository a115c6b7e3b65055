#pragma once
// The frame-and-bias bundle: one Ceres problem for T_R_W (robot base R in the Earth-fixed W),
// T_S_H (flange H in the sensor frame S), the IMS biases and the time offset between the robot
// clock and the IMS clock, from a record in which the robot stops in a set of rest poses and
// moves between them.
//
// Measurements (W Earth-fixed ENU, gravity g_W(p) and Earth rate Omega from ims::EarthModel):
//  - rest pose i (robot still over [begin_ims_s, end_ims_s]): the mean specific force equals
//    -R_S_W g_W + b_a, the mean angular rate R_S_W Omega + b_g, with
//    R_W_S_i = R_W_R R_R_H(q_i + dq_i) R_H_S from the forward kinematics of the rest pose's
//    link-side joint angles q_i plus a per-pose joint deviation dq_i (backlash play, unmodelled
//    deflection; prior N(0, q_link_sigma_rad));
//  - motion i -> i+1: the IMU preintegration (calib/imu_preintegration.hpp, bias Jacobians,
//    Earth rate, Coriolis) from rest i at zero velocity must arrive at rest i+1 with zero
//    velocity, the attitude and the position of the forward kinematics;
//  - during motion: the gyro rate minus bias minus Earth rate equals R_S_H omega_H(t_ims - dt),
//    omega_H from the robot's joint readings (this is what makes the time offset dt observable).
//
// Convention for the origin of W (the IMS senses no absolute position): W's origin is the
// sensor's position at the first rest pose, so the translation of T_R_W is not a free
// parameter but follows from the rest of the solution. Compare with a truth expressed in the
// same convention (frame_calibration_truth_convention below).
//
// Observability: the heading of R in W (rotation of T_R_W about the vertical) is seen only
// through the Earth rate (gyrocompassing): its 1-sigma is about
// ARW / (|Omega| cos(latitude) sqrt(total time)), e.g. ~0.06 deg for a 0.002 deg/sqrt(h) gyro
// over 2 minutes. The covariance reports it as it is; the observability report names it.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/imu_preintegration.hpp"
#include "calib/robot_description.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"

namespace imscal::calib {

// One rest pose of the robot.
struct RestObservation {
  std::string label;         // for reports ("rest 3 at 41.2 s")
  double begin_ims_s = 0.0;  // interior of the rest on the IMS clock (edges trimmed by the caller)
  double end_ims_s = 0.0;
  JointVector q_link_rad = JointVector::Zero();        // link-side joint angles at rest
  JointVector q_link_sigma_rad = JointVector::Zero();  // prior 1-sigma of their remaining error
  // The modelled static deflection that q_link_rad was corrected for (calib/static_deflection):
  // q_link = q_internal - q_windup - q_play. Zero when the readings are link angles. With
  // FrameCalibrationOptions::estimate_deflection_scale the bundle scales both per joint.
  JointVector q_windup_rad = JointVector::Zero();  // gear wind-up tau_g / k
  JointVector q_play_rad = JointVector::Zero();    // backlash play taken up, (b / 2) sign(tau_g)
};

// The robot's joint readings, for the flange rate during motion (time offset) [robot clock].
struct RobotJointSeries {
  std::vector<double> t_robot_s;
  std::vector<JointVector> q_rad;  // internal (motor-side) readings are fine: rates only
};

// The sensor's stochastic model (white noise densities and bias priors).
struct ImuNoiseModel {
  double gyro_noise_density_rad_per_sqrt_s = 0.0;  // angle random walk
  double acc_noise_density_m_s_per_sqrt_s = 0.0;   // velocity random walk
  double gyro_bias_sigma_rad_s = 0.0;              // prior 1-sigma of the (constant) gyro bias
  double acc_bias_sigma_m_s2 = 0.0;                // prior 1-sigma of the accelerometer bias
  // Floors added in quadrature to the motion residuals' sigmas: unmodelled effects of the
  // preintegration (vibration, second-order terms) [rad], [m/s], [m].
  double rotation_floor_rad = 1e-7;
  double velocity_floor_m_s = 1e-6;
  double position_floor_m = 2e-6;
  // Output quantisation of the increments (LSB) [rad], [m/s]; 0 if none. The rest means carry
  // at most one LSB over their duration (added by frame_calibration.cpp).
  double gyro_quantization_rad = 0.0;
  double acc_quantization_m_s = 0.0;
};

struct FrameCalibrationInput {
  const ims::ImuSeries* imu = nullptr;  // increments (ImuQuantity::kIncrements), IMS clock
  ims::Site site;
  KinematicModel kinematics;
  std::vector<RestObservation> rests;  // in time order, at least 3
  RobotJointSeries robot;              // may be empty: then dt stays at its initial value
  ImuNoiseModel noise;
  double time_offset_initial_s = 0.0;  // t_ims = t_robot + dt, e.g. from estimate_time_offset
  std::string source;                  // for messages (file names)
  // The sensor's position at the first rest relative to the site point (W origin of the gravity
  // model) [m]: only for the gravity field (normal gravity falls by 3.1e-6 m/s^2 per metre of
  // height, 0.3 ug per 1 m); a tape-measure value is plenty. Zero: the sensor at the site point.
  Eigen::Vector3d first_rest_position_W_m = Eigen::Vector3d::Zero();
};

struct FrameCalibrationOptions {
  bool estimate_time_offset = true;
  bool estimate_scale_factors = false;  // accelerometer and gyro scale factors (3 + 3)
  // Per-joint factors k_w, k_p of the modelled wind-up and play of the rests
  // (RestObservation::q_windup_rad, q_play_rad): the link angle of rest i is
  //   q_link + dq_i + (1 - k_w) q_windup + (1 - k_p) q_play,
  // i.e. k = 1 the robot file's stiffness and play are right, k = 0 the drives are rigid and
  // without play at rest. Prior N(1, deflection_scale_sigma) each; joints whose modelled
  // deflection is zero at every rest keep k = 1. The rest poses see k through the gravity
  // torques that change from pose to pose (wind-up) and the tilt of loaded joints (play).
  bool estimate_deflection_scale = true;
  double deflection_scale_sigma = 1.0;
  // Robust loss on the per-pose and per-motion residual blocks (Huber, in units of sigma).
  double huber_scale_sigma = 3.0;
  // A pose or motion whose normalised residual (sqrt of its chi-square / dof) exceeds this is
  // listed as an outlier.
  double outlier_threshold_sigma = 4.0;
  // Gyro-rate residuals during motion: averaged over windows of this length (decorrelates the
  // model error of the joint-reading rates), only where the flange turns faster than
  // min_rate_rad_s.
  double rate_window_s = 0.02;
  double min_rate_rad_s = 0.05;
  int max_iterations = 100;
  // Ceres linear solver: SPARSE_NORMAL_CHOLESKY (SuiteSparse) for the sparse per-pose blocks.
  bool sparse = true;
  bool report_progress = false;  // Ceres per-iteration log
};

// An estimated quantity with its 1-sigma, in reporting units.
struct EstimatedVector {
  std::string name;                     // e.g. "T_S_H.rotation", "gyro_bias"
  std::string unit;                     // e.g. "deg", "mm", "deg/h", "ug", "ms"
  std::vector<std::string> components;  // e.g. {"x", "y", "z"} or {"roll", "pitch", "yaw"}
  Eigen::VectorXd value;
  Eigen::VectorXd sigma;
};

// A direction of the unknowns the data does not determine (or only weakly).
struct WeakDirection {
  std::string description;  // "heading of R in W (rotation of T_R_W about the vertical)"
  double sigma = 0.0;       // its 1-sigma in `unit`
  std::string unit;
  std::string suggestion;  // "add rest time or a heading reference", "add rotations about x_H"
};

struct PoseResidual {
  std::string label;
  double normalised = 0.0;    // sqrt(chi-square / dof) of the pose's residuals
  double rotation_rad = 0.0;  // attitude residual (accelerometers/gyros at rest)
  double position_m = 0.0;    // for motions: position residual at the end
  bool outlier = false;
};

struct FrameCalibrationResult {
  Eigen::Isometry3d T_R_W = Eigen::Isometry3d::Identity();  // W origin: see convention above
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  ImuBiases biases;
  Eigen::Vector3d gyro_scale_factor = Eigen::Vector3d::Zero();  // dimensionless (1e-6 = 1 ppm)
  Eigen::Vector3d acc_scale_factor = Eigen::Vector3d::Zero();
  double time_offset_s = 0.0;  // t_ims = t_robot + time_offset_s
  // Per rest: the estimated link angle minus RestObservation::q_link_rad (dq_i plus the scaled
  // wind-up and play, see estimate_deflection_scale) [rad].
  std::vector<JointVector> joint_deviation_rad;
  // The factors k_w, k_p of estimate_deflection_scale (1: the robot file's model; 1 where not
  // estimated) with their 1-sigma (0 where not estimated).
  JointVector windup_scale = JointVector::Ones();
  JointVector play_scale = JointVector::Ones();
  JointVector windup_scale_sigma = JointVector::Zero();
  JointVector play_scale_sigma = JointVector::Zero();

  // Tangent-space covariance of the frames, biases and time offset in the order of
  // `parameter_names` (rotations as small angles in the left frame: R_W_R, R_S_H; positions;
  // biases; dt) [SI]; correlations derived from it.
  std::vector<std::string> parameter_names;
  Eigen::MatrixXd covariance;
  Eigen::MatrixXd correlation;
  bool covariance_rank_deficient = false;  // pseudo-inverse used; see weak_directions
  std::vector<EstimatedVector> estimates;  // the same in reporting units with 1-sigma
  std::vector<WeakDirection> weak_directions;

  std::vector<PoseResidual> rest_residuals;
  std::vector<PoseResidual> motion_residuals;
  std::vector<std::string> outliers;  // labels, with the reason

  // Initial values (closed-form hand-eye + cross-correlation) for the record.
  Eigen::Isometry3d initial_T_R_W = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d initial_T_S_H = Eigen::Isometry3d::Identity();
  double initial_time_offset_s = 0.0;

  std::string solver_brief_report;  // ceres::Solver::Summary::BriefReport()
  int iterations = 0;
  double final_cost = 0.0;
  bool converged = false;
};

// Solves the bundle from automatic initial values. Throws InputError for unusable input (no
// increments, rests outside the record, fewer than 3 rests) and HandEyeUnobservable
// (calib/hand_eye.hpp) when the rest poses cannot determine the frames (too few, identical, no
// rotation about one axis), naming the missing directions.
FrameCalibrationResult calibrate_frames(const FrameCalibrationInput& input,
                                        const FrameCalibrationOptions& options = {});

// A known T_R_W (e.g. simulation truth with W's origin at the site) moved to this file's
// convention: W's origin at the sensor's position at the first rest pose, given the true T_S_H
// and the true link-side joint angles of that pose.
Eigen::Isometry3d frame_calibration_truth_convention(const Eigen::Isometry3d& T_R_W_true,
                                                     const Eigen::Isometry3d& T_S_H_true,
                                                     const KinematicModel& kinematics,
                                                     const JointVector& q_link_first_rest_rad);

}  // namespace imscal::calib
