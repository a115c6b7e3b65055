// imscal.read_robot_log: the controller's log of a run (robot/robot_log.hpp, FORMAT.md §2).
#include <string>

#include "python/bindings.hpp"
#include "robot/robot_log.hpp"

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

}  // namespace

void bind_calib(py::module_& m) {
  m.def("read_robot_log", &read_robot_log, "file"_a, "robot"_a = "",
        "Reads a robot log (robot.csv) into numpy arrays: t_s, payload_kg (N,), q_desired_rad "
        "and q_internal_rad (N, 6), with robot, cycle_s and joint_names. A non-empty robot must "
        "match the file's.");
}

}  // namespace imscal::python
