#pragma once
// The files of a verification (`imscal verify`), per scenario in one folder:
//   verification.json / .csv / .txt   before/after ISO 9283 table (+ ablation), reductions
//   fig5_paths.csv, fig5.gp           desired and attained flange paths, xy and yz (paper Fig. 5)
//   fig6_deviation.csv, fig6.gp       path deviation along the path (paper Fig. 6)
//   commanded.csv, attained_<case>_<cycle>.csv  path files for `imscal evaluate`
// Lengths in mm, angles in degrees, velocities in m/s (datasets/FORMAT.md).
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/atomic_file.hpp"
#include "eval/verification.hpp"

namespace imscal::eval {

// What a verification ran with, recorded in verification.json.
struct VerificationRecord {
  std::uint64_t seed = 1;
  int look_ahead_cycles = 0;
  int inversion_iterations = 0;
  std::string table;  // the table file, empty when identified in the verification
  bool measured_with_ims = true;
};

// Writes the files above into `dir` (created) and returns the text report (verification.txt).
std::string write_verification_files(const std::filesystem::path& dir,
                                     const VerificationResult& result,
                                     const VerificationRecord& record, Overwrite overwrite);

// The figures of the compensated case of a verification.json, against the uncompensated one.
struct VerifiedFigures {
  double before_mm = 0.0, after_mm = 0.0, reduction_percent = 0.0, true_reduction_percent = 0.0;
  double scatter_floor_mm = 0.0;  // the cycles' own scatter with the precontrol, as measured
  double systematic_mm = 0.0;     // the largest deviation of the cycles' mean path with it
};

// Throws std::runtime_error when the file has no compensated case.
VerifiedFigures read_verified_figures(const std::filesystem::path& verification_json);

}  // namespace imscal::eval
