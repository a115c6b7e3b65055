#include "calib/tool_imu_check_session.hpp"

#include <fmt/format.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "calib/attitude_filter.hpp"
#include "calib/orientation_error.hpp"
#include "calib/orientation_losses.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"

namespace imscal::calib {

namespace {

nlohmann::json vector_json(const Eigen::Vector3d& v, double scale = 1.0) {
  return {v.x() * scale, v.y() * scale, v.z() * scale};
}

const char* sigma_method(const RotationCalibration& c) {
  if (!c.sigma_from_bootstrap) return "covariance";
  return c.sigma_resampling == SigmaResampling::kMotionSegments ? "motion-segment bootstrap"
                                                                : "moving-block bootstrap";
}

nlohmann::json calibration_json(const RotationCalibration& c) {
  nlohmann::json j;
  j["q_T_S_wxyz"] = {c.q_T_S.w(), c.q_T_S.x(), c.q_T_S.y(), c.q_T_S.z()};
  j["rotation_angle_deg"] = Eigen::AngleAxisd(c.q_T_S).angle() * kDegPerRad;
  j["sigma_rotation_deg"] = vector_json(c.sigma_rotation_rad, kDegPerRad);
  j["gyro_bias_deg_s_as_labelled"] = vector_json(c.gyro_bias_rad_s, kDegPerRad);
  j["sigma_gyro_bias_deg_s"] = vector_json(c.sigma_bias_rad_s, kDegPerRad);
  j["rest_gyro_bias_deg_s_as_labelled"] = vector_json(c.rest_bias_rad_s, kDegPerRad);
  j["sigma_rest_gyro_bias_deg_s"] = vector_json(c.sigma_rest_bias_rad_s, kDegPerRad);
  j["rest_samples"] = c.rest_sample_count;
  j["rest_bias_prior"] = c.rest_bias_prior_used;
  j["gyro_scale"] = vector_json(c.gyro_scale);
  j["sigma_gyro_scale"] = vector_json(c.sigma_scale);
  j["gyro_cross_coupling"] = vector_json(c.gyro_cross_coupling);
  j["sigma_gyro_cross_coupling"] = vector_json(c.sigma_cross_coupling);
  j["time_offset_s"] = c.time_offset_s;
  j["sigma_time_offset_s"] = c.sigma_time_offset_s;
  j["sigma_method"] = sigma_method(c);
  j["bootstrap_replicates"] = c.bootstrap_replicates;
  j["bootstrap_segments"] = c.bootstrap_unit_count;
  j["covariance_sigma_rotation_deg"] = vector_json(c.covariance_sigma_rotation_rad, kDegPerRad);
  j["covariance_sigma_time_offset_s"] = c.covariance_sigma_time_offset_s;
  j["covariance_ok"] = c.covariance_ok;
  j["window_count"] = c.window_count;
  j["rms_residual_deg"] = c.rms_residual_rad * kDegPerRad;
  j["solver"] = c.summary;
  return j;
}

void print_calibration(const std::string& title, const RotationCalibration& c,
                       const TextSink& print) {
  print(fmt::format(
      "{}: R_T_S angle {:.3f} deg (1 sigma {:.3f} {:.3f} {:.3f} deg, {}), time offset {:.4f} +- "
      "{:.4f} s,\n  gyro bias {:.4g} {:.4g} {:.4g} deg/s (as labelled), scale {:.5g} {:.5g} "
      "{:.5g}, cross-coupling {:.3g} {:.3g} {:.3g}, window residual RMS {:.3f} deg over {} "
      "windows\n  the rests read {:.4g} {:.4g} {:.4g} deg/s (1 sigma {:.2g} {:.2g} {:.2g}, {} "
      "samples; {})\n",
      title, Eigen::AngleAxisd(c.q_T_S).angle() * kDegPerRad, c.sigma_rotation_rad.x() * kDegPerRad,
      c.sigma_rotation_rad.y() * kDegPerRad, c.sigma_rotation_rad.z() * kDegPerRad, sigma_method(c),
      c.time_offset_s, c.sigma_time_offset_s, c.gyro_bias_rad_s.x() * kDegPerRad,
      c.gyro_bias_rad_s.y() * kDegPerRad, c.gyro_bias_rad_s.z() * kDegPerRad, c.gyro_scale.x(),
      c.gyro_scale.y(), c.gyro_scale.z(), c.gyro_cross_coupling.x(), c.gyro_cross_coupling.y(),
      c.gyro_cross_coupling.z(), c.rms_residual_rad * kDegPerRad, c.window_count,
      c.rest_bias_rad_s.x() * kDegPerRad, c.rest_bias_rad_s.y() * kDegPerRad,
      c.rest_bias_rad_s.z() * kDegPerRad, c.sigma_rest_bias_rad_s.x() * kDegPerRad,
      c.sigma_rest_bias_rad_s.y() * kDegPerRad, c.sigma_rest_bias_rad_s.z() * kDegPerRad,
      c.rest_sample_count,
      c.rest_bias_prior_used ? "a prior on the bias" : "the bias's start, not a prior"));
}

nlohmann::json error_json(const OrientationErrorStats& e) {
  return {{"rms_deg", e.rms_rad * kDegPerRad},     {"median_deg", e.median_rad * kDegPerRad},
          {"p90_deg", e.p90_rad * kDegPerRad},     {"max_deg", e.max_rad * kDegPerRad},
          {"final_deg", e.final_rad * kDegPerRad}, {"samples", e.sample_count}};
}

std::string error_text(const OrientationErrorStats& e) {
  return fmt::format(
      "median {:.2f} deg, 90th percentile {:.2f} deg, RMS {:.2f} deg, max {:.2f} deg",
      e.median_rad * kDegPerRad, e.p90_rad * kDegPerRad, e.rms_rad * kDegPerRad,
      e.max_rad * kDegPerRad);
}

nlohmann::json segment_json(const SegmentRotation& s) {
  return {{"begin_s", s.begin_s},
          {"end_s", s.end_s},
          {"first_line", s.first_line},
          {"last_line", s.last_line},
          {"robot_angle_deg", s.robot_angle_rad * kDegPerRad},
          {"gyro_angle_deg", s.gyro_angle_rad * kDegPerRad},
          {"difference_deg", s.difference_rad * kDegPerRad},
          {"loss_deg", s.loss_rad * kDegPerRad},
          {"axis_tilt_deg", s.axis_tilt_rad * kDegPerRad}};
}

// The findings of the record's checks, printed and as JSON.
void report_findings(const ToolImuAnalysis& analysis, nlohmann::json& report,
                     const TextSink& print) {
  report["findings"] = nlohmann::json::array();
  for (const auto& f : analysis.findings) {
    print(fmt::format("[{}{}] {}\n    {}\n", to_string(f.kind), f.is_defect ? "" : " (ok)", f.where,
                      f.message));
    report["findings"].push_back({{"kind", to_string(f.kind)},
                                  {"where", f.where},
                                  {"size", f.size},
                                  {"unit", f.unit},
                                  {"defect", f.is_defect},
                                  {"message", f.message}});
  }
}

// The calibrated gyro's rotation per motion segment against the robot's, every loss listed, and
// the orientation error from the start and restarted after each loss.
nlohmann::json report_orientation(const ToolImuRecord& record, const ToolImuAnalysis& analysis,
                                  const RotationCalibration& applied, const std::string& source,
                                  bool restart, const TextSink& print) {
  const OrientationLossCheck check = find_orientation_losses(record, applied);
  print(fmt::format(
      "rotation lost per motion segment (calibrated gyro against the robot, calibration from "
      "{}): {} segments judged, {} with a loss of 5 deg or more\n",
      source, check.segments.size(), check.losses.size()));
  nlohmann::json out;
  out["calibration_source"] = source;
  out["segments_judged"] = check.segments.size();
  out["segments"] = nlohmann::json::array();
  for (const auto& segment : check.segments) out["segments"].push_back(segment_json(segment));
  out["losses"] = nlohmann::json::array();
  for (const auto& loss : check.losses) {
    print(fmt::format(
        "  [orientation_loss] lines {}-{}, sensor time {:.2f}-{:.2f} s: the robot turned {:.1f} "
        "deg, the gyro {:.1f} deg; {:.1f} deg of rotation about the turn's axis lost (or added), "
        "{:.1f} deg across it\n",
        loss.first_line, loss.last_line, loss.begin_s, loss.end_s,
        loss.robot_angle_rad * kDegPerRad, loss.gyro_angle_rad * kDegPerRad,
        loss.loss_rad * kDegPerRad, loss.axis_tilt_rad * kDegPerRad));
    out["losses"].push_back(segment_json(loss));
  }
  const auto spans =
      restart ? lost_spans(analysis, check) : std::vector<std::pair<double, double>>{};
  const RestartedOrientationError error = orientation_error_with_restarts(record, applied, spans);
  print(fmt::format(
      "orientation error of the calibrated gyro against the robot: from the start {} over {} "
      "samples\n",
      error_text(error.from_start), error.from_start.sample_count));
  out["from_start"] = error_json(error.from_start);
  if (restart) {
    print(fmt::format(
        "  restarted from the robot's pose after each of {} lost spans (the spans left out): {} "
        "over {} of the {} samples\n",
        spans.size(), error_text(error.with_restarts), error.with_restarts.sample_count,
        error.from_start.sample_count));
    out["with_restarts"] = error_json(error.with_restarts);
    out["restart_times_s"] = error.restart_times_s;
  }
  return out;
}

// The AHRS's own orientation error, or the reason it is refused as a reference (its rates do
// not follow the robot's; the IMU's results stand without it).
nlohmann::json report_ahrs(const ToolImuRecord& ahrs, const TextSink& print) {
  try {
    const AhrsAlignment alignment = align_ahrs_to_robot(ahrs);
    const OrientationErrorStats error =
        orientation_error(ahrs, alignment.time_offset_s, alignment.t_s, alignment.q_B_T);
    print(fmt::format(
        "AHRS {} (alignment to tool and base fitted on this same record): {} over {} samples\n",
        ahrs.file, error_text(error), error.sample_count));
    nlohmann::json out = error_json(error);
    out["file"] = ahrs.file;
    out["refused"] = false;
    out["time_offset_s"] = alignment.time_offset_s;
    return out;
  } catch (const InputError& e) {
    print(fmt::format("AHRS {} REFUSED as a reference: {}\n", ahrs.file, e.what()));
    return {{"file", ahrs.file}, {"refused", true}, {"reason", e.what()}};
  }
}

}  // namespace

nlohmann::json check_tool_imu_session(const ToolImuCheckSessionOptions& args,
                                      const TextSink& print) {
  nlohmann::json report;
  const ToolImuRecord record = read_tool_imu_record(args.imu);
  // An unreadable AHRS file is bad input (exit 2) before any work; one that reads but does not
  // follow the robot is refused as a reference below, beside the IMU's results.
  std::optional<ToolImuRecord> ahrs;
  if (!args.xsens.empty()) ahrs = read_tool_imu_record(args.xsens);
  const ToolImuAnalysis analysis = check_tool_imu_record(record);
  print(fmt::format("{}: {} rows\n", record.file, record.t_s.size()));
  report["file"] = record.file;
  report["rows"] = record.t_s.size();
  report_findings(analysis, report, print);
  const RotationCalibration own = calibrate_rotation(record, analysis);
  print_calibration("rotation calibration on this record", own, print);
  report["calibration"] = calibration_json(own);

  RotationCalibration applied = own;
  std::string source = record.file + " (this record)";
  if (!args.calibration_from.empty()) {
    const ToolImuRecord other = read_tool_imu_record(args.calibration_from);
    applied = calibrate_rotation(other, check_tool_imu_record(other));
    print_calibration("calibration from " + other.file, applied, print);
    report["calibration_from"] = calibration_json(applied);
    source = other.file;
    // This run's own clock offset and standstill bias (what a user has at run time).
    applied.time_offset_s = analysis.time_offset_s;
    gyro_bias_at_rest(record, applied.time_offset_s, 0.01, applied.gyro_bias_rad_s, 3.0);
  }
  report["orientation"] =
      report_orientation(record, analysis, applied, source, !args.no_restart, print);
  if (ahrs) report["ahrs_orientation_error"] = report_ahrs(*ahrs, print);
  return report;
}

}  // namespace imscal::calib
