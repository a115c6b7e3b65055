// `imscal evaluate`: ISO 9283 path characteristics (eval/iso9283_path.hpp) and the perpendicular
// path deviation (eval/path_deviation.hpp) of one or more attained paths (cycles) against the
// commanded path, from path files (datasets/FORMAT.md, "Path files": t_s,x_m,y_m,z_m,qw,qx,qy,qz;
// the same columns as the simulator's truth/flange_poses.csv, so those are read too).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/numeric_table.hpp"
#include "core/units.hpp"
#include "eval/iso9283_path.hpp"
#include "eval/path_deviation.hpp"
#include "tools/command_registry.hpp"

namespace {

using imscal::kDegPerRad;
namespace eval = imscal::eval;

struct EvaluateArgs {
  std::string commanded, out;
  std::vector<std::string> attained;
  double velocity_m_s = 0.0;  // <= 0: the commanded path's top speed
  double from_s = -1e300, to_s = 1e300;
  double window_s = 0.25;
  int points = 200;
  bool force = false;
};

eval::PoseSeries read_path(const std::string& file, double from_s, double to_s) {
  const imscal::NumericTable t = imscal::read_numeric_table(file);
  const char* names[] = {"t_s", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz"};
  std::array<std::size_t, 8> col{};
  for (int i = 0; i < 8; ++i) col[std::size_t(i)] = t.column(names[i]);
  eval::PoseSeries out;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    eval::PathPose p;
    p.t_s = t.at(r, col[0]);
    if (!out.empty() && !(p.t_s > out.back().t_s)) {
      throw imscal::InputError(file, t.lines[r], "t_s", "time does not increase");
    }
    if (p.t_s < from_s || p.t_s > to_s) continue;
    p.p_m = {t.at(r, col[1]), t.at(r, col[2]), t.at(r, col[3])};
    p.q = Eigen::Quaterniond(t.at(r, col[4]), t.at(r, col[5]), t.at(r, col[6]), t.at(r, col[7]));
    const double norm = p.q.norm();
    if (std::abs(norm - 1.0) > 1e-6) {
      throw imscal::InputError(file, t.lines[r], "qw",
                               fmt::format("quaternion norm {} is not 1", norm));
    }
    p.q.normalize();
    out.push_back(p);
  }
  if (out.size() < 2) {
    throw imscal::InputError(file, t.header_line, "t_s",
                             "fewer than two poses in the evaluated time range");
  }
  return out;
}

void run(const EvaluateArgs& args) {
  if (!args.out.empty() && !args.force && std::filesystem::exists(args.out)) {
    throw imscal::InputError(args.out, 0, "", "output exists; use --force to overwrite it");
  }
  const eval::PoseSeries commanded = read_path(args.commanded, args.from_s, args.to_s);
  std::vector<eval::PoseSeries> attained;
  for (const auto& f : args.attained) {
    attained.push_back(read_path(f, args.from_s - args.window_s, args.to_s + args.window_s));
  }
  double v_c = args.velocity_m_s;
  if (!(v_c > 0.0)) {
    for (std::size_t k = 1; k < commanded.size(); ++k) {
      v_c = std::max(v_c, (commanded[k].p_m - commanded[k - 1].p_m).norm() /
                              (commanded[k].t_s - commanded[k - 1].t_s));
    }
  }
  eval::Iso9283Options options;
  options.calculation_points = args.points;
  options.time_window_s = args.window_s;
  eval::Iso9283PathResult r;
  try {
    r = eval::iso9283_path(commanded, attained, v_c, options);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError(args.attained.front(), 0, "", e.what());
  }
  std::vector<eval::TimedPoint> desired;
  for (const auto& p : commanded) desired.push_back({p.t_s, p.p_m});
  double max_dev = 0.0;
  nlohmann::json per_cycle = nlohmann::json::array();
  for (std::size_t j = 0; j < attained.size(); ++j) {
    std::vector<eval::TimedPoint> actual;
    for (const auto& p : attained[j])
      if (p.t_s >= commanded.front().t_s && p.t_s <= commanded.back().t_s)
        actual.push_back({p.t_s, p.p_m});
    const eval::PathDeviation d = eval::path_deviation(desired, actual, args.window_s);
    max_dev = std::max(max_dev, d.max_m);
    per_cycle.push_back({{"file", args.attained[j]},
                         {"max_path_deviation_mm", d.max_m * 1e3},
                         {"rms_path_deviation_mm", d.rms_m * 1e3}});
  }
  constexpr double deg = kDegPerRad;
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  const nlohmann::json out = {{"commanded", args.commanded},
                              {"cycles", r.cycles},
                              {"length_m", r.length_m},
                              {"commanded_speed_m_s", v_c},
                              {"AT_p_mm", r.AT_p_m * 1e3},
                              {"RT_p_mm", finite(r.RT_p_m * 1e3)},
                              {"AT_a_deg", r.AT_abc_rad[0] * deg},
                              {"AT_b_deg", r.AT_abc_rad[1] * deg},
                              {"AT_c_deg", r.AT_abc_rad[2] * deg},
                              {"RT_a_deg", finite(r.RT_abc_rad[0] * deg)},
                              {"RT_b_deg", finite(r.RT_abc_rad[1] * deg)},
                              {"RT_c_deg", finite(r.RT_abc_rad[2] * deg)},
                              {"AV_percent", finite(r.AV_percent)},
                              {"RV_percent", finite(r.RV_percent)},
                              {"FV_m_s", finite(r.FV_m_s)},
                              {"max_path_deviation_mm", max_dev * 1e3},
                              {"missed_crossings", r.missed_crossings},
                              {"per_cycle", per_cycle}};
  std::cout << fmt::format(
      "{} cycle(s), path {:.1f} mm at {:.3f} m/s: AT_p {:.3f} mm, RT_p {:.3f} mm, AT_abc {:.4f} "
      "{:.4f} {:.4f} deg, AV {:+.2f} %, RV {:.2f} %, FV {:.4f} m/s, max path deviation {:.3f} mm\n",
      r.cycles, r.length_m * 1e3, v_c, r.AT_p_m * 1e3, r.RT_p_m * 1e3, r.AT_abc_rad[0] * deg,
      r.AT_abc_rad[1] * deg, r.AT_abc_rad[2] * deg, r.AV_percent, r.RV_percent, r.FV_m_s,
      max_dev * 1e3);
  if (!args.out.empty()) {
    imscal::write_file_atomically(
        args.out, imscal::json_text(out, 1, args.out),
        args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  }
}

imscal::tools::CommandRegistration registration{
    "evaluate", "ISO 9283 path accuracy of attained paths against the commanded path",
    [](CLI::App& sub) {
      auto args = std::make_shared<EvaluateArgs>();
      sub.add_option("--commanded", args->commanded, "commanded path file (t_s,x_m,..,qz)")
          ->required();
      sub.add_option("--attained", args->attained, "attained path file, one per cycle")->required();
      sub.add_option("--velocity-m-s", args->velocity_m_s,
                     "commanded path speed for AV/RV/FV (default: the commanded top speed)");
      sub.add_option("--from-s", args->from_s, "evaluate the commanded path from this time");
      sub.add_option("--to-s", args->to_s, "... up to this time");
      sub.add_option("--window-s", args->window_s,
                     "an attained point is matched within this time of its commanded point");
      sub.add_option("--points", args->points, "ISO 9283 calculation points");
      sub.add_option("--out", args->out, "figures.json (optional)");
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
