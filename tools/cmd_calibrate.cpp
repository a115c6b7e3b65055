// `imscal calibrate --imu FILE --robot-log FILE --robot ROBOT.yaml --sensor SPEC.yaml
//  [--config YAML] [--unit-calibration YAML] [--frames PREVIOUS/frames.json] --out DIR [--force]`:
//  the wrist/sensor calibration of the paper. From the raw
// IMS record and the robot's log: rest poses (calib/rest_poses.hpp), the frame-and-bias bundle
// (calib/frame_calibration.hpp: T_R_W, T_S_H, biases, time offset with covariance), the mounting
// validation (calib/mounting_validation.hpp) and the joint errors (calib/joint_space_errors.hpp).
// Writes, all or nothing (core/output_folder.hpp), the files of datasets/FORMAT.md §16:
//   frames.json  mounting_report.json  summary.txt  joint_errors.csv
// With --frames (a later session with the same robot, base and mount, e.g. identification runs
// with too few rests for the frames): T_R_W's rotation and T_S_H are taken from the earlier
// session's frames.json and held; the bundle estimates the biases and the clock offset from as
// few as one rest, and the mounting report gives this record's residuals against those frames
// (a slipped mount shows there) instead of the halves and segments (which calibrate frames).
// Exit codes: 0 verdict pass or warn, 1 verdict fail (the outputs are still written), 2 bad input.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

#include "calib/calibration_config.hpp"
#include "calib/calibration_json.hpp"
#include "calib/frame_calibration.hpp"
#include "calib/frames_json.hpp"
#include "calib/joint_space_errors.hpp"
#include "calib/mounting_report_json.hpp"
#include "calib/mounting_validation.hpp"
#include "calib/rest_poses.hpp"
#include "calib/robot_description.hpp"
#include "calib/robot_log.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "core/progress.hpp"
#include "core/sha256.hpp"
#include "core/units.hpp"
#include "core/version.hpp"
#include "ident/joint_error_io.hpp"
#include "ims/imu_conversion.hpp"
#include "ims/imu_file.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/zupt_options.hpp"
#include "tools/command_registry.hpp"
#include "tools/joint_limit_checks.hpp"

