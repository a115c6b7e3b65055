#pragma once
// The frame-and-bias bundle: one Ceres problem for T_R_W (robot base R in the Earth-fixed W),
// T_S_H (flange H in the sensor frame S), the IMS biases and the time offset between the robot
// clock and the IMS clock, from a record in which the robot stops in a set of rest poses and
// moves between them.
//
// Measurements (W Earth-fixed ENU, gravity g_W(p) and Earth rate Omega from ims::EarthModel):
//  - rest pose i (robot still over [begin_ims_s, end_ims_s]): the mean specific force equals
//    -R_S_W g_W + b_a,i, the mean angular rate R_S_W Omega + b_g, with
//    R_W_S_i = R_W_R R_R_H(q_i + dq_i) R_H_S from the forward kinematics of the rest pose's
//    link-side joint angles q_i plus a per-pose joint deviation dq_i (backlash play, unmodelled
//    deflection; prior N(0, q_link_sigma_rad));
//  - motion i -> i+1: the IMU preintegration (calib/imu_preintegration.hpp, bias Jacobians,
//    Earth rate, Coriolis) from rest i at zero velocity must arrive at rest i+1 with zero
//    velocity, the attitude and the position of the forward kinematics (accelerometer bias: the
//    mean of b_a,i and b_a,i+1);
//  - the accelerometer bias drifts between rests as a random walk (ImuNoiseModel::
//    acc_bias_drift_psd; one constant b_a when it is 0);
//  - during motion: the gyro rate minus bias minus Earth rate equals R_S_H omega_H(t_ims - dt),
//    omega_H from the robot's joint readings (this is what makes the time offset dt observable).
//    The readings are motor-side: the link lags them by the gear deflection that the friction at
//    the gear output causes, s c_j / k_j per joint for a share s of the viscous friction c_j
//    acting there (stiffness k_j; 15-75 us on the KR 16 at s = 0.1). That lag looks like a clock
//    offset, so s is estimated with dt (it differs per joint, dt does not): omega_H - s lag_H.
//
// Convention for the origin of W (the IMS senses no absolute position): W's origin is the
// sensor's position at the first rest pose, so the translation of T_R_W is not a free
// parameter but follows from the rest of the solution. Compare with a truth expressed in the
// same convention (frame_calibration_truth_convention below).
//
// Observability: the heading of R in W (rotation of T_R_W about the vertical) is seen only
// through the Earth rate (gyrocompassing): its 1-sigma is about
// k ARW / (|Omega| cos(latitude) sqrt(total rest time)), k = 1.45 with the gyro bias estimated
// from the same 8 mounting poses (tests/calib/test_heading_observability.cpp), e.g. 0.064 deg
// for a 0.002 deg/sqrt(h) gyro over 4 minutes of rest; 0.005 deg takes ~11 h. The covariance
// reports it as it is; the observability report names it.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "calib/imu_preintegration.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "robot/robot_description.hpp"

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
  // Creep: a still-commanded arm may still move slowly after a move (the joint controllers
  // settle through friction; 1e-5..1e-4 rad over a rest on the elastic KR 16). The joint readings
  // at the window's begin and end minus q_link_rad's reading (the mean), and the joint rates
  // there [rad], [rad/s]: the gear deflection does not change measurably during such creep, so
  // the link moves by the same amounts (calib/rest_poses.cpp fills them from the robot log;
  // zero: the robot is still). The bundle uses them for the mean rate and acceleration over the
  // rest and for the poses and velocities at the ends of the motions.
  JointVector q_creep_begin_rad = JointVector::Zero();
  JointVector q_creep_end_rad = JointVector::Zero();
  JointVector q_rate_begin_rad_s = JointVector::Zero();
  JointVector q_rate_end_rad_s = JointVector::Zero();
};

// The robot's joint readings, for the flange rate during motion (time offset) [robot clock].
struct RobotJointSeries {
  std::vector<double> t_robot_s;
  std::vector<JointVector> q_rad;  // internal (motor-side) readings are fine: rates only
  // Per joint, c_j / k_j: how far the link lags the reading if all of the drive's viscous
  // friction acted at the gear output [s] (robot_joint_series(log, robot) fills it from the
  // robot file). Zero: the readings are taken as link rates (no link share estimated).
  JointVector link_lag_per_share_s = JointVector::Zero();
};

