// `imscal check-tool-imu`: reads a tool-mounted IMU record (sensor rates + robot tool pose),
// prints every defect found (NaN rows, time steps, robot quaternions, gyro rails, scale/unit,
// time offset, lost motion, quaternion convention, axis misalignment) and the rotation
// calibration (R_T_S, gyro bias and scale, time offset, 1 sigma). With --calibration-from, the
// calibration is taken from another record and the orientation error of the calibrated gyro
// against this record's robot poses is printed; with --xsens, the AHRS's own error beside it.
// --out writes all of it as JSON (atomically).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "calib/attitude_filter.hpp"
#include "calib/orientation_error.hpp"
#include "calib/rotation_calibration.hpp"
#include "calib/tool_imu_record.hpp"
#include "core/atomic_file.hpp"
#include "core/json_output.hpp"
#include "tools/command_registry.hpp"

namespace {

using namespace imscal::calib;
constexpr double kDeg = 180.0 / M_PI;

struct Args {
  std::string imu;
  std::string xsens;
  std::string calibration_from;
  std::string out;
};

nlohmann::json vector_json(const Eigen::Vector3d& v, double scale = 1.0) {
  return {v.x() * scale, v.y() * scale, v.z() * scale};
}

nlohmann::json calibration_json(const RotationCalibration& c) {
  nlohmann::json j;
  j["q_T_S_wxyz"] = {c.q_T_S.w(), c.q_T_S.x(), c.q_T_S.y(), c.q_T_S.z()};
  j["rotation_angle_deg"] = Eigen::AngleAxisd(c.q_T_S).angle() * kDeg;
  j["sigma_rotation_deg"] = vector_json(c.sigma_rotation_rad, kDeg);
  j["gyro_bias_deg_s_as_labelled"] = vector_json(c.gyro_bias_rad_s, kDeg);
  j["sigma_gyro_bias_deg_s"] = vector_json(c.sigma_bias_rad_s, kDeg);
  j["gyro_scale"] = vector_json(c.gyro_scale);
  j["sigma_gyro_scale"] = vector_json(c.sigma_scale);
  j["time_offset_s"] = c.time_offset_s;
  j["sigma_time_offset_s"] = c.sigma_time_offset_s;
  j["covariance_ok"] = c.covariance_ok;
  j["window_count"] = c.window_count;
  j["rms_residual_deg"] = c.rms_residual_rad * kDeg;
  j["solver"] = c.summary;
  return j;
}

void print_calibration(const std::string& title, const RotationCalibration& c) {
  std::cout << fmt::format(
      "{}: R_T_S angle {:.3f} deg (1 sigma {:.3f} {:.3f} {:.3f} deg), time offset {:.4f} +- "
      "{:.4f} s,\n  gyro bias {:.4g} {:.4g} {:.4g} deg/s (as labelled), scale {:.5g} {:.5g} "
      "{:.5g}, window residual RMS {:.3f} deg over {} windows\n",
      title, Eigen::AngleAxisd(c.q_T_S).angle() * kDeg, c.sigma_rotation_rad.x() * kDeg,
      c.sigma_rotation_rad.y() * kDeg, c.sigma_rotation_rad.z() * kDeg, c.time_offset_s,
      c.sigma_time_offset_s, c.gyro_bias_rad_s.x() * kDeg, c.gyro_bias_rad_s.y() * kDeg,
      c.gyro_bias_rad_s.z() * kDeg, c.gyro_scale.x(), c.gyro_scale.y(), c.gyro_scale.z(),
      c.rms_residual_rad * kDeg, c.window_count);
}

void run(const Args& args) {
  nlohmann::json report;
  const ToolImuRecord record = read_tool_imu_record(args.imu);
  const ToolImuAnalysis analysis = check_tool_imu_record(record);
  std::cout << fmt::format("{}: {} rows\n", record.file, record.t_s.size());
  report["file"] = record.file;
  report["rows"] = record.t_s.size();
  for (const auto& f : analysis.findings) {
    std::cout << fmt::format("[{}{}] {}\n    {}\n", to_string(f.kind), f.is_defect ? "" : " (ok)",
                             f.where, f.message);
    report["findings"].push_back({{"kind", to_string(f.kind)},
                                  {"where", f.where},
                                  {"size", f.size},
                                  {"unit", f.unit},
                                  {"defect", f.is_defect},
                                  {"message", f.message}});
  }
  const RotationCalibration own = calibrate_rotation(record, analysis);
  print_calibration("rotation calibration on this record", own);
  report["calibration"] = calibration_json(own);

  if (!args.calibration_from.empty()) {
    const ToolImuRecord source = read_tool_imu_record(args.calibration_from);
    RotationCalibration applied = calibrate_rotation(source, check_tool_imu_record(source));
    print_calibration("calibration from " + source.file, applied);
    report["calibration_from"] = calibration_json(applied);
    // This run's own clock offset and standstill bias (what a user has at run time).
    applied.time_offset_s = analysis.time_offset_s;
    gyro_bias_at_rest(record, applied.time_offset_s, 0.01, applied.gyro_bias_rad_s, 3.0);
    const AttitudeTrack track = run_attitude_filter(record, applied);
    const OrientationErrorStats error =
        orientation_error(record, applied.time_offset_s, track.t_s, track.q_B_T);
    std::cout << fmt::format(
        "orientation error of the calibrated gyro against the robot (from the start): RMS "
        "{:.3f} deg, max {:.3f} deg over {} samples\n",
        error.rms_rad * kDeg, error.max_rad * kDeg, error.sample_count);
    report["orientation_error"] = {{"rms_deg", error.rms_rad * kDeg},
                                   {"max_deg", error.max_rad * kDeg},
                                   {"samples", error.sample_count}};
  }
  if (!args.xsens.empty()) {
    const ToolImuRecord ahrs = read_tool_imu_record(args.xsens);
    const AhrsAlignment alignment = align_ahrs_to_robot(ahrs);
    const OrientationErrorStats error =
        orientation_error(ahrs, alignment.time_offset_s, alignment.t_s, alignment.q_B_T);
    std::cout << fmt::format(
        "AHRS {} (alignment to tool and base fitted on this same record): RMS {:.3f} deg, max "
        "{:.3f} deg over {} samples\n",
        ahrs.file, error.rms_rad * kDeg, error.max_rad * kDeg, error.sample_count);
    report["ahrs_orientation_error"] = {{"file", ahrs.file},
                                        {"rms_deg", error.rms_rad * kDeg},
                                        {"max_deg", error.max_rad * kDeg},
                                        {"samples", error.sample_count},
                                        {"time_offset_s", alignment.time_offset_s}};
  }
  if (!args.out.empty())
    imscal::write_file_atomically(args.out, imscal::json_text(report, 2, args.out));
}

imscal::tools::CommandRegistration registration{
    "check-tool-imu",
    "Report the defects of a tool-mounted IMU record and calibrate its rotation part",
    [](CLI::App& sub) {
      auto args = std::make_shared<Args>();
      sub.add_option("--imu", args->imu, "Sensor CSV (t_s, gyro_*_dps, acc_*_g, robot_*)")
          ->required();
      sub.add_option("--xsens", args->xsens, "AHRS CSV (sens_q0..3, robot_*) of the same path");
      sub.add_option("--calibration-from", args->calibration_from,
                     "Calibrate on this sensor CSV and apply it to --imu");
      sub.add_option("--out", args->out, "JSON report (written atomically)");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
