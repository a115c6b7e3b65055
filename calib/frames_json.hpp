#pragma once
// frames.json of a calibration session (`imscal calibrate`; datasets/FORMAT.md §16.2), read back
// for a later session of the same robot, base and IMS mount (`calibrate --frames`): T_R_W's
// rotation, T_S_H and their covariance, and the drives' link share of the viscous friction where
// the session estimated it.
#include <filesystem>
#include <optional>
#include <string>

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

// Reads `file`; refuses (InputError naming the file and the field) a file that is not JSON or
// repeats a key, of another format version, of another robot than `robot_name`, with a
// covariance that is not the bundle's layout, or with a missing or non-finite value
// (frames.json writes NaN as null).
SessionFrames read_frames_json(const std::filesystem::path& file, const std::string& robot_name);

}  // namespace imscal::calib
