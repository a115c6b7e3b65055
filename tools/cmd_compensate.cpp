// `imscal compensate`: the precontrol (ident/precontrol.hpp) run offline on a robot log: for every
// controller cycle of robot.csv the offsets Δq̂ it would hand to the controller, with its state,
// and the supervisor's events. The same calls a controller integrator makes online.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>
#include <sstream>

#include "calib/robot_log.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "ident/parameter_table_io.hpp"
#include "ident/precontrol.hpp"
#include "tools/command_registry.hpp"

namespace {
namespace ident = imscal::ident;

struct CompensateArgs {
  std::string table, robot_log, out;
  double offset_tolerance_rad = 0.0;  // 0: the precontrol's default
  bool force = false;
};

const char* state_name(ident::PrecontrolState s) {
  switch (s) {
    case ident::PrecontrolState::kActive:
      return "active";
    case ident::PrecontrolState::kFadingOut:
      return "fading_out";
    case ident::PrecontrolState::kInactive:
      return "inactive";
  }
  return "?";
}

void run(const CompensateArgs& args) {
  if (!args.force && std::filesystem::exists(args.out)) {
    throw imscal::InputError(args.out, 0, "", "output exists; use --force to overwrite it");
  }
  const ident::ParameterTable table = ident::read_parameters_json(args.table);
  const imscal::calib::RobotLog log =
      imscal::calib::read_robot_log_csv(args.robot_log, table.robot);
  ident::PrecontrolOptions options;
  options.caller_cycle_s = log.cycle_s;
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
  for (std::size_t k = 0; k < log.samples.size(); ++k) {
    const auto& s = log.samples[k];
    std::array<double, ident::kPrecontrolJoints> q{};
    for (int j = 0; j < ident::kPrecontrolJoints; ++j) q[std::size_t(j)] = s.q_desired_rad[j];
    // Cycle numbers from the time stamps: a lost cycle in the log reaches the supervisor.
    const auto cycle = static_cast<std::uint64_t>(std::llround(s.t_s / log.cycle_s));
    const ident::PrecontrolOutput out = precontrol->cycle(q, s.payload_kg, cycle);
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
      sub.add_option("--out", args->out, "offsets.csv")->required();
      sub.add_option("--offset-tolerance-rad", args->offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint [rad] (default 0.005)");
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
