// `imscal calibrate --imu FILE --robot-log FILE --robot ROBOT.yaml --sensor SPEC.yaml
//  [--config YAML] [--unit-calibration YAML] [--frames PREVIOUS/frames.json]
//  [--heading-reference YAW_DEG,SIGMA_DEG] --out DIR [--force]`:
//  the wrist/sensor calibration of the paper (calib::calibrate_session,
//  calib/calibration_session.hpp). Writes, all or nothing (core/output_folder.hpp), the files of
//  datasets/FORMAT.md §16:
//   frames.json  mounting_report.json  summary.txt  joint_errors.csv
// With --frames (a later session with the same robot, base and mount): T_R_W's rotation and
// T_S_H are taken from the earlier session's frames.json and held.
// Exit codes: 0 verdict pass or warn, 1 verdict fail (the outputs are still written), 2 bad input.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calib/calibration_session.hpp"
#include "calib/calibration_session_inputs.hpp"
#include "calib/calibration_session_outputs.hpp"
#include "calib/calibration_session_progress.hpp"
#include "core/output_folder.hpp"
#include "core/progress.hpp"
#include "core/progress_channel.hpp"
#include "core/version.hpp"
#include "eval/calibration_joint_errors.hpp"
#include "tools/command_registry.hpp"

namespace {
namespace fs = std::filesystem;
namespace calib = imscal::calib;
using namespace imscal;

struct CalibrateArgs {
  calib::SessionFiles files;
  std::string out;
  bool force = false;
};

bool writes_joint_errors(const std::vector<fs::path>& outputs) {
  return std::find(outputs.begin(), outputs.end(), fs::path("joint_errors.csv")) != outputs.end();
}

void run(const CalibrateArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  // Refuse existing outputs before any work (exit 2 through InputError); the config decides
  // whether joint_errors.csv is written.
  const std::vector<fs::path> outputs = calib::session_output_names(args.files);
  const Overwrite overwrite = args.force ? Overwrite::kAllow : Overwrite::kRefuse;
  { OutputFolder check(args.out, outputs, overwrite); }

  Progress progress;
  // The whole command's share for `imscal run` (one copy: it keeps the highest share reported).
  const calib::SessionProgress share = calib::command_share_progress(progress_channel());
  progress.update("read", 0.0);
  calib::LoadedSession loaded = calib::read_session_inputs(args.files);
  // The staged outputs, made when the first joint-error row comes (or at the end):
  // joint_errors.csv's rows go there as they are computed, not held.
  std::optional<OutputFolder> folder;
  std::optional<eval::CalibrationJointErrorsCsv> joint_errors;
  const auto open_outputs = [&] {
    if (folder) return;
    folder.emplace(args.out, outputs, overwrite);
    if (writes_joint_errors(outputs))
      joint_errors.emplace(folder->staged("joint_errors.csv"), loaded.inputs.log);
  };
  if (writes_joint_errors(outputs)) {
    loaded.options.joint_error_rows = [&](const calib::JointErrorRow& row) {
      open_outputs();
      joint_errors->add(row);
    };
  }
  const calib::SessionResult session = calib::calibrate_session(
      loaded.inputs, loaded.options, [&](const std::string& stage, double fraction) {
        progress.update(stage, fraction);
        share(stage, fraction);
      });
  progress.update("write", 0.0);
  share("write", 0.0);
  open_outputs();
  const calib::SessionFiles& f = args.files;
  calib::stage_session_outputs(*folder, f, loaded, session);
  if (joint_errors && session.joint_errors)
    joint_errors->commit(
        *session.joint_errors, loaded.inputs.log,
        fmt::format("imscal {} calibrate --imu {} --robot-log {}", kVersion, f.imu, f.robot_log));
  folder->commit();
  progress.finish();
  share("write", 1.0);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const calib::MountingValidation& validation = session.validation;
  std::cout << fmt::format("verdict: {}\n", calib::to_string(validation.verdict));
  for (const auto& reason : validation.reasons) std::cout << "  - " << reason << '\n';
  spdlog::info("calibrate: wrote {} files to {} in {:.1f} s", outputs.size(), args.out, seconds);
  if (validation.verdict == calib::Verdict::kFail)
    throw tools::CheckFailed(fmt::format("mounting verdict fail ({}); outputs written to {}",
                                         validation.reasons.front(), args.out));
}

tools::CommandRegistration registration{
    "calibrate",
    "Calibrate T_R_W, T_S_H, IMS biases and the clock offset from rest poses; validate the "
    "mounting; joint errors",
    [](CLI::App& sub) {
      auto args = std::make_shared<CalibrateArgs>();
      calib::SessionFiles& f = args->files;
      sub.add_option("--imu", f.imu, "Raw IMS record (.csv, .imsb, .imu)")->required();
      sub.add_option("--robot-log", f.robot_log, "Robot controller log (robot.csv)")->required();
      sub.add_option(
          "--robot", f.robot,
          "Robot description (datasets/robots/*.yaml or a .urdf); default: the config's");
      sub.add_option("--sensor", f.sensor,
                     "IMS sensor spec (datasets/sensors/*.yaml); default: the config's");
      sub.add_option("--config", f.config,
                     "Calibration config (datasets/calibration/calibrate-default.yaml)");
      sub.add_option("--unit-calibration", f.unit_calibration,
                     "The IMS unit's lab calibration (scale factors, misalignments; "
                     "ims/sensor_error_model.hpp format), applied to the raw record; default: "
                     "the config's unit_calibration");
      sub.add_option(
          "--frames", f.frames,
          "frames.json of an earlier session with the same robot, base and IMS mount: T_R_W's "
          "rotation and T_S_H (with their covariance) are taken from it and held, and only the "
          "biases and the clock offset are estimated, from as few as 1 rest (e.g. identification "
          "runs); the mounting report then gives this record's residuals against those frames. "
          "Refused: another robot, another format version, missing or NaN values");
      sub.add_option("--heading-reference", f.heading_reference,
                     "YAW_DEG,SIGMA_DEG: a surveyed heading of the robot base, the yaw of T_W_R "
                     "(its x axis counterclockwise from East) with its 1-sigma, as a prior in the "
                     "bundle; the IMS-only heading is reported beside it. Default: the config's "
                     "heading_reference");
      sub.add_option("--out", args->out, "Output folder")->required();
      sub.add_flag("--force", args->force, "Replace existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
