#pragma once
// Path files (datasets/FORMAT.md, "Path files": t_s,x_m,y_m,z_m,qw,qx,qy,qz) and their ISO 9283
// path characteristics (eval/iso9283_path.hpp) with the perpendicular path deviation of every
// attained cycle (eval/path_deviation.hpp). `imscal evaluate` and the Python module's
// `evaluate_paths` work through here.
#include <filesystem>
#include <vector>

#include "eval/iso9283_path.hpp"
#include "eval/path_deviation.hpp"

namespace imscal::eval {

// The poses with from_s <= t_s <= to_s. InputError (file, line, field) for a time that does not
// increase, a quaternion whose norm is not 1 (to 1e-6), fewer than two poses in the range.
PoseSeries read_path_file(const std::filesystem::path& file, double from_s = -1e300,
                          double to_s = 1e300);

struct PathEvaluation {
  Iso9283PathResult iso;
  double commanded_speed_m_s = 0.0;  // v_c of AV, RV and FV
  // Per attained cycle, against the commanded poses within the commanded time range.
  std::vector<PathDeviation> deviation;
  double max_path_deviation_m = 0.0;  // over all cycles
};

// velocity_m_s <= 0: the commanded path's top speed (between consecutive poses). Throws
// std::invalid_argument where iso9283_path does.
PathEvaluation evaluate_paths(const PoseSeries& commanded, const std::vector<PoseSeries>& attained,
                              double velocity_m_s, const Iso9283Options& options);

}  // namespace imscal::eval
