// imscal.read_robot_log and imscal.calibrate: the controller's log of a run (calib/robot_log.hpp,
// FORMAT.md §2) and the calibration session of `imscal calibrate`
// (calib/calibration_session.hpp).
#include <string>
#include <vector>

#include "calib/calibration_session.hpp"
#include "calib/calibration_session_inputs.hpp"
#include "calib/calibration_session_json.hpp"
#include "calib/calibration_session_summary.hpp"
#include "calib/robot_log.hpp"
#include "core/json_output.hpp"
#include "python/bindings.hpp"

namespace imscal::python {
namespace {

using namespace pybind11::literals;

py::dict read_robot_log(const std::string& file, const std::string& robot) {
  const calib::RobotLog log = calib::read_robot_log_csv(file, robot, "the robot argument");
  const auto& s = log.samples;
  py::list joint_names;
  for (const auto& name : log.joint_names) joint_names.append(name);
  auto joints = [&](calib::JointVector calib::RobotLogSample::*member) {
    return matrix(s.size(), calib::kJointCount,
                  [&](std::size_t r, std::size_t c) { return (s[r].*member)[long(c)]; });
  };
  return py::dict(
      "robot"_a = log.robot_name, "cycle_s"_a = log.cycle_s, "joint_names"_a = joint_names,
      "t_s"_a =
          matrix(s.size(), 1, [&](std::size_t r, std::size_t) { return s[r].t_s; }).attr("ravel")(),
      "payload_kg"_a =
          matrix(s.size(), 1, [&](std::size_t r, std::size_t) { return s[r].payload_kg; })
              .attr("ravel")(),
      "q_desired_rad"_a = joints(&calib::RobotLogSample::q_desired_rad),
      "q_internal_rad"_a = joints(&calib::RobotLogSample::q_internal_rad));
}

// Samples x 6 of a joint-space series.
py::array_t<double> joint_rows(const std::vector<calib::JointVector>& q) {
  return matrix(q.size(), calib::kJointCount,
                [&](std::size_t r, std::size_t c) { return q[r][long(c)]; });
}

// The session of `imscal calibrate` (calib/calibration_session.hpp) on the same files: its
// frames.json and mounting_report.json as dicts (the files' text, through json), summary.txt and
// the joint errors joint_errors.csv holds (None when the config turns them off).
py::dict calibrate(const calib::SessionFiles& files) {
  const calib::LoadedSession loaded = calib::read_session_inputs(files);
  const calib::SessionResult session = calib::calibrate_session(loaded.inputs, loaded.options);
  const calib::SessionJson json = calib::session_json(files, loaded, session);
  const py::object json_loads = py::module_::import("json").attr("loads");
  py::object joint_errors = py::none();
  if (session.joint_errors) {
    const calib::JointSpaceErrors& e = *session.joint_errors;
    joint_errors =
        py::dict("t_s"_a = vector_array(e.t_s), "payload_kg"_a = vector_array(e.payload_kg),
                 "q_desired_rad"_a = joint_rows(e.q_desired_rad),
                 "q_measured_rad"_a = joint_rows(e.q_measured_rad),
                 "q_internal_rad"_a = joint_rows(e.q_internal_rad));
  }
  py::list reasons;
  for (const auto& reason : session.validation.reasons) reasons.append(reason);
  return py::dict(
      "verdict"_a = calib::to_string(session.validation.verdict), "reasons"_a = reasons,
      "frames"_a = json_loads(json_text(json.frames, 1, "frames.json")),
      "mounting_report"_a = json_loads(json_text(json.mounting_report, 1, "mounting_report.json")),
      "summary"_a =
          calib::session_summary_text({files.imu, files.robot_log, files.frames}, session),
      "joint_errors"_a = joint_errors);
}

}  // namespace

void bind_calib(py::module_& m) {
  m.def("read_robot_log", &read_robot_log, "file"_a, "robot"_a = "",
        "Reads a robot log (robot.csv) into numpy arrays: t_s, payload_kg (N,), q_desired_rad "
        "and q_internal_rad (N, 6), with robot, cycle_s and joint_names. A non-empty robot must "
        "match the file's.");
  m.def(
      "calibrate",
      [](const std::string& imu, const std::string& robot_log, const std::string& robot,
         const std::string& sensor, const std::string& config, const std::string& unit_calibration,
         const std::string& frames, const std::string& heading_reference) {
        return calibrate(
            {imu, robot_log, robot, sensor, config, unit_calibration, frames, heading_reference});
      },
      "imu"_a, "robot_log"_a, py::kw_only(), "robot"_a = "", "sensor"_a = "", "config"_a = "",
      "unit_calibration"_a = "", "frames"_a = "", "heading_reference"_a = "",
      "The wrist/sensor calibration of `imscal calibrate` (the same options, empty: the "
      "config's): 'verdict' and 'reasons' of the mounting check, 'frames' and "
      "'mounting_report' (frames.json and mounting_report.json as dicts), 'summary' "
      "(summary.txt) and 'joint_errors' (t_s, payload_kg (N,), q_desired_rad, q_measured_rad, "
      "q_internal_rad (N, 6): what joint_errors.csv holds; None when the config has them off). "
      "A mounting verdict 'fail' is returned, not raised.");
}

}  // namespace imscal::python
