// imscal.read_joint_errors, imscal.identify, imscal.model_torques and imscal.Precontrol:
// joint_errors.csv (ident/joint_error_io.hpp), the ARX identification of `imscal identify`
// (eval/identification_session.hpp), the rigid-body torques of a path (eval/model_torque.hpp) and
// the precontrol's control cycle (ident/precontrol.hpp), as `imscal compensate` steps it.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/units.hpp"
#include "eval/identification_session.hpp"
#include "eval/model_torque.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "ident/precontrol.hpp"
#include "python/bindings.hpp"
#include "robot/robot_description.hpp"

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
                  "q_internal_rad"_a = log.has_q_internal()
                                           ? py::object(by_sample(log.q_internal_rad))
                                           : py::object(py::none()),
                  "segments"_a = segments);
}

// The session of `imscal identify` (eval/identification_session.hpp): the table as
// parameters.json holds it (a dict), identification_report.json (a dict) and the held-out fit of
// every joint's table. `robot` and `gravity_m_s2` are its --robot and --gravity-m-s2, the
// rigid-body model a config with the model-torque input needs.
py::dict identify(const std::string& joint_errors, const std::string& config_file,
                  const std::string& robot, const std::array<double, 3>& gravity_m_s2,
                  bool search_order) {
  eval::IdentificationSessionOptions options;
  options.joint_errors = joint_errors;
  options.config = config_file;
  options.search_order = search_order;
  const Eigen::Vector3d gravity(gravity_m_s2[0], gravity_m_s2[1], gravity_m_s2[2]);
  options.model_torque = [&robot, &gravity](
                             const std::string& data_robot, const std::string& data_file,
                             const std::string& needed_by_file, const std::string& needed_by_field,
                             double data_cycle_s) {
    return eval::load_model_torque_source(robot, gravity, data_robot, data_file, needed_by_file,
                                          needed_by_field, data_cycle_s);
  };
  const eval::IdentificationResult result =
      eval::identify_session(eval::prepare_identification(options));
  py::list fit_percent, failures;
  for (const auto& outcome : result.outcomes) {
    fit_percent.append(outcome.result.table_fit.joint_error_fit_percent);
    failures.append(outcome.failure);
  }
  const py::object json_loads = py::module_::import("json").attr("loads");
  return py::dict(
      "table"_a = json_loads(ident::parameters_json_text(result.table)),
      "report"_a = result.report.is_null()
                       ? py::object(py::none())
                       : json_loads(json_text(result.report, 1, "identification_report.json")),
      "joint_error_fit_percent"_a = fit_percent, "failures"_a = failures);
}

// The joint torques of the robot's rigid-body model along a desired path (N, 6) with its payload
// (N,), as `imscal compensate --robot` feeds them to a table with the model-torque input
// (eval/model_torque.hpp: central differences over the whole path); with a table (its
// parameters.json), its refined links' masses and centres of mass (eval::with_table_links).
py::array_t<double> model_torques(const std::string& robot,
                                  const py::array_t<double, py::array::c_style>& q_desired_rad,
                                  const std::vector<double>& payload_kg, double cycle_s,
                                  const std::array<double, 3>& gravity_m_s2,
                                  const std::string& table) {
  const auto q = q_desired_rad.unchecked<2>();
  const std::size_t n = std::size_t(q.shape(0));
  if (q.shape(1) != calib::kJointCount || payload_kg.size() != n)
    throw InputError("", 0, "q_desired_rad",
                     "expected (N, 6) joint angles and N payloads, one row per cycle");
  eval::ModelTorqueSource model;
  model.robot = calib::load_robot_description(robot);
  model.gravity_in_base_m_s2 = Eigen::Vector3d(gravity_m_s2[0], gravity_m_s2[1], gravity_m_s2[2]);
  if (!table.empty())
    model = eval::with_table_links(std::move(model), ident::read_parameters_json(table), table);
  std::vector<std::vector<double>> path(calib::kJointCount, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t j = 0; j < path.size(); ++j) path[j][k] = q(py::ssize_t(k), py::ssize_t(j));
  const std::vector<std::pair<std::size_t, std::size_t>> whole{{0, n}};
  const auto torque = eval::model_torques_along(model, cycle_s, path, payload_kg, whole);
  return matrix(n, torque.size(), [&](std::size_t r, std::size_t c) { return torque[c][r]; });
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
  }

  py::tuple step(
      const std::array<double, ident::kPrecontrolJoints>& q_desired_rad, double payload_kg,
      std::uint64_t cycle,
      const std::optional<std::array<double, ident::kPrecontrolJoints>>& model_torque_nm) {
    const ident::PrecontrolOutput out =
        model_torque_nm ? precontrol_->cycle(q_desired_rad, payload_kg, *model_torque_nm, cycle)
                        : precontrol_->cycle(q_desired_rad, payload_kg, cycle);
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
  bool needs_model_torque() const { return precontrol_->needs_model_torque(); }
  void reactivate() { precontrol_->reactivate(); }

 private:
  ident::ParameterTable table_;
  std::unique_ptr<ident::Precontrol> precontrol_;
};

}  // namespace

