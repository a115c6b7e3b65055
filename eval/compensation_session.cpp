#include "eval/compensation_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

#include "core/input_error.hpp"
#include "core/payload_plausibility.hpp"
#include "ident/parameter_table_io.hpp"
#include "ident/precontrol.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"

namespace imscal::eval {

namespace {

// The joint torques of the robot's rigid-body model along the log's desired path
// ([joint][sample]; eval/model_torque.hpp), for a table whose models take them.
std::vector<std::vector<double>> model_torques(const CompensationSessionOptions& args,
                                               const ident::ParameterTable& table,
                                               const calib::RobotLog& log) {
  if (!args.model_torque)
    throw InputError(args.table, 0, "extra_inputs", "no rigid-body model given");
  const ModelTorqueSource model = with_table_links(
      args.model_torque(log.robot_name, args.robot_log, args.table, "extra_inputs"), table,
      args.table);
  const std::size_t n = log.samples.size();
  std::vector<std::vector<double>> q(calib::kJointCount, std::vector<double>(n));
  std::vector<double> payload(n);
  for (std::size_t k = 0; k < n; ++k) {
    payload[k] = log.samples[k].payload_kg;
    for (int j = 0; j < calib::kJointCount; ++j)
      q[std::size_t(j)][k] = log.samples[k].q_desired_rad[j];
  }
  const std::vector<std::pair<std::size_t, std::size_t>> whole{{0, n}};
  return model_torques_along(model, log.cycle_s, q, payload, whole);
}

// The log's payload against the rating the table was identified for: the upper bound of its
// payload cells, or, for a table without payload cells, the rating in --robot's file.
void check_log_payload(const CompensationSessionOptions& args, const ident::ParameterTable& table,
                       const calib::RobotLog& log) {
  double rated_kg = 0.0;
  std::string rating_of;
  for (const ident::CellDimension& d :
       table.joints.empty() ? std::vector<ident::CellDimension>{} : table.joints.front().dimensions)
    if (d.quantity == ident::OperatingQuantity::kPayload) {
      rated_kg = d.bounds.back();
      rating_of =
          fmt::format("the parameter table {} (its payload cells' upper bound)", args.table);
    }
  if (rated_kg <= 0.0 && !args.robot.empty()) {
    const auto robot = calib::load_robot_description(args.robot);
    rated_kg = robot.nominal_payload_kg;
    rating_of = fmt::format("robot {} ({})", robot.name, robot.source);
  }
  std::vector<double> payload, t;
  for (const auto& sample : log.samples) {
    payload.push_back(sample.payload_kg);
    t.push_back(sample.t_s);
  }
  check_payload_series(payload, t, rated_kg, {args.robot_log, 0, "payload_kg", rating_of});
}

// The offsets file's header: what made it and its columns.
std::string offsets_header(const CompensationSessionOptions& args, const calib::RobotLog& log) {
  std::ostringstream csv;
  csv << "# imscal-offsets: 1\n# robot: " << log.robot_name << "\n# cycle_s: " << log.cycle_s
      << "\n# table: " << args.table << "\n# robot_log: " << args.robot_log
      << "\nt_s,state,outside_table";
  for (const auto& name : log.joint_names) csv << ",offset_" << name << "_rad";
  csv << "\n";
  return csv.str();
}

// One cycle's row, its events logged.
std::string run_cycle(ident::Precontrol& precontrol, const calib::RobotLog& log, std::size_t k,
                      std::size_t preview, const std::vector<std::vector<double>>& torque,
                      CompensationRunSummary& summary) {
  const auto& s = log.samples[k];
  const std::size_t ahead = std::min(log.samples.size() - 1, k + preview);
  std::array<double, ident::kPrecontrolJoints> q{}, tau{};
  for (int j = 0; j < ident::kPrecontrolJoints; ++j) {
    q[std::size_t(j)] = log.samples[ahead].q_desired_rad[j];
    if (!torque.empty()) tau[std::size_t(j)] = torque[std::size_t(j)][ahead];
  }
  // Cycle numbers from the time stamps: a lost cycle in the log reaches the supervisor.
  const auto cycle = static_cast<std::uint64_t>(std::llround(s.t_s / log.cycle_s));
  const ident::PrecontrolOutput out =
      torque.empty() ? precontrol.cycle(q, log.samples[ahead].payload_kg, cycle)
                     : precontrol.cycle(q, log.samples[ahead].payload_kg, tau, cycle);
  summary.active_cycles += out.state == ident::PrecontrolState::kActive;
  std::string row =
      fmt::format("{},{},{}", s.t_s, ident::to_string(out.state), out.outside_table ? 1 : 0);
  for (double o : out.offset_rad) row += fmt::format(",{}", o);
  row += "\n";
  std::array<ident::PrecontrolEvent, ident::kPrecontrolEventCapacity> events{};
  const int n = precontrol.read_events(events.data(), int(events.size()));
  for (int i = 0; i < n; ++i) {
    ++summary.events;
    const ident::PrecontrolEvent& e = events[std::size_t(i)];
    spdlog::warn("precontrol event at t = {} s (cycle {}): joint {}: {} (value {})", s.t_s, e.cycle,
                 e.joint < 0 ? std::string("all") : log.joint_names[std::size_t(e.joint)],
                 ident::to_string(e.cause), e.value);
  }
  return row;
}

}  // namespace

CompensationRunSummary compensate_robot_log(const CompensationSessionOptions& args) {
  const ident::ParameterTable table = ident::read_parameters_json(args.table);
  const calib::RobotLog log =
      calib::read_robot_log_csv(args.robot_log, table.robot, "the parameter table " + args.table);
  check_log_payload(args, table, log);
  if (!args.robot.empty())
    calib::check_robot_log_joint_limits(log, args.robot_log,
                                        calib::load_robot_description(args.robot));
  ident::PrecontrolOptions options;
  options.caller_cycle_s = log.cycle_s;
  // A log may start in the middle of a motion, and a fault need not end the run: the precontrol
  // engages smoothly and re-engages (ident/precontrol.hpp, auto_engage).
  options.auto_engage = true;
  if (args.offset_tolerance_rad > 0.0) options.offset_tolerance_rad.fill(args.offset_tolerance_rad);
  auto precontrol = std::make_unique<ident::Precontrol>();
  std::string why;
  if (!ident::Precontrol::create(table, log.robot_name, options, precontrol.get(), &why)) {
    throw InputError(args.table, 0, "", "the precontrol refuses this table: " + why);
  }
  CompensationRunSummary summary;
  summary.offsets_csv = offsets_header(args, log);
  summary.cycles = log.samples.size();
  const std::vector<std::vector<double>> torque = precontrol->needs_model_torque()
                                                      ? model_torques(args, table, log)
                                                      : std::vector<std::vector<double>>{};
  // An inverse-form table is fed the desired path preview_cycles ahead (the interpolator's
  // look-ahead online; the log's later samples here, the last one held).
  const auto preview = static_cast<std::size_t>(table.preview_cycles);
  for (std::size_t k = 0; k < log.samples.size(); ++k)
    summary.offsets_csv += run_cycle(*precontrol, log, k, preview, torque, summary);
  return summary;
}

}  // namespace imscal::eval
