// `imscal calibrate-kinematics --robot FILE --poses FILE [--held-out FILE] --out FILE.json`:
// kinematic calibration of an arm from laser-tracker positions (calib/kinematic_calibration.hpp).
// The DH deviations, the tracker <- base transform and the target on the flange are fitted on
// the --poses rows (without --held-out: the 1st, 3rd, 5th ... row; the others are held out) and
// judged on the held-out poses against the nominal model with its own best base and target fit
// on the same rows. Prints and writes (JSON, atomically) both models' position errors on the
// fitted and the held-out poses, every parameter with 1σ or the reason it was not estimated.
// A calibrated model that predicts the held-out poses worse than the nominal one is a failed
// check (exit 1), after the report is written.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "calib/kinematic_calibration.hpp"
#include "calib/robot_description.hpp"
#include "calib/tracker_poses.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "tools/command_registry.hpp"
#include "tools/joint_limit_checks.hpp"

namespace {

using namespace imscal::calib;

struct Args {
  std::string robot, poses, held_out, out;
  double min_independence = 1e-2;
  bool force = false;
};

struct ErrorStats {
  double rms_mm = 0.0, max_mm = 0.0, median_mm = 0.0;
};

ErrorStats error_stats(const KinematicCalibration& c, const std::vector<TrackerPose>& poses) {
  std::vector<double> e = position_errors_m(c, poses);
  ErrorStats s;
  double sum = 0.0;
  for (double v : e) sum += v * v;
  s.rms_mm = std::sqrt(sum / static_cast<double>(e.size())) * 1e3;
  std::sort(e.begin(), e.end());
  s.max_mm = e.back() * 1e3;
  s.median_mm = e[e.size() / 2] * 1e3;
  return s;
}

nlohmann::json stats_json(const ErrorStats& s) {
  return {{"rms_mm", s.rms_mm}, {"median_mm", s.median_mm}, {"max_mm", s.max_mm}};
}

nlohmann::json calibration_json(const KinematicCalibration& c) {
  nlohmann::json j;
  j["estimated_parameters"] = c.estimated_count;
  j["residual_sigma_mm"] = c.residual_sigma_m * 1e3;
  j["solver"] = c.solver_summary;
  const Eigen::Matrix3d R = c.T_tracker_base.linear();
  j["T_tracker_base"] = {{"rotation", {R.row(0), R.row(1), R.row(2)}},
                         {"translation_m", c.T_tracker_base.translation()}};
  j["target_in_flange_m"] = c.p_H_target_m;
  nlohmann::json dh = nlohmann::json::array();
  for (const DhParameters& p : c.model.dh) {
    dh.push_back(
        {{"a_m", p.a_m}, {"alpha_rad", p.alpha_rad}, {"d_m", p.d_m}, {"offset_rad", p.offset_rad}});
  }
  j["dh"] = dh;
  j["parameters"] = nlohmann::json::array();
  for (const KinematicParameter& p : c.parameters) {
    nlohmann::json row{{"name", p.name},           {"unit", p.unit},
                       {"value", p.value},         {"sigma", p.sigma},
                       {"estimated", p.estimated}, {"independence", p.independence}};
    if (!p.estimated) row["reason"] = p.reason;
    j["parameters"].push_back(row);
  }
  return j;
}

// The fit and held-out sets: from two files, or alternate rows of one.
void split_poses(const Args& args, const RobotDescription& robot, std::vector<TrackerPose>& fit,
                 std::vector<TrackerPose>& held_out, std::string& split) {
  const TrackerPoses poses = read_tracker_poses(args.poses);
  imscal::tools::check_tracker_pose_limits(poses, robot);
  if (!args.held_out.empty()) {
    fit = poses.poses;
    const TrackerPoses judged = read_tracker_poses(args.held_out);
    imscal::tools::check_tracker_pose_limits(judged, robot);
    held_out = judged.poses;
    split = fmt::format("fitted on every row of {}, held out: every row of {}", args.poses,
                        args.held_out);
    return;
  }
  for (std::size_t k = 0; k < poses.poses.size(); ++k) {
    (k % 2 == 0 ? fit : held_out).push_back(poses.poses[k]);
  }
  split =
      fmt::format("alternate rows of {}: 1st, 3rd, ... fitted, 2nd, 4th, ... held out", args.poses);
  if (held_out.empty())
    throw imscal::InputError(args.poses, 0, "", "one pose: nothing to hold out");
}

// Poses that cannot give a calibration (too few, or not determining the tracker frame) are bad
// input: an InputError naming the pose file.
KinematicCalibration fit_or_refuse(const KinematicModel& nominal,
                                   const std::vector<TrackerPose>& fit,
                                   const KinematicCalibrationOptions& options, const Args& args) {
  try {
    return calibrate_kinematics(nominal, fit, options);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError(args.poses, 0, "", e.what());
  }
}

void print_errors(const char* name, const ErrorStats& fit, const ErrorStats& held_out) {
  std::cout << fmt::format(
      "{:<10} fitted poses RMS {:.3f} mm, max {:.3f} mm | held-out RMS {:.3f} mm, median {:.3f} "
      "mm, max {:.3f} mm\n",
      name, fit.rms_mm, fit.max_mm, held_out.rms_mm, held_out.median_mm, held_out.max_mm);
}

void print_parameters(const KinematicCalibration& c) {
  for (const KinematicParameter& p : c.parameters) {
    const double scale = p.unit == "m" ? 1e3 : 180.0 / M_PI;
    const char* unit = p.unit == "m" ? "mm" : "deg";
    if (p.estimated) {
      std::cout << fmt::format("  {:<9} {:>10.4f} +- {:.4f} {}\n", p.name, p.value * scale,
                               p.sigma * scale, unit);
    } else {
      std::cout << fmt::format("  {:<9} not estimated: {}\n", p.name, p.reason);
    }
  }
}

void run(const Args& args) {
  imscal::prepare_output_file(args.out,
                              args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  const RobotDescription robot = load_robot_description(args.robot);
  std::vector<TrackerPose> fit, held_out;
  std::string split;
  split_poses(args, robot, fit, held_out, split);
  KinematicCalibrationOptions options;
  options.min_independence = args.min_independence;
  options.estimate_geometry = false;
  const KinematicCalibration nominal = fit_or_refuse(robot.kinematics, fit, options, args);
  options.estimate_geometry = true;
  const KinematicCalibration calibrated = fit_or_refuse(robot.kinematics, fit, options, args);
  const ErrorStats nominal_fit = error_stats(nominal, fit);
  const ErrorStats nominal_held = error_stats(nominal, held_out);
  const ErrorStats calibrated_fit = error_stats(calibrated, fit);
  const ErrorStats calibrated_held = error_stats(calibrated, held_out);
  std::cout << fmt::format("{} ({} fitted, {} held-out poses)\n", split, fit.size(),
                           held_out.size());
  print_errors("nominal", nominal_fit, nominal_held);
  print_errors("calibrated", calibrated_fit, calibrated_held);
  print_parameters(calibrated);
  const bool better = calibrated_held.rms_mm < nominal_held.rms_mm;
  nlohmann::json report{{"robot", args.robot},
                        {"split", split},
                        {"fitted_poses", fit.size()},
                        {"held_out_poses", held_out.size()},
                        {"nominal", calibration_json(nominal)},
                        {"calibrated", calibration_json(calibrated)},
                        {"calibrated_beats_nominal_on_held_out", better}};
  report["nominal"]["fitted_errors"] = stats_json(nominal_fit);
  report["nominal"]["held_out_errors"] = stats_json(nominal_held);
  report["calibrated"]["fitted_errors"] = stats_json(calibrated_fit);
  report["calibrated"]["held_out_errors"] = stats_json(calibrated_held);
  imscal::write_file_atomically(
      args.out, imscal::json_text(report, 2, args.out),
      args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  if (!better) {
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
      sub.add_option("--robot", args->robot, "Robot file (YAML or URDF)")->required();
      sub.add_option("--poses", args->poses, "Tracker poses CSV (q*_rad, meas_*_mm) to fit")
          ->required();
      sub.add_option("--held-out", args->held_out,
                     "Tracker poses CSV to judge on (default: alternate rows of --poses)");
      sub.add_option("--out", args->out, "JSON report (written atomically)")->required();
      sub.add_option(
             "--min-independence", args->min_independence,
             "Parameters whose scaled Jacobian column is less independent are not estimated")
          ->check(CLI::Range(1e-9, 0.5));
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
