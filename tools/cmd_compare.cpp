// `imscal compare`: errors of an estimated trajectory (e.g. from `imscal mechanize`) against a
// reference trajectory (e.g. the truth of `imscal synthesize`), matched by time stamp.
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/units.hpp"
#include "ims/trajectory_comparison.hpp"
#include "tools/command_registry.hpp"

namespace {

using imscal::kDegPerRad;
namespace ims = imscal::ims;

struct CompareArgs {
  std::string estimate;
  std::string reference;
  std::string json_out;
  double max_position_rms_mm = -1.0;  // optional acceptance check (exit code 1 when exceeded)
};

void run(const CompareArgs& args) {
  const ims::NavTrajectory estimate = ims::read_trajectory_csv(args.estimate);
  const ims::NavTrajectory reference = ims::read_trajectory_csv(args.reference);
  ims::TrajectoryComparison c;
  try {
    c = ims::compare_trajectories(estimate, reference);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError(args.estimate, 0, "t_s", e.what());
  }
  std::cout << fmt::format(
      "{} states matched\nposition error: RMS {:.4f} mm, max {:.4f} mm\nattitude error: RMS "
      "{:.6f} deg, max {:.6f} deg\n",
      c.matched_states, 1e3 * c.position_rms_m, 1e3 * c.position_max_m,
      kDegPerRad * c.attitude_rms_rad, kDegPerRad * c.attitude_max_rad);
  nlohmann::json j = {{"estimate", args.estimate},
                      {"reference", args.reference},
                      {"matched_states", c.matched_states},
                      {"position_error_rms_mm", 1e3 * c.position_rms_m},
                      {"position_error_max_mm", 1e3 * c.position_max_m},
                      {"attitude_error_rms_deg", kDegPerRad * c.attitude_rms_rad},
                      {"attitude_error_max_deg", kDegPerRad * c.attitude_max_rad}};
  if (!std::isnan(c.normalised_error_rms[0])) {
    const auto& n = c.normalised_error_rms;
    std::cout << fmt::format(
        "RMS(error/sigma): attitude {:.2f} {:.2f} {:.2f}, velocity {:.2f} {:.2f} {:.2f}, "
        "position {:.2f} {:.2f} {:.2f} (about 1 when the 1-sigma is honest)\n",
        n[0], n[1], n[2], n[3], n[4], n[5], n[6], n[7], n[8]);
    j["normalised_error_rms"] = {{"attitude_enu", {n[0], n[1], n[2]}},
                                 {"velocity", {n[3], n[4], n[5]}},
                                 {"position", {n[6], n[7], n[8]}}};
  }
  if (!args.json_out.empty())
    imscal::write_file_atomically(args.json_out, imscal::json_text(j, 2, args.json_out));
  if (args.max_position_rms_mm >= 0.0 && 1e3 * c.position_rms_m > args.max_position_rms_mm) {
    throw imscal::tools::CheckFailed(
        fmt::format("position error RMS {:.4f} mm exceeds --max-position-rms-mm {:.4f}",
                    1e3 * c.position_rms_m, args.max_position_rms_mm));
  }
}

imscal::tools::CommandRegistration registration{
    "compare", "Errors of an estimated trajectory against a reference trajectory",
    [](CLI::App& sub) {
      auto args = std::make_shared<CompareArgs>();
      sub.add_option("--estimate", args->estimate, "Estimated trajectory CSV (imscal mechanize)")
          ->required();
      sub.add_option("--reference", args->reference,
                     "Reference trajectory CSV (e.g. truth/trajectory.csv of imscal synthesize)")
          ->required();
      sub.add_option("--json", args->json_out, "Write the figures to this JSON file");
      sub.add_option("--max-position-rms-mm", args->max_position_rms_mm,
                     "Fail (exit code 1) when the position error RMS exceeds this");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
