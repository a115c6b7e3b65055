#pragma once
// The output files of a calibration session (`imscal calibrate`, datasets/FORMAT.md §16) in an
// all-or-nothing output folder (core/output_folder.hpp): frames.json, mounting_report.json and
// summary.txt (calib/calibration_session_json.hpp, calib/calibration_session_summary.hpp), and
// joint_errors.csv when the config asks for the joint errors. joint_errors.csv is the command's
// to write (ident/joint_error_io.hpp: calib may not use ident).
#include <filesystem>
#include <vector>

#include "calib/calibration_session.hpp"
#include "calib/calibration_session_inputs.hpp"
#include "core/output_folder.hpp"

namespace imscal::calib {

// The files the session writes, relative to its output folder; reads the config (if any) for
// whether joint_errors.csv is among them. Throws InputError for an unusable config.
std::vector<std::filesystem::path> session_output_names(const SessionFiles& files);

// Writes frames.json, mounting_report.json and summary.txt into `folder`'s staging area (the
// caller commits).
void stage_session_outputs(OutputFolder& folder, const SessionFiles& files,
                           const LoadedSession& loaded, const SessionResult& session);

}  // namespace imscal::calib
