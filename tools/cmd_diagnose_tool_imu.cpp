// `imscal diagnose-tool-imu --imu TRAINING.csv --held-out HELD.csv [--out FILE.json]`: the gap
// between a tool-mounted IMU's gyro and the rate of the robot's reported tool motion
// (eval/gap_imu_signals.hpp), measured after the unit check: the effects (unit or scale error,
// clock offset, axis misalignment, scale factors, bias, saturation) fitted on the training record
// and kept while they shrink the held-out record's gap (a second sequence of the same sensor).
// Prints the verdict and the steps; --out writes them as JSON (atomically).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "calib/tool_imu_record.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/units.hpp"
#include "eval/gap_imu_signals.hpp"
#include "tools/command_registry.hpp"

namespace {

using namespace imscal;

struct Args {
  std::string imu, held_out, out;
  bool force = false;
};

nlohmann::json model_json(const eval::ImuGapModel& m) {
  nlohmann::json rails = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) {
    rails.push_back(m.rail_rad_s[i] < 1e299 ? nlohmann::json(m.rail_rad_s[i] * kDegPerRad)
                                            : nullptr);
  }
  const Eigen::Matrix3d& R = m.R_T_S;
  return {{"time_offset_s", m.time_offset_s},
          {"R_T_S", {R.row(0), R.row(1), R.row(2)}},
          {"axis_angle_deg", Eigen::AngleAxisd(R).angle() * kDegPerRad},
          {"scale_as_labelled", m.scale},
          {"bias_deg_s_as_labelled", m.bias_rad_s * kDegPerRad},
          {"rail_deg_s_as_labelled", rails}};
}

nlohmann::json diagnosis_json(const Args& args, const eval::ImuGapDiagnosis& d) {
  nlohmann::json steps = nlohmann::json::array();
  for (const eval::ImuGapStep& s : d.steps) {
    steps.push_back({{"effect", eval::to_string(s.effect)},
                     {"from_unit_check", s.from_unit_check},
                     {"held_out_rms_deg_s", s.heldout_rms_rad_s * kDegPerRad},
                     {"held_out_shrinkage_percent", s.heldout_shrinkage_percent},
                     {"size", s.size}});
  }
  nlohmann::json not_supported = nlohmann::json::array();
  for (eval::ImuGapEffect e : d.not_supported) not_supported.push_back(eval::to_string(e));
  return {{"training", args.imu},
          {"held_out", args.held_out},
          {"unit_scale", d.unit_scale},
          {"held_out_rms_as_labelled_deg_s", d.heldout_rms_as_labelled_rad_s * kDegPerRad},
          {"training_rms_deg_s", d.training_rms_rad_s * kDegPerRad},
          {"held_out_rms_deg_s", d.heldout_rms_rad_s * kDegPerRad},
          {"held_out_rms_modelled_deg_s", d.heldout_rms_modelled_rad_s * kDegPerRad},
          {"held_out_noise_deg_s", d.heldout_noise_rad_s * kDegPerRad},
          {"excluded_training_s", d.excluded_training_s},
          {"excluded_held_out_s", d.excluded_heldout_s},
          {"steps", steps},
          {"not_supported", not_supported},
          {"model", model_json(d.model)},
          {"verdict", d.verdict}};
}

void run(const Args& args) {
  if (!args.out.empty())
    prepare_output_file(args.out, args.force ? Overwrite::kAllow : Overwrite::kRefuse);
  const calib::ToolImuRecord training = calib::read_tool_imu_record(args.imu);
  const calib::ToolImuRecord held_out = calib::read_tool_imu_record(args.held_out);
  if (!training.has_raw_imu || !held_out.has_raw_imu) {
    throw InputError(training.has_raw_imu ? args.held_out : args.imu, 0, "gyro_x_dps",
                     "no raw gyro columns: the gap diagnosis needs a raw IMU record");
  }
  const eval::ImuGapDiagnosis d = eval::diagnose_imu_gap(training, held_out);
  std::cout << d.verdict << "\n";
  for (const eval::ImuGapStep& s : d.steps) {
    std::cout << fmt::format("  + {:<18} held-out RMS {:.2f} deg/s ({:.0f} % smaller): {}\n",
                             eval::to_string(s.effect), s.heldout_rms_rad_s * kDegPerRad,
                             s.heldout_shrinkage_percent, s.size);
  }
  if (!args.out.empty()) {
    write_file_atomically(args.out, json_text(diagnosis_json(args, d), 2, args.out),
                          args.force ? Overwrite::kAllow : Overwrite::kRefuse);
  }
}

tools::CommandRegistration registration{
    "diagnose-tool-imu",
    "Gap between a tool IMU's gyro and the robot's tool rate, after the unit check, held out",
    [](CLI::App& sub) {
      auto args = std::make_shared<Args>();
      sub.add_option("--imu", args->imu, "Training record (sensor CSV, check-tool-imu's format)")
          ->required();
      sub.add_option("--held-out", args->held_out, "Held-out record of the same sensor")
          ->required();
      sub.add_option("--out", args->out, "JSON report (written atomically)");
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
