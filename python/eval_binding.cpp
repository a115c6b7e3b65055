// imscal.read_path and imscal.evaluate_paths: path files and their ISO 9283 path
// characteristics (eval/path_evaluation.hpp), with the keys of `imscal evaluate --out`.
#include <string>
#include <vector>

#include "core/units.hpp"
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

// NaN (a figure that needs two cycles, or a speed that was not reached) stays NaN here, where
// figures.json writes null.
py::dict evaluate_paths(const std::string& commanded_file,
                        const std::vector<std::string>& attained_files, double velocity_m_s,
                        double from_s, double to_s, double window_s, int points) {
  const eval::PoseSeries commanded = eval::read_path_file(commanded_file, from_s, to_s);
  std::vector<eval::PoseSeries> attained;
  for (const auto& f : attained_files) {
    attained.push_back(eval::read_path_file(f, from_s - window_s, to_s + window_s));
  }
  eval::Iso9283Options options;
  options.calculation_points = points;
  options.time_window_s = window_s;
  const eval::PathEvaluation e = eval::evaluate_paths(commanded, attained, velocity_m_s, options);
  const eval::Iso9283PathResult& r = e.iso;
  py::list per_cycle;
  for (std::size_t j = 0; j < attained.size(); ++j) {
    per_cycle.append(py::dict("file"_a = attained_files[j],
                              "max_path_deviation_mm"_a = e.deviation[j].max_m * 1e3,
                              "rms_path_deviation_mm"_a = e.deviation[j].rms_m * 1e3));
  }
  constexpr double deg = kDegPerRad;
  return py::dict("cycles"_a = r.cycles, "length_m"_a = r.length_m,
                  "commanded_speed_m_s"_a = e.commanded_speed_m_s, "AT_p_mm"_a = r.AT_p_m * 1e3,
                  "RT_p_mm"_a = r.RT_p_m * 1e3, "AT_a_deg"_a = r.AT_abc_rad[0] * deg,
                  "AT_b_deg"_a = r.AT_abc_rad[1] * deg, "AT_c_deg"_a = r.AT_abc_rad[2] * deg,
                  "RT_a_deg"_a = r.RT_abc_rad[0] * deg, "RT_b_deg"_a = r.RT_abc_rad[1] * deg,
                  "RT_c_deg"_a = r.RT_abc_rad[2] * deg, "AV_percent"_a = r.AV_percent,
                  "RV_percent"_a = r.RV_percent, "FV_m_s"_a = r.FV_m_s,
                  "max_path_deviation_mm"_a = e.max_path_deviation_m * 1e3,
                  "missed_crossings"_a = r.missed_crossings, "per_cycle"_a = per_cycle);
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
}

}  // namespace imscal::python
