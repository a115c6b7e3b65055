#pragma once
// A coarse alignment session as `imscal align` runs it: levelling and gyrocompassing at rest
// (ims/coarse_alignment.hpp) over an interval of a raw IMS record, with the 1-sigma of each
// angle, and optionally per disjoint window to show their agreement. Its result document (the
// alignment JSON of datasets/FORMAT.md: angles in degrees, heading clockwise from North of the
// sensor's +Y axis, PSINS yaw counter-clockwise, rates in deg/h) and a text summary. Bad options
// are InputErrors naming the command line's option.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "ims/coarse_alignment.hpp"

namespace imscal::ims {

struct AlignmentSessionOptions {
  std::string input;                 // raw IMS file (.imu PSINS, .csv, .imsb)
  double start_s = 0.0;              // start of the rest interval after the record start
  std::optional<double> duration_s;  // default: to the end of the record
  std::optional<double> window_s;    // also align disjoint windows of this length
  std::string site;                  // "LAT,LON,H" [deg, deg, m]; empty: the file's
  int block_count = CoarseAlignmentOptions{}.block_count;
};

struct AlignmentSession {
  nlohmann::json document;  // the result file's content
  std::string summary;      // a line per alignment, the checks, the windows' spread
};

AlignmentSession align_session(const AlignmentSessionOptions& options);

// One alignment as it appears in the result document.
nlohmann::json alignment_json(const CoarseAlignment& alignment);

}  // namespace imscal::ims