// The sensor's stochastic model (white noise densities and bias priors).
struct ImuNoiseModel {
  double gyro_noise_density_rad_per_sqrt_s = 0.0;  // angle random walk
  double acc_noise_density_m_s_per_sqrt_s = 0.0;   // velocity random walk
  double gyro_bias_sigma_rad_s = 0.0;              // prior 1-sigma of the (constant) gyro bias
  double acc_bias_sigma_m_s2 = 0.0;                // prior 1-sigma of the accelerometer bias
  // Power spectral density of the accelerometer bias's in-run drift, modelled as a random walk
  // between the rests: each rest has its own bias, b_(i+1) - b_i ~ N(0, psd dt_i) per axis (the
  // spec's Gauss-Markov terms: sum of 2 sigma^2 / tau; 10 ug over 600 s drifts by 1.6 ug in 8 s
  // and 5.5 ug over 110 s, against 0.4 ug of white noise in all the rests of a campaign)
  // [(m/s^2)^2 / s]. 0: one constant bias. The gyro bias stays constant: its drift (0.0008 deg/h
  // over 2 min for a navigation-grade unit) is far below what the rests resolve.
  double acc_bias_drift_psd = 0.0;
  // Floors added in quadrature to the motion residuals' sigmas: unmodelled effects of the
  // preintegration (vibration, second-order terms) [rad], [m/s], [m].
  double rotation_floor_rad = 1e-7;
  double velocity_floor_m_s = 1e-6;
  double position_floor_m = 2e-6;
  // Output quantisation of the increments (LSB) [rad], [m/s]; 0 if none. The rest means carry
  // at most one LSB over their duration (added by calib/frame_noise.cpp).
  double gyro_quantization_rad = 0.0;
  double acc_quantization_m_s = 0.0;
};

// T_R_W's rotation and T_S_H from an earlier session with the same robot, base and mount (its
// frames.json): the bundle then holds them and estimates only what changes between sessions,
// the biases (turn-on), the clock offset and the per-rest unknowns, from as few as one rest.
// W's origin stays the convention above (the sensor at this record's first rest): T_R_W's
// translation is derived anew, only its rotation R_W_R is taken.
struct KnownFrames {
  Eigen::Matrix3d R_W_R = Eigen::Matrix3d::Identity();
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  // Their tangent covariance from the earlier session, [R_W_R (rad, small angles about W ENU),
  // R_S_H (rad, about S), p_S_H (m)]: reported in the result's covariance as it is (the rest of
  // the covariance is conditional on these frames: the bundle does not move them).
  Eigen::Matrix<double, 9, 9> covariance = Eigen::Matrix<double, 9, 9>::Zero();
  std::string source;  // e.g. the frames.json path, for messages
};

// A surveyed heading of the robot base (e.g. from a total station or the site's floor plan):
// the yaw of T_W_R, R_W_R = Rz(yaw) Ry(pitch) Rx(roll), i.e. the base's x axis counterclockwise
// from East about the vertical (frames.json's T_W_R.rpy_deg[2]) [rad], with its 1-sigma [rad].
// The bundle adds it as a prior residual on R_W_R's yaw (not a held value): the covariance, the
// mounting verdict and the report then carry both it and what the IMS sees through the Earth
// rate (FrameCalibrationResult::heading).
struct HeadingReference {
  double yaw_rad = 0.0;
  double sigma_rad = 0.0;  // > 0
  std::string source;      // where it came from, for messages ("--heading-reference", a file)
};

