// `imscal serve`: the precontrol (ident/precontrol.hpp) online behind KUKA RSI: binds a UDP port,
// answers every controller datagram with the joint corrections of a parameter table, the IPOC
// echoed (online/rsi_server.hpp, online/rsi_session.hpp), and logs every fault and supervisor
// event. Runs until interrupted (SIGINT/SIGTERM) or, with --idle-timeout-s, until the controller
// stops sending.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <memory>
#include <stdexcept>

#include "core/input_error.hpp"
#include "ident/parameter_table_io.hpp"
#include "online/rsi_server.hpp"
#include "online/rsi_session.hpp"
#include "online/udp_socket.hpp"
#include "tools/command_registry.hpp"

namespace {
namespace ident = imscal::ident;
namespace online = imscal::online;

std::atomic<bool> g_stop{false};

extern "C" void request_stop(int) {
  g_stop = true;
}

struct ServeArgs {
  std::string table, robot, bind = "0.0.0.0", mode = "absolute";
  int port = 0;
  online::RsiSessionOptions session;
  double cycle_ms = 4.0, late_ms = 0.0, idle_timeout_s = 0.0;
  double offset_tolerance_rad = 0.0;
  double max_setpoint_speed_deg_s = 1000.0;
};

// The table, refused when the interface cannot feed its models: RSI sends the current set-point
// only, neither the preview an inverse-form table needs nor the model torque (decision 0024).
ident::ParameterTable servable_table(const std::string& file) {
  ident::ParameterTable table = ident::read_parameters_json(file);
  if (table.preview_cycles > 0) {
    throw imscal::InputError(
        file, 0, "preview_cycles",
        "the table needs the desired path " + std::to_string(table.preview_cycles) +
            " cycles ahead, which RSI does not send; identify a table without preview for "
            "serving (model.form: joint-error, see docs/decisions/0024)");
  }
  for (ident::TableInput input : table.extra_inputs) {
    if (input == ident::TableInput::kModelTorque) {
      throw imscal::InputError(file, 0, "extra_inputs",
                               "the table's models take the model torque, which `serve` does not "
                               "compute; identify without model.model_torque for serving");
    }
  }
  return table;
}

void log_events(online::RsiSession& session) {
  std::array<online::RsiFaultEvent, 32> faults{};
  for (int n; (n = session.read_faults(faults.data(), int(faults.size()))) > 0;) {
    for (int i = 0; i < n; ++i) {
      const online::RsiFaultEvent& f = faults[std::size_t(i)];
      if (f.fault == online::RsiFault::kMalformed) {
        spdlog::warn("RSI: malformed datagram refused: {}",
                     online::to_string(static_cast<online::RsiParseError>(f.detail)));
      } else {
        spdlog::warn("RSI: IPOC {}: {} (value {})", f.ipoc, online::to_string(f.fault), f.value);
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

void run(ServeArgs args) {
  const ident::ParameterTable table = servable_table(args.table);
  args.session.mode = args.mode == "increment" ? online::RsiCorrectionMode::kIncrement
                                               : online::RsiCorrectionMode::kAbsolute;
  args.session.cycle_s = args.cycle_ms * 1e-3;
  args.session.late_after_s = args.late_ms * 1e-3;
  ident::PrecontrolOptions precontrol;
  if (args.offset_tolerance_rad > 0.0)
    precontrol.offset_tolerance_rad.fill(args.offset_tolerance_rad);
  precontrol.max_input_speed_rad_s = args.max_setpoint_speed_deg_s * M_PI / 180.0;
  std::string why;
  const std::string robot = args.robot.empty() ? table.robot : args.robot;
  std::unique_ptr<online::RsiSession> session =
      online::RsiSession::create(table, robot, precontrol, args.session, &why);
  if (!session) throw imscal::InputError(args.table, 0, "", "cannot serve this table: " + why);
  try {
    (void)online::udp_peer(args.bind, 0);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError("--bind", 0, "", e.what());
  }
  online::UdpSocket socket(args.bind, static_cast<std::uint16_t>(args.port));
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  spdlog::info("serve: RSI on {}:{}, {} corrections, cycle {} ms, table {} ({})", args.bind,
               socket.port(), args.mode, args.cycle_ms, args.table, robot);
  online::RsiServerOptions options;
  options.idle_timeout_s = args.idle_timeout_s;
  const online::RsiServerStats stats =
      online::serve_rsi(socket, *session, g_stop, options, [&] { log_events(*session); });
  log_events(*session);
  spdlog::info("serve: {} datagrams, {} answered, {} not answered", stats.datagrams, stats.answered,
               stats.not_answered);
}

imscal::tools::CommandRegistration registration{
    "serve", "Serve the precontrol online to a KUKA controller over RSI (UDP, XML)",
    [](CLI::App& sub) {
      auto args = std::make_shared<ServeArgs>();
      sub.add_option("--table", args->table, "parameters.json (imscal identify; no preview)")
          ->required();
      sub.add_option("--port", args->port, "UDP port the controller sends to")
          ->required()
          ->check(CLI::Range(0, 65535));
      sub.add_option("--bind", args->bind, "local IPv4 address to bind (default all)");
      sub.add_option("--mode", args->mode, "AKorr as the RSI configuration sums it")
          ->check(CLI::IsMember({"absolute", "increment"}));
      sub.add_option("--robot", args->robot, "robot the table must be for (default: the table's)");
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
