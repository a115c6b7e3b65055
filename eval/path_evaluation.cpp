#include "eval/path_evaluation.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "core/input_error.hpp"
#include "core/numeric_table.hpp"

namespace imscal::eval {

PoseSeries read_path_file(const std::filesystem::path& path, double from_s, double to_s) {
  const std::string file = path.string();
  const NumericTable t = read_numeric_table(file);
  const char* names[] = {"t_s", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz"};
  std::array<std::size_t, 8> col{};
  for (int i = 0; i < 8; ++i) col[std::size_t(i)] = t.column(names[i]);
  PoseSeries out;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    PathPose p;
    p.t_s = t.at(r, col[0]);
    if (!out.empty() && !(p.t_s > out.back().t_s)) {
      throw InputError(file, t.lines[r], "t_s", "time does not increase");
    }
    if (p.t_s < from_s || p.t_s > to_s) continue;
    p.p_m = {t.at(r, col[1]), t.at(r, col[2]), t.at(r, col[3])};
    p.q = Eigen::Quaterniond(t.at(r, col[4]), t.at(r, col[5]), t.at(r, col[6]), t.at(r, col[7]));
    const double norm = p.q.norm();
    if (std::abs(norm - 1.0) > 1e-6) {
      throw InputError(file, t.lines[r], "qw", fmt::format("quaternion norm {} is not 1", norm));
    }
    p.q.normalize();
    out.push_back(p);
  }
  if (out.size() < 2) {
    throw InputError(file, t.header_line, "t_s",
                     "fewer than two poses in the evaluated time range");
  }
  return out;
}

PathEvaluation evaluate_paths(const PoseSeries& commanded, const std::vector<PoseSeries>& attained,
                              double velocity_m_s, const Iso9283Options& options) {
  PathEvaluation e;
  e.commanded_speed_m_s = velocity_m_s;
  if (!(velocity_m_s > 0.0)) {
    e.commanded_speed_m_s = 0.0;
    for (std::size_t k = 1; k < commanded.size(); ++k) {
      e.commanded_speed_m_s =
          std::max(e.commanded_speed_m_s, (commanded[k].p_m - commanded[k - 1].p_m).norm() /
                                              (commanded[k].t_s - commanded[k - 1].t_s));
    }
  }
  e.iso = iso9283_path(commanded, attained, e.commanded_speed_m_s, options);
  std::vector<TimedPoint> desired;
  for (const auto& p : commanded) desired.push_back({p.t_s, p.p_m});
  for (const PoseSeries& cycle : attained) {
    std::vector<TimedPoint> actual;
    for (const auto& p : cycle) {
      if (p.t_s >= commanded.front().t_s && p.t_s <= commanded.back().t_s) {
        actual.push_back({p.t_s, p.p_m});
      }
    }
    e.deviation.push_back(path_deviation(desired, actual, options.time_window_s));
    e.max_path_deviation_m = std::max(e.max_path_deviation_m, e.deviation.back().max_m);
  }
  return e;
}

}  // namespace imscal::eval