void bind_ident(py::module_& m) {
  m.def("read_joint_errors", &read_joint_errors, "file"_a,
        "Reads a joint_errors.csv: t_s, payload_kg (N,), q_desired_rad, q_measured_rad, "
        "q_internal_rad (N, joints; None without the file's q_internal block), with robot, "
        "cycle_s, joint_names and the gap-free segments "
        "as (begin, end) sample ranges. The joint error is q_desired_rad - q_measured_rad.");
  m.def("identify", &identify, "joint_errors"_a, "config"_a, py::kw_only(), "robot"_a = "",
        "gravity_m_s2"_a = std::array<double, 3>{0.0, 0.0, -kStandardGravity_m_s2},
        "search_transmission_error_order"_a = false,
        "The per-joint ARX error models of `imscal identify` from a joint_errors.csv and an "
        "identification config: 'table' (parameters.json as a dict), 'report' "
        "(identification_report.json as a dict; None when no joint was identified), "
        "'joint_error_fit_percent' (held-out fit of each joint's table) and 'failures' (empty "
        "where identified). robot (a robot file) and gravity_m_s2 (in the robot base) give the "
        "rigid-body model of a config with the model-torque input, as --robot and "
        "--gravity-m-s2 do.");
  m.def("model_torques", &model_torques, "robot"_a, "q_desired_rad"_a, "payload_kg"_a, "cycle_s"_a,
        "gravity_m_s2"_a = std::array<double, 3>{0.0, 0.0, -kStandardGravity_m_s2},
        "table"_a = std::string(),
        "The joint torques [N m] (N, 6) of the robot file's rigid-body model along a desired path "
        "(N, 6) [rad] with its payload (N,) [kg] sampled every cycle_s, as `imscal compensate "
        "--robot` feeds them to Precontrol.step for a table with the model-torque input. With "
        "table (a parameters.json), the links its identification refined take its masses and "
        "centres of mass, as compensate does.");
  py::class_<PythonPrecontrol>(m, "Precontrol",
                               "The online error compensation on a parameters.json, one step() "
                               "per controller cycle (as `imscal compensate` runs it).")
      .def(py::init<const std::string&, const std::string&, double, bool, double>(), "table"_a,
           "robot"_a = "", "caller_cycle_s"_a = 0.002, "auto_engage"_a = true,
           "offset_tolerance_rad"_a = 0.0)
      .def("step", &PythonPrecontrol::step, "q_desired_rad"_a, "payload_kg"_a, "cycle"_a,
           "model_torque_nm"_a = py::none(),
           "One cycle: the 6 desired joint angles [rad] (preview_cycles ahead for an "
           "inverse-form table), the payload [kg], the cycle number and, for a table with the "
           "model-torque input (needs_model_torque), the model's 6 joint torques [N m] at the "
           "same sample (model_torques); without them such a table deactivates (missing "
           "torque). Returns (offset_rad (6,), state, outside_table).")
      .def("events", &PythonPrecontrol::events, "The supervisor's events since the last call.")
      .def("reactivate", &PythonPrecontrol::reactivate)
      .def_property_readonly("preview_cycles", &PythonPrecontrol::preview_cycles)
      .def_property_readonly("needs_model_torque", &PythonPrecontrol::needs_model_torque);
}

}  // namespace imscal::python
