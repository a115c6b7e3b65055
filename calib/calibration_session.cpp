// One calibration session (calib/calibration_session.hpp): rests and the initial clock offset,
// the bundle, the mounting validation and the joint errors.
#include "calib/calibration_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "calib/rest_sufficiency.hpp"
#include "core/input_error.hpp"
#include "ims/zupt_options.hpp"

namespace imscal::calib {
namespace {

void report(const SessionProgress& progress, const std::string& stage, double fraction) {
  if (progress) progress(stage, fraction);
}

RestPoseOptions rest_pose_options(const CalibrationConfig& config) {
  RestPoseOptions options;
  options.min_duration_s = config.rests.min_duration_s;
  options.edge_trim_s = config.rests.trim_s;
  options.detector_threshold_sigmas = config.rests.detector_threshold_sigmas;
  options.max_joint_spread_rad = config.rests.max_joint_spread_rad;
  options.settle_tolerance_rad = config.rests.settle_tolerance_rad;
  options.deflection.model_uncertainty_fraction = config.priors.deflection_uncertainty_fraction;
  options.deflection.sigma_floor_rad = config.priors.joint_sigma_floor_rad;
  return options;
}

// Rests at a zero clock offset, the initial offset from their first one, and the rests again at
// that offset (the robot log's poses are matched to the IMS rests on the IMS clock).
void find_rests_and_time_offset(const SessionInputs& in, const CalibrationConfig& config,
                                const SessionProgress& progress, SessionResult& out) {
  report(progress, "rests", 0.0);
  RestPoseInput rest_input;
  rest_input.imu = &in.imu;
  rest_input.log = &in.log;
  rest_input.robot = &in.robot;
  rest_input.sensor = in.sensor;
  rest_input.site = *in.imu.site;
  rest_input.payload.mass_kg = config.payload.mass_kg;
  rest_input.payload.com_m = config.payload.com_T_m;
  rest_input.source = in.source;
  const RestPoseOptions rest_options = rest_pose_options(config);
  const RestPoseResult detection = find_rest_poses(rest_input, rest_options);
  if (detection.detection.intervals.empty())
    throw InputError(in.source, 0, "",
                     "no rest found in the IMS record: the record must start at rest and the "
                     "robot must stop in the calibration poses");
  report(progress, "time offset", 0.0);
  TimeOffsetOptions dt_options;
  dt_options.max_abs_offset_s = config.max_abs_time_offset_s;
  out.initial_time_offset = estimate_initial_time_offset(
      in.imu, in.log, in.robot.kinematics, detection.detection.intervals.front(), dt_options);
  spdlog::info("calibrate: initial time offset {:.3f} ms (correlation peak {:.3f})",
               out.initial_time_offset.offset_s * 1e3, out.initial_time_offset.peak_correlation);
  rest_input.time_offset_s = out.initial_time_offset.offset_s;
  report(progress, "rests", 0.5);
  out.rests = find_rest_poses(rest_input, rest_options);
  for (const auto& why : out.rests.rejected) spdlog::warn("calibrate: rest not used: {}", why);
  for (const auto& why : out.rests.trimmed) spdlog::warn("calibrate: rest used in part: {}", why);
  spdlog::info("calibrate: {} rest poses ({} rejected)", out.rests.rests.size(),
               out.rests.rejected.size());
  if (auto shortage = rest_shortage(out.rests, in.log, rest_options)) {
    spdlog::warn("calibrate: {}", *shortage);
    out.rest_shortage = std::move(*shortage);
  }
}

FrameCalibrationInput bundle_input(const SessionInputs& in, const CalibrationConfig& config,
                                   const SessionResult& out) {
  FrameCalibrationInput frame_input;
  frame_input.imu = &in.imu;
  frame_input.site = *in.imu.site;
  frame_input.kinematics = in.robot.kinematics;
  frame_input.rests = out.rests.rests;
  // With the robot description: the link-side friction lag of each drive (c / k) that the
  // bundle estimates with the clock offset (calib/frame_calibration.hpp).
  frame_input.robot = robot_joint_series(in.log, in.robot);
  frame_input.noise = imu_noise_model(in.sensor, config.priors);
  frame_input.time_offset_initial_s = out.initial_time_offset.offset_s;
  frame_input.source = in.source;
  frame_input.first_rest_position_W_m = config.first_rest_position_W_m;
  if (in.previous) frame_input.known_frames = in.previous->frames;
  frame_input.heading_reference = config.heading_reference;
  return frame_input;
}

// The bundle's options; with an earlier session's frames, its link share as the prior.
FrameCalibrationOptions bundle_options(const SessionInputs& in, const CalibrationConfig& config) {
  FrameCalibrationOptions bundle = config.bundle;
  if (!in.previous) return bundle;
  spdlog::info("calibrate: T_R_W's rotation and T_S_H held at {} (sha256 {})", in.previous->path,
               in.previous->sha256);
  // The drives' link share as that session found it, as this one's prior: it trades against
  // the clock offset, which a record with few rests and short pauses separates poorly
  // (measured: 0.32 +- 0.06 here against 0.06 +- 0.07 there, and the clock 0.1 ms off).
  if (in.previous->link_share) {
    bundle.link_share_prior_mean = *in.previous->link_share;
    bundle.link_share_prior_sigma = *in.previous->link_share_sigma;
    spdlog::info("calibrate: link share prior {:.3f} +- {:.3f} from {}",
                 bundle.link_share_prior_mean, bundle.link_share_prior_sigma, in.previous->path);
  }
  return bundle;
}

JointSpaceErrors session_joint_errors(const SessionInputs& in, const SessionResult& out,
                                      const SessionOptions& options) {
  const FrameCalibrationResult& result = out.frames;
  JointSpaceInput js;
  js.imu = &in.imu;
  js.log = &in.log;
  js.site = *in.imu.site;
  js.kinematics = in.robot.kinematics;
  js.frames = {result.T_R_W, result.T_S_H, result.biases, result.time_offset_s};
  js.first_rest = out.rests.rests.front();
  if (!result.joint_deviation_rad.empty())
    js.first_rest.q_link_rad += result.joint_deviation_rad.front();
  js.zupt = ims::zupt_options_from_spec(in.sensor);
  js.source = in.source;
  JointSpaceOptions joint_space;
  joint_space.row_sink = options.joint_error_rows;
  JointSpaceErrors errors = joint_space_errors(js, joint_space);
  spdlog::info("calibrate: joint errors at {} robot samples", errors.sums.rows);
  return errors;
}

}  // namespace

MountingValidation previous_frames_validation(const FrameCalibrationResult& result,
                                              const MountingThresholds& thresholds,
                                              double outlier_threshold_sigma,
                                              const SessionFrames& previous) {
  MountingValidation v = assess_mounting(result, {}, {}, thresholds);
  double worst = 0.0;
  for (const auto* list : {&result.rest_residuals, &result.motion_residuals})
    for (const auto& r : *list) worst = std::max(worst, r.normalised);
  const std::size_t motions = result.motion_residuals.size();
  MountingCheck check;
  check.name = "previous_frames";
  if (motions == 0) {
    check.level = Verdict::kWarn;
    check.message = fmt::format(
        "frames held at {}: with {} rest and no motion between rests the biases absorb the rest "
        "residuals, so a slipped mount cannot be seen against these frames (record 2 or more "
        "rests)",
        previous.path, result.rest_residuals.size());
  } else {
    check.level = Verdict::kPass;
    check.message = fmt::format(
        "frames held at {}: this record's {} rests and {} motions against them, largest "
        "normalised residual {:.2f} sigma (outlier above {}; a slipped mount shows there)",
        previous.path, result.rest_residuals.size(), motions, worst, outlier_threshold_sigma);
  }
  v.checks.push_back(check);
  if (check.level != Verdict::kPass) {
    if (v.verdict == Verdict::kPass) v.reasons.clear();  // the "all passed" line
    v.verdict = std::max(v.verdict, check.level);
    v.reasons.push_back(check.message);
  }
  return v;
}

SessionResult calibrate_session(const SessionInputs& in, const SessionOptions& options,
                                const SessionProgress& progress) {
  const CalibrationConfig& config = options.config;
  if (!in.imu.site)
    throw InputError(in.source, 0, "site", "the IMS record states no site (gravity, Earth rate)");
  check_heading_reference(config.heading_reference,
                          in.previous ? std::optional(in.previous->frames) : std::nullopt,
                          in.source);
  SessionResult out;
  find_rests_and_time_offset(in, config, progress, out);

  report(progress, "bundle", 0.0);
  FrameCalibrationInput frame_input = bundle_input(in, config, out);
  out.frames = calibrate_frames(frame_input, bundle_options(in, config));
  spdlog::info("calibrate: bundle {} after {} iterations",
               out.frames.converged ? "converged" : "did NOT converge", out.frames.iterations);

  // Mounting validation: with the frames of an earlier session, this record's residuals against
  // them (the halves and segments would calibrate frames, which this record need not determine).
  out.validation =
      in.previous
          ? previous_frames_validation(out.frames, config.validation.thresholds,
                                       config.bundle.outlier_threshold_sigma, *in.previous)
          : validate_mounting(frame_input, config.bundle, out.frames, config.validation, progress);
  frame_input.robot = {};  // the joint series, as long as the record: done with
  if (config.joint_errors) {
    report(progress, "joint errors", 0.0);
    out.joint_errors = session_joint_errors(in, out, options);
  }
  return out;
}

}  // namespace imscal::calib
