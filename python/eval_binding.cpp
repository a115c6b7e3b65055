// imscal.read_path and imscal.evaluate_paths: path files and their ISO 9283 path
// characteristics (eval/path_evaluation.hpp), with the keys of `imscal evaluate --out`.
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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
