// imscal.read_joint_errors, imscal.identify and imscal.Precontrol: joint_errors.csv
// (ident/joint_error_io.hpp), the ARX identification of `imscal identify`
// (ident/identify_joints.hpp) and the precontrol's control cycle (ident/precontrol.hpp), as `imscal
// compensate` steps it.
#include <array>
#include <memory>
#include <string>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "ident/identification_config.hpp"
#include "ident/identify_joints.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "ident/precontrol.hpp"
#include "python/bindings.hpp"

namespace imscal::python {
namespace {

using namespace pybind11::literals;

// [joint][sample] -> (samples, joints)
py::array_t<double> by_sample(const std::vector<std::vector<double>>& q) {
  const std::size_t n = q.empty() ? 0 : q.front().size();
  return matrix(n, q.size(), [&](std::size_t r, std::size_t c) { return q[c][r]; });
}

py::dict read_joint_errors(const std::string& file) {
  const ident::JointErrorLog log = ident::read_joint_errors_csv(file);
  py::list segments;
  for (const auto& [begin, end] : log.segments()) segments.append(py::make_tuple(begin, end));
  return py::dict("robot"_a = log.robot, "cycle_s"_a = log.cycle_s, "source"_a = log.source,
                  "joint_names"_a = log.joint_names, "t_s"_a = vector_array(log.time_s),
                  "payload_kg"_a = vector_array(log.payload_kg),
                  "q_desired_rad"_a = by_sample(log.q_desired_rad),
                  "q_measured_rad"_a = by_sample(log.q_measured_rad),
                  "q_internal_rad"_a = by_sample(log.q_internal_rad), "segments"_a = segments);
}

// The table as parameters.json holds it (a dict) and the held-out fit of every joint's table.
py::dict identify(const std::string& joint_errors, const std::string& config_file) {
  const ident::JointErrorLog log = ident::read_joint_errors_csv(joint_errors);
  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(config_file));
  if (config.options.model_torque_input) {
    throw InputError(config_file, 0, "model.model_torque",
                     "the model-torque input needs the robot's dynamics along the path: not "
                     "offered from Python, use `imscal identify --robot`");
  }
  ident::ParameterTable table = ident::parameter_table_header(
      log, config,
      {joint_errors, ident::file_sha256_hex(joint_errors), log.sample_count(), log.source});
  py::list fit_percent, failures;
  for (auto& outcome : ident::identify_joints(log, config)) {
    fit_percent.append(outcome.result.table_fit.joint_error_fit_percent);
    failures.append(outcome.failure);
    table.joints.push_back(std::move(outcome.result.parameters));
  }
  const py::object json_loads = py::module_::import("json").attr("loads");
  return py::dict("table"_a = json_loads(ident::parameters_json_text(table)),
                  "joint_error_fit_percent"_a = fit_percent, "failures"_a = failures);
}

// The precontrol with its table; one call of step() per controller cycle.
class PythonPrecontrol {
 public:
  PythonPrecontrol(const std::string& table_file, const std::string& robot, double caller_cycle_s,
                   bool auto_engage, double offset_tolerance_rad)
      : table_(ident::read_parameters_json(table_file)),
        precontrol_(std::make_unique<ident::Precontrol>()) {
    ident::PrecontrolOptions options;
    options.caller_cycle_s = caller_cycle_s;
    options.auto_engage = auto_engage;
    if (offset_tolerance_rad > 0.0) options.offset_tolerance_rad.fill(offset_tolerance_rad);
    std::string why;
    if (!ident::Precontrol::create(table_, robot.empty() ? table_.robot : robot, options,
                                   precontrol_.get(), &why)) {
      throw InputError(table_file, 0, "", "the precontrol refuses this table: " + why);
    }
    if (precontrol_->needs_model_torque()) {
      throw InputError(table_file, 0, "extra_inputs",
                       "the table's models take the model torque: not offered from Python, use "
                       "`imscal compensate --robot`");
    }
  }

  py::tuple step(const std::array<double, ident::kPrecontrolJoints>& q_desired_rad,
                 double payload_kg, std::uint64_t cycle) {
    const ident::PrecontrolOutput out = precontrol_->cycle(q_desired_rad, payload_kg, cycle);
    py::array_t<double> offset(ident::kPrecontrolJoints, out.offset_rad.data());
    return py::make_tuple(offset, ident::to_string(out.state), out.outside_table);
  }

  py::list events() {
    std::array<ident::PrecontrolEvent, ident::kPrecontrolEventCapacity> buffer{};
    const int n = precontrol_->read_events(buffer.data(), int(buffer.size()));
    py::list out;
    for (int i = 0; i < n; ++i) {
      const ident::PrecontrolEvent& e = buffer[std::size_t(i)];
      out.append(py::dict("cycle"_a = e.cycle, "joint"_a = int(e.joint),
                          "cause"_a = ident::to_string(e.cause), "value"_a = e.value));
    }
    return out;
  }

  int preview_cycles() const { return table_.preview_cycles; }
  void reactivate() { precontrol_->reactivate(); }

 private:
  ident::ParameterTable table_;
  std::unique_ptr<ident::Precontrol> precontrol_;
};

}  // namespace

void bind_ident(py::module_& m) {
  m.def("read_joint_errors", &read_joint_errors, "file"_a,
        "Reads a joint_errors.csv: t_s, payload_kg (N,), q_desired_rad, q_measured_rad, "
        "q_internal_rad (N, joints), with robot, cycle_s, joint_names and the gap-free segments "
        "as (begin, end) sample ranges. The joint error is q_desired_rad - q_measured_rad.");
  m.def("identify", &identify, "joint_errors"_a, "config"_a,
        "The per-joint ARX error models of `imscal identify` from a joint_errors.csv and an "
        "identification config: 'table' (parameters.json as a dict), 'joint_error_fit_percent' "
        "(held-out fit of each joint's table) and 'failures' (empty where identified).");
  py::class_<PythonPrecontrol>(m, "Precontrol",
                               "The online error compensation on a parameters.json, one step() "
                               "per controller cycle (as `imscal compensate` runs it).")
      .def(py::init<const std::string&, const std::string&, double, bool, double>(), "table"_a,
           "robot"_a = "", "caller_cycle_s"_a = 0.002, "auto_engage"_a = true,
           "offset_tolerance_rad"_a = 0.0)
      .def("step", &PythonPrecontrol::step, "q_desired_rad"_a, "payload_kg"_a, "cycle"_a,
           "One cycle: the 6 desired joint angles [rad] (preview_cycles ahead for an "
           "inverse-form table), the payload [kg], the cycle number. Returns (offset_rad (6,), "
           "state, outside_table).")
      .def("events", &PythonPrecontrol::events, "The supervisor's events since the last call.")
      .def("reactivate", &PythonPrecontrol::reactivate)
      .def_property_readonly("preview_cycles", &PythonPrecontrol::preview_cycles);
}

}  // namespace imscal::python
