#pragma once
// mounting_report.json of a calibration session (`imscal calibrate`; datasets/FORMAT.md §16.3):
// the mounting verdict with every check, the combined T_S_H with its 1-sigma, the rest and motion
// residuals, the halves and segments with their differences, the weak directions and the
// thresholds used. Written and read here, so that the two cannot drift apart.
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "calib/mounting_validation.hpp"

namespace imscal::calib {

struct MountingReport {
  std::string created_by;  // "imscal 0.1.0"
  // The earlier session's frames.json the frames were held at (`calibrate --frames`), if any.
  std::optional<std::string> frames_from;
  // The validation as written: the estimates' covariance holds only the 1-sigma the file gives
  // (its diagonal), a part's `converged` is not written (false).
  MountingValidation validation;
  MountingThresholds thresholds;
  std::size_t segment_rests = 0;
};

// The document; `frames_from` and `inputs` as in frames.json (null when absent).
nlohmann::json mounting_report_json(const MountingReport& report, const nlohmann::json& frames_from,
                                    const nlohmann::json& inputs);

// Reads `file`; InputError naming the file and the field (its JSON path) for a file that is not
// JSON, repeats a key, is of another kind or format version, or lacks a field or holds one of
// another type.
MountingReport read_mounting_report(const std::filesystem::path& file);

}  // namespace imscal::calib
