#include "eval/path_evaluation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/numeric_table.hpp"
#include "core/units.hpp"
#include "eval/path_deviation.hpp"

namespace imscal::eval {

PoseSeries read_path_file(const std::string& file, double from_s, double to_s) {
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

std::string path_file_text(const std::vector<Eigen::Matrix<double, 8, 1>>& rows,
                           const std::string& what) {
  std::string s = "# imscal-path: 1\n# frame: R (robot base), flange H\n# content: " + what +
                  "\nt_s,x_m,y_m,z_m,qw,qx,qy,qz\n";
  for (const auto& r : rows)
    s += fmt::format("{},{},{},{},{},{},{},{}\n", r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7]);
  return s;
}

namespace {

// The commanded path's top speed between consecutive poses.
double top_speed_m_s(const PoseSeries& commanded) {
  double v_c = 0.0;
  for (std::size_t k = 1; k < commanded.size(); ++k) {
    v_c = std::max(v_c, (commanded[k].p_m - commanded[k - 1].p_m).norm() /
                            (commanded[k].t_s - commanded[k - 1].t_s));
  }
  return v_c;
}

// Each cycle's path deviation over the commanded path's time span; `max_dev` the largest.
nlohmann::json per_cycle_deviations(const PathEvaluationOptions& args, const PoseSeries& commanded,
                                    const std::vector<PoseSeries>& attained, double& max_dev) {
  std::vector<TimedPoint> desired;
  for (const auto& p : commanded) desired.push_back({p.t_s, p.p_m});
  max_dev = 0.0;
  nlohmann::json per_cycle = nlohmann::json::array();
  for (std::size_t j = 0; j < attained.size(); ++j) {
    std::vector<TimedPoint> actual;
    for (const auto& p : attained[j])
      if (p.t_s >= commanded.front().t_s && p.t_s <= commanded.back().t_s)
        actual.push_back({p.t_s, p.p_m});
    const PathDeviation d = path_deviation(desired, actual, args.window_s);
    max_dev = std::max(max_dev, d.max_m);
    per_cycle.push_back({{"file", args.attained[j]},
                         {"max_path_deviation_mm", d.max_m * 1e3},
                         {"rms_path_deviation_mm", d.rms_m * 1e3}});
  }
  return per_cycle;
}

}  // namespace

PathEvaluation evaluate_paths(const PathEvaluationOptions& args) {
  const PoseSeries commanded = read_path_file(args.commanded, args.from_s, args.to_s);
  std::vector<PoseSeries> attained;
  for (const auto& f : args.attained) {
    attained.push_back(read_path_file(f, args.from_s - args.window_s, args.to_s + args.window_s));
  }
  const double v_c = args.velocity_m_s > 0.0 ? args.velocity_m_s : top_speed_m_s(commanded);
  Iso9283Options options;
  options.calculation_points = args.points;
  options.time_window_s = args.window_s;
  Iso9283PathResult r;
  try {
    r = iso9283_path(commanded, attained, v_c, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.attained.front(), 0, "", e.what());
  }
  double max_dev = 0.0;
  const nlohmann::json per_cycle = per_cycle_deviations(args, commanded, attained, max_dev);
  constexpr double deg = kDegPerRad;
  PathEvaluation e;
  e.document = {{"commanded", args.commanded},
                {"cycles", r.cycles},
                {"length_m", r.length_m},
                {"commanded_speed_m_s", v_c},
                {"AT_p_mm", r.AT_p_m * 1e3},
                {"RT_p_mm", json_number_or_null(r.RT_p_m * 1e3)},
                {"AT_a_deg", r.AT_abc_rad[0] * deg},
                {"AT_b_deg", r.AT_abc_rad[1] * deg},
                {"AT_c_deg", r.AT_abc_rad[2] * deg},
                {"RT_a_deg", json_number_or_null(r.RT_abc_rad[0] * deg)},
                {"RT_b_deg", json_number_or_null(r.RT_abc_rad[1] * deg)},
                {"RT_c_deg", json_number_or_null(r.RT_abc_rad[2] * deg)},
                {"AV_percent", json_number_or_null(r.AV_percent)},
                {"RV_percent", json_number_or_null(r.RV_percent)},
                {"FV_m_s", json_number_or_null(r.FV_m_s)},
                {"max_path_deviation_mm", max_dev * 1e3},
                {"missed_crossings", r.missed_crossings},
                {"per_cycle", per_cycle}};
  e.summary = fmt::format(
      "{} cycle(s), path {:.1f} mm at {:.3f} m/s: AT_p {:.3f} mm, RT_p {:.3f} mm, AT_abc {:.4f} "
      "{:.4f} {:.4f} deg, AV {:+.2f} %, RV {:.2f} %, FV {:.4f} m/s, max path deviation {:.3f} mm\n",
      r.cycles, r.length_m * 1e3, v_c, r.AT_p_m * 1e3, r.RT_p_m * 1e3, r.AT_abc_rad[0] * deg,
      r.AT_abc_rad[1] * deg, r.AT_abc_rad[2] * deg, r.AV_percent, r.RV_percent, r.FV_m_s,
      max_dev * 1e3);
  return e;
}

}  // namespace imscal::eval