struct FrameCalibrationInput {
  const ims::ImuSeries* imu = nullptr;  // increments (ImuQuantity::kIncrements), IMS clock
  ims::Site site;
  KinematicModel kinematics;
  std::vector<RestObservation> rests;  // in time order, at least 3 (1 with known_frames)
  RobotJointSeries robot;              // may be empty: then dt stays at its initial value
  ImuNoiseModel noise;
  double time_offset_initial_s = 0.0;  // t_ims = t_robot + dt, e.g. from estimate_time_offset
  std::string source;                  // for messages (file names)
  // The sensor's position at the first rest relative to the site point (W origin of the gravity
  // model) [m]: only for the gravity field (normal gravity falls by 3.1e-6 m/s^2 per metre of
  // height, 0.3 ug per 1 m); a tape-measure value is plenty. Zero: the sensor at the site point.
  Eigen::Vector3d first_rest_position_W_m = Eigen::Vector3d::Zero();
  // Set: the frames are held at these values (KnownFrames above), not estimated.
  std::optional<KnownFrames> known_frames;
  // Set: a prior on the base's yaw (refused with known_frames, which hold R_W_R).
  std::optional<HeadingReference> heading_reference;
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
  // How well the joint readings describe a creeping arm's motion at the rests
  // (RestObservation::q_creep_*): their sigma as a fraction of the creep's mean rate,
  // acceleration and end velocities (the gears' transmission error: up to A N ~ 1 % of the
  // motor's motion for 10 arcsec at N = 160; the friction's share at the gear output) [1].
  double creep_model_fraction = 0.02;
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
  // The link share s of the drives' viscous friction (see the measurements above), estimated
  // with dt when RobotJointSeries::link_lag_per_share_s is set; prior N(mean, sigma): anywhere
  // in [0, 1] (all at the motor .. all at the gear output).
  bool estimate_link_share = true;
  double link_share_prior_mean = 0.5;
  double link_share_prior_sigma = 0.5;
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

// The heading of the robot base (yaw of T_W_R, see HeadingReference) as the bundle found it,
// and from the IMS alone (gyrocompassing through the Earth rate): without a reference both are
// the same; with one, the IMS-only figures are the posterior's with the reference's information
// taken out again (1 / sigma_ims^2 = 1 / sigma^2 - 1 / sigma_ref^2, the estimate likewise; exact
// for a linear problem, checked against a solve without the reference in
// tests/calib/test_heading_reference.cpp) [rad].
struct HeadingEstimate {
  double yaw_rad = 0.0;
  double sigma_rad = 0.0;
  double ims_only_yaw_rad = 0.0;
  double ims_only_sigma_rad = 0.0;  // infinite when the IMS alone does not see the heading
  std::optional<HeadingReference> reference;
};

struct FrameCalibrationResult {
  Eigen::Isometry3d T_R_W = Eigen::Isometry3d::Identity();  // W origin: see convention above
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  // The gyro bias and the accelerometer bias at the first rest (where a smoothing of the record
  // starts); the covariance's acc_bias is that of the first rest too.
  ImuBiases biases;
  std::vector<Eigen::Vector3d> acc_bias_at_rests_m_s2;  // per rest (all equal without drift)
  Eigen::Vector3d gyro_scale_factor = Eigen::Vector3d::Zero();  // dimensionless (1e-6 = 1 ppm)
  Eigen::Vector3d acc_scale_factor = Eigen::Vector3d::Zero();
  double time_offset_s = 0.0;  // t_ims = t_robot + time_offset_s
  // The link share of the drives' viscous friction seen in the rate windows, with its 1-sigma
  // (0 and 0 where not estimated).
  double link_share = 0.0;
  double link_share_sigma = 0.0;
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
  Eigen::VectorXd parameter_values;  // the estimates in that order [SI; rotations: rotation vector]
  Eigen::MatrixXd covariance;
  Eigen::MatrixXd correlation;
  // From the covariance's R_W_R.up; unset when the covariance failed or the frames were held.
  std::optional<HeadingEstimate> heading;
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

  // An entry of the covariance by name: "<block>.<component>" as in parameter_names (e.g.
  // "gyro_bias.x", "R_W_R.up", "windup_scale_deviation.A2"), or the block's name alone when it
  // has one component ("time_offset", "link_share"). Its 1-sigma and its estimate in the
  // covariance's units (SI; rotations: small angles, their value the rotation vector) [rad, m,
  // rad/s, m/s^2, s, 1]. Throw std::out_of_range for a parameter not estimated (or when the
  // covariance failed).
  double sigma(const std::string& name) const;
  double value(const std::string& name) const;
  std::size_t parameter_index(const std::string& name) const;
};

// Solves the bundle from automatic initial values (with input.known_frames: from those frames,
// held constant). Throws InputError for unusable input (no increments, rests outside the record,
// fewer than 3 rests, or none with known_frames) and HandEyeUnobservable
// (calib/hand_eye.hpp) when the rest poses cannot determine the frames (too few, identical, no
// rotation about one axis), naming the missing directions.
FrameCalibrationResult calibrate_frames(const FrameCalibrationInput& input,
                                        const FrameCalibrationOptions& options = {});

// Throws InputError (source, field heading_reference) for a reference with held frames (they hold
// R_W_R) or without a finite yaw and a sigma > 0; calibrate_frames checks it, callers may check
// before long work.
void check_heading_reference(const std::optional<HeadingReference>& heading,
                             const std::optional<KnownFrames>& known_frames,
                             const std::string& source);

// A known T_R_W (e.g. simulation truth with W's origin at the site) moved to this file's
// convention: W's origin at the sensor's position at the first rest pose, given the true T_S_H
// and the true link-side joint angles of that pose.
Eigen::Isometry3d frame_calibration_truth_convention(const Eigen::Isometry3d& T_R_W_true,
                                                     const Eigen::Isometry3d& T_S_H_true,
                                                     const KinematicModel& kinematics,
                                                     const JointVector& q_link_first_rest_rad);

}  // namespace imscal::calib
