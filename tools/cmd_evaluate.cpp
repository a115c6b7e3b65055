// `imscal evaluate` (eval/path_evaluation.hpp): ISO 9283 path characteristics
// (eval/iso9283_path.hpp) and the perpendicular
// path deviation (eval/path_deviation.hpp) of one or more attained paths (cycles) against the
// commanded path, from path files (datasets/FORMAT.md, "Path files": t_s,x_m,y_m,z_m,qw,qx,qy,qz;
// the same columns as the simulator's truth/flange_poses.csv, so those are read too).
#include <filesystem>
#include <iostream>
#include <memory>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "eval/path_evaluation.hpp"
#include "tools/command_registry.hpp"

namespace {

struct EvaluateArgs {
  imscal::eval::PathEvaluationOptions session;
  std::string out;
  bool force = false;
};

void run(const EvaluateArgs& args) {
  if (!args.out.empty() && !args.force && std::filesystem::exists(args.out)) {
    throw imscal::InputError(args.out, 0, "", "output exists; use --force to overwrite it");
  }
  const imscal::eval::PathEvaluation e = imscal::eval::evaluate_paths(args.session);
  std::cout << e.summary;
  if (!args.out.empty()) {
    imscal::write_file_atomically(
        args.out, imscal::json_text(e.document, 1, args.out),
        args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  }
}

imscal::tools::CommandRegistration registration{
    "evaluate", "ISO 9283 path accuracy of attained paths against the commanded path",
    [](CLI::App& sub) {
      auto args = std::make_shared<EvaluateArgs>();
      sub.add_option("--commanded", args->session.commanded, "commanded path file (t_s,x_m,..,qz)")
          ->required();
      sub.add_option("--attained", args->session.attained, "attained path file, one per cycle")
          ->required();
      sub.add_option("--velocity-m-s", args->session.velocity_m_s,
                     "commanded path speed for AV/RV/FV (default: the commanded top speed)");
      sub.add_option("--from-s", args->session.from_s,
                     "evaluate the commanded path from this time");
      sub.add_option("--to-s", args->session.to_s, "... up to this time");
      sub.add_option("--window-s", args->session.window_s,
                     "an attained point is matched within this time of its commanded point");
      sub.add_option("--points", args->session.points, "ISO 9283 calculation points");
      sub.add_option("--out", args->out, "figures.json (optional)");
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
