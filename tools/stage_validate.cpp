#include "tools/stage_validate.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "ims/imu_file.hpp"
#include "robot/robot_log.hpp"

namespace imscal::tools {

using nlohmann::json;

StageInputs ValidateStage::inputs() const {
  StageInputs in;
  if (config_.imu) in.files.emplace_back("imu", *config_.imu);
  if (config_.robot_log) in.files.emplace_back("robot_log", *config_.robot_log);
  in.config = {{"robot", config_.validate.robot},
               {"min_overlap_s", config_.validate.min_overlap_s},
               {"allow_imu_gaps", config_.validate.allow_imu_gaps}};
  return in;
}

StageOutcome ValidateStage::run(StageWorkspace& workspace) {
  json result = json::object();
  std::optional<std::pair<double, double>> imu_span, robot_span;
  workspace.progress(0.0);
  if (config_.imu) {
    ims::ImuReadOptions options;
    options.allow_gaps = config_.validate.allow_imu_gaps;
    ims::ImuReadReport report;
    const ims::ImuSeries series = ims::read_imu_file(*config_.imu, options, &report);
    if (series.samples.empty()) throw InputError(config_.imu->string(), 0, "", "no samples");
    imu_span = {series.samples.front().t_s, series.samples.back().t_s};
    result["imu"] = {{"file", config_.imu->string()},
                     {"samples", report.samples},
                     {"first_t_s", imu_span->first},
                     {"last_t_s", imu_span->second},
                     {"duration_s", report.duration_s},
                     {"nominal_dt_s", series.nominal_dt_s},
                     {"median_dt_s", report.median_dt_s},
                     {"max_step_s", report.max_step_s},
                     {"gap_count", report.gap_count},
                     {"jitter_count", report.jitter_count},
                     {"saturated_count", report.saturated_count},
                     {"static_windows", report.static_windows},
                     {"warnings", report.warnings}};
    if (report.static_specific_force_m_s2)
      result["imu"]["static_specific_force_m_s2"] = *report.static_specific_force_m_s2;
    if (report.expected_gravity_m_s2)
      result["imu"]["expected_gravity_m_s2"] = *report.expected_gravity_m_s2;
    spdlog::info("validate: {}", report.brief());
  }
  workspace.progress(0.5);
  if (config_.robot_log) {
    const calib::RobotLog log =
        calib::read_robot_log_csv(*config_.robot_log, config_.validate.robot);
    if (log.samples.empty()) throw InputError(config_.robot_log->string(), 0, "", "no samples");
    robot_span = {log.samples.front().t_s, log.samples.back().t_s};
    double min_payload = log.samples.front().payload_kg, max_payload = min_payload;
    for (const auto& s : log.samples) {
      min_payload = std::min(min_payload, s.payload_kg);
      max_payload = std::max(max_payload, s.payload_kg);
    }
    result["robot_log"] = {{"file", config_.robot_log->string()},
                           {"robot", log.robot_name},
                           {"joints", log.joint_names},
                           {"cycle_s", log.cycle_s},
                           {"samples", log.samples.size()},
                           {"first_t_s", robot_span->first},
                           {"last_t_s", robot_span->second},
                           {"duration_s", robot_span->second - robot_span->first},
                           {"payload_kg_min", min_payload},
                           {"payload_kg_max", max_payload}};
    spdlog::info("validate: robot log {}: {} samples, {:.3f} .. {:.3f} s, cycle {} s",
                 config_.robot_log->string(), log.samples.size(), robot_span->first,
                 robot_span->second, log.cycle_s);
  }
  workspace.progress(1.0);

  StageOutcome outcome;
  if (imu_span && robot_span) {
    // Raw clocks: the calibration estimates their offset, but it cannot bridge records that
    // were not taken at the same time.
    const double begin = std::max(imu_span->first, robot_span->first);
    const double end = std::min(imu_span->second, robot_span->second);
    const double overlap = end - begin;
    result["overlap"] = {{"begin_s", begin},
                         {"end_s", end},
                         {"duration_s", std::max(0.0, overlap)},
                         {"min_overlap_s", config_.validate.min_overlap_s}};
    if (overlap <= 0.0)
      throw InputError(config_.imu->string(), 0, "t_s",
                       fmt::format("the IMS record [{:.3f}, {:.3f}] s and the robot log {} "
                                   "[{:.3f}, {:.3f}] s do not overlap in time",
                                   imu_span->first, imu_span->second, config_.robot_log->string(),
                                   robot_span->first, robot_span->second));
    if (overlap < config_.validate.min_overlap_s) {
      outcome.status = StageStatus::kCheckFailed;
      outcome.message = fmt::format(
          "IMS record and robot log overlap {:.3f} s only, less than validate.min_overlap_s = {} s",
          overlap, config_.validate.min_overlap_s);
    } else {
      outcome.message = fmt::format("IMS and robot log overlap {:.3f} s", overlap);
    }
  } else {
    outcome.message = imu_span ? "IMS record read (no robot log to overlap)"
                               : "robot log read (no IMS record to overlap)";
  }
  result["check"] = {{"status", to_string(outcome.status)}, {"message", outcome.message}};
  write_file_atomically(workspace.output_dir() / "validation.json",
                        imscal::json_text(result, 1, "validation.json"));
  outcome.summary = result.contains("overlap") ? result["overlap"] : json::object();
  return outcome;
}

}  // namespace imscal::tools
