// The output files of a calibration session (calib/calibration_session_outputs.hpp).
#include "calib/calibration_session_outputs.hpp"

#include "calib/calibration_config.hpp"
#include "calib/calibration_session_json.hpp"
#include "calib/calibration_session_summary.hpp"
#include "core/atomic_file.hpp"
#include "core/json_output.hpp"

namespace imscal::calib {

std::vector<std::filesystem::path> session_output_names(const SessionFiles& files) {
  std::vector<std::filesystem::path> outputs = {"frames.json", "mounting_report.json",
                                                "summary.txt"};
  if (files.config.empty() || load_calibration_config(files.config).joint_errors)
    outputs.push_back("joint_errors.csv");
  return outputs;
}

void stage_session_outputs(OutputFolder& folder, const SessionFiles& files,
                           const LoadedSession& loaded, const SessionResult& session) {
  const SessionJson json = session_json(files, loaded, session);
  write_file_atomically(folder.staged("frames.json"),
                        json_text(json.frames, 1, (folder.folder() / "frames.json").string()));
  write_file_atomically(
      folder.staged("mounting_report.json"),
      json_text(json.mounting_report, 1, (folder.folder() / "mounting_report.json").string()));
  write_file_atomically(folder.staged("summary.txt"),
                        session_summary_text({files.imu, files.robot_log, files.frames}, session));
}

}  // namespace imscal::calib
