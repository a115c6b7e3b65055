#pragma once
// The frame-and-bias bundle's working state (calib/frame_calibration.hpp): its unknowns, the
// switches of its optional models, the parameter layout they declare, and one function per
// group of residual terms and per optional model. calibrate_frames sets a bundle up, solves it
// twice (calib/frame_bundle_solve.cpp) and reports (calib/frame_calibration_report.cpp).
//
// Design:
//  - Unknowns: q_W_R, q_S_H (quaternions, left perturbation), p_S_H, b_g, b_a (per rest when it
//    drifts, ImuNoiseModel::acc_bias_drift_psd), dt with the link share, optional
//    scale factors, dq_i per rest (joints with prior sigma 0 held by a SubsetManifold). W's
//    origin is the sensor at the first rest: p_W_R is derived (never a parameter), and the
//    motion residuals only use position differences, so it needs no residual of its own.
//  - Residuals (calib/frame_residuals.hpp): rest means (6), motions (9, closed-form Brownian
//    covariance with the gravity cross terms, calib/frame_noise.hpp), gyro rate in windows
//    during motion (3 per window, for dt), joint-deviation priors, and with a surveyed heading a
//    prior on the base's yaw (HeadingReference). Scale factors enter only the
//    rests (where 100 ppm of g is 1e-3 m/s^2); the motions take the sensor's scale as exact.
//  - The rate windows carry dt alone (R_S_H, b_g from the previous solution; see RateResidual).
//  - Two solves: the first with a guessed rate-window sigma (1e-3 rad/s); then the window
//    sigma is set to the RMS of the first solve's rate residuals (model error of the joint
//    rates; windows ~independent), the preintegrations are re-linearised at the estimated biases
//    and the Earth rate of every window is taken from the first solution; the second solve gives
//    the result and its covariance.
//  - Huber loss per block with scale huber_scale_sigma * sqrt(block dimension), so that a block
//    at its expected chi-square is not down-weighted.
//  - Ceres sees the parameter and residual blocks in a fixed order (frames, biases, the optional
//    models' blocks, joint deviations, rests, motions, rate windows): build_frame_stage adds
//    them in that order, whatever order the layout reports them in.
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "calib/frame_calibration.hpp"
#include "calib/frame_initialisation.hpp"
#include "calib/frame_measurements.hpp"
#include "calib/frame_parameter_layout.hpp"
#include "calib/frame_residuals.hpp"
#include "calib/imu_preintegration.hpp"

namespace imscal::calib {

// The unknowns as Ceres parameter blocks, all in one buffer. ceres::Covariance orders its
// columns by the blocks' addresses (it sorts the parameter pointers, covariance_impl.cc), and
// its sparse QR rounds by that order: blocks in separate allocations would make the covariance's
// last bits follow the heap's layout (what was allocated and freed before, down to the output
// folder's name). In one buffer the order is fixed: the accelerometer biases, the joint
// deviations, then the named blocks in their declaration order below. A new named block goes into
// kNamedBlocks (frame_bundle.cpp), the one list that sizes the buffer and lays it out.
struct FrameUnknowns {
  FrameUnknowns() = default;
  FrameUnknowns(const FrameUnknowns&) = delete;  // the pointers below point into storage_
  FrameUnknowns& operator=(const FrameUnknowns&) = delete;

  // Lays the buffer out for `rest_count` rests and `acc_bias_count` accelerometer-bias blocks
  // (1, or one per rest when it drifts) and sets the initial values (identity rotations, zeros).
  void allocate(std::size_t rest_count, std::size_t acc_bias_count);

  double* q_W_R = nullptr;  // 4, Eigen order x, y, z, w
  double* q_S_H = nullptr;  // 4
  double* p_S_H = nullptr;  // 3
  double* b_g = nullptr;    // 3
  // Accelerometer bias blocks (3 each); b_a_blocks per rest (without drift all the one block).
  std::vector<double*> b_a;
  std::vector<double*> b_a_blocks;
  double* dt = nullptr;          // 1
  double* link_share = nullptr;  // 1
  double* s_g = nullptr;         // 3
  double* s_a = nullptr;         // 3
  double* m_w = nullptr;         // 6: 1 - k_w (estimate_deflection_scale)
  double* m_p = nullptr;         // 6: 1 - k_p
  std::vector<double*> dq;       // 6 per rest
  const std::vector<RestObservation>* rests = nullptr;

  Eigen::Matrix3d R_W_R() const;
  Eigen::Matrix3d R_S_H() const;
  ImuBiases biases() const;  // the accelerometer bias of the first rest
  // dq_i plus the scaled wind-up and play of rest i.
  JointVector joint_deviation(std::size_t i) const;

