#pragma once
// Path files (datasets/FORMAT.md, "Path files": t_s,x_m,y_m,z_m,qw,qx,qy,qz; the same columns
// as the simulator's truth/flange_poses.csv, so those are read too), and their evaluation as
// `imscal evaluate` runs it: ISO 9283 path characteristics (eval/iso9283_path.hpp) and the
// perpendicular path deviation (eval/path_deviation.hpp) of one or more attained paths (cycles)
// against the commanded path. Lengths in mm and angles in degrees in the result document.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/iso9283_path.hpp"

namespace imscal::eval {

// The poses of a path file with from_s <= t_s <= to_s; InputError naming file, line and field
// on time that does not increase, a quaternion off unit norm, or fewer than two poses.
PoseSeries read_path_file(const std::string& file, double from_s, double to_s);

// A path file's text: rows of (t_s, x_m, y_m, z_m, qw, qx, qy, qz) in the robot base R, flange H;
// `what` is its content line.
std::string path_file_text(const std::vector<Eigen::Matrix<double, 8, 1>>& rows,
                           const std::string& what);

struct PathEvaluationOptions {
  std::string commanded;              // commanded path file
  std::vector<std::string> attained;  // attained path files, one per cycle
  double velocity_m_s = 0.0;          // <= 0: the commanded path's top speed
  double from_s = -1e300, to_s = 1e300;
  double window_s = 0.25;  // an attained point is matched within this time of its commanded point
  int points = 200;        // ISO 9283 calculation points
};

struct PathEvaluation {
  nlohmann::json document;  // figures.json
  std::string summary;      // one line
};

PathEvaluation evaluate_paths(const PathEvaluationOptions& options);

}  // namespace imscal::eval
