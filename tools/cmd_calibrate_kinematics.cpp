// `imscal calibrate-kinematics --robot FILE --poses FILE [--held-out FILE] --out FILE.json`:
// kinematic calibration of an arm from laser-tracker positions
// (calib/kinematic_calibration_session.hpp).
// The DH deviations, the tracker <- base transform and the target on the flange are fitted on
// the --poses rows (without --held-out: the 1st, 3rd, 5th ... row; the others are held out) and
// judged on the held-out poses against the nominal model with its own best base and target fit
// on the same rows. Prints and writes (JSON, atomically) both models' position errors on the
// fitted and the held-out poses, every parameter with 1σ or the reason it was not estimated.
// A calibrated model that predicts the held-out poses worse than the nominal one is a failed
// check (exit 1), after the report is written.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "calib/kinematic_calibration_session.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "tools/command_registry.hpp"

namespace {

struct Args {
  imscal::calib::KinematicSessionOptions session;
  std::string out;
  bool force = false;
};

void run(const Args& args) {
  if (!args.force && std::filesystem::exists(args.out)) {
    throw imscal::InputError(args.out, 0, "", "output exists; use --force to overwrite it");
  }
  const imscal::calib::KinematicSession s =
      imscal::calib::calibrate_kinematics_session(args.session);
  std::cout << s.text;
  imscal::write_file_atomically(
      args.out, imscal::json_text(s.report, 2, args.out),
      args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  if (!s.calibrated_beats_nominal) {
    throw imscal::tools::CheckFailed(
        "the calibrated model predicts the held-out poses worse than "
        "the nominal one");
  }
}

imscal::tools::CommandRegistration registration{
    "calibrate-kinematics",
    "DH deviations, tracker base and target from laser-tracker poses, judged on held-out poses",
    [](CLI::App& sub) {
      auto args = std::make_shared<Args>();
      sub.add_option("--robot", args->session.robot, "Robot file (YAML or URDF)")->required();
      sub.add_option("--poses", args->session.poses, "Tracker poses CSV (q*_rad, meas_*_mm) to fit")
          ->required();
      sub.add_option("--held-out", args->session.held_out,
                     "Tracker poses CSV to judge on (default: alternate rows of --poses)");
      sub.add_option("--out", args->out, "JSON report (written atomically)")->required();
      sub.add_option(
             "--min-independence", args->session.min_independence,
             "Parameters whose scaled Jacobian column is less independent are not estimated")
          ->check(CLI::Range(1e-9, 0.5));
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
