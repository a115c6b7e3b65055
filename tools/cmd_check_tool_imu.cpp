// `imscal check-tool-imu` (calib/tool_imu_check_session.hpp): reads a tool-mounted IMU record
// (sensor rates + robot tool pose), prints every defect found (NaN rows, time steps, robot
// quaternions, gyro rails, scale/unit, time offset, lost motion, quaternion convention, axis
// misalignment) and the rotation calibration (R_T_S, gyro bias and scale, time offset, 1 sigma).
// The calibration (this record's own, or with --calibration-from another record's, with this run's
// clock offset and standstill bias) is applied to the gyro: every motion segment whose rotation the
// gyro lost by 5 deg or more is listed, and the orientation error against the robot's poses is
// printed from the start and restarted after each lost span (--no-restart: from the start only).
// With
// --xsens, the AHRS's own error beside it, or the reason its record is refused as a reference.
// --out writes all of it as JSON (atomically). A record the calibration cannot use ends with
// an InputError (exit 2), before any output is written.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>

#include "calib/tool_imu_check_session.hpp"
#include "core/atomic_file.hpp"
#include "core/json_output.hpp"
#include "tools/command_registry.hpp"

namespace {

struct Args {
  imscal::calib::ToolImuCheckSessionOptions session;
  std::string out;
};

void run(const Args& args) {
  const nlohmann::json report = imscal::calib::check_tool_imu_session(
      args.session, [](const std::string& text) { std::cout << text; });
  if (!args.out.empty())
    imscal::write_file_atomically(args.out, imscal::json_text(report, 2, args.out));
}

imscal::tools::CommandRegistration registration{
    "check-tool-imu",
    "Report the defects of a tool-mounted IMU record and calibrate its rotation part",
    [](CLI::App& sub) {
      auto args = std::make_shared<Args>();
      sub.add_option("--imu", args->session.imu, "Sensor CSV (t_s, gyro_*_dps, acc_*_g, robot_*)")
          ->required();
      sub.add_option("--xsens", args->session.xsens,
                     "AHRS CSV (sens_q0..3, robot_*) of the same path");
      sub.add_option("--calibration-from", args->session.calibration_from,
                     "Calibrate on this sensor CSV and apply it to --imu");
      sub.add_option("--out", args->out, "JSON report (written atomically)");
      sub.add_flag("--no-restart", args->session.no_restart,
                   "Do not restart the orientation from the robot's pose after a lost span");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