 private:
  std::vector<double> storage_;  // every block above, allocated once
};

// The deflection-scale model: per joint, estimated only where some rest has a modelled wind-up /
// play (FrameCalibrationOptions::estimate_deflection_scale).
struct DeflectionScaleModel {
  std::vector<int> fixed_windup, fixed_play;  // joints held at k = 1
  JointVector windup_inverse_sigma = JointVector::Zero();
  JointVector play_inverse_sigma = JointVector::Zero();
  bool windup_estimated() const { return fixed_windup.size() < std::size_t{kJointCount}; }
  bool play_estimated() const { return fixed_play.size() < std::size_t{kJointCount}; }
};

// omega_H(t) and lag_H(t) (calib/frame_residuals.hpp, RateResidual) on a uniform robot-time
// grid, from the joint readings (central differences).
struct FlangeRateGrid {
  double t0_s = 0.0;
  double step_s = 1.0;
  std::vector<double> values;  // 6 per node
  std::unique_ptr<ceres::Grid1D<double, 6>> grid;
  std::unique_ptr<RateResidual::Interpolator> interpolator;
  double t_end_s() const { return t0_s + step_s * static_cast<double>(values.size() / 6 - 1); }
};

// A window of the gyro rate during motion (time-offset model).
struct RateWindow {
  std::size_t first = 0;
  std::size_t count = 0;
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero();
  std::vector<double> mid_times;
  Eigen::Matrix3d R_R_H_mid = Eigen::Matrix3d::Identity();  // flange attitude (Earth-rate term)
};

// What a rest's creep (RestObservation::q_creep_*, q_rate_*) means for the sensor.
struct RestCreep {
  Eigen::Vector3d mean_rate_H = Eigen::Vector3d::Zero();          // [rad/s]
  Eigen::Vector3d mean_acceleration_R = Eigen::Vector3d::Zero();  // [m/s^2]
  Eigen::Vector3d velocity_begin_R = Eigen::Vector3d::Zero();     // [m/s]
  Eigen::Vector3d velocity_end_R = Eigen::Vector3d::Zero();
};

// One solve: its problem and the functors of its residuals (for the residual report).
struct FrameStage {
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ImuPreintegration> motions;
  std::vector<RestResidual> rest_functors;
  std::vector<MotionResidual> motion_functors;
  std::vector<Eigen::Matrix<double, 9, 9>> motion_covariance_factor;  // L (raw = L * whitened)
  std::vector<RateResidual> rate_functors;
  ceres::Solver::Summary summary;
};

// The bundle: set up from the input (checks, rest windows, initial values, optional models,
// layout). Holds pointers into itself (layout, b_a_blocks): neither copied nor moved.
struct FrameBundle {
  FrameBundle(const FrameCalibrationInput& input, const FrameCalibrationOptions& options);
  FrameBundle(const FrameBundle&) = delete;
  FrameBundle& operator=(const FrameBundle&) = delete;

  const FrameCalibrationInput& input;
  const FrameCalibrationOptions& options;
  std::string source;  // for messages
  ims::EarthModel earth;
  std::vector<RestWindow> rests;
  std::vector<ImuPreintegration> chain_motions;  // at zero biases, for the initial values
  FrameInitialValues init;
  FrameUnknowns x;

  // Optional models.
  bool frames_known = false;          // KnownFrames: frames held, bias priors
  bool acc_bias_drifts = false;       // a b_a per rest with a random walk between them
  DeflectionScaleModel deflection;    // wind-up and play scales
  bool time_offset_observed = false;  // rate windows exist and dt is estimated
  bool link_share_estimated = false;  // with dt, where the robot file gives the lags
  std::unique_ptr<FlangeRateGrid> rate_grid;
  std::vector<RateWindow> rate_windows;
  double rate_window_noise = 0.0;  // white-noise floor of a window's mean rate [rad/s]
  double rate_sigma = 1e-3;        // first solve: a guess [rad/s]; the second: the data's RMS

  FrameParameterLayout layout;  // the reported blocks, declared by the models above
};

// Residual groups (calib/frame_bundle_residuals.cpp), in the order build_frame_stage adds them.
void add_frame_and_bias_blocks(FrameBundle& b, ceres::Problem& problem);
void add_joint_deviations(FrameBundle& b, ceres::Problem& problem);
std::vector<Eigen::Vector3d> rest_positions_W(const FrameBundle& b);  // gravity field only [m]
std::vector<RestCreep> rest_creeps(const FrameBundle& b);
void add_rest_residuals(FrameBundle& b, FrameStage& stage, const std::vector<Eigen::Vector3d>& p_W,
                        const std::vector<RestCreep>& creep);
void add_motion_residuals(FrameBundle& b, FrameStage& stage,
                          const std::vector<Eigen::Vector3d>& p_W,
                          const std::vector<RestCreep>& creep);

// Optional models (calib/frame_bundle_models.cpp): set_up_* at construction (switches, initial
// values, layout), add_* per solve.
void set_up_deflection_scale(FrameBundle& b);
void set_up_time_offset(FrameBundle& b);
void add_known_frames(FrameBundle& b, ceres::Problem& problem);
void add_heading_reference(FrameBundle& b, ceres::Problem& problem);
void add_acc_bias_drift(FrameBundle& b, ceres::Problem& problem);
void add_scale_factors(FrameBundle& b, ceres::Problem& problem);
void add_deflection_scale(FrameBundle& b, ceres::Problem& problem);
void add_time_offset(FrameBundle& b, FrameStage& stage);
RateResidual rate_functor(const FrameBundle& b, const RateWindow& w);  // at the current x

// Solving (calib/frame_bundle_solve.cpp): the problem of one stage at the biases `linearisation`
// (preintegrations), and both solves; returns {first, final}.
void build_frame_stage(FrameBundle& b, FrameStage& stage, const ImuBiases& linearisation);
void solve_frame_stage(const FrameBundle& b, FrameStage& stage);
std::pair<FrameStage, FrameStage> solve_frame_bundle(FrameBundle& b);

// Reporting (calib/frame_calibration_report.cpp): the result of the solved bundle.
FrameCalibrationResult report_frame_bundle(const FrameBundle& b, const FrameStage& first,
                                           FrameStage& final_stage);

}  // namespace imscal::calib
