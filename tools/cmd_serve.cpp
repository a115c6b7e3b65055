// `imscal serve`: the precontrol (ident/precontrol.hpp) online behind KUKA RSI or ABB EGM: binds a
// UDP port, answers every controller datagram (online/udp_server.hpp) with the joint corrections
// of a parameter table, the IPOC echoed (RSI: online/rsi_session.hpp), or with the program's path
// plus the corrections, the seqno echoed (EGM position guidance: online/egm_session.hpp), and
// logs every fault and supervisor event. Runs until interrupted (SIGINT/SIGTERM) or, with
// --idle-timeout-s, until the controller stops sending.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <memory>
#include <stdexcept>

#include "core/input_error.hpp"
#include "eval/model_torque.hpp"
#include "ident/parameter_table_io.hpp"
#include "online/egm_session.hpp"
#include "online/path_follower.hpp"
#include "online/rsi_session.hpp"
#include "online/udp_server.hpp"
#include "online/udp_socket.hpp"
#include "robot/robot_log.hpp"
#include "tools/command_registry.hpp"
#include "tools/model_torque_option.hpp"

namespace {
namespace ident = imscal::ident;
namespace online = imscal::online;

std::atomic<bool> g_stop{false};

extern "C" void request_stop(int) {
  g_stop = true;
}

struct ServeArgs {
  std::string protocol = "rsi", table, bind = "0.0.0.0", mode = "absolute", path;
  imscal::tools::ModelTorqueOption model_torque;  // for tables with the model-torque input
  int port = 0;
  online::RsiSessionOptions session;
  online::EgmSessionOptions egm;
  double cycle_ms = 4.0, late_ms = 0.0, idle_timeout_s = 0.0;
  double offset_tolerance_rad = 0.0;
  double max_setpoint_speed_deg_s = 1000.0;
  // With a loaded path the precontrol is fed this many table cycles beyond the table's preview:
  // the delay of its smoother (2 tau = 8 ms), as `imscal verify` does (eval/verification.hpp).
  int look_ahead_cycles = 4;
  std::string path_clock = "motion";  // online/path_follower.hpp: "motion" or "stream"
};

// The robot program's desired path (a robot log: q_desired and payload per sample), with the
// model torque along it when the table's models take it (eval/model_torque.hpp, as `imscal
// compensate`), for a table with a preview or the model torque (decision 0024).
online::LoadedPath load_path(const ServeArgs& args, const ident::ParameterTable& table) {
  const imscal::calib::RobotLog log = imscal::calib::read_robot_log_csv(
      args.path, table.robot, "the parameter table " + args.table);
  if (!args.model_torque.robot.empty())
    imscal::calib::check_robot_log_joint_limits(
        log, args.path, imscal::calib::load_robot_description(args.model_torque.robot));
  online::LoadedPath path;
  path.cycle_s = log.cycle_s;
  const std::size_t n = log.samples.size();
  std::vector<std::vector<double>> q(imscal::calib::kJointCount, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    std::array<double, online::kPathJoints> sample{};
    for (int j = 0; j < online::kPathJoints; ++j) {
      sample[std::size_t(j)] = log.samples[k].q_desired_rad[j];
      q[std::size_t(j)][k] = sample[std::size_t(j)];
    }
    path.q_rad.push_back(sample);
    path.payload_kg.push_back(log.samples[k].payload_kg);
  }
  const bool needs_torque = std::find(table.extra_inputs.begin(), table.extra_inputs.end(),
                                      ident::TableInput::kModelTorque) != table.extra_inputs.end();
  if (needs_torque) {
    const imscal::eval::ModelTorqueSource model =
        args.model_torque.source(log.robot_name, args.path, args.table, "extra_inputs");
    const std::vector<std::pair<std::size_t, std::size_t>> whole{{0, n}};
    const auto torque =
        imscal::eval::model_torques_along(model, log.cycle_s, q, path.payload_kg, whole);
    path.torque_nm.resize(n);
    for (std::size_t k = 0; k < n; ++k)
      for (int j = 0; j < online::kPathJoints; ++j)
        path.torque_nm[k][std::size_t(j)] = torque[std::size_t(j)][k];
  }
  return path;
}

// How far ahead of the set-point the precontrol is fed [s].
double ahead_s(const ServeArgs& args, const ident::ParameterTable& table) {
  return (table.preview_cycles + args.look_ahead_cycles) * table.sample_time_s;
}

// RSI: the path followed by the controller's IPOC.
std::unique_ptr<online::PathFollower> follow_path(const ServeArgs& args,
                                                  const ident::ParameterTable& table) {
  online::LoadedPath path = load_path(args, table);
  try {
    online::PathFollowerOptions follow;
    follow.clock_from_first_datagram = args.path_clock == "stream";
    return std::make_unique<online::PathFollower>(std::move(path), args.cycle_ms * 1e-3,
                                                  ahead_s(args, table), follow);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError(args.path, 0, "cycle_s", e.what());
  }
}

// Without a loaded path the table must not need one: RSI sends the current set-point only.
void check_servable_without_path(const std::string& file, const ident::ParameterTable& table) {
  if (table.preview_cycles > 0) {
    throw imscal::InputError(
        file, 0, "preview_cycles",
        "the table needs the desired path " + std::to_string(table.preview_cycles) +
            " cycles ahead, which RSI does not send: give the program's path (--path robot.csv) "
            "or serve a table without preview (docs/decisions/0024)");
  }
  for (ident::TableInput input : table.extra_inputs) {
    if (input == ident::TableInput::kModelTorque) {
      throw imscal::InputError(file, 0, "extra_inputs",
                               "the table's models take the model torque along the desired path: "
                               "give the program's path (--path robot.csv) and --robot");
    }
  }
}

void log_events(online::DatagramSession& session, bool egm) {
  std::array<online::SessionFaultEvent, 32> faults{};
  const char* counter = egm ? "EGM: seqno" : "RSI: IPOC";
  for (int n; (n = session.read_faults(faults.data(), int(faults.size()))) > 0;) {
    for (int i = 0; i < n; ++i) {
      const online::SessionFaultEvent& f = faults[std::size_t(i)];
      if (f.fault == online::SessionFault::kMalformed) {
        spdlog::warn("{}: malformed datagram refused: {}", egm ? "EGM" : "RSI",
                     egm ? online::to_string(static_cast<online::EgmParseError>(f.detail))
                         : online::to_string(static_cast<online::RsiParseError>(f.detail)));
      } else {
        spdlog::warn("{} {}: {} (value {})", counter, f.counter, online::to_string(f.fault),
                     f.value);
      }
    }
  }
  std::array<ident::PrecontrolEvent, 32> events{};
  for (int n; (n = session.precontrol().read_events(events.data(), int(events.size()))) > 0;) {
    for (int i = 0; i < n; ++i) {
      const ident::PrecontrolEvent& e = events[std::size_t(i)];
      spdlog::info("precontrol: cycle {}: {}: {} (value {})", e.cycle,
                   e.joint < 0 ? std::string("all joints") : fmt::format("A{}", e.joint + 1),
                   ident::to_string(e.cause), e.value);
    }
  }
}

ident::PrecontrolOptions precontrol_options(const ServeArgs& args) {
  ident::PrecontrolOptions precontrol;
  if (args.offset_tolerance_rad > 0.0)
    precontrol.offset_tolerance_rad.fill(args.offset_tolerance_rad);
  precontrol.max_input_speed_rad_s = args.max_setpoint_speed_deg_s * M_PI / 180.0;
  return precontrol;
}

std::unique_ptr<online::DatagramSession> rsi_session(ServeArgs& args,
                                                     const ident::ParameterTable& table) {
  std::unique_ptr<online::PathFollower> path;
  if (args.path.empty()) {
    check_servable_without_path(args.table, table);
  } else {
    path = follow_path(args, table);
  }
  args.session.mode = args.mode == "increment" ? online::RsiCorrectionMode::kIncrement
                                               : online::RsiCorrectionMode::kAbsolute;
  args.session.cycle_s = args.cycle_ms * 1e-3;
  args.session.late_after_s = args.late_ms * 1e-3;
  std::string why;
  auto session = online::RsiSession::create(table, table.robot, precontrol_options(args),
                                            args.session, &why, std::move(path));
  if (!session) throw imscal::InputError(args.table, 0, "", "cannot serve this table: " + why);
  return session;
}

// EGM position guidance: the server plays the program's path (docs/decisions/0033).
std::unique_ptr<online::DatagramSession> egm_session(ServeArgs& args,
                                                     const ident::ParameterTable& table) {
  if (args.path.empty())
    throw imscal::InputError("--path", 0, "",
                             "EGM position guidance streams the program's desired path: give it "
                             "(--path robot.csv)");
  args.egm.cycle_s = args.cycle_ms * 1e-3;
  args.egm.late_after_s = args.late_ms * 1e-3;
  args.egm.payload_kg = args.session.payload_kg;
  std::string why;
  auto session = online::EgmSession::create(table, table.robot, precontrol_options(args), args.egm,
                                            load_path(args, table), ahead_s(args, table), &why);
  if (!session) throw imscal::InputError(args.path, 0, "", "cannot serve this path: " + why);
  return session;
}

void run(ServeArgs args) {
  const ident::ParameterTable table = ident::read_parameters_json(args.table);
  const bool egm = args.protocol == "egm";
  std::unique_ptr<online::DatagramSession> session =
      egm ? egm_session(args, table) : rsi_session(args, table);
  try {
    (void)online::udp_peer(args.bind, 0);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError("--bind", 0, "", e.what());
  }
  online::UdpSocket socket(args.bind, static_cast<std::uint16_t>(args.port));
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  spdlog::info(
      "serve: {} on {}:{}, {}, cycle {} ms, table {} ({})", egm ? "EGM" : "RSI", args.bind,
      socket.port(),
      egm ? std::string("position guidance along ") + args.path : args.mode + " corrections",
      args.cycle_ms, args.table, table.robot);
  online::UdpServerOptions options;
  options.idle_timeout_s = args.idle_timeout_s;
  const online::UdpServerStats stats =
      online::serve_udp(socket, *session, g_stop, options, [&] { log_events(*session, egm); });
  log_events(*session, egm);
  spdlog::info("serve: {} datagrams, {} answered, {} not answered", stats.datagrams, stats.answered,
               stats.not_answered);
}

imscal::tools::CommandRegistration registration{
    "serve",
    "Serve the precontrol online to a robot controller: KUKA RSI (UDP, XML) or ABB EGM (UDP, "
    "protocol buffers)",
    [](CLI::App& sub) {
      auto args = std::make_shared<ServeArgs>();
      sub.add_option("--protocol", args->protocol, "rsi (default) or egm")
          ->check(CLI::IsMember({"rsi", "egm"}));
      sub.add_option("--table", args->table, "parameters.json (imscal identify)")->required();
      sub.add_option("--port", args->port, "UDP port the controller sends to")
          ->required()
          ->check(CLI::Range(0, 65535));
      sub.add_option("--bind", args->bind, "local IPv4 address to bind (default all)");
      sub.add_option("--mode", args->mode, "AKorr as the RSI configuration sums it")
          ->check(CLI::IsMember({"absolute", "increment"}));
      sub.add_option("--path", args->path,
                     "the program's desired path (robot.csv): RSI follows it by IPOC (needed by "
                     "tables with a preview or the model torque); EGM streams it (required)");
      sub.add_option("--start-tolerance-rad", args->egm.start_tolerance_rad,
                     "EGM: the robot is at the path's first pose within this, per joint")
          ->check(CLI::PositiveNumber);
      sub.add_option("--track-tolerance-rad", args->egm.track_tolerance_rad,
                     "EGM: a measured joint farther from its target is a fault")
          ->check(CLI::PositiveNumber);
      args->model_torque.add_to(sub);
      sub.add_option(
             "--look-ahead-cycles", args->look_ahead_cycles,
             "with --path: table cycles fed ahead beyond the preview (default 4, as verify)")
          ->check(CLI::Range(0, 32));
      sub.add_option("--path-clock", args->path_clock,
                     "with --path: start its clock at the motion from its start pose, or with the "
                     "stream's first datagram (a path recorded from RSI_ON)")
          ->check(CLI::IsMember({"motion", "stream"}));
      sub.add_option("--robot-type", args->session.robot_type,
                     "Type attribute of <Rob> expected (default: any)");
      sub.add_option("--sensor-type", args->session.sensor_type,
                     "Type attribute of the answer's <Sen>");
      sub.add_option("--cycle-ms", args->cycle_ms, "RSI cycle (4 or 12 ms)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--ipoc-per-cycle", args->session.ipoc_per_cycle,
                     "IPOC advance per cycle (default 4: milliseconds at 4 ms)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--payload-kg", args->session.payload_kg, "payload for the operating point")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--late-ms", args->late_ms,
                     "a datagram this much later than the cycle is a fault (0: not checked)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--max-setpoint-speed-deg-s", args->max_setpoint_speed_deg_s,
                     "a faster set-point change is a jump (fault)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--offset-tolerance-rad", args->offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint (default: the table's envelope)");
      sub.add_option("--idle-timeout-s", args->idle_timeout_s,
                     "stop when no datagram came for this long (0: run until interrupted)")
          ->check(CLI::NonNegativeNumber);
      sub.callback([args] { run(*args); });
    }};
}  // namespace