namespace {
namespace fs = std::filesystem;
namespace calib = imscal::calib;
using nlohmann::json;
using namespace imscal;

struct CalibrateArgs {
  std::string imu;
  std::string robot_log;
  std::string robot;
  std::string sensor;
  std::string config;
  std::string unit_calibration;
  std::string frames;  // earlier session's frames.json (--frames); empty: estimate the frames
  std::string out;
  bool force = false;
};

json input_json(const std::string& file) {
  if (file.empty()) return nullptr;
  return {{"path", file}, {"sha256", sha256_hex_of_file(file)}};
}

struct Inputs {
  calib::CalibrationConfig config;
  fs::path robot_file, sensor_file;
  std::optional<fs::path> unit_calibration_file;
  calib::RobotDescription robot;
  ims::SensorSpec spec;
  ims::ImuSeries imu;
  calib::RobotLog log;
  std::optional<calib::SessionFrames> previous;  // --frames
};

// A robot file without drive stiffness (a kinematics-only URDF, say) makes the bundle treat the
// arm as rigid: no gear wind-up, backlash or friction terms, and sigmas that do not contain them.
void warn_if_rigid(const calib::RobotDescription& robot) {
  std::string rigid;
  for (const calib::JointDescription& joint : robot.joints) {
    if (joint.drive.stiffness_nm_per_rad <= 0.0) rigid += (rigid.empty() ? "" : ", ") + joint.name;
  }
  if (rigid.empty()) return;
  spdlog::warn(
      "calibrate: robot {} ({}) gives no drive for {}: the arm is taken as rigid there (no gear "
      "wind-up or backlash at rest, no friction at the link); the sigmas do not include them",
      robot.name, robot.source, rigid);
}

Inputs read_inputs(const CalibrateArgs& args) {
  Inputs in;
  if (!args.config.empty()) in.config = calib::load_calibration_config(args.config);
  auto pick = [&](const std::string& given, const std::optional<fs::path>& from_config,
                  const char* option) {
    if (!given.empty()) return fs::path(given);
    if (from_config) return *from_config;
    throw InputError(
        args.config.empty() ? "command line" : args.config, 0, option,
        fmt::format("no {} file: give {} or the config key '{}'", option + 2, option, option + 2));
  };
  in.robot_file = pick(args.robot, in.config.robot_file, "--robot");
  in.sensor_file = pick(args.sensor, in.config.sensor_file, "--sensor");
  in.robot = calib::load_robot_description(in.robot_file);
  warn_if_rigid(in.robot);
  const std::string rating_of = fmt::format("robot {} ({})", in.robot.name, in.robot.source);
  check_payload_plausible(in.config.payload.mass_kg, in.robot.nominal_payload_kg,
                          {args.config.empty() ? "the calibration defaults" : args.config, 0,
                           "payload.mass_kg", rating_of});
  in.spec = ims::load_sensor_spec(in.sensor_file);
  // The earlier session's frames before the (long) records: a wrong file fails fast.
  if (!args.frames.empty()) in.previous = calib::read_frames_json(args.frames, in.robot.name);
  ims::ImuReadOptions read_options;
  if (in.spec.gyro.range > 0.0) read_options.gyro_range_rad_s = in.spec.gyro.range;
  if (in.spec.acc.range > 0.0) read_options.acc_range_m_s2 = in.spec.acc.range;
  in.imu = ims::read_imu_file(args.imu, read_options);
  if (in.imu.quantity == ims::ImuQuantity::kRates) in.imu = ims::rates_to_increments(in.imu);
  // The unit's lab calibration (scale factors, misalignments): applied to the raw record first.
  in.unit_calibration_file = in.config.unit_calibration_file;
  if (!args.unit_calibration.empty()) in.unit_calibration_file = fs::path(args.unit_calibration);
  if (in.unit_calibration_file) {
    in.imu = ims::correct(in.imu, ims::load_sensor_error_model(*in.unit_calibration_file));
    spdlog::info("calibrate: corrected {} with the unit calibration {}", args.imu,
                 in.unit_calibration_file->string());
  }
  if (!in.imu.site)
    throw InputError(args.imu, 0, "site",
                     "the IMS file does not state its site (site_latitude_deg, "
                     "site_longitude_deg, site_height_m): gravity and Earth rate need it");
  in.log = calib::read_robot_log_csv(args.robot_log, in.robot.name);
  tools::check_robot_log_joint_limits(in.log, args.robot_log, in.robot);
  std::vector<double> payload_kg, t_s;
  for (const calib::RobotLogSample& sample : in.log.samples) {
    payload_kg.push_back(sample.payload_kg);
    t_s.push_back(sample.t_s);
  }
  check_payload_series(payload_kg, t_s, in.robot.nominal_payload_kg,
                       {args.robot_log, 0, "payload_kg", rating_of});
  // The two records must overlap in time (up to the time-offset search range).
  const double imu_begin = in.imu.samples.front().t_s, imu_end = in.imu.samples.back().t_s;
  const double log_begin = in.log.samples.front().t_s, log_end = in.log.samples.back().t_s;
  const double margin = in.config.max_abs_time_offset_s;
  if (imu_end + margin < log_begin || log_end + margin < imu_begin)
    throw InputError(args.imu, 0, "t_s",
                     fmt::format("the IMS record [{:.3f}, {:.3f}] s and the robot log {} "
                                 "[{:.3f}, {:.3f}] s do not overlap in time (clock offsets up to "
                                 "{} s are searched)",
                                 imu_begin, imu_end, args.robot_log, log_begin, log_end, margin));
  return in;
}

std::string summary_text(const CalibrateArgs& args, const calib::FrameCalibrationResult& r,
                         const calib::MountingValidation& v, const calib::RestPoseResult& rests,
                         const calib::TimeOffsetResult& dt0, const calib::JointSpaceErrors* je) {
  std::ostringstream s;
  auto line = [&](const std::string& text) { s << text << '\n'; };
  line(fmt::format("imscal {} calibrate", kVersion));
  line(fmt::format("IMS record  {}", args.imu));
  line(fmt::format("robot log   {}", args.robot_log));
  if (!args.frames.empty())
    line(fmt::format("frames      {} (T_R_W's rotation and T_S_H held: not estimated here)",
                     args.frames));
  line("");
  line(fmt::format("VERDICT: {}", calib::to_string(v.verdict)));
  for (const auto& reason : v.reasons) line("  - " + reason);
  line("");
  line(fmt::format("rests used: {}, rejected: {}", rests.rests.size(), rests.rejected.size()));
  for (const auto& why : rests.rejected) line("  rejected: " + why);
  for (const auto& why : rests.trimmed) line("  trimmed: " + why);
  line(fmt::format("initial time offset (cross-correlation): {:.3f} ms (peak {:.3f})",
                   dt0.offset_s * 1e3, dt0.peak_correlation));
  line(fmt::format("solver: {} ({} iterations, {})", r.converged ? "converged" : "NOT converged",
                   r.iterations, r.solver_brief_report));
  line("");
  line("estimates (value +- 1 sigma):");
  for (const auto& e : r.estimates) {
    std::string values;
    for (Eigen::Index k = 0; k < e.value.size(); ++k)
      values += fmt::format(
          "  {}={:.6g}+-{:.2g}",
          k < Eigen::Index(e.components.size()) ? e.components[std::size_t(k)] : std::to_string(k),
          e.value[k], k < e.sigma.size() ? e.sigma[k] : 0.0);
    line(fmt::format("  {} [{}]:{}", e.name, e.unit, values));
  }
  const Eigen::Vector3d rpy_S_H = calib::roll_pitch_yaw(r.T_S_H.linear()) / kRadPerDeg;
  line(fmt::format("  T_S_H: xyz {:.4f} {:.4f} {:.4f} mm, rpy {:.5f} {:.5f} {:.5f} deg",
                   r.T_S_H.translation().x() * 1e3, r.T_S_H.translation().y() * 1e3,
                   r.T_S_H.translation().z() * 1e3, rpy_S_H.x(), rpy_S_H.y(), rpy_S_H.z()));
  const Eigen::Vector3d rpy_R_W = calib::roll_pitch_yaw(r.T_R_W.linear()) / kRadPerDeg;
  line(
      fmt::format("  T_R_W: xyz {:.4f} {:.4f} {:.4f} mm, rpy {:.5f} {:.5f} {:.5f} deg "
                  "(W origin: the sensor at rest 1)",
                  r.T_R_W.translation().x() * 1e3, r.T_R_W.translation().y() * 1e3,
                  r.T_R_W.translation().z() * 1e3, rpy_R_W.x(), rpy_R_W.y(), rpy_R_W.z()));
  if (!r.weak_directions.empty()) {
    line("");
    line("weak directions:");
    for (const auto& w : r.weak_directions)
      line(
          fmt::format("  {}: 1 sigma {:.3g} {}; {}", w.description, w.sigma, w.unit, w.suggestion));
  }
  line("");
  line("mounting checks:");
  for (const auto& c : v.checks)
    line(fmt::format("  [{}] {}: {}", calib::to_string(c.level), c.name, c.message));
  line("");
  line("rest residuals (normalised, rotation):");
  for (const auto& p : r.rest_residuals)
    line(fmt::format("  {:<28} {:7.2f} sigma {:10.6f} deg{}", p.label, p.normalised,
                     p.rotation_rad / kRadPerDeg, p.outlier ? "  OUTLIER" : ""));
  line("motion residuals (normalised, rotation, position):");
  for (const auto& p : r.motion_residuals)
    line(fmt::format("  {:<28} {:7.2f} sigma {:10.6f} deg {:9.4f} mm{}", p.label, p.normalised,
                     p.rotation_rad / kRadPerDeg, p.position_m * 1e3,
                     p.outlier ? "  OUTLIER" : ""));
  if (je) {
    line("");
    line(fmt::format(
        "joint errors: {} samples ({} outside the IMS record, {} inverse-kinematics "
        "failures, {} left out near the wrist singularity)",
        je->t_s.size(), je->outside_record, je->ik_failures, je->near_wrist_singularity));
    // The position the smoother could not observe, corrected where the arm stood at a pose
    // again (calib/revisited_poses.hpp) and interpolated at the other standstills.
    const auto returns =
        std::count_if(je->revisited_pose_errors.begin(), je->revisited_pose_errors.end(),
                      [](const auto& e) { return e.revisit; });
    if (returns > 0) {
      double largest = 0.0;
      for (const auto& e : je->revisited_pose_errors) largest = std::max(largest, e.error_W.norm());
      line(fmt::format(
          "  position corrected at {} returns to a pose stood at before, {} standstills in all "
          "(largest {:.3f} mm)",
          returns, je->revisited_pose_errors.size(), largest * 1e3));
    }
    if (!je->t_s.empty()) {
      for (int j = 0; j < calib::kJointCount; ++j) {
        double sum = 0.0, worst = 0.0;
        for (std::size_t k = 0; k < je->t_s.size(); ++k) {
          const double e = je->q_desired_rad[k][j] - je->q_measured_rad[k][j];
          sum += e * e;
          worst = std::max(worst, std::abs(e));
        }
        line(fmt::format("  A{}: RMS {:.4f} mrad, max {:.4f} mrad", j + 1,
                         std::sqrt(sum / double(je->t_s.size())) * 1e3, worst * 1e3));
      }
    }
  }
  return s.str();
}

// The mounting check of a record calibrated with an earlier session's frames: the bundle's
// outlier check on this record's rests and motions against those frames (a slipped or
// re-mounted IMS shows up as outliers there) and what the record can say at all.
calib::MountingValidation previous_frames_validation(const calib::FrameCalibrationResult& result,
                                                     const calib::MountingThresholds& thresholds,
                                                     double outlier_threshold_sigma,
                                                     const calib::SessionFrames& previous) {
  calib::MountingValidation v = calib::assess_mounting(result, {}, {}, thresholds);
  double worst = 0.0;
  for (const auto* list : {&result.rest_residuals, &result.motion_residuals})
    for (const auto& r : *list) worst = std::max(worst, r.normalised);
  const std::size_t motions = result.motion_residuals.size();
  calib::MountingCheck check;
  check.name = "previous_frames";
  if (motions == 0) {
    check.level = calib::Verdict::kWarn;
    check.message = fmt::format(
        "frames held at {}: with {} rest and no motion between rests the biases absorb the rest "
        "residuals, so a slipped mount cannot be seen against these frames (record 2 or more "
        "rests)",
        previous.path, result.rest_residuals.size());
  } else {
    check.level = calib::Verdict::kPass;
    check.message = fmt::format(
        "frames held at {}: this record's {} rests and {} motions against them, largest "
        "normalised residual {:.2f} sigma (outlier above {}; a slipped mount shows there)",
        previous.path, result.rest_residuals.size(), motions, worst, outlier_threshold_sigma);
  }
  v.checks.push_back(check);
  if (check.level != calib::Verdict::kPass) {
    if (v.verdict == calib::Verdict::kPass) v.reasons.clear();  // the "all passed" line
    v.verdict = std::max(v.verdict, check.level);
    v.reasons.push_back(check.message);
  }
  return v;
}

ident::JointErrorLog joint_error_log(const calib::JointSpaceErrors& e, const calib::RobotLog& log,
                                     const std::string& source) {
  ident::JointErrorLog out;
  out.robot = e.robot.empty() ? log.robot_name : e.robot;
  out.cycle_s = e.cycle_s;
  out.source = source;
  out.joint_names.assign(log.joint_names.begin(), log.joint_names.end());
  out.time_s = e.t_s;
  out.payload_kg = e.payload_kg;
  out.q_desired_rad.assign(calib::kJointCount, {});
  out.q_measured_rad.assign(calib::kJointCount, {});
  out.q_internal_rad.assign(calib::kJointCount, {});
  for (std::size_t k = 0; k < e.t_s.size(); ++k)
    for (int j = 0; j < calib::kJointCount; ++j) {
      out.q_desired_rad[std::size_t(j)].push_back(e.q_desired_rad[k][j]);
      out.q_measured_rad[std::size_t(j)].push_back(e.q_measured_rad[k][j]);
      out.q_internal_rad[std::size_t(j)].push_back(e.q_internal_rad[k][j]);
    }
  ident::split_at_gaps(out);
  return out;
}

void run(const CalibrateArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  // Refuse existing outputs before any work (exit 2 through InputError).
  std::vector<fs::path> outputs = {"frames.json", "mounting_report.json", "summary.txt"};
  {
    // The config decides whether joint_errors.csv is written; read it first for that.
    const bool with_joint_errors =
        args.config.empty() || calib::load_calibration_config(args.config).joint_errors;
    if (with_joint_errors) outputs.push_back("joint_errors.csv");
  }
  const Overwrite overwrite = args.force ? Overwrite::kAllow : Overwrite::kRefuse;
  { OutputFolder check(args.out, outputs, overwrite); }

  Progress progress;
  progress.update("read", 0.0);
  Inputs in = read_inputs(args);
  const calib::CalibrationConfig& config = in.config;

  // Rest poses and the initial time offset.
  progress.update("rests", 0.0);
  calib::RestPoseInput rest_input;
  rest_input.imu = &in.imu;
  rest_input.log = &in.log;
  rest_input.robot = &in.robot;
  rest_input.sensor = in.spec;
  rest_input.site = *in.imu.site;
  rest_input.payload.mass_kg = config.payload.mass_kg;
  rest_input.payload.com_m = config.payload.com_T_m;
  rest_input.source = args.imu;
  calib::RestPoseOptions rest_options;
  rest_options.min_duration_s = config.rests.min_duration_s;
  rest_options.edge_trim_s = config.rests.trim_s;
  rest_options.max_joint_spread_rad = config.rests.max_joint_spread_rad;
  rest_options.settle_tolerance_rad = config.rests.settle_tolerance_rad;
  rest_options.deflection.model_uncertainty_fraction =
      config.priors.deflection_uncertainty_fraction;
  rest_options.deflection.sigma_floor_rad = config.priors.joint_sigma_floor_rad;
  const calib::RestPoseResult detection = calib::find_rest_poses(rest_input, rest_options);
  if (detection.detection.intervals.empty())
    throw InputError(args.imu, 0, "",
                     "no rest found in the IMS record: the record must start at rest and the "
                     "robot must stop in the calibration poses");
  progress.update("time offset", 0.0);
  calib::TimeOffsetOptions dt_options;
  dt_options.max_abs_offset_s = config.max_abs_time_offset_s;
  const calib::TimeOffsetResult dt0 = calib::estimate_initial_time_offset(
      in.imu, in.log, in.robot.kinematics, detection.detection.intervals.front(), dt_options);
  spdlog::info("calibrate: initial time offset {:.3f} ms (correlation peak {:.3f})",
               dt0.offset_s * 1e3, dt0.peak_correlation);
  rest_input.time_offset_s = dt0.offset_s;
  progress.update("rests", 0.5);
  const calib::RestPoseResult rests = calib::find_rest_poses(rest_input, rest_options);
  for (const auto& why : rests.rejected) spdlog::warn("calibrate: rest not used: {}", why);
  for (const auto& why : rests.trimmed) spdlog::warn("calibrate: rest used in part: {}", why);
  spdlog::info("calibrate: {} rest poses ({} rejected)", rests.rests.size(), rests.rejected.size());

  // The bundle.
  progress.update("bundle", 0.0);
  calib::FrameCalibrationInput frame_input;
  frame_input.imu = &in.imu;
  frame_input.site = *in.imu.site;
  frame_input.kinematics = in.robot.kinematics;
  frame_input.rests = rests.rests;
  // With the robot description: the link-side friction lag of each drive (c / k) that the
  // bundle estimates with the clock offset (calib/frame_calibration.hpp).
  frame_input.robot = calib::robot_joint_series(in.log, in.robot);
  frame_input.noise = calib::imu_noise_model(in.spec, config.priors);
  frame_input.time_offset_initial_s = dt0.offset_s;
  frame_input.source = args.imu;
  frame_input.first_rest_position_W_m = config.first_rest_position_W_m;
  calib::FrameCalibrationOptions bundle = config.bundle;
  if (in.previous) {
    frame_input.known_frames = in.previous->frames;
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
  }
  const calib::FrameCalibrationResult result = calib::calibrate_frames(frame_input, bundle);
  spdlog::info("calibrate: bundle {} after {} iterations",
               result.converged ? "converged" : "did NOT converge", result.iterations);

  // Mounting validation: with the frames of an earlier session, this record's residuals against
  // them (the halves and segments would calibrate frames, which this record need not determine).
  const calib::MountingValidation validation =
      in.previous ? previous_frames_validation(result, config.validation.thresholds,
                                               config.bundle.outlier_threshold_sigma, *in.previous)
                  : calib::validate_mounting(frame_input, config.bundle, result, config.validation,
                                             [&](const std::string& stage, double fraction) {
                                               progress.update(stage, fraction);
                                             });

  // Joint errors.
  std::optional<calib::JointSpaceErrors> joint_errors;
  if (config.joint_errors) {
    progress.update("joint errors", 0.0);
    calib::JointSpaceInput js;
    js.imu = &in.imu;
    js.log = &in.log;
    js.site = *in.imu.site;
    js.kinematics = in.robot.kinematics;
    js.frames = {result.T_R_W, result.T_S_H, result.biases, result.time_offset_s};
    js.first_rest = rests.rests.front();
    if (!result.joint_deviation_rad.empty())
      js.first_rest.q_link_rad += result.joint_deviation_rad.front();
    js.zupt = ims::zupt_options_from_spec(in.spec);
    js.source = args.imu;
    joint_errors = calib::joint_space_errors(js);
    spdlog::info("calibrate: joint errors at {} robot samples", joint_errors->t_s.size());
  }

  // Outputs.
  progress.update("write", 0.0);
  const std::string created_by = std::string("imscal ") + kVersion;
  const json inputs = {
      {"imu", input_json(args.imu)},
      {"robot_log", input_json(args.robot_log)},
      {"robot", input_json(in.robot_file.string())},
      {"sensor", input_json(in.sensor_file.string())},
      {"config", input_json(args.config)},
      {"unit_calibration",
       input_json(in.unit_calibration_file ? in.unit_calibration_file->string() : std::string())},
      {"frames", input_json(args.frames)}};
  const json frames_from =
      in.previous ? json{{"path", in.previous->path},
                         {"sha256", in.previous->sha256},
                         {"held",
                          "T_R_W's rotation and T_S_H (with their covariance) are the earlier "
                          "session's, not estimated here; T_R_W's translation follows this "
                          "record's rest 1 (W convention); the other estimates are conditional "
                          "on these frames"}}
                  : json(nullptr);
  calib::FramesJsonContext frames_context;
  frames_context.created_by = created_by;
  frames_context.robot = in.robot.name;
  frames_context.frames_from = frames_from;
  frames_context.inputs = inputs;
  frames_context.time_offset_peak_correlation = dt0.peak_correlation;
  frames_context.rests_used = rests.rests.size();
  frames_context.rests_rejected = rests.rejected;
  frames_context.rests_trimmed = rests.trimmed;
  const json frames = calib::frames_json(result, frames_context);
  calib::MountingReport mounting;
  mounting.created_by = created_by;
  mounting.validation = validation;
  mounting.thresholds = config.validation.thresholds;
  mounting.segment_rests = config.validation.segment_rests;
  const json report = calib::mounting_report_json(mounting, frames_from, inputs);

  OutputFolder folder(args.out, outputs, overwrite);
  write_file_atomically(folder.staged("frames.json"),
                        json_text(frames, 1, (folder.folder() / "frames.json").string()));
  write_file_atomically(folder.staged("mounting_report.json"),
                        json_text(report, 1, (folder.folder() / "mounting_report.json").string()));
  write_file_atomically(
      folder.staged("summary.txt"),
      summary_text(args, result, validation, rests, dt0, joint_errors ? &*joint_errors : nullptr));
  if (joint_errors)
    ident::write_joint_errors_csv(
        folder.staged("joint_errors.csv"),
        joint_error_log(*joint_errors, in.log,
                        fmt::format("{} calibrate --imu {} --robot-log {}", created_by, args.imu,
                                    args.robot_log)));
  folder.commit();
  progress.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << fmt::format("verdict: {}\n", calib::to_string(validation.verdict));
  for (const auto& reason : validation.reasons) std::cout << "  - " << reason << '\n';
  spdlog::info("calibrate: wrote {} files to {} in {:.1f} s", outputs.size(), args.out, seconds);
  if (validation.verdict == calib::Verdict::kFail)
    throw tools::CheckFailed(fmt::format("mounting verdict fail ({}); outputs written to {}",
                                         validation.reasons.front(), args.out));
}

tools::CommandRegistration registration{
    "calibrate",
    "Calibrate T_R_W, T_S_H, IMS biases and the clock offset from rest poses; validate the "
    "mounting; joint errors",
    [](CLI::App& sub) {
      auto args = std::make_shared<CalibrateArgs>();
      sub.add_option("--imu", args->imu, "Raw IMS record (.csv, .imsb, .imu)")->required();
      sub.add_option("--robot-log", args->robot_log, "Robot controller log (robot.csv)")
          ->required();
      sub.add_option(
          "--robot", args->robot,
          "Robot description (datasets/robots/*.yaml or a .urdf); default: the config's");
      sub.add_option("--sensor", args->sensor,
                     "IMS sensor spec (datasets/sensors/*.yaml); default: the config's");
      sub.add_option("--config", args->config,
                     "Calibration config (datasets/calibration/calibrate-default.yaml)");
      sub.add_option("--unit-calibration", args->unit_calibration,
                     "The IMS unit's lab calibration (scale factors, misalignments; "
                     "ims/sensor_error_model.hpp format), applied to the raw record; default: "
                     "the config's unit_calibration");
      sub.add_option(
          "--frames", args->frames,
          "frames.json of an earlier session with the same robot, base and IMS mount: T_R_W's "
          "rotation and T_S_H (with their covariance) are taken from it and held, and only the "
          "biases and the clock offset are estimated, from as few as 1 rest (e.g. identification "
          "runs); the mounting report then gives this record's residuals against those frames. "
          "Refused: another robot, another format version, missing or NaN values");
      sub.add_option("--out", args->out, "Output folder")->required();
      sub.add_flag("--force", args->force, "Replace existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
