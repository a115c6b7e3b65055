// The JSON outputs of a calibration session (calib/calibration_session_json.hpp).
#include "calib/calibration_session_json.hpp"

#include <string>

#include "calib/frames_json.hpp"
#include "calib/mounting_report_json.hpp"
#include "core/sha256.hpp"
#include "core/version.hpp"

namespace imscal::calib {
namespace {

using nlohmann::json;

json input_json(const std::string& file) {
  if (file.empty()) return nullptr;
  return {{"path", file}, {"sha256", sha256_hex_of_file(file)}};
}

json inputs_json(const SessionFiles& f, const LoadedSession& loaded) {
  return {{"imu", input_json(f.imu)},
          {"robot_log", input_json(f.robot_log)},
          {"robot", input_json(loaded.robot_file.string())},
          {"sensor", input_json(loaded.sensor_file.string())},
          {"config", input_json(f.config)},
          {"unit_calibration",
           input_json(loaded.unit_calibration_file ? loaded.unit_calibration_file->string()
                                                   : std::string())},
          {"frames", input_json(f.frames)}};
}

json frames_from_json(const std::optional<SessionFrames>& previous) {
  if (!previous) return nullptr;
  return {{"path", previous->path},
          {"sha256", previous->sha256},
          {"held",
           "T_R_W's rotation and T_S_H (with their covariance) are the earlier session's, not "
           "estimated here; T_R_W's translation follows this record's rest 1 (W convention); the "
           "other estimates are conditional on these frames"}};
}

}  // namespace

SessionJson session_json(const SessionFiles& files, const LoadedSession& loaded,
                         const SessionResult& session) {
  const std::string created_by = std::string("imscal ") + kVersion;
  const json inputs = inputs_json(files, loaded);
  const json frames_from = frames_from_json(loaded.inputs.previous);
  FramesJsonContext context;
  context.created_by = created_by;
  context.robot = loaded.inputs.robot.name;
  context.frames_from = frames_from;
  context.inputs = inputs;
  context.time_offset_peak_correlation = session.initial_time_offset.peak_correlation;
  context.rests_used = session.rests.rests.size();
  context.rests_rejected = session.rests.rejected;
  context.rests_trimmed = session.rests.trimmed;
  MountingReport mounting;
  mounting.created_by = created_by;
  mounting.validation = session.validation;
  mounting.thresholds = loaded.options.config.validation.thresholds;
  mounting.segment_rests = loaded.options.config.validation.segment_rests;
  return {frames_json(session.frames, context),
          mounting_report_json(mounting, frames_from, inputs)};
}

}  // namespace imscal::calib
