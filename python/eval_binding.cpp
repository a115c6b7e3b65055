// imscal.read_path, imscal.evaluate_paths and imscal.diagnose: path files and their ISO 9283 path
// characteristics (eval/path_evaluation.hpp), with the keys of `imscal evaluate --out`, and the
// gap diagnosis of `imscal diagnose` (eval/gap_session.hpp).
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "eval/gap_report.hpp"
#include "eval/gap_session.hpp"
#include "eval/path_evaluation.hpp"
#include "python/bindings.hpp"

namespace imscal::python {
namespace {

using namespace pybind11::literals;

py::dict read_path(const std::string& file, double from_s, double to_s) {
  const eval::PoseSeries s = eval::read_path_file(file, from_s, to_s);
  return py::dict(
      "t_s"_a =
          matrix(s.size(), 1, [&](std::size_t r, std::size_t) { return s[r].t_s; }).attr("ravel")(),
      "p_m"_a =
          matrix(s.size(), 3, [&](std::size_t r, std::size_t c) { return s[r].p_m[long(c)]; }),
      "q_wxyz"_a = matrix(
          s.size(), 4, [&](std::size_t r, std::size_t c) { return quaternion_wxyz(s[r].q, c); }));
}

// A figures.json value as Python: objects as dicts, arrays as lists, null (a figure that needs
// two cycles, or a speed that was not reached) as NaN.
py::object to_python(const nlohmann::json& v) {
  if (v.is_null()) return py::float_(std::numeric_limits<double>::quiet_NaN());
  if (v.is_boolean()) return py::bool_(v.get<bool>());
  if (v.is_number_integer()) return py::int_(v.get<long long>());
  if (v.is_number()) return py::float_(v.get<double>());
  if (v.is_string()) return py::str(v.get<std::string>());
  if (v.is_array()) {
    py::list list;
    for (const nlohmann::json& item : v) list.append(to_python(item));
    return list;
  }
  py::dict dict;
  for (const auto& [key, item] : v.items()) dict[py::str(key)] = to_python(item);
  return dict;
}

py::dict evaluate_paths(const std::string& commanded_file,
                        const std::vector<std::string>& attained_files, double velocity_m_s,
                        double from_s, double to_s, double window_s, int points) {
  eval::PathEvaluationOptions options;
  options.commanded = commanded_file;
  options.attained = attained_files;
  options.velocity_m_s = velocity_m_s;
  options.from_s = from_s;
  options.to_s = to_s;
  options.window_s = window_s;
  options.points = points;
  return to_python(eval::evaluate_paths(options).document);
}

// The session of `imscal diagnose` (eval/gap_session.hpp): report.json as a dict (the file's
// text, through json), report.txt, the verdict and what to measure next, and the gap itself.
py::dict diagnose(const eval::GapSessionOptions& options) {
  const eval::GapSession s = eval::diagnose_gap_session(options);
  const py::object json_loads = py::module_::import("json").attr("loads");
  const auto& g = s.signals.gap_rad;
  return py::dict(
      "report"_a =
          json_loads(json_text(eval::diagnosis_json(s.signals, s.diagnosis), 1, "diagnosis.json")),
      "text"_a = eval::diagnosis_text(s.signals, s.diagnosis), "verdict"_a = s.diagnosis.verdict,
      "measure_next"_a = s.diagnosis.measure_next, "t_s"_a = vector_array(s.signals.time_s),
      "gap_rad"_a = matrix(s.signals.sample_count(), g.size(),
                           [&](std::size_t r, std::size_t c) { return g[c][r]; }));
}

}  // namespace

void bind_eval(py::module_& m) {
  m.def(
      "read_path", &read_path, "file"_a, "from_s"_a = -1e300, "to_s"_a = 1e300,
      "Reads a path file (t_s,x_m,y_m,z_m,qw,qx,qy,qz) into t_s (N,), p_m (N, 3), q_wxyz (N, 4).");
  m.def("evaluate_paths", &evaluate_paths, "commanded"_a, "attained"_a, py::kw_only(),
        "velocity_m_s"_a = 0.0, "from_s"_a = -1e300, "to_s"_a = 1e300, "window_s"_a = 0.25,
        "points"_a = 200,
        "ISO 9283 path characteristics of attained path files (one per cycle) against the "
        "commanded one, as `imscal evaluate`: a dict with the keys of its figures.json (AT_p_mm, "
        "RT_p_mm, AT_a_deg, ..., max_path_deviation_mm, per_cycle). velocity_m_s <= 0: the "
        "commanded top speed.");
  m.def(
      "diagnose",
      [](const std::string& joint_errors, const std::string& robot, const std::string& table,
         const std::string& sim_joint_errors, double max_analysed_s, const std::string& frames,
         const std::string& scenario) {
        if (table.empty() == sim_joint_errors.empty())
          throw InputError(joint_errors, 0, "table",
                           "give the sim side: either table or sim_joint_errors");
        eval::GapSessionOptions options;
        options.joint_errors = joint_errors;
        options.table = table;
        options.sim_joint_errors = sim_joint_errors;
        options.robot = robot;
        options.max_analysed_s = max_analysed_s;
        options.frames = frames;
        options.scenario = scenario;
        return diagnose(options);
      },
      "joint_errors"_a, "robot"_a, py::kw_only(), "table"_a = "", "sim_joint_errors"_a = "",
      "max_analysed_s"_a = eval::AnalysisWindows{}.max_s, "frames"_a = "", "scenario"_a = "",
      "The sim-to-real gap diagnosis of `imscal diagnose`: the measured joint_errors.csv "
      "against an identified table (parameters.json) or a second joint_errors.csv; frames: "
      "calibrate's frames.json for the measurement budget, scenario: the one whose nominal "
      "model made sim_joint_errors (the joint model refined on it), as the command's options. "
      "Returns "
      "'report' (report.json as a dict), 'text' (report.txt), 'verdict', 'measure_next', and "
      "the analysed samples' t_s (N,) and gap_rad (N, joints), real minus sim joint error.");
}

}  // namespace imscal::python
