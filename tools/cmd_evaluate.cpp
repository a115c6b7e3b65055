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
#include "core/units.hpp"
#include "eval/path_evaluation.hpp"
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

void run(const EvaluateArgs& args) {
  if (!args.out.empty() && !args.force && std::filesystem::exists(args.out)) {
    throw imscal::InputError(args.out, 0, "", "output exists; use --force to overwrite it");
  }
  const eval::PoseSeries commanded = eval::read_path_file(args.commanded, args.from_s, args.to_s);
  std::vector<eval::PoseSeries> attained;
  for (const auto& f : args.attained) {
    attained.push_back(
        eval::read_path_file(f, args.from_s - args.window_s, args.to_s + args.window_s));
  }
  eval::Iso9283Options options;
  options.calculation_points = args.points;
  options.time_window_s = args.window_s;
  eval::PathEvaluation e;
  try {
    e = eval::evaluate_paths(commanded, attained, args.velocity_m_s, options);
  } catch (const std::invalid_argument& error) {
    throw imscal::InputError(args.attained.front(), 0, "", error.what());
  }
  const eval::Iso9283PathResult& r = e.iso;
  const double v_c = e.commanded_speed_m_s;
  const double max_dev = e.max_path_deviation_m;
  nlohmann::json per_cycle = nlohmann::json::array();
  for (std::size_t j = 0; j < attained.size(); ++j) {
    per_cycle.push_back({{"file", args.attained[j]},
                         {"max_path_deviation_mm", e.deviation[j].max_m * 1e3},
                         {"rms_path_deviation_mm", e.deviation[j].rms_m * 1e3}});
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
