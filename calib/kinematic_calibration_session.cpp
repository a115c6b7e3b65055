#include "calib/kinematic_calibration_session.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "calib/kinematic_calibration.hpp"
#include "calib/tracker_pose_limits.hpp"
#include "calib/tracker_poses.hpp"
#include "core/input_error.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

namespace {

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
void split_poses(const KinematicSessionOptions& args, const RobotDescription& robot,
                 std::vector<TrackerPose>& fit, std::vector<TrackerPose>& held_out,
                 std::string& split) {
  const TrackerPoses poses = read_tracker_poses(args.poses);
  check_tracker_pose_limits(poses, robot);
  if (!args.held_out.empty()) {
    fit = poses.poses;
    const TrackerPoses judged = read_tracker_poses(args.held_out);
    check_tracker_pose_limits(judged, robot);
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
  if (held_out.empty()) throw InputError(args.poses, 0, "", "one pose: nothing to hold out");
}

// Poses that cannot give a calibration (too few, or not determining the tracker frame) are bad
// input: an InputError naming the pose file.
KinematicCalibration fit_or_refuse(const KinematicModel& nominal,
                                   const std::vector<TrackerPose>& fit,
                                   const KinematicCalibrationOptions& options,
                                   const KinematicSessionOptions& args) {
  try {
    return calibrate_kinematics(nominal, fit, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.poses, 0, "", e.what());
  }
}

std::string errors_text(const char* name, const ErrorStats& fit, const ErrorStats& held_out) {
  return fmt::format(
      "{:<10} fitted poses RMS {:.3f} mm, max {:.3f} mm | held-out RMS {:.3f} mm, median {:.3f} "
      "mm, max {:.3f} mm\n",
      name, fit.rms_mm, fit.max_mm, held_out.rms_mm, held_out.median_mm, held_out.max_mm);
}

std::string parameters_text(const KinematicCalibration& c) {
  std::string text;
  for (const KinematicParameter& p : c.parameters) {
    const double scale = p.unit == "m" ? 1e3 : 180.0 / M_PI;
    const char* unit = p.unit == "m" ? "mm" : "deg";
    if (p.estimated) {
      text += fmt::format("  {:<9} {:>10.4f} +- {:.4f} {}\n", p.name, p.value * scale,
                          p.sigma * scale, unit);
    } else {
      text += fmt::format("  {:<9} not estimated: {}\n", p.name, p.reason);
    }
  }
  return text;
}

}  // namespace

KinematicSession calibrate_kinematics_session(const KinematicSessionOptions& args) {
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
  KinematicSession s;
  s.text = fmt::format("{} ({} fitted, {} held-out poses)\n", split, fit.size(), held_out.size());
  s.text += errors_text("nominal", nominal_fit, nominal_held);
  s.text += errors_text("calibrated", calibrated_fit, calibrated_held);
  s.text += parameters_text(calibrated);
  s.calibrated_beats_nominal = calibrated_held.rms_mm < nominal_held.rms_mm;
  s.report = {{"robot", args.robot},
              {"split", split},
              {"fitted_poses", fit.size()},
              {"held_out_poses", held_out.size()},
              {"nominal", calibration_json(nominal)},
              {"calibrated", calibration_json(calibrated)},
              {"calibrated_beats_nominal_on_held_out", s.calibrated_beats_nominal}};
  s.report["nominal"]["fitted_errors"] = stats_json(nominal_fit);
  s.report["nominal"]["held_out_errors"] = stats_json(nominal_held);
  s.report["calibrated"]["fitted_errors"] = stats_json(calibrated_fit);
  s.report["calibrated"]["held_out_errors"] = stats_json(calibrated_held);
  return s;
}

}  // namespace imscal::calib
