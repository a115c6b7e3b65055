// `imscal compensate`: the precontrol (ident/precontrol.hpp) run offline on a robot log: for every
// controller cycle of robot.csv the offsets Δq̂ it would hand to the controller, with its state,
// and the supervisor's events. The same calls a controller integrator makes online.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

#include "calib/robot_description.hpp"
#include "calib/robot_log.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "eval/model_torque.hpp"
#include "ident/parameter_table_io.hpp"
#include "ident/precontrol.hpp"
#include "tools/command_registry.hpp"
#include "tools/model_torque_option.hpp"

namespace {
namespace ident = imscal::ident;

struct CompensateArgs {
  std::string table, robot_log, out;
  imscal::tools::ModelTorqueOption model_torque;  // for tables with the model-torque input
  double offset_tolerance_rad = 0.0;              // 0: the precontrol's default
  bool force = false;
};

// The joint torques of the robot's rigid-body model along the log's desired path
// ([joint][sample]; eval/model_torque.hpp), for a table whose models take them.
std::vector<std::vector<double>> model_torques(const CompensateArgs& args,
                                               const imscal::calib::RobotLog& log) {
  const imscal::eval::ModelTorqueSource model =
      args.model_torque.source(log.robot_name, args.robot_log, args.table, "extra_inputs");
  const std::size_t n = log.samples.size();
  std::vector<std::vector<double>> q(imscal::calib::kJointCount, std::vector<double>(n));
  std::vector<double> payload(n);
  for (std::size_t k = 0; k < n; ++k) {
    payload[k] = log.samples[k].payload_kg;
    for (int j = 0; j < imscal::calib::kJointCount; ++j)
      q[std::size_t(j)][k] = log.samples[k].q_desired_rad[j];
  }
  const std::vector<std::pair<std::size_t, std::size_t>> whole{{0, n}};
  return imscal::eval::model_torques_along(model, log.cycle_s, q, payload, whole);
}

// The log's payload against the rating the table was identified for: the upper bound of its
// payload cells, or, for a table without payload cells, the rating in --robot's file.
void check_log_payload(const CompensateArgs& args, const ident::ParameterTable& table,
                       const imscal::calib::RobotLog& log) {
  double rated_kg = 0.0;
  std::string rating_of;
  for (const ident::CellDimension& d :
       table.joints.empty() ? std::vector<ident::CellDimension>{} : table.joints.front().dimensions)
    if (d.quantity == ident::OperatingQuantity::kPayload) {
      rated_kg = d.bounds.back();
      rating_of =
          fmt::format("the parameter table {} (its payload cells' upper bound)", args.table);
    }
  if (rated_kg <= 0.0 && !args.model_torque.robot.empty()) {
    const auto robot = imscal::calib::load_robot_description(args.model_torque.robot);
    rated_kg = robot.nominal_payload_kg;
    rating_of = fmt::format("robot {} ({})", robot.name, robot.source);
  }
  std::vector<double> payload, t;
  for (const auto& sample : log.samples) {
    payload.push_back(sample.payload_kg);
    t.push_back(sample.t_s);
  }
  imscal::check_payload_series(payload, t, rated_kg, {args.robot_log, 0, "payload_kg", rating_of});
}

const char* state_name(ident::PrecontrolState s) {
  switch (s) {
    case ident::PrecontrolState::kActive:
      return "active";
    case ident::PrecontrolState::kFadingOut:
      return "fading_out";
    case ident::PrecontrolState::kInactive:
      return "inactive";
    case ident::PrecontrolState::kEngaging:
      return "engaging";
  }
  return "?";
}

void run(const CompensateArgs& args) {
  imscal::prepare_output_file(args.out,
                              args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  const ident::ParameterTable table = ident::read_parameters_json(args.table);
  const imscal::calib::RobotLog log = imscal::calib::read_robot_log_csv(
      args.robot_log, table.robot, "the parameter table " + args.table);
  check_log_payload(args, table, log);
  if (!args.model_torque.robot.empty())
    imscal::calib::check_robot_log_joint_limits(
        log, args.robot_log, imscal::calib::load_robot_description(args.model_torque.robot));
  ident::PrecontrolOptions options;
  options.caller_cycle_s = log.cycle_s;
  // A log may start in the middle of a motion, and a fault need not end the run: the precontrol
  // engages smoothly and re-engages (ident/precontrol.hpp, auto_engage).
  options.auto_engage = true;
  if (args.offset_tolerance_rad > 0.0) options.offset_tolerance_rad.fill(args.offset_tolerance_rad);
  auto precontrol = std::make_unique<ident::Precontrol>();
  std::string why;
  if (!ident::Precontrol::create(table, log.robot_name, options, precontrol.get(), &why)) {
    throw imscal::InputError(args.table, 0, "", "the precontrol refuses this table: " + why);
  }
  std::ostringstream csv;
  csv << "# imscal-offsets: 1\n# robot: " << log.robot_name << "\n# cycle_s: " << log.cycle_s
      << "\n# table: " << args.table << "\n# robot_log: " << args.robot_log
      << "\nt_s,state,outside_table";
  for (const auto& name : log.joint_names) csv << ",offset_" << name << "_rad";
  csv << "\n";
  std::array<ident::PrecontrolEvent, ident::kPrecontrolEventCapacity> events{};
  std::size_t active = 0, event_count = 0;
  const std::vector<std::vector<double>> torque = precontrol->needs_model_torque()
                                                      ? model_torques(args, log)
                                                      : std::vector<std::vector<double>>{};
  // An inverse-form table is fed the desired path preview_cycles ahead (the interpolator's
  // look-ahead online; the log's later samples here, the last one held).
  const auto preview = static_cast<std::size_t>(table.preview_cycles);
  for (std::size_t k = 0; k < log.samples.size(); ++k) {
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
        torque.empty() ? precontrol->cycle(q, log.samples[ahead].payload_kg, cycle)
                       : precontrol->cycle(q, log.samples[ahead].payload_kg, tau, cycle);
    active += out.state == ident::PrecontrolState::kActive;
    csv << fmt::format("{},{},{}", s.t_s, state_name(out.state), out.outside_table ? 1 : 0);
    for (double o : out.offset_rad) csv << fmt::format(",{}", o);
    csv << "\n";
    const int n = precontrol->read_events(events.data(), int(events.size()));
    for (int i = 0; i < n; ++i) {
      ++event_count;
      spdlog::warn("precontrol event at t = {} s (cycle {}): joint {}: {} (value {})", s.t_s,
                   events[std::size_t(i)].cycle,
                   events[std::size_t(i)].joint < 0
                       ? std::string("all")
                       : log.joint_names[std::size_t(events[std::size_t(i)].joint)],
                   ident::to_string(events[std::size_t(i)].cause), events[std::size_t(i)].value);
    }
  }
  imscal::write_file_atomically(
      args.out, csv.str(), args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  spdlog::info("compensate: {} cycles, {} active, {} events; wrote {}", log.samples.size(), active,
               event_count, args.out);
}

imscal::tools::CommandRegistration registration{
    "compensate", "Run the precontrol on a robot log: the offsets per cycle with their state",
    [](CLI::App& sub) {
      auto args = std::make_shared<CompensateArgs>();
      sub.add_option("--table", args->table, "parameters.json (imscal identify)")->required();
      sub.add_option("--robot-log", args->robot_log, "robot.csv (desired joints, payload)")
          ->required();
      args->model_torque.add_to(sub);
      sub.add_option("--out", args->out, "offsets.csv")->required();
      sub.add_option("--offset-tolerance-rad", args->offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint [rad] (default 0.005)");
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
