#pragma once
// The JSON outputs of a calibration session (datasets/FORMAT.md §16): frames.json
// (calib/frames_json.hpp) and mounting_report.json (calib/mounting_report_json.hpp), each with
// the session's input files and their SHA-256, and with the earlier session's frames.json where
// the frames were held at it.
#include <nlohmann/json.hpp>

#include "calib/calibration_session.hpp"
#include "calib/calibration_session_inputs.hpp"

namespace imscal::calib {

struct SessionJson {
  nlohmann::json frames;           // frames.json
  nlohmann::json mounting_report;  // mounting_report.json
};

// Reads every input file once more for its SHA-256.
SessionJson session_json(const SessionFiles& files, const LoadedSession& loaded,
                         const SessionResult& session);

}  // namespace imscal::calib
