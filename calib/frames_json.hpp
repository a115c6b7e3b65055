#pragma once
// frames.json of a calibration session (`imscal calibrate`; datasets/FORMAT.md §16.2): written
// from the bundle's result, and read back for a later session of the same robot, base and IMS mount
// (`calibrate --frames`): T_R_W's rotation, T_S_H and their covariance, and the drives' link share
// of the viscous friction where the session estimated it.
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calib/frame_calibration.hpp"

namespace imscal::calib {

struct SessionFrames {
  KnownFrames frames;
  std::string path;
  std::string sha256;  // of the file, for the later session's provenance
  std::string robot;
  // The link share of the drives' viscous friction that session found, with its 1-sigma (a
  // property of the robot's drives, like the frames of its mount); absent in files without it.
  std::optional<double> link_share, link_share_sigma;
};

// What frames.json records beside the bundle's result.
struct FramesJsonContext {
  std::string created_by;  // "imscal 0.1.0"
  std::string robot;       // the robot's name (a later session of another robot is refused)
  // null, or the earlier session's frames.json the frames were held at: {path, sha256, held}.
  nlohmann::json frames_from;
  nlohmann::json inputs;                      // the input files with their SHA-256
  double time_offset_peak_correlation = 0.0;  // of the initial clock offset's cross-correlation
  std::size_t rests_used = 0;
  std::vector<std::string> rests_rejected, rests_trimmed;  // why, one line each
};

// The document: frames in mm, deg, deg/h, ug and ms, the estimates, the covariance in SI units in
// the order of the parameter names, the solver's summary and the initial values.
nlohmann::json frames_json(const FrameCalibrationResult& result, const FramesJsonContext& context);

// Reads `file`; refuses (InputError naming the file and the field) a file that is not JSON or
// repeats a key, of another format version, of another robot than `robot_name`, with a
// covariance that is not the bundle's layout, or with a missing or non-finite value
// (frames.json writes NaN as null).
SessionFrames read_frames_json(const std::filesystem::path& file, const std::string& robot_name);

}  // namespace imscal::calib
